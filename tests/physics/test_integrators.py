"""The numerical integrators of :mod:`physics.integrators`, against the exact solution.

Layers: the registry and the interface; the convergence order of each fixed-step method (slope
of the error as the step shrinks); tolerance proportionality of the adaptive pairs; the
geometric properties (|L| kept to rounding, the space vector L kept, the energy error bounded
with no drift) with a non-geometric method as the control that shows each check can fail;
convergence to :class:`physics.FreeRigidBody` on ordinary and extreme bodies; random bodies.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

import poinsot.physics.integrators.attitudes as attitudes_module
from poinsot.physics import FreeRigidBody
from poinsot.physics.core.errors import attitude_error, energy, omega_error, relative_drift
from poinsot.physics.integrators import INTEGRATORS, Trajectory, integrate

EPS = float(np.finfo(float).eps)

FIXED = [name for name, i in INTEGRATORS.items() if i.kind == "fixed"]
ADAPTIVE = [name for name, i in INTEGRATORS.items() if i.kind == "adaptive"]
GEOMETRIC = [name for name, i in INTEGRATORS.items() if i.conserves_norm]

ORDER_SLOPE_TOL = 0.1
"""|fitted slope - order| allowed in log(error) vs log(h). The steps span a factor 8, where the
measured slopes are 1.994-2.000 for both second-order methods; a first-order error term (a wrong
sub-step ordering, a non-symmetric composition) shows as a slope near 1."""

TOL_PROPORTIONALITY = 0.2
"""|slope - 1| allowed in log(global error) vs log(rtol) for the adaptive pairs over six decades:
measured 1.00 (RK45) and 1.03 (DOP853). An absolute tolerance that does not scale with rtol, or
a wrong scaling of the state, flattens the slope."""

NORM_RTOL = 1e-13
"""|L| relative deviation allowed for the geometric methods over 2e4 steps. Every sub-step is a
rotation of m (or, for the midpoint, an exact solve of a quadratic-invariant-preserving map) so
only rounding remains: ~eps per step in a random walk, eps sqrt(2e4 * 5) ~ 7e-14 at worst;
measured 2e-14. A non-conserving method (RK45 at rtol 1e-8) is off by ~1e-6."""

MIDPOINT_ENERGY_RTOL = 1e-13
"""The implicit midpoint keeps 2T = m . I^-1 m (a quadratic invariant) exactly up to the
solve and rounding: measured 4e-14 over 2e4 steps (same random-walk bound as NORM_RTOL)."""

NO_DRIFT_FACTOR = 1.5
"""Symplectic splitting: the worst energy error over the last tenth of 500 periods may exceed
the worst over the first tenth by at most this factor (bounded oscillation, measured 0.94-1.05).
RK45 at rtol 1e-8 grows by 10x over the same span (secular drift)."""

FIXED_ERROR_CONSTANT = 1.0
"""Fixed-step methods: global error (omega relative, attitude in rad) at most
``FIXED_ERROR_CONSTANT * (t / tau) * (h nu)^2`` with ``nu = 2 pi / tau`` the fastest turning rate.
The largest term is the midpoint's Cayley attitude: each step turns by 2 atan(h |w| / 2)
instead of h |w|, (h |w|)^3 / 12 short, so t |w|^3 h^2 / 12 <= (2 pi / 12) (t / tau) (h nu)^2
= 0.52 (t / tau) (h nu)^2; measured constants 0.44-0.62 for it and <= 0.14 for the
splitting, at n = tau / h = 128 and 2048 alike (the asymptotic regime)."""

ADAPTIVE_FINE_ATOL = 1e-8
"""Adaptive pairs at rtol 1e-11 over two periods: error bound (measured 1e-11..1e-10)."""


# --------------------------------------------------------------------------------------------
# Helpers


def body_case(name: str) -> tuple[np.ndarray, np.ndarray, Rotation]:
    """Bodies used below, with a non-trivial initial attitude."""
    cases = {
        # a uniform 1x2x3 box, minor-axis family, m ~ 0.4
        "generic": ((13.0, 10.0, 5.0), (0.3, 0.6, 0.9)),
        # Toutatis' moments (Hudson & Ostro 1995), long-axis mode
        "toutatis": ((1.0, 3.0836, 3.235), (1.714199, 0.0, 0.644256)),
        # a needle spinning fast about its axis (exactly symmetric)
        "needle": ((1e-4, 1.0, 1.0), (50.0, 1.0, 0.5)),
        # violates the triangle inequality: stiff Euler rates ~1e3
        "non-physical": ((1.0, 10.0, 1000.0), (1.0, 1.0, 1.0)),
        # a near-oblate body: the elliptic parameter is ~1e-5
        "near-oblate": ((1.0, 1.0 + 1e-6, 2.0), (1.0, 0.5, 0.3)),
        # unsorted input with the major axis first
        "unsorted": ((3.0, 1.0, 2.0), (0.2, -0.7, 0.5)),
    }
    inertia, omega0 = cases[name]
    return np.array(inertia), np.array(omega0), Rotation.from_rotvec([0.4, -1.1, 0.7])


def time_scale(inertia: np.ndarray, omega0: np.ndarray) -> float:
    """2 pi over the fastest turning rate |omega| max(1, |I_j - I_k| / I_i)."""
    ratios = [abs(inertia[(k + 1) % 3] - inertia[(k + 2) % 3]) / inertia[k] for k in range(3)]
    return 2.0 * math.pi / (float(np.linalg.norm(omega0)) * max(1.0, *ratios))


def errors(traj: Trajectory, body: FreeRigidBody, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(relative omega error, geodesic attitude angle [rad]) at every time."""
    w, attitude = body.state(t)
    return omega_error(traj.omega, w), attitude_error(traj.attitude, attitude)


