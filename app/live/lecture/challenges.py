"""Predict, then play: the challenges of :mod:`~poinsot.app.live.lecture.challenge_set` in a folder
of the control panel, one browser's own.

"Start the challenge" (or the menu's "A challenge's body") loads the challenge's own body (the
T-handle draws the T-handle), paused at t = 0, and keeps its secret while the student predicts:
the readouts say they are hidden, no ω plot, no whole polhode, no body sliders (the D slider's I₂
mark would tell), play and step refused, no regime in the caption or the source line. The
student answers (flip or stay and the axis from two lists that start at "choose…", or a time
typed in a text box) and presses "Answer, then play": an answer not chosen, or a time that is
not a number, is answered with a message and the challenge stays; otherwise the same body is
loaded again at t = 0 with all it tells, and plays (the twins in the Dzhanibekov scene), the
verdict appears where the answer was, with the theory's answer and the sentence that explains
it, and the page scrolls "Next challenge" into view. "Next challenge" loads the next body, paused
at t = 0; after the last the set starts again. The panel above the folder is the same in both
phases, so the verdict does not move.

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
    CHOOSE,
    OUTCOMES,
    Challenge,
    challenge_set,
    parse_time,
)
from poinsot.app.live.panel.clock import SimClock
from poinsot.app.live.panel.widgets import on_user, set_value
from poinsot.app.model.elements import ALL_ELEMENTS, STANDARD_PLOTS, Control, Element
from poinsot.app.model.presets import Preset
from poinsot.app.viser_private import scroll_to_button

#: Order of the folder in the control panel (after the lecture tools).
FOLDER_ORDER = 95.0
FOLDER = "Predict, then play"
START = "Start the challenge"
ANSWER = "Your answer (time units)"
PLAY = "Answer, then play"
NEXT = "Next challenge"
#: The menu's entry for a challenge's body, and its heading.
LABEL = "A challenge's body"
MENU_GROUP = "Predict, then play"
#: Before the first start: what the folder is.
INTRO = (
    "Eight questions, from easy to hard. Each draws its body at t = 0, paused; predict what "
    "it does, then watch it."
)
#: The caption over the legend while a challenge's body is shown.
CAPTION = (
    "A challenge: predict how this body moves (the panel's 'Predict, then play' folder); "
    "the readouts and the plot of ω come with the answer."
)
#: The panel's groups of a challenge's body, the same before and after the answer (the folder's
#: place stays): no sliders of the body (the D slider's I₂ mark would tell the answer).
CONTROLS = frozenset({Control.SPEED, Control.PLAYBACK, Control.TRAIL, Control.VISIBILITY})
#: Its elements, the same before and after: not the whole polhode (its loop tells the answer).
ELEMENTS = ALL_ELEMENTS - {Element.POLHODE_FULL}


class ChallengeSession(Protocol):
    """What the challenges use of a session (each call only posts to its queue)."""

    client: viser.ClientHandle
    clock: SimClock

    def add_menu_entry(self, group: str, label: str, choose: Callable[[], None]) -> None: ...
    def show_playback(self) -> None: ...
    def choose_preset(self, preset: Preset) -> None: ...

    def choose_scene(self, scene: SceneSpec) -> None: ...

    def post(self, action: Callable[[], None], key: object = None) -> None: ...


def body_preset(challenge: Challenge, number: int, revealed: bool) -> Preset:
    """The preset that shows ``challenge``'s body (its ``number`` in the set, from 1): before
    the answer (``revealed`` False) with what tells the answer withheld."""
    p = challenge.params
    return Preset(
        key="challenge",
        label=LABEL,
        source=f"challenge {number}: {challenge.body}",
        inertia=p.inertia,
        D=p.D,
        pole_sign=p.pole_sign,
        omega_norm=p.omega_norm,
        omega0=p.omega0,
        trail_points=2400,
        solid=challenge.solid,
        elements=ELEMENTS,
        controls=CONTROLS,
        plots=STANDARD_PLOTS if revealed else frozenset(),
        caption=CAPTION if not revealed else f"The challenge's motion: {challenge.shown()}.",
        challenge=True,
        withheld=not revealed,
    )


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
        self.started = self.revealed = False
        gui = session.client.gui
        with gui.add_folder(FOLDER, order=order, expand_by_default=False):
            # The question, then what answers it: a refusal, or the verdict and "Next", where
            # the answer's widgets were (on screen where the student just pressed).
            self.question = gui.add_markdown(INTRO)
            self.start = gui.add_button(START, icon=viser.Icon.PLAYER_PLAY)
            self.message = gui.add_markdown("")
            self.reveal = gui.add_markdown("")
            self.next = gui.add_button(NEXT, visible=False)
            self.outcome = gui.add_dropdown("Flip or stay?", (CHOOSE, *OUTCOMES), visible=False)
            self.axis = gui.add_dropdown("About which axis?", (CHOOSE, *AXES), visible=False)
            self.time = gui.add_text(ANSWER, "", visible=False)
            self.play = gui.add_button(PLAY, icon=viser.Icon.PLAYER_PLAY, visible=False)
            self.scoreboard = gui.add_markdown("")
        on_user(self.start, lambda _: self.begin(), self._report)
        on_user(self.play, lambda _: self.answer(), self._report)
        on_user(self.next, lambda _: self.go_on(), self._report)
        session.add_menu_entry(MENU_GROUP, LABEL, self.begin)

    @property
    def current(self) -> Challenge:
        return self.challenges[self.index]

    def _report(self, exc: Exception) -> None:
        self.message.content = f"**Could not do that:** {exc}"

    def begin(self) -> None:
        """Show the current challenge: its body loaded at t = 0 (paused until the answer)."""
        with self._lock:
            self.started = True
            self._show_question()
            self._load(self.current, revealed=self.revealed)
        self._scroll_to(NEXT if self.revealed else PLAY)

    def _show_question(self) -> None:
        c = self.current
        n = len(self.challenges)
        self.question.content = f"**{self.index + 1} of {n}: {c.title}**\n\n{c.prompt}"
        timed = c.kind != "axis"
        asking = not self.revealed
        self.outcome.visible = self.axis.visible = asking and not timed
        self.time.visible = asking and timed
        self.play.visible, self.next.visible, self.start.visible = asking, not asking, False
        if asking:  # a new question: nothing chosen yet
            self.reveal.content = ""
            set_value(self.outcome, CHOOSE)
            set_value(self.axis, CHOOSE)
            set_value(self.time, "")
        self.message.content = ""
        self.scoreboard.content = self._score_text()

    def _score_text(self) -> str:
        return f"Score: **{self.score} / {self.answered}** (this session only)"

    def guess(self) -> tuple[bool, int] | float:
        """The student's answer to the current challenge (ValueError: not one)."""
        if self.current.kind != "axis":
            return parse_time(str(self.time.value))
        outcome, axis = str(self.outcome.value), str(self.axis.value)
        if outcome not in OUTCOMES or axis not in AXES:
            raise ValueError("choose an outcome and an axis from the lists first")
        return outcome == OUTCOMES[0], AXES.index(axis)

    def answer(self) -> None:
        """Judge the answer, then play the challenge's motion from t = 0 and reveal the
        theory's; an answer not given is refused with a message (not scored)."""
        with self._lock:
            if self.revealed or not self.started:
                return
            try:
                guess = self.guess()
            except ValueError as exc:
                reason = str(exc)
                self.message.content = (
                    f"**{reason[:1].upper()}{reason[1:]}.** The challenge stays: answer, then play."
                )
                return
            c = self.current
            right = c.judge(guess)
            self.answered += 1
            self.score += int(right)
            self.revealed = True
            verdict = "Right!" if right else "Not quite."
            self.reveal.content = (
                f"**{verdict}** You said: {c.shown(guess)}. The theory: **{c.shown()}**.\n\n"
                f"{c.explanation}"
            )
            self._show_question()
            self._load(c, revealed=True)
        self._scroll_to(NEXT)

    def _load(self, challenge: Challenge, revealed: bool) -> None:
        """The challenge's body at t = 0 (every choice of a preset rebuilds it from t = 0):
        paused while the student predicts, playing once the answer is in (all posted)."""
        session = self.session
        if not revealed:  # paused first: the body comes at t = 0 and stays there
            session.post(lambda: self._run(paused=True))
        if revealed and challenge.kind == "lag" and challenge.twin_ratio == 10.0:
            session.choose_scene(scene_by_name("dzhanibekov"))  # its defaults: ε, ε/10
        else:
            number = self.index + 1
            session.choose_preset(body_preset(challenge, number, revealed))
        if revealed:  # played from t = 0 once it is there
            session.post(lambda: self._run(paused=False))

    def _scroll_to(self, button: str) -> None:
        """The page scrolls ``button`` into view, after the widgets the body's choice adds
        above it (posted behind it: the session's queue runs in order)."""
        client = self.session.client
        self.session.post(lambda: scroll_to_button(client, button, FOLDER))

    def _run(self, paused: bool) -> None:
        """(Session thread) The clock paused or playing, as the playback buttons show."""
        self.session.clock.paused = paused
        self.session.show_playback()

    def go_on(self) -> None:
        """The next challenge (after the last, the first again), its body paused at t = 0."""
        with self._lock:
            if not self.revealed:
                return
            self.index = (self.index + 1) % len(self.challenges)
            self.revealed = False
            self._show_question()
            self._load(self.current, revealed=False)
        self._scroll_to(PLAY)


def add_challenges(session: ChallengeSession) -> ChallengeControls:
    """Mount the challenges on ``session``'s control panel."""
    return ChallengeControls(session)
