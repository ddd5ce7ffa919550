"""Predict, then play in a real browser at 1280×800: each of the eight challenges draws its own
body paused at t = 0 and shows none of its answer before it is answered (the page's whole text
and the readouts are read), an answer not chosen is refused with a message, and the verdict and
"Next challenge" are on screen once the answer is in."""

from __future__ import annotations

import re

import pytest
from conftest import BrowserPage, session_of, wait_until

from poinsot.app.live.lecture import challenges
from poinsot.app.live.lecture.challenge_set import AXES, HANDLE, OUTCOMES, Challenge
from poinsot.app.live.session.rebuild import WITHHELD
from poinsot.app.model.parameters import drawn_solid
from poinsot.app.model.presets import T_HANDLE

pytestmark = pytest.mark.browser

#: Words that tell an answer, or name a body the challenge is not.
TELLS = ("regime", "polhode around", "separatrix (unstable)", "Your own body", "Custom (edited)")
#: The time readout of a challenge's body, both parts in one reading: the answered challenge's
#: replay also showed "t = 0.00" (running), and "paused" may reach the page a window later.
AT_START = re.compile(r"t = 0\.00\b.*paused")


def _in_view(page: BrowserPage, text: str) -> bool:
    """The button or text ``text`` is wholly inside the 800 px high viewport."""
    box = page.page.get_by_role("button", name=text, exact=True).bounding_box()
    return box is not None and box["y"] >= 0 and box["y"] + box["height"] <= 800


def _time_shown(page: BrowserPage) -> str:
    loc = page.page.locator("p").filter(has_text=re.compile(r"t = +-?\d"))
    return loc.first.inner_text()


def _answer(page: BrowserPage, folder, c: Challenge) -> None:
    """The right answer, given from the page's own widgets."""
    if c.kind == "axis":
        flips, axis = c.answer  # type: ignore[misc]
        page.choose("Flip or stay?", OUTCOMES[0 if flips else 1])
        page.choose("About which axis?", AXES[axis])
        assert wait_until(lambda: folder.axis.value == AXES[axis], 10)
    else:
        label = f"//label[normalize-space()='{challenges.ANSWER}']"  # viser's text box: no id
        box = page.page.locator(f"xpath={label}/ancestor::div[.//input][1]//input")
        box.fill(f"{c.answer:.6g}")
        box.press("Tab")
        assert wait_until(lambda: folder.time.value == f"{c.answer:.6g}", 10)
    page.click_button(challenges.PLAY)


def test_each_challenge_keeps_its_secret_until_answered(make_app, open_page) -> None:
    app = make_app()
    page = open_page(app.url, width=1280, height=800, live_view=False)  # reads no pixels
    session = session_of(app)
    assert wait_until(lambda: session.stats.frames > 20, 20)
    folder = session.lecture.challenges
    assert folder is not None
    page.open_folder(challenges.FOLDER)
    page.click_button(challenges.START)
    for n, c in enumerate(folder.challenges):
        page.page.get_by_text(f"{n + 1} of 8: {c.title}").wait_for(timeout=20000)
        # Its body built (the last challenge's, replayed from t = 0 once answered, may still be
        # at t = 0 on a loaded machine: the time alone does not tell the two apart).
        assert wait_until(
            lambda: (
                session.build.params == c.params  # noqa: B023
                and session.frame is not None
                and session.frame.t == 0.0
            ),
            20,
        ), (c.title, session.build.params, c.params)
        assert session.preset.withheld and session.clock.paused
        # its own body: the T-handle draws the T-handle, the box the box
        expected = c.solid or drawn_solid(c.params.inertia, session.preset, ())
        assert session.build.solid == expected, c.title
        assert (c.body == HANDLE) == (session.build.solid is T_HANDLE), c.title
        page.page.get_by_text(WITHHELD.strip("_")).wait_for(timeout=20000)
        assert wait_until(lambda: AT_START.search(_time_shown(page)), 20), _time_shown(page)
        text = page.page.locator("body").inner_text()
        for secret in (*TELLS, c.explanation, c.shown()):
            assert secret not in text, (c.title, secret)
        assert page.page.get_by_role("img", name=re.compile("ω in the body frame")).count() == 0
        # pressing Answer without an answer is refused, not scored
        page.click_button(challenges.PLAY)
        refusal = "choose an outcome" if c.kind == "axis" else "type a time first"
        page.page.get_by_text(re.compile(refusal, re.I)).wait_for(timeout=15000)
        assert folder.answered == n and not folder.revealed
        _answer(page, folder, c)
        page.page.get_by_text("Right!").wait_for(state="visible", timeout=20000)
        assert wait_until(lambda: _in_view(page, challenges.NEXT), 15), c.title
        verdict = page.page.get_by_text("Right!").bounding_box()
        assert verdict is not None and 0 <= verdict["y"] <= 800 - verdict["height"]
        assert folder.score == folder.answered == n + 1
        page.click_button(challenges.NEXT)
    assert set(page.errors) <= {challenges_drag_binding()}, page.errors
    assert session.stats.errors == 0, session.stats.last_error


def challenges_drag_binding() -> str:
    """viser's drag binding on the ellipsoid answers a mouse press so (as in the pointer's)."""
    return "Unable to preventDefault inside passive event listener invocation."