def slope(x: list[float], y: list[float]) -> float:
    return float(np.polyfit(np.log(x), np.log(y), 1)[0])


def relative_energy_error(inertia: np.ndarray, omega0: np.ndarray, omega: np.ndarray):
    return relative_drift(energy(inertia, omega), float(energy(inertia, omega0)))


# --------------------------------------------------------------------------------------------
# Registry and interface


def test_registry_lists_the_required_methods():
    assert set(INTEGRATORS) == {"RK45", "DOP853", "splitting", "midpoint"}
    assert {n: INTEGRATORS[n].order for n in INTEGRATORS} == {
        "RK45": 5,
        "DOP853": 8,
        "splitting": 2,
        "midpoint": 2,
    }
    assert set(FIXED) == {"splitting", "midpoint"} == set(GEOMETRIC)


@pytest.mark.parametrize("method", sorted(INTEGRATORS))
def test_interface_shapes_and_initial_state(method):
    inertia, omega0, attitude0 = body_case("unsorted")
    t = np.array([0.0, 0.3, 0.3, 1.7])  # a repeated time is allowed
    omega, attitude, cost = integrate(method, inertia, omega0, attitude0, t)
    assert INTEGRATORS[method].name == method
    assert omega.shape == (4, 3)
    assert len(attitude) == 4
    assert cost > 0
    # Fixed-step methods carry m = I omega: omega = (I omega0) / I is omega0 to one rounding.
    np.testing.assert_allclose(omega[0], omega0, rtol=2 * EPS, atol=0)
    assert (attitude[0] * attitude0.inv()).magnitude() < 4 * EPS
    np.testing.assert_allclose(omega[1], omega[2], rtol=0, atol=1e-15)


@pytest.mark.parametrize("method", sorted(INTEGRATORS))
def test_default_attitude_is_identity_and_t0_only(method):
    inertia, omega0, _ = body_case("generic")
    omega, attitude, _ = integrate(method, inertia, omega0, None, [0.0])
    np.testing.assert_allclose(omega[0], omega0, rtol=2 * EPS, atol=0)
    assert attitude[0].magnitude() < 4 * EPS


