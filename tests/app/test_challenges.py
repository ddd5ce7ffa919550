"""Predict, then play: the challenge set and one session's folder, driven as a browser does
(through a probe).

* A set has eight challenges from easy to hard, the same for the same seed; every answer is
  the theory's, checked here by independent means: flip or stay against DOP853 (does the
  spin's component change sign), the first flip against DOP853's, the twin's lag against the
  two exact motions.
* No flip-or-stay question names its axis or its outcome.
* "Start the challenge" loads the challenge's own body paused at t = 0, with the readouts, the
  plot and the I₂ mark withheld and play refused; an answer not chosen (or not typed, or not a
  number) is answered with a message and the challenge stays; a right answer loads the
  challenge's motion at t = 0, reveals the theory and counts in the score.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import session_of, wait_until
from scipy.integrate import solve_ivp

from poinsot.app.live.lecture import challenges
from poinsot.app.live.lecture.challenge_set import (
    AXES,
    CHOOSE,
    OUTCOMES,
    challenge_set,
    parse_time,
)
from poinsot.app.live.session.rebuild import WITHHELD
from poinsot.app.model.elements import Control, Plot
from poinsot.app.model.parameters import drawn_solid
from poinsot.app.model.presets import T_HANDLE
from poinsot.physics import FreeRigidBody
from poinsot.physics.models.flip import integrated_flip_times
from poinsot.physics.models.twins import measured_lag


def _dop853_zeros(J: np.ndarray, w0: np.ndarray, axis: int, t_end: float) -> np.ndarray:
    """The zeros of ω_axis in a DOP853 integration of Euler's equations (rtol 1e-12)."""

    def euler(_t: float, w: np.ndarray) -> np.ndarray:
        return np.array(
            [
                (J[1] - J[2]) * w[1] * w[2] / J[0],
                (J[2] - J[0]) * w[2] * w[0] / J[1],
                (J[0] - J[1]) * w[0] * w[1] / J[2],
            ]
        )

    def zero(_t: float, w: np.ndarray) -> float:
        return float(w[axis])

    sol = solve_ivp(euler, (0.0, t_end), w0, "DOP853", rtol=1e-12, atol=1e-14, events=zero)
    return np.asarray(sol.t_events[0])


@pytest.mark.parametrize("seed", [0, 1, 19])
def test_a_set_is_seeded_and_its_answers_meet_independent_references(seed: int) -> None:
    one, again = challenge_set(seed), challenge_set(seed)
    assert 6 <= len(one) <= 10
    assert [c.prompt for c in one] == [c.prompt for c in again]
    assert [c.kind for c in one] == ["axis"] * 4 + ["time"] * 2 + ["lag"] * 2
    for c in one:
        J, w0 = np.asarray(c.params.inertia), np.asarray(c.params.omega0 or c.params.build().omega0)
        if c.kind == "axis":
            flips, axis = c.answer  # type: ignore[misc]
            body = c.params.build()
            caller_axis = int(np.argsort(J)[axis])
            assert caller_axis == int(np.argmax(np.abs(J * body.omega0)))
            # DOP853: the spin's component changes sign within a period iff it flips
            times = _dop853_zeros(J, body.omega0, caller_axis, 1.05 * body.period)
            assert (len(times) > 0) == flips, c.title
        elif c.kind == "time":
            dop = integrated_flip_times(J, w0, 1.5 * c.answer)  # type: ignore[operator]
            assert c.answer == pytest.approx(dop[0], rel=1e-7)
        else:
            first = FreeRigidBody(J, w0)
            w1 = w0.copy()
            eps = float(np.arctan2(w0[0], w0[1]))
            w1[0], w1[1] = 2.0 * np.sin(eps / c.twin_ratio), 2.0 * np.cos(eps / c.twin_ratio)
            lag = measured_lag(first, FreeRigidBody(J, w1), 3.0 * c.answer + 50.0)  # type: ignore[operator]
            assert c.answer == pytest.approx(lag, rel=1e-9)
    assert challenge_set(seed + 1)[3].params != one[3].params or seed == 0


def test_a_time_is_read_as_people_type_it() -> None:
    assert parse_time(" 7,5 ") == 7.5 and parse_time("1e1") == 10.0
    for bad in ("soon", "", "nan", "-3"):
        with pytest.raises(ValueError):
            parse_time(bad)


def _markdowns(probe) -> str:
    return "\n".join(str(w.props.get("_markdown", "")) for w in probe.widgets.values())


def _settled(session) -> None:
    """Every action posted so far has run, and the rebuild it asked for: the frame thread
    reads, in order behind them, whether a rebuild is due and how many were applied; if one is
    due, the count must pass that (a rebuild counts once it is applied, not as it begins)."""
    marker: list[tuple[bool, int]] = []
    session.post(lambda: marker.append((session.build.dirty, session.build.generation)))
    assert wait_until(lambda: bool(marker), 20)
    due, applied = marker[0]
    if due:
        assert wait_until(lambda: session.build.generation > applied, 20)


def test_the_questions_name_neither_their_axis_nor_their_outcome() -> None:
    for seed in (0, 7):
        for c in challenge_set(seed):
            text = f"{c.title} {c.prompt} {c.body}".lower()
            for giveaway in ("largest", "smallest", "middle axis", "intermediate", "flips"):
                if c.kind == "axis":
                    assert giveaway not in text, (c.title, giveaway)
            assert "stable" not in text and "dzhanibekov" not in text, c.title


