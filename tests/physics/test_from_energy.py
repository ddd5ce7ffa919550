"""``FreeRigidBody.from_energy``: a body from the moments, D = |L|²/2T, |ω0| or |L| and a pole.

* It is the two-step construction it replaces (``omega_from_energy``, then
  ``attitude_with_L_along_z``, then ``FreeRigidBody``), bit for bit, off the separatrix.
* Round trip: the body's D, |ω0| or |L|, pole sign and L along +z are what was asked for.
* ``D`` equal to the intermediate moment is the separatrix itself, with ``D == I2`` exactly, for
  any triaxial moments (no float ω0 lies on it: the two-step construction lands at ``1 - m``
  ~ 1e-16 on one side, e.g. in the minor family with k² = 1 to rounding for (1, 2, 2.6));
  its ω(t) follows an independent integration from the rounded ω0 while the two stay close.
* Bad input raises a ValueError that names the culprit; the moments are checked once.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from reference import integrate_dop853
from scipy.spatial.transform import Rotation

from poinsot.physics import FreeRigidBody, Regime, attitude_with_L_along_z, omega_from_energy
from poinsot.physics.core import free_body, initial_state, validation

EPS = float(np.finfo(float).eps)

D_RTOL = 1e-13
"""D read back from the body against the D asked for: ω0 is a few roundings of square roots of
ratios of the moments and D (cancellation-free for D inside (I1, I3))."""

SEPARATRIX_FOLLOW_ATOL = 1e-9
"""ω of the exact separatrix against DOP853 (rtol 1e-13) from the rounded ω0, |ω0| = 1, over
t <= 6: the rounding of ω0 (1e-16) grows like e^{σt} near the unstable axis (σ ~ 1 here) and
DOP853's own error is ~1e-12; both stay far below this."""

TIMES = np.array([0.0, 0.3, 1.7, -2.2, 12.5, 1e3])

MOMENTS = [
    (1.0, 2.0, 3.0),
    (3.0, 1.0, 2.0),
    (2.6, 1.0, 2.0),
    (0.1, 10.0, 5.0),
    (1e-3, 7.0, 4e3),
    (1e100, 3e100, 2e100),
]


def _sorted(inertia) -> list[float]:
    return sorted(float(x) for x in inertia)


@pytest.mark.parametrize("inertia", MOMENTS + [(1.0, 1.0, 2.0), (2.0, 2.0, 2.0)])
@pytest.mark.parametrize("frac", [0.0, 0.2, 0.7, 1.0])
@pytest.mark.parametrize("pole_sign", [1.0, -1.0])
def test_it_is_the_two_step_construction(inertia, frac: float, pole_sign: float) -> None:
    lo, _, hi = _sorted(inertia)
    D = lo + frac * (hi - lo)
    body = FreeRigidBody.from_energy(inertia, D, omega_norm=1.7, pole_sign=pole_sign)
    omega0 = omega_from_energy(inertia, D, 1.7, pole_sign)
    attitude0 = attitude_with_L_along_z(inertia, omega0)
    two_step = FreeRigidBody(inertia, omega0, attitude0)
    np.testing.assert_array_equal(body.omega0, omega0)
    np.testing.assert_array_equal(body.attitude0.as_quat(), attitude0.as_quat())
    assert body.regime is two_step.regime and body.D == two_step.D
    w, rot = body.state(TIMES)
    w2, rot2 = two_step.state(TIMES)
    np.testing.assert_array_equal(w, w2)
    np.testing.assert_array_equal(rot.as_quat(), rot2.as_quat())