def test_fixed_step_grid_cuts_each_interval_into_equal_steps():
    inertia, omega0, attitude0 = body_case("generic")
    # ceil(0.25/0.1) = 3, ceil(0.75/0.1) = 8, ceil(0.05/0.1) = 1; 0.3/0.1 = 2.9999999999999996
    # must count as 3 steps, not 4.
    for method in FIXED:
        assert integrate(method, inertia, omega0, attitude0, [0.25, 1.0, 1.05], 0.1).cost == 12
        assert integrate(method, inertia, omega0, attitude0, [0.3], 0.1).cost == 3


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"method": "Euler"}, "unknown method"),
        ({"inertia": (1.0, 0.0, 2.0)}, "inertia"),
        ({"inertia": (1.0, 2.0)}, "inertia"),
        ({"omega0": (1.0, np.nan, 2.0)}, "omega0"),
        ({"t_eval": [0.0, 2.0, 1.0]}, "non-decreasing"),
        ({"t_eval": [-1.0, 2.0]}, "non-negative"),
        ({"t_eval": []}, "non-empty"),
        ({"setting": 0.0}, "setting"),
        ({"setting": math.inf}, "setting"),
        ({"attitude0": Rotation.random(2, random_state=1)}, "attitude0"),
    ],
)
def test_bad_input_raises_readable_value_error(kwargs, message):
    args = {
        "method": "splitting",
        "inertia": (1.0, 2.0, 3.0),
        "omega0": (1.0, 0.5, 0.2),
        "attitude0": None,
        "t_eval": [0.0, 1.0],
        "setting": 0.1,
    }
    args.update(kwargs)
    with pytest.raises(ValueError, match=message):
        integrate(**args)


def test_midpoint_refuses_a_step_its_solver_cannot_take():
    with pytest.raises(ValueError, match="smaller step"):
        integrate("midpoint", (13.0, 10.0, 5.0), (0.3, 0.6, 0.9), None, [10.0], 5.0)


def test_chunked_attitude_assembly_matches_a_single_chunk(monkeypatch):
    """The attitude of a long run is assembled chunk by chunk; the chunking must not matter."""
    inertia, omega0, attitude0 = body_case("generic")
    t = np.linspace(0.0, 30.0, 7)
    for method in FIXED:
        whole = integrate(method, inertia, omega0, attitude0, t, 0.01)
        monkeypatch.setattr(attitudes_module, "_CHUNK", 37)
        chunked = integrate(method, inertia, omega0, attitude0, t, 0.01)
        monkeypatch.undo()
        np.testing.assert_array_equal(whole.omega, chunked.omega)
        assert np.max((whole.attitude * chunked.attitude.inv()).magnitude()) < 1e-13


def test_prefix_products_match_sequential_products():
    q = Rotation.random(1000, random_state=3).as_quat().T
    counts = np.array([0, 1, 2, 3, 511, 512, 513, 999, 1000, 1000])
    tree = attitudes_module.prefix_products(q, counts)
    acc = Rotation.identity()
    expected = {0: acc}
    for k in range(1000):
        acc = acc * Rotation.from_quat(q[:, k])
        expected[k + 1] = acc
    for i, n in enumerate(counts):
        assert (Rotation.from_quat(tree[:, i]) * expected[int(n)].inv()).magnitude() < 1e-13


# --------------------------------------------------------------------------------------------
# Convergence order


@pytest.mark.parametrize("case", ["generic", "toutatis", "unsorted"])
@pytest.mark.parametrize("method", FIXED)
def test_fixed_step_convergence_order(method, case):
    inertia, omega0, attitude0 = body_case(case)
    body = FreeRigidBody(inertia, omega0, attitude0)
    t_end = 2.0 * body.period
    t = np.array([t_end])
    tau = time_scale(inertia, omega0)
    steps = [tau / n for n in (64, 128, 256, 512)]
    w_err, a_err = [], []
    for h in steps:
        w, a = errors(integrate(method, inertia, omega0, attitude0, t, h), body, t)
        w_err.append(w[-1])
        a_err.append(a[-1])
    order = INTEGRATORS[method].order
    assert abs(slope(steps, w_err) - order) < ORDER_SLOPE_TOL, (w_err, slope(steps, w_err))
    assert abs(slope(steps, a_err) - order) < ORDER_SLOPE_TOL, (a_err, slope(steps, a_err))
    assert all(b < a for a, b in zip(w_err, w_err[1:], strict=False))