def test_answer_then_play_in_a_session(poinsot_app, probe) -> None:
    session = session_of(poinsot_app)
    assert probe.wait_for(lambda p: challenges.START in p.labels(), 15)
    folder = session.lecture.challenges
    assert folder is not None
    probe.set_value(probe.widget(challenges.START)[0], True)
    assert wait_until(lambda: folder.started, 10)
    _settled(session)
    first = folder.current
    assert first.kind == "axis"
    assert session.preset.withheld and session.clock.paused and session.frame.t == 0.0
    assert session.panel.motion.readouts.content == WITHHELD
    assert probe.wait_for(lambda p: p.widget("Flip or stay?")[1].value == CHOOSE, 10)
    # Answer without a choice: refused, with a message, not scored
    probe.set_value(probe.widget(challenges.PLAY)[0], True)
    assert wait_until(lambda: "choose an outcome" in folder.message.content.lower(), 10)
    assert not folder.revealed and folder.answered == 0
    flips, axis = first.answer  # type: ignore[misc]
    probe.set_value(probe.widget("Flip or stay?")[0], OUTCOMES[0 if flips else 1])
    probe.set_value(probe.widget("About which axis?")[0], AXES[axis])
    assert wait_until(lambda: folder.axis.value == AXES[axis], 10)
    probe.set_value(probe.widget(challenges.PLAY)[0], True)
    assert wait_until(lambda: folder.revealed, 10)
    reveal = folder.reveal
    assert wait_until(
        lambda: "Right!" in reveal.content and first.explanation in reveal.content, 30
    )
    assert folder.score == folder.answered == 1
    assert wait_until(lambda: session.params == first.params, 10)  # its motion plays
    assert wait_until(lambda: not session.clock.paused and not session.preset.withheld, 10)
    readouts = session.panel.motion.readouts
    assert wait_until(lambda: "regime" in readouts.content, 30)
    # the next three, all answered "it stays, about e₁": the score counts the right ones
    for n in range(2, 5):
        probe.set_value(probe.widget(challenges.NEXT)[0], True)
        assert wait_until(lambda: not folder.revealed and folder.axis.value == CHOOSE, 10)
        probe.set_value(probe.widget("Flip or stay?")[0], OUTCOMES[1])
        probe.set_value(probe.widget("About which axis?")[0], AXES[0])
        assert wait_until(lambda: folder.axis.value == AXES[0], 10)
        probe.set_value(probe.widget(challenges.PLAY)[0], True)
        assert wait_until(lambda n=n: folder.answered == n, 10)
    right = 1 + sum(c.answer == (False, 0) for c in folder.challenges[1:4])
    assert folder.score == right
    # The count is taken before the scoreboard is written: wait for the board.
    assert wait_until(lambda: f"Score: **{right} / 4**" in folder.scoreboard.content, 10), (
        folder.scoreboard.content
    )
    probe.set_value(probe.widget(challenges.NEXT)[0], True)
    assert wait_until(lambda: not folder.revealed, 10)
    assert folder.current.kind == "time"
    probe.set_value(probe.widget(challenges.PLAY)[0], True)  # nothing typed: refused
    assert wait_until(lambda: "type a time first" in folder.message.content.lower(), 10)
    probe.set_value(probe.widget(challenges.ANSWER)[0], "soon")
    probe.set_value(probe.widget(challenges.PLAY)[0], True)
    assert wait_until(lambda: "not a number" in folder.message.content, 10)
    assert not folder.revealed and folder.answered == 4
    assert session.stats.errors == 0, session.stats.last_error


def test_each_challenge_draws_its_body_paused_at_zero_and_keeps_its_secret(
    poinsot_app, probe
) -> None:
    session = session_of(poinsot_app)
    folder = session.lecture.challenges
    assert folder is not None
    folder.begin()
    for n, c in enumerate(folder.challenges):
        _settled(session)
        assert folder.index == n and not folder.revealed
        shown = session.preset
        assert shown.withheld and shown.label == challenges.LABEL, n
        assert session.clock.paused and session.frame is not None and session.frame.t == 0.0
        assert session.params == c.params
        expected = c.solid if c.solid is not None else drawn_solid(c.params.inertia, shown, ())
        assert session.build.solid == expected, c.title
        if "T-handle" in c.title:
            assert session.build.solid is T_HANDLE
        assert Plot.OMEGA not in session.panel.groups  # no plot to read the answer off
        assert not ({Control.ENERGY, Control.INERTIA} & session.panel.groups)  # no I₂ mark
        assert session.panel.motion.readouts.content == WITHHELD
        assert probe.wait_for(lambda p: WITHHELD in _markdowns(p), 10)
        page = _markdowns(probe)
        for secret in (c.explanation, c.shown(), "regime", "Your own body", "Custom (edited)"):
            assert secret not in page, (c.title, secret)
        session.toggle_pause()  # play is refused until the answer is in
        _settled(session)
        assert session.clock.paused and "Answer the challenge first" in session.status
        folder.revealed = True  # as an answer does (the reveal itself is tested above)
        folder.go_on()
    assert session.stats.errors == 0, session.stats.last_error