@pytest.mark.parametrize("inertia", MOMENTS)
@pytest.mark.parametrize("frac", [0.05, 0.3, 0.5, 0.8, 0.95])
@pytest.mark.parametrize("pole_sign", [1, -1])
def test_round_trip(inertia, frac: float, pole_sign: int) -> None:
    lo, mid, hi = _sorted(inertia)
    D = lo + frac * (hi - lo)
    body = FreeRigidBody.from_energy(inertia, D, omega_norm=0.8, pole_sign=pole_sign)
    assert body.D == pytest.approx(D, rel=D_RTOL)
    assert np.linalg.norm(body.omega0) == pytest.approx(0.8, rel=4 * EPS)
    L = body.angular_momentum
    np.testing.assert_allclose(L / np.linalg.norm(L), [0.0, 0.0, 1.0], atol=8 * EPS)
    np.testing.assert_allclose(body.plane_normal, [0.0, 0.0, 1.0], atol=8 * EPS)
    ii = np.asarray(inertia)
    order = np.argsort(ii, kind="stable")
    if D > mid:
        assert body.regime is Regime.MAJOR_AXIS
        assert np.sign(body.omega0[order[2]]) == pole_sign
    elif D < mid:
        assert body.regime is Regime.MINOR_AXIS
        assert np.sign(body.omega0[order[0]]) == pole_sign


@pytest.mark.parametrize("inertia", MOMENTS)
def test_momentum_norm_instead_of_omega_norm(inertia) -> None:
    lo, _, hi = _sorted(inertia)
    D = 0.4 * lo + 0.6 * hi
    size = 3.5 * hi  # |L| in the moments' units times rad per time unit
    body = FreeRigidBody.from_energy(inertia, D, momentum_norm=size, pole_sign=-1)
    assert float(np.linalg.norm(np.asarray(inertia) * body.omega0)) == pytest.approx(
        size, rel=8 * EPS
    )
    assert float(np.linalg.norm(body.angular_momentum)) == pytest.approx(size, rel=8 * EPS)
    assert body.D == pytest.approx(D, rel=D_RTOL)
    with_omega = FreeRigidBody.from_energy(
        inertia, D, omega_norm=float(np.linalg.norm(body.omega0)), pole_sign=-1
    )
    np.testing.assert_allclose(with_omega.omega0, body.omega0, rtol=8 * EPS)


def test_intermediate_moment_is_the_exact_separatrix() -> None:
    """(1, 2, 2.6) with D = 2: the two-step construction lands in the minor family with k² = 1
    to rounding (1 - m = 2e-16, and D = 1.9999999999999998 for |ω0| = 3.7); from_energy builds
    the separatrix, D exactly 2."""
    inertia = (1.0, 2.0, 2.6)
    body = FreeRigidBody.from_energy(inertia, 2.0, omega_norm=1.0)
    assert body.regime is Regime.SEPARATRIX
    assert body.D == 2.0
    assert body.parameter == 1.0 and body.complementary_parameter == 0.0
    assert body.period == math.inf
    two_step = FreeRigidBody(inertia, omega_from_energy(inertia, 2.0))
    assert two_step.regime is Regime.MINOR_AXIS  # what it replaces
    assert 0.0 < two_step.complementary_parameter < 1e-15
    assert FreeRigidBody(inertia, omega_from_energy(inertia, 2.0, 3.7)).D != 2.0
    assert FreeRigidBody.from_energy(inertia, 2.0, omega_norm=3.7).D == 2.0
    np.testing.assert_array_equal(body.omega0, two_step.omega0)
    np.testing.assert_array_equal(body.omega(0.0), body.omega0)
    # The separatrix runs into the intermediate axis: ω → ±A2 e2.
    far = body.omega(60.0)
    assert abs(far[1]) == pytest.approx(float(np.linalg.norm(far)), rel=1e-12)


@pytest.mark.parametrize(
    "inertia", [(1.0, 2.0, 2.6), (2.6, 1.0, 2.0), (3.0, 7.0, 5.0), (0.3, 0.7, 0.35)]
)
@pytest.mark.parametrize("pole_sign", [1, -1])
def test_the_exact_separatrix_follows_an_integration(inertia, pole_sign: int) -> None:
    mid = _sorted(inertia)[1]
    body = FreeRigidBody.from_energy(inertia, mid, pole_sign=pole_sign)
    assert body.regime is Regime.SEPARATRIX and body.D == mid
    t = np.linspace(0.0, 6.0, 13)
    w_num, _ = integrate_dop853(inertia, body.omega0, t)
    assert np.max(np.abs(body.omega(t) - w_num)) <= SEPARATRIX_FOLLOW_ATOL
    # scalar and array paths agree on the separatrix built from D, as everywhere
    for tk in (0.7, -3.1, 40.0):
        np.testing.assert_allclose(body.omega(tk), body.omega(np.array([tk]))[0], rtol=4e-16)