@pytest.mark.parametrize("method", ADAPTIVE)
def test_adaptive_error_is_proportional_to_tolerance(method):
    inertia, omega0, attitude0 = body_case("generic")
    body = FreeRigidBody(inertia, omega0, attitude0)
    t = np.array([2.0 * body.period])
    tols = [1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11]
    errs, costs = [], []
    for tol in tols:
        traj = integrate(method, inertia, omega0, attitude0, t, tol)
        w, a = errors(traj, body, t)
        errs.append(max(w[-1], a[-1]))
        costs.append(traj.cost)
    assert abs(slope(tols, errs) - 1.0) < TOL_PROPORTIONALITY, errs
    assert errs[-1] < 1e-9
    # Cost grows like error^(-1/order) or slower: a high-order pair pays little for accuracy.
    assert slope(costs, errs) < -(INTEGRATORS[method].order - 1), (costs, errs)


# --------------------------------------------------------------------------------------------
# Geometric properties


@pytest.mark.parametrize("method", GEOMETRIC)
def test_geometric_methods_keep_the_angular_momentum_to_rounding(method):
    inertia, omega0, attitude0 = body_case("generic")
    body = FreeRigidBody(inertia, omega0, attitude0)
    g = np.linalg.norm(body.angular_momentum)
    t = np.linspace(0.0, 20000 * 0.05, 201)  # 2e4 steps of 0.05, ~80 periods
    traj = integrate(method, inertia, omega0, attitude0, t, 0.05)
    m = inertia * traj.omega
    assert np.max(np.abs(np.linalg.norm(m, axis=1) / g - 1.0)) < NORM_RTOL
    space = traj.attitude.apply(m)
    assert np.max(np.linalg.norm(space - body.angular_momentum, axis=1)) / g < NORM_RTOL


def test_the_norm_check_detects_a_non_conserving_method():
    inertia, omega0, attitude0 = body_case("generic")
    g = np.linalg.norm(inertia * omega0)
    t = np.linspace(0.0, 1000.0, 201)
    traj = integrate("RK45", inertia, omega0, attitude0, t, 1e-8)
    assert np.max(np.abs(np.linalg.norm(inertia * traj.omega, axis=1) / g - 1.0)) > 1e3 * NORM_RTOL


def test_midpoint_keeps_the_energy_to_rounding():
    inertia, omega0, attitude0 = body_case("generic")
    t = np.linspace(0.0, 20000 * 0.05, 201)
    traj = integrate("midpoint", inertia, omega0, attitude0, t, 0.05)
    assert np.max(relative_energy_error(inertia, omega0, traj.omega)) < MIDPOINT_ENERGY_RTOL


def _first_and_last_tenth(method: str, setting: float) -> tuple[float, float]:
    inertia, omega0, attitude0 = body_case("generic")
    period = FreeRigidBody(inertia, omega0).period
    t = np.linspace(0.0, 500 * period, 2001)
    # RK45 at rtol 1e-8 over 500 periods takes ~5e4 steps, past the default budget (1e4).
    traj = integrate(method, inertia, omega0, attitude0, t, setting, max_steps=200_000)
    err = relative_energy_error(inertia, omega0, traj.omega)
    tenth = len(t) // 10
    return float(err[1 : tenth + 1].max()), float(err[-tenth:].max())


def test_splitting_energy_error_is_bounded_and_shrinks_with_the_step():
    period = FreeRigidBody(*body_case("generic")[:2]).period
    first, last = _first_and_last_tenth("splitting", period / 32)
    assert 0 < last < NO_DRIFT_FACTOR * first
    first_half_step, last_half_step = _first_and_last_tenth("splitting", period / 64)
    assert last_half_step < NO_DRIFT_FACTOR * first_half_step
    # At least second order in h (measured ratio 7.5-8 at these steps).
    assert first / first_half_step > 3.5


