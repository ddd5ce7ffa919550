"""Predict, then play in a real browser: a student answers the first challenge from the page's
own widgets and sees the reveal (the theory's answer and its sentence) and the score."""

from __future__ import annotations

import pytest
from conftest import session_of, wait_until

from poinsot.app.live.lecture import challenges
from poinsot.app.live.lecture.challenge_set import AXES, OUTCOMES

pytestmark = pytest.mark.browser


def test_a_student_answers_a_challenge_and_sees_the_reveal_and_the_score(make_app, open_page):
    app = make_app()
    page = open_page(app.url, width=1280, height=800, live_view=False)
    session = session_of(app)
    assert wait_until(lambda: session.stats.frames > 20, 20)
    folder = session.lecture.challenges
    assert folder is not None
    first = folder.current
    flips, axis = first.answer  # type: ignore[misc]
    page.open_folder(challenges.FOLDER)
    page.page.get_by_text(first.prompt).wait_for(state="visible", timeout=15000)
    page.choose("Flip or stay?", OUTCOMES[0 if flips else 1])
    page.choose("About which axis?", AXES[axis])
    page.click_button(challenges.PLAY)
    page.page.get_by_text("Right!").wait_for(state="visible", timeout=15000)
    page.page.get_by_text(first.explanation).wait_for(state="visible", timeout=15000)
    page.page.get_by_text("1 / 1").wait_for(state="visible", timeout=15000)
    assert folder.score == folder.answered == 1
    assert wait_until(lambda: session.params == first.params, 10)
    page.page.get_by_role("button", name=challenges.NEXT, exact=True).wait_for(timeout=15000)
    assert page.errors == []
    assert session.stats.errors == 0, session.stats.last_error