@settings(max_examples=200, deadline=None, derandomize=True)
@given(
    logs=st.lists(st.floats(-6.0, 6.0), min_size=3, max_size=3, unique=True),
    pole_sign=st.sampled_from([1, -1]),
    log_norm=st.floats(-50.0, 50.0),
)
def test_any_triaxial_moments_give_the_separatrix_at_d_equal_i2(logs, pole_sign, log_norm):
    inertia = [10.0**x for x in logs]
    mid = _sorted(inertia)[1]
    if len(set(inertia)) < 3:
        return
    body = FreeRigidBody.from_energy(inertia, mid, omega_norm=10.0**log_norm, pole_sign=pole_sign)
    assert body.regime is Regime.SEPARATRIX
    assert body.D == mid
    w = body.omega(np.array([0.0, 1.0, -1.0]) / 10.0**log_norm)
    assert np.all(np.isfinite(w))
    assert float(np.linalg.norm(w[0])) == pytest.approx(10.0**log_norm, rel=8 * EPS)


def test_symmetric_moments_at_d_equal_i2_are_a_permanent_rotation() -> None:
    """Two equal moments: D = I1 = I2 is the spin about a transverse axis, no separatrix."""
    body = FreeRigidBody.from_energy((1.0, 1.0, 3.0), 1.0)
    assert body.regime is Regime.PERMANENT_ROTATION and body.D == 1.0


def test_explicit_attitude0() -> None:
    rot = Rotation.from_rotvec([0.1, 0.2, -0.3])
    body = FreeRigidBody.from_energy((1.0, 2.0, 3.0), 2.5, attitude0=rot)
    np.testing.assert_array_equal(body.attitude0.as_quat(), rot.as_quat())
    assert (body.attitude(0.0) * rot.inv()).magnitude() <= 4 * EPS


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        ({"inertia": (1.0, 2.0, 3.0), "D": 0.5}, r"D = \|L\|²/2T must lie between"),
        ({"inertia": (1.0, 2.0, 3.0), "D": 3.5}, r"D = \|L\|²/2T must lie between"),
        ({"inertia": (1.0, 2.0, 3.0), "D": math.nan}, r"D must be a finite number"),
        ({"inertia": (1.0, 2.0, 3.0), "D": "two"}, r"D must be a real number, not the text"),
        ({"inertia": (1.0, 0.0, 3.0), "D": 2.0}, r"moments of inertia must be positive"),
        ({"inertia": (1.0, 2.0), "D": 2.0}, r"moments of inertia must be three"),
        ({"inertia": (1.0, 2.0, 3.0), "D": 2.0, "omega_norm": 0.0}, r"\|omega0\| must be"),
        ({"inertia": (1.0, 2.0, 3.0), "D": 2.0, "omega_norm": -1.0}, r"\|omega0\| must be"),
        ({"inertia": (1.0, 2.0, 3.0), "D": 2.0, "momentum_norm": math.inf}, r"\|L\| must be"),
        (
            {"inertia": (1.0, 2.0, 3.0), "D": 2.0, "omega_norm": 1.0, "momentum_norm": 2.0},
            r"not both",
        ),
        ({"inertia": (1.0, 2.0, 3.0), "D": 2.0, "attitude0": np.eye(3)}, r"attitude0"),
        ({"inertia": (1e-200, 1.0, 1e200), "D": 1.0}, r"300 decades"),
    ],
)
def test_bad_input(kwargs, pattern: str) -> None:
    with pytest.raises(ValueError, match=pattern):
        FreeRigidBody.from_energy(**kwargs)


def test_the_moments_are_checked_once(monkeypatch) -> None:
    calls = []
    original = validation.check_inertia

    def counting(value):
        calls.append(value)
        return original(value)

    for module in (free_body, initial_state, validation):
        monkeypatch.setattr(module, "check_inertia", counting)
    FreeRigidBody.from_energy((1.0, 2.0, 3.0), 2.5, omega_norm=2.0, pole_sign=-1)
    assert len(calls) == 1