@pytest.mark.slow
def test_the_drift_check_detects_a_drifting_method():
    first, last = _first_and_last_tenth("RK45", 1e-8)
    assert last > 5 * NO_DRIFT_FACTOR * first


# --------------------------------------------------------------------------------------------
# Convergence to the exact solution


@pytest.mark.parametrize(
    "case", ["generic", "toutatis", "needle", "non-physical", "near-oblate", "unsorted"]
)
@pytest.mark.parametrize("method", sorted(INTEGRATORS))
def test_every_method_converges_to_the_exact_solution(method, case):
    inertia, omega0, attitude0 = body_case(case)
    body = FreeRigidBody(inertia, omega0, attitude0)
    t = np.linspace(0.0, 2.0 * body.period, 41)
    integrator = INTEGRATORS[method]
    if integrator.kind == "fixed":
        tau = time_scale(inertia, omega0)
        coarse, fine = tau / 128, tau / 2048
        bound = FIXED_ERROR_CONSTANT * (t[-1] / tau) * (2.0 * math.pi / 2048) ** 2
        coarse_bound = FIXED_ERROR_CONSTANT * (t[-1] / tau) * (2.0 * math.pi / 128) ** 2
    else:
        coarse, fine, bound, coarse_bound = 1e-6, 1e-11, ADAPTIVE_FINE_ATOL, math.inf
    w_c, a_c = errors(integrate(method, inertia, omega0, attitude0, t, coarse), body, t)
    w_f, a_f = errors(integrate(method, inertia, omega0, attitude0, t, fine), body, t)
    assert w_f.max() < bound and a_f.max() < bound, (w_f.max(), a_f.max(), bound)
    assert w_c.max() < coarse_bound and a_c.max() < coarse_bound
    assert w_f.max() < w_c.max() / 10 and a_f.max() < a_c.max() / 10


# --------------------------------------------------------------------------------------------
# Random bodies (including non-physical ratios)

moments = st.floats(min_value=1e-3, max_value=1e3)
rates = st.floats(min_value=-2.0, max_value=2.0)


# A fixed sample (as the suite's other property tests): drawn afresh each run, 40 bodies a run
# found, once in many runs, bodies with two equal large moments and a tiny third, e.g.
# (814, 814, 0.001) with omega0 = (0, 2, 1), where a step of tau / 32 is far too long for the
# stiff third axis (the midpoint's fixed-point iteration does not converge there and says so: a
# smaller step), and (202, 202, 0.001), whose space vector drifted 5.7e-12 of |m| over the 300
# steps, past the bound below.
@settings(max_examples=40, deadline=None, derandomize=True)
@given(
    inertia=st.tuples(moments, moments, moments),
    omega0=st.tuples(rates, rates, rates).filter(lambda w: np.linalg.norm(w) > 1e-3),
    rotvec=st.tuples(rates, rates, rates),
    method=st.sampled_from(GEOMETRIC),
)
def test_geometric_methods_keep_L_for_random_bodies(inertia, omega0, rotvec, method):
    inertia = np.array(inertia)
    omega0 = np.array(omega0)
    attitude0 = Rotation.from_rotvec(rotvec)
    tau = time_scale(inertia, omega0)
    t = np.linspace(0.0, 300 * tau / 32, 11)  # 300 steps of tau / 32
    traj = integrate(method, inertia, omega0, attitude0, t, tau / 32)
    m0 = inertia * omega0
    g = np.linalg.norm(m0)
    m = inertia * traj.omega
    # Kept to rounding: a few ulps per step over the 300 steps. (Nearly symmetric bodies with a
    # tiny third moment, e.g. (687, 687, 0.003), spin fast about that axis and reach about
    # 2e-13 in |m| and 9e-13 in the space vector, the worst of 1500 random bodies.)
    bound = 300 * 64 * np.finfo(float).eps  # 4.3e-12
    assert np.max(np.abs(np.linalg.norm(m, axis=1) / g - 1.0)) < bound / 4
    space = traj.attitude.apply(m)
    assert np.max(np.linalg.norm(space - attitude0.apply(m0), axis=1)) / g < bound
