"""physics.integrators.Propagation: a method advanced piece by piece with its whole state carried
(what the app's numerical ghost draws frame by frame) is the same solution as one
:func:`~physics.integrators.integrate` call, whatever the pieces, and its work per call is
bounded."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from poinsot.physics.core.errors import attitude_error, energy, relative_drift
from poinsot.physics.integrators import INTEGRATORS, Propagation, integrate

INERTIA = np.array([1.0, 2.0, 2.6])
OMEGA0 = np.array([0.35, 0.4, 1.1])
ATTITUDE0 = Rotation.from_rotvec([0.3, -0.2, 0.5])
SETTINGS = {"RK45": 1e-3, "DOP853": 1e-6, "splitting": 0.05, "midpoint": 0.05}
#: Frame-sized pieces: 1/60 of a time unit, a hundred periods' worth of frames is too many for
#: a unit test; 30 time units (about 3 periods) in 1800 pieces.
FRAME = 1.0 / 60.0
SPAN = 30.0

PIECES_EQUAL_ADAPTIVE = 0.0
"""The adaptive pairs take the very steps of solve_ivp and read its dense output: identical."""
PIECES_EQUAL_FIXED = 1e-12
"""Fixed-step methods carry omega (not m = I omega) between pieces: one rounding of m / I per
piece, ~1e-16 each over 1800 pieces, well below this."""


def angle(a: Rotation, b: Rotation) -> float:
    return float(attitude_error(a, b))


ADAPTIVE = [name for name, i in INTEGRATORS.items() if i.kind == "adaptive"]
FIXED = [name for name, i in INTEGRATORS.items() if i.kind == "fixed"]


@pytest.mark.parametrize("method", ADAPTIVE)
def test_adaptive_frame_by_frame_is_one_integrate_call(method):
    setting = SETTINGS[method]
    prop = Propagation(method, INERTIA, OMEGA0, ATTITUDE0, setting)
    times = FRAME * np.arange(1, int(SPAN / FRAME) + 1)
    states = [prop.advance(t) for t in times]
    check = np.arange(299, len(times), 300)
    # A far last output time: solve_ivp then never shortens a step before the checked times.
    ref = integrate(method, INERTIA, OMEGA0, ATTITUDE0, np.append(times[check], 1e3), setting)
    for i, k in enumerate(check):
        assert states[k].t == times[k]
        np.testing.assert_allclose(
            states[k].omega, ref.omega[i], rtol=0, atol=PIECES_EQUAL_ADAPTIVE
        )
        assert angle(states[k].attitude, ref.attitude[i]) <= 1e-15
    assert states[-1].cost < ref.cost  # the far output time costs integrate() extra steps


@pytest.mark.parametrize("method", FIXED)
def test_fixed_step_frame_by_frame_is_one_integrate_call(method):
    """At grid times t = k h, frame by frame equals integrate() with its equal steps of h."""
    h = SETTINGS[method]
    prop = Propagation(method, INERTIA, OMEGA0, ATTITUDE0, h)
    grid = h * np.array([1, 37, 200, 599])
    times = np.sort(np.concatenate([FRAME * np.arange(1, int(SPAN / FRAME) + 1), grid]))
    states = {t: prop.advance(t) for t in times}
    ref = integrate(method, INERTIA, OMEGA0, ATTITUDE0, grid, h)
    for i, t in enumerate(grid):
        np.testing.assert_allclose(states[t].omega, ref.omega[i], rtol=0, atol=PIECES_EQUAL_FIXED)
        assert angle(states[t].attitude, ref.attitude[i]) <= PIECES_EQUAL_FIXED
    assert prop.cost == int(times[-1] / h + 1e-9)  # the whole steps carried, no more


@pytest.mark.parametrize("method", list(INTEGRATORS))
def test_the_solution_does_not_depend_on_how_often_it_is_looked_at(method):
    """Frames at 60 Hz, at 7 Hz or one jump: the same state at the end (the shorter step that
    reaches a time between grid points is not carried)."""
    setting = SETTINGS[method]
    finals = []
    for dt in (FRAME, 1.0 / 7.0, SPAN):
        prop = Propagation(method, INERTIA, OMEGA0, ATTITUDE0, setting)
        for t in np.arange(dt, SPAN, dt):
            prop.advance(t)
        finals.append(prop.advance(SPAN))
    for state in finals[1:]:
        np.testing.assert_allclose(state.omega, finals[0].omega, rtol=0, atol=1e-12)
        assert angle(state.attitude, finals[0].attitude) < 1e-12


def test_restarting_each_frame_would_hide_the_drift():
    """Why the state is carried: RK45 at rtol 1e-3, restarted from its own state at every frame,
    is forced to take >= 1 step per frame and is orders of magnitude more accurate than the
    same method run once (which is what the ghost must show)."""
    carried = Propagation("RK45", INERTIA, OMEGA0, ATTITUDE0, 1e-3)
    omega, attitude = OMEGA0, ATTITUDE0
    for t in FRAME * np.arange(1, int(SPAN / FRAME) + 1):
        state = carried.advance(t)
        run = integrate("RK45", INERTIA, omega, attitude, [FRAME], 1e-3)
        omega, attitude = run.omega[0], run.attitude[0]
    energy0 = float(energy(INERTIA, OMEGA0))
    carried_error = relative_drift(energy(INERTIA, state.omega), energy0)
    restarted_error = relative_drift(energy(INERTIA, omega), energy0)
    assert carried_error > 1e-5
    assert restarted_error < carried_error / 100


@pytest.mark.parametrize("method", list(INTEGRATORS))
def test_the_work_of_one_call_is_capped(method):
    prop = Propagation(method, INERTIA, OMEGA0, ATTITUDE0, SETTINGS[method])
    state = prop.advance(1e4, max_cost=20)
    assert state.t < 1e4
    # A fixed-step call stops at the cap; an adaptive one within its last step (<= 13 RHS
    # evaluations for DOP853, plus rejected attempts).
    assert state.cost <= 20 + (0 if INTEGRATORS[method].kind == "fixed" else 40)
    assert prop.t == pytest.approx(state.t)
    again = prop.advance(1e4, max_cost=20)
    assert again.t > state.t  # and the next call continues from there
    assert np.all(np.isfinite(again.omega))


@pytest.mark.parametrize("method", list(INTEGRATORS))
def test_a_later_start_is_the_same_motion_shifted(method):
    """The free body's equations do not depend on t: starting at t0 = 7.5 is starting at 0."""
    setting = SETTINGS[method]
    late = Propagation(method, INERTIA, OMEGA0, ATTITUDE0, setting, t0=7.5).advance(7.5 + 4.0)
    early = Propagation(method, INERTIA, OMEGA0, ATTITUDE0, setting).advance(4.0)
    assert late.t == pytest.approx(11.5)
    np.testing.assert_allclose(late.omega, early.omega, rtol=0, atol=1e-12)
    assert angle(late.attitude, early.attitude) < 1e-12


@pytest.mark.parametrize("method", list(INTEGRATORS))
def test_the_start_and_going_back(method):
    prop = Propagation(method, INERTIA, OMEGA0, ATTITUDE0, SETTINGS[method], t0=2.0)
    start = prop.advance(2.0)
    # No step yet (scipy's stepper evaluates the RHS twice to choose its first step).
    assert start.t == 2.0 and start.cost <= 2
    np.testing.assert_array_equal(start.omega, OMEGA0)
    assert angle(start.attitude, ATTITUDE0) < 1e-15
    prop.advance(20.0)
    with pytest.raises(ValueError, match="before"):
        prop.advance(3.0)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"method": "Euler"}, "unknown method"),
        ({"inertia": (1.0, -2.0, 3.0)}, "inertia"),
        ({"omega0": (np.nan, 0.0, 1.0)}, "omega0"),
        ({"setting": 0.0}, "setting"),
        ({"t0": np.inf}, "t0"),
    ],
)
def test_bad_input_raises_readable_value_error(kwargs, message):
    args = {"method": "RK45", "inertia": INERTIA, "omega0": OMEGA0, **kwargs}
    with pytest.raises(ValueError, match=message):
        Propagation(**args)
