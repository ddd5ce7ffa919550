"""The game engines' rotation steps (:data:`GAME_STEPS`) against the exact solution, the flip
verdicts of :mod:`physics.integrators.engine_check`, and the step budget of the adaptive pairs.

References: the exact solution (elliptic functions) and, for the flips, the elliptic flip clock
of :func:`physics.models.flip.flip_theory` (2K/λ between flips), not the code under test.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from poinsot.physics import FreeRigidBody
from poinsot.physics.integrators import GAME_STEPS, INTEGRATORS, METHODS, Propagation, integrate
from poinsot.physics.integrators.engine_check import exact_flip_times, flip_times, run_flips
from poinsot.physics.models.flip import flip_theory

EPS = float(np.finfo(float).eps)
ORDER_SLOPE_TOL = 0.15
"""|fitted slope - order| in log(error) vs log(h) over a factor 8 of steps; a first-order term
left in RK4 (a wrong stage weight) or a missing term in a first-order step shows as a slope one
off."""

#: The generic body of the integrator tests (a uniform 1x2x3 box) with a tilted attitude.
INERTIA = np.array([13.0, 10.0, 5.0])
OMEGA0 = np.array([0.3, 0.6, 0.9])
ATTITUDE0 = Rotation.from_rotvec([0.4, -1.1, 0.7])

#: A T-handle flicked near its middle axis at 12 rad/s (~2 turns a second), ε = 0.05 rad.
T_HANDLE = np.array([1.0, 2.2782, 3.1839])
FLICK = 12.0 * np.array([math.sin(0.05), math.cos(0.05), 0.0])


def test_game_steps_are_registered_apart_from_the_study():
    assert set(GAME_STEPS) == {"no-gyro", "gyro-explicit", "gyro-implicit", "jolt", "rk4"}
    assert {n: i.order for n, i in GAME_STEPS.items()} == {
        "no-gyro": 0,
        "gyro-explicit": 1,
        "gyro-implicit": 1,
        "jolt": 1,
        "rk4": 4,
    }
    assert all(i.kind == "fixed" and i.default_setting == 1 / 60 for i in GAME_STEPS.values())
    assert not set(GAME_STEPS) & set(INTEGRATORS)
    assert METHODS == {**INTEGRATORS, **GAME_STEPS}


@pytest.mark.parametrize("method", sorted(GAME_STEPS))
def test_initial_state_and_step_count(method):
    t = np.array([0.0, 0.25, 0.25, 1.0])
    run = integrate(method, INERTIA, OMEGA0, ATTITUDE0, t, 0.1)
    np.testing.assert_array_equal(run.omega[0], OMEGA0)
    assert (run.attitude[0] * ATTITUDE0.inv()).magnitude() < 4 * EPS
    np.testing.assert_array_equal(run.omega[1], run.omega[2])
    assert run.cost == 3 + 8  # ceil(0.25 / 0.1) + ceil(0.75 / 0.1)


@pytest.mark.parametrize("method", ["gyro-explicit", "gyro-implicit", "jolt", "rk4"])
def test_convergence_order(method):
    body = FreeRigidBody(INERTIA, OMEGA0, ATTITUDE0)
    t = np.array([2.0 * body.period])
    w_exact, a_exact = body.state(t)
    steps = [body.period / n for n in (256, 512, 1024, 2048)]
    w_err, a_err = [], []
    for h in steps:
        run = integrate(method, INERTIA, OMEGA0, ATTITUDE0, t, h)
        w_err.append(float(np.linalg.norm(run.omega[0] - w_exact[0]) / np.linalg.norm(OMEGA0)))
        a_err.append(float((run.attitude[0] * a_exact[0].inv()).magnitude()))
    order = GAME_STEPS[method].order
    for errs in (w_err, a_err):
        fitted = float(np.polyfit(np.log(steps), np.log(errs), 1)[0])
        assert abs(fitted - order) < ORDER_SLOPE_TOL, (errs, fitted)


def test_without_the_gyroscopic_term_the_body_turns_about_a_fixed_axis():
    """ω in the body is kept exactly and the attitude is R0 exp(t [ω0]x): the step never
    converges to the free body, whatever the step."""
    t = np.linspace(0.0, 10.0, 11)
    body = FreeRigidBody(INERTIA, OMEGA0, ATTITUDE0)
    errors = []
    for h in (1 / 60, 1 / 240, 1 / 960):
        run = integrate("no-gyro", INERTIA, OMEGA0, ATTITUDE0, t, h)
        np.testing.assert_array_equal(run.omega, np.tile(OMEGA0, (len(t), 1)))
        fixed_axis = ATTITUDE0 * Rotation.from_rotvec(np.outer(t, OMEGA0))
        assert np.max((run.attitude * fixed_axis.inv()).magnitude()) < 1e-12
        errors.append(float(np.max(np.linalg.norm(run.omega - body.omega(t), axis=1))))
    assert min(errors) > 0.1 * np.linalg.norm(OMEGA0)


def test_invariants_of_each_step():
    """Jolt keeps |L| to rounding; the explicit torque only adds to |L| and the energy at every
    step; the implicit step only takes from them (backward Euler dissipates)."""
    t = np.arange(1, 601) / 60.0
    m0 = T_HANDLE * FLICK
    for method in ("jolt", "gyro-explicit", "gyro-implicit"):
        w = integrate(
            method, T_HANDLE, FLICK, None, t, 1 / 60 if method != "gyro-explicit" else 1 / 960
        ).omega
        size = np.linalg.norm(T_HANDLE * w, axis=1) / np.linalg.norm(m0)
        energy = np.sum(T_HANDLE * w * w, axis=1) / np.sum(m0 * FLICK)
        if method == "jolt":
            assert np.max(np.abs(size - 1.0)) < 1e-13
            assert np.max(np.abs(energy - 1.0)) > 1e-6  # the energy is not kept
        elif method == "gyro-explicit":
            assert np.all(np.diff(size) > 0.0) and np.all(np.diff(energy) > 0.0)
        else:
            assert np.all(np.diff(size) < 0.0) and np.all(np.diff(energy) < 0.0)


def test_the_flip_clock_matches_the_elliptic_theory():
    theory = flip_theory(T_HANDLE, FLICK)
    flips = exact_flip_times(FreeRigidBody(T_HANDLE, FLICK), np.array([0.0, 60.0]))
    expected = theory.first_flip_time + theory.time_between_flips * np.arange(flips.size)
    assert flips.size == int((60.0 - theory.first_flip_time) // theory.time_between_flips) + 1
    np.testing.assert_allclose(flips, expected, atol=1e-4)


def test_a_wobble_about_a_stable_axis_is_no_flip():
    body = FreeRigidBody(T_HANDLE, [0.3, 0.3, 2.0])  # near the major axis
    t = np.linspace(0.0, 60.0, 6001)
    w = body.omega(t)
    assert np.any(np.diff(np.sign(w[:, 1])) != 0)  # ω_mid does change sign ...
    assert flip_times(T_HANDLE, w, t).size == 0  # ... but the axis never reverses


def test_flip_verdicts():
    """No gyroscopic term: no flip; the implicit step damps the flip (the flips stop while the
    exact body goes on flipping); the exact solution and RK4 at 1/240 s flip on time."""
    theory = flip_theory(T_HANDLE, FLICK)
    duration = 60.0
    exact = run_flips(T_HANDLE, FLICK, duration, "exact", 1 / 240)
    assert exact.flips.size == 50
    np.testing.assert_allclose(exact.flips[0], theory.first_flip_time, atol=1e-4)
    for h in (1 / 60, 1 / 240):
        assert run_flips(T_HANDLE, FLICK, duration, "no-gyro", h).flips.size == 0
    damped = run_flips(T_HANDLE, FLICK, duration, "gyro-implicit", 1 / 60)
    assert damped.flips.size < exact.flips.size
    assert damped.flips[-1] < duration - 10 * theory.time_between_flips
    assert damped.energy_drift < -0.5
    rk4 = run_flips(T_HANDLE, FLICK, duration, "rk4", 1 / 240)
    assert rk4.flips.size == exact.flips.size
    np.testing.assert_allclose(rk4.flips, exact.flips, atol=1e-4)
    assert abs(rk4.energy_drift) < 1e-6
    assert run_flips(T_HANDLE, FLICK, duration, "gyro-explicit", 1 / 60).blew_up


STIFF = ("DOP853", [1000.0, 1.0, 1.0], [-1000.0, -1000.0, -1000.0], None)


def test_a_stiff_run_stops_at_its_step_budget():
    """The fuzz's case ran for minutes: DOP853 needs ~1e6 steps per time unit here. With a
    budget of 200 steps it stops at once, having covered a sliver of the span."""
    with pytest.raises(ValueError, match="max_steps") as caught:
        integrate(*STIFF, [0.0, 50.0], max_steps=200)
    message = str(caught.value)
    assert "took 200 steps" in message
    assert "exact solution" in message and "tolerance" in message and "stiff" in message
    reached = float(message.split("reached only t = ")[1].split(" ")[0])
    assert reached < 1e-3 * 50.0  # the whole span would take over 1e7 steps


def test_the_step_budget_counts_steps_and_is_off_for_an_easy_run():
    t = np.linspace(0.0, 20.0, 5)
    free = integrate("DOP853", INERTIA, OMEGA0, None, t, 1e-8)
    budget = integrate("DOP853", INERTIA, OMEGA0, None, t, 1e-8, max_steps=10_000)
    np.testing.assert_array_equal(free.omega, budget.omega)
    with pytest.raises(ValueError, match="took 3 steps"):
        integrate("DOP853", INERTIA, OMEGA0, None, t, 1e-8, max_steps=3)
    with pytest.raises(ValueError, match="max_steps"):
        integrate("rk4", INERTIA, OMEGA0, None, t, 1 / 60, max_steps=100)
    with pytest.raises(ValueError, match="max_steps"):
        integrate("RK45", INERTIA, OMEGA0, None, t, 1e-8, max_steps=0)


def test_propagation_without_a_work_cap_stops_at_the_default_budget(monkeypatch):
    import poinsot.physics.integrators.propagation as propagation

    monkeypatch.setattr(propagation, "DEFAULT_MAX_STEPS", 50)
    p = Propagation(*STIFF)
    with pytest.raises(ValueError, match="took 50 steps"):
        p.advance(1.0)
