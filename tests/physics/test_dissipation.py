"""Explorer 1: internal dissipation at fixed |L| drives D from near I1 up to I3 [BG58].

* The stated law 2T(t) = G²/I3 + (2T0 - G²/I3) e^{-2κt} solves dT/dt = -κ(2T - G²/I3) (DOP853).
* Along the piecewise-exact motion |m| = G and L = R m are kept to rounding.
* Each window runs on the polhode of the law's D at its start; D follows the law to within its
  change over one window.
* The polhode switches family exactly once, minor -> major, within one window of t*.
* The motion ends as a flat spin about the major axis.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from poinsot.physics import FreeRigidBody, Regime
from poinsot.physics.models.dissipation import EnergySink

INVARIANT_RTOL = 1e-12
"""|m| and L = R m over hundreds of windows: each window is exact and the carry keeps |m| = G
and R m to a few roundings (measured 1e-15 for |m|, 3e-14 for L)."""

LAW_RTOL = 1e-11
"""The closed-form law against DOP853 (rtol 1e-13) of the energy ODE over 2κt = 25."""

WINDOW_D_RTOL = 1e-13
"""D of the motion in a window against the law at the window's start: the nearest point is
computed on the closed-form polhode of that D (a few roundings; measured 2e-15)."""

INERTIA = (1.0, 2.0, 3.0)
ROT0 = Rotation.from_rotvec([0.4, -0.2, 0.9])


@pytest.fixture(scope="module")
def explorer() -> EnergySink:
    # Spun about the minor axis with a visible wobble (D0 = 1.10 I1), κ = 0.05, 2κ t_end = 25.
    return EnergySink(
        INERTIA, (1.0, 0.15, 0.1), kappa=0.05, t_end=250.0, window=0.5, attitude0=ROT0
    )


@pytest.fixture(scope="module")
def samples(explorer):
    t = np.linspace(0.0, explorer.t_end, 25001)
    w, R = explorer.state(t)
    return t, w, R


def test_the_stated_law_solves_its_equation(explorer):
    G2, I3, kappa = explorer.G**2, INERTIA[2], explorer.kappa

    def rhs(_t, two_T):  # d(2T)/dt = -2κ (2T - G²/I3)
        return -2.0 * kappa * (two_T - G2 / I3)

    two_T0 = float(explorer.two_T(0.0))
    t = np.linspace(0.0, explorer.t_end, 101)
    sol = solve_ivp(rhs, (0.0, t[-1]), [two_T0], method="DOP853", t_eval=t, rtol=1e-13, atol=1e-16)
    np.testing.assert_allclose(explorer.two_T(t), sol.y[0], rtol=LAW_RTOL)
    w0 = np.array([1.0, 0.15, 0.1])
    assert two_T0 == pytest.approx(float(w0 @ (np.array(INERTIA) * w0)), rel=1e-15)
    # D(t) rises monotonically from D0 to I3, through I2 at the stated crossing time
    D = explorer.D(np.linspace(0.0, explorer.t_end, 1001))
    assert np.all(np.diff(D) > 0.0) and D[0] == pytest.approx(explorer.D0)
    assert float(explorer.D(explorer.crossing_time)) == pytest.approx(INERTIA[1], rel=1e-14)
    assert INERTIA[2] - D[-1] < 1e-9


def test_invariants_are_kept(explorer, samples):
    _, w, R = samples
    m = np.array(INERTIA) * w
    G = np.linalg.norm(m, axis=1)
    assert np.abs(G / explorer.G - 1.0).max() <= INVARIANT_RTOL
    L = R.apply(m)
    assert np.abs(L - L[0]).max() <= INVARIANT_RTOL * explorer.G
    np.testing.assert_allclose(L[0], ROT0.apply(np.array(INERTIA) * [1.0, 0.15, 0.1]), atol=1e-15)


def test_D_follows_the_stated_law(explorer, samples):
    t, w, _ = samples
    D_motion = explorer.G**2 / np.sum(np.array(INERTIA) * w * w, axis=1)
    np.testing.assert_allclose(D_motion, explorer.window_D(t), rtol=WINDOW_D_RTOL)
    # the staircase stays within one window's change of the law
    per_window = np.abs(explorer.D(t) - explorer.D(t - explorer.window)).max()
    assert np.abs(D_motion - explorer.D(t)).max() <= per_window
    assert per_window < 0.02 * INERTIA[2]


def test_first_window_is_the_free_motion(explorer):
    t = np.linspace(0.0, 0.49, 50)
    w, R = explorer.state(t)
    free = FreeRigidBody(INERTIA, (1.0, 0.15, 0.1), ROT0)
    np.testing.assert_allclose(w, free.omega(t), atol=1e-15)
    np.testing.assert_allclose(R.as_quat(), free.attitude(t).as_quat(), atol=1e-15)


def test_family_switches_exactly_once_at_the_crossing(explorer, samples):
    t, w, _ = samples
    t_star, h = explorer.crossing_time, explorer.window
    assert 0.0 < t_star < explorer.t_end
    # the label of each window's exact motion
    labels = explorer.regimes
    changes = [k for k in range(1, len(labels)) if labels[k] is not labels[k - 1]]
    assert len(changes) == 1
    k = changes[0]
    assert labels[k - 1] is Regime.MINOR_AXIS and labels[k] is Regime.MAJOR_AXIS
    assert explorer.starts[k - 1] < t_star <= explorer.starts[k]
    # read off the motion itself: the sign of Δ2 = G² - 2T I2 flips once, within a window
    J = np.array(INERTIA)
    delta2 = explorer.G**2 - np.sum(J * w * w, axis=1) * J[1]
    above = delta2 > 0.0
    flips = np.flatnonzero(above[1:] != above[:-1])
    assert flips.size == 1
    assert abs(t[flips[0] + 1] - t_star) <= h
    # and the polhode drawn at a time is that of the window
    assert explorer.body_at(t_star - 2 * h).regime is Regime.MINOR_AXIS
    assert explorer.body_at(t_star + 2 * h).regime is Regime.MAJOR_AXIS


def test_ends_as_a_flat_spin_about_the_major_axis(explorer, samples):
    _, w, _ = samples
    m = np.array(INERTIA) * w[-1]
    assert abs(m[2]) / explorer.G >= 1.0 - 1e-9
    assert explorer.body_at(explorer.t_end).regime is Regime.MAJOR_AXIS


def test_the_carry_is_continuous(explorer):
    # each carry moves m by a small step on the sphere, largest where D changes fastest
    assert explorer.jumps[0] == 0.0
    assert explorer.jumps.max() < 0.1
    finer = EnergySink(INERTIA, (1.0, 0.15, 0.1), kappa=0.05, t_end=20.0, window=0.25)
    assert finer.jumps.max() < 0.65 * explorer.jumps[: finer.jumps.size].max()


def test_starting_above_the_separatrix_never_crosses():
    sink = EnergySink(INERTIA, (0.3, 0.2, 1.0), kappa=0.1, t_end=40.0)
    assert sink.crossing_time < 0.0
    assert set(sink.regimes) == {Regime.MAJOR_AXIS}


@pytest.mark.parametrize(
    "args",
    [
        dict(inertia=(2.0, 1.0, 3.0), omega0=(1.0, 0.1, 0.1), kappa=0.1, t_end=10.0),
        dict(inertia=INERTIA, omega0=(0.0, 0.0, 1.0), kappa=0.1, t_end=10.0),
        dict(inertia=INERTIA, omega0=(0.0, 0.0, 0.0), kappa=0.1, t_end=10.0),
        dict(inertia=INERTIA, omega0=(1.0, math.nan, 0.0), kappa=0.1, t_end=10.0),
        dict(inertia=INERTIA, omega0=(1.0, 0.1, 0.1), kappa=0.0, t_end=10.0),
        dict(inertia=INERTIA, omega0=(1.0, 0.1, 0.1), kappa=0.1, t_end=-1.0),
        dict(inertia=INERTIA, omega0=(1.0, 0.1, 0.1), kappa=0.1, t_end=10.0, window=0.0),
    ],
)
def test_bad_input_is_a_readable_value_error(args):
    with pytest.raises(ValueError, match=r"\w+ \w+"):
        EnergySink(**args)


def test_times_outside_the_run_are_refused(explorer):
    with pytest.raises(ValueError, match="t_end"):
        explorer.state([0.0, explorer.t_end + 1.0])
    with pytest.raises(ValueError, match="finite"):
        explorer.state([math.nan])
