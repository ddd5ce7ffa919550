"""Predict, then play: the challenges of :mod:`~poinsot.app.live.lecture.challenge_set` in a folder
of the control panel, one browser's own.

The student reads a challenge, answers it (flip or stay and the axis from two dropdowns, or a
time typed in a text box) and presses "Answer, then play": the motion of the challenge is
loaded at t = 0 and plays (the twins in the Dzhanibekov scene), and the answer the theory
gives is shown beside the prediction with the sentence that explains it, and the score. A
time that is not a number is answered with a message and the challenge stays. "Next
challenge" goes on; after the last the set starts again.

The set is drawn from a seed of this session's own; the score lives in this object only
(nothing is stored on the server beyond the session). Callbacks run on viser's worker threads
and only post to the session's queue (:class:`ChallengeSession`); the state is under a lock.
"""

from __future__ import annotations

import secrets
import threading
from collections.abc import Callable
from typing import Protocol

import viser

from poinsot.app.lessons import scene_by_name
from poinsot.app.lessons.support.spec import SceneSpec
from poinsot.app.live.lecture.challenge_set import (
    AXES,
    OUTCOMES,
    Challenge,
    challenge_set,
    parse_time,
)
from poinsot.app.live.panel.clock import SimClock
from poinsot.app.live.panel.widgets import on_user
from poinsot.app.model.parameters import Parameters
from poinsot.app.model.presets import CUSTOM, Preset

#: Order of the folder in the control panel (after the lecture tools).
FOLDER_ORDER = 95.0
FOLDER = "Predict, then play"
ANSWER = "Your answer (time units)"
PLAY = "Answer, then play"
NEXT = "Next challenge"


class ChallengeSession(Protocol):
    """What the challenges use of a session (each call only posts to its queue)."""

    client: viser.ClientHandle
    clock: SimClock

    def choose_preset(self, preset: Preset) -> None: ...

    def choose_scene(self, scene: SceneSpec) -> None: ...

    def edit(self, change: Callable[[Parameters], Parameters]) -> None: ...

    def toggle_pause(self) -> None: ...


class ChallengeControls:
    """The folder, the set and the score of one session."""

    def __init__(
        self, session: ChallengeSession, seed: int | None = None, order: float = FOLDER_ORDER
    ) -> None:
        self.session = session
        self.seed = secrets.randbits(32) if seed is None else int(seed)
        self.challenges = challenge_set(self.seed)
        self._lock = threading.Lock()
        self.index = self.score = self.answered = 0
        self.revealed = False
        gui = session.client.gui
        with gui.add_folder(FOLDER, order=order, expand_by_default=False):
            self.question = gui.add_markdown("")
            self.outcome = gui.add_dropdown("Flip or stay?", OUTCOMES)
            self.axis = gui.add_dropdown("About which axis?", AXES)
            self.time = gui.add_text(ANSWER, "")
            self.play = gui.add_button(PLAY, icon=viser.Icon.PLAYER_PLAY)
            self.message = gui.add_markdown("")
            self.reveal = gui.add_markdown("")
            self.next = gui.add_button(NEXT, visible=False)
            self.scoreboard = gui.add_markdown("")
        on_user(self.play, lambda _: self.answer(), self._report)
        on_user(self.next, lambda _: self.go_on(), self._report)
        with self._lock:
            self._show_question()

    @property
    def current(self) -> Challenge:
        return self.challenges[self.index]

    def _report(self, exc: Exception) -> None:
        self.message.content = f"**Could not do that:** {exc}"

    def _show_question(self) -> None:
        c = self.current
        n = len(self.challenges)
        self.question.content = f"**{self.index + 1} of {n}: {c.title}**\n\n{c.prompt}"
        timed = c.kind != "axis"
        self.outcome.visible = self.axis.visible = not timed
        self.time.visible = timed
        self.play.visible, self.next.visible = True, False
        self.message.content = self.reveal.content = ""
        self.scoreboard.content = self._score_text()

    def _score_text(self) -> str:
        return f"Score: **{self.score} / {self.answered}** (this session only)"

    def guess(self) -> tuple[bool, int] | float:
        """The student's answer to the current challenge (ValueError: not one)."""
        if self.current.kind != "axis":
            return parse_time(str(self.time.value))
        outcome, axis = str(self.outcome.value), str(self.axis.value)
        if outcome not in OUTCOMES or axis not in AXES:
            raise ValueError("choose an outcome and an axis from the lists")
        return outcome == OUTCOMES[0], AXES.index(axis)

    def answer(self) -> None:
        """Judge the answer, then play the challenge's motion and reveal the theory's."""
        with self._lock:
            if self.revealed:
                return
            try:
                guess = self.guess()
            except ValueError as exc:
                self.message.content = f"**{exc}.** The challenge stays: try again."
                return
            c = self.current
            right = c.judge(guess)
            self.answered += 1
            self.score += int(right)
            self.revealed = True
            verdict = "Right!" if right else "Not quite."
            self.message.content = ""
            self.reveal.content = (
                f"**{verdict}** You said: {c.shown(guess)}. The theory: **{c.shown()}**.\n\n"
                f"{c.explanation}"
            )
            self.play.visible, self.next.visible = False, True
            self.scoreboard.content = self._score_text()
            self._play(c)

    def _play(self, challenge: Challenge) -> None:
        """Load the challenge's motion at t = 0 and run the clock (all posted)."""
        if challenge.kind == "lag" and challenge.twin_ratio == 10.0:
            self.session.choose_scene(scene_by_name("dzhanibekov"))  # its defaults: ε, ε/10
        else:
            self.session.choose_preset(CUSTOM)
            self.session.edit(_replace_with(challenge.params))
        if self.session.clock.paused:
            self.session.toggle_pause()

    def go_on(self) -> None:
        """The next challenge (after the last, the first again)."""
        with self._lock:
            if not self.revealed:
                return
            self.index = (self.index + 1) % len(self.challenges)
            self.revealed = False
            self._show_question()


def _replace_with(params: Parameters) -> Callable[[Parameters], Parameters]:
    """An edit that replaces the session's parameters by ``params``."""
    return lambda _old: params


def add_challenges(session: ChallengeSession) -> ChallengeControls:
    """Mount the challenges on ``session``'s control panel."""
    return ChallengeControls(session)
