"""The one quaternion algebra (``physics.core.rotations``) and the error measures
(``physics.core.errors``).

Against scipy's ``Rotation`` (composition, ``apply``, ``from_rotvec``, ``inv``), against mpmath
for the geodesic angle, and on known values. The component functions must give the same bits
for plain floats as for arrays: the scalar paths of the closed forms rely on it.
"""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from poinsot.physics.core import errors
from poinsot.physics.core.rotations import (
    axis_angle,
    conjugate,
    geodesic_angle,
    hamilton,
    multiply,
    rotate,
    rotate_vector,
)

EPS = float(np.finfo(float).eps)

COMPOSE_ATOL = 4 * EPS
"""Quaternion components of a product against scipy's composition: each component is a sum of
four products of numbers <= 1 (a few roundings), scipy forms the same sum in another order."""

ROTATE_RTOL = 8 * EPS
"""``R v`` against ``Rotation.apply`` relative to ``|v|``: two nested cross products (scipy
goes through the rotation matrix), a few roundings each."""

SMALL_ANGLE_RTOL = 2 * EPS
"""Geodesic angle of a small rotation from the identity, relative: ``4 atan2(|p - q|, |p + q|)``
keeps full relative accuracy (``2 acos(p·q)`` would return 0 below ~1e-8)."""

ANGLE_ATOL = 4 * EPS
"""Geodesic angle between arbitrary float quaternions against mpmath on the same inputs,
absolute [rad]: the normalisation rounds each component once (~eps)."""

RNG = np.random.default_rng(20240517)
P = Rotation.random(64, random_state=11).as_quat()
Q = Rotation.random(64, random_state=12).as_quat()


def _same_rotation(q: np.ndarray, r: np.ndarray) -> np.ndarray:
    """|q - (±r)| per row, the sign chosen (a quaternion and its negative are one rotation)."""
    sign = np.where(np.sum(q * r, axis=-1, keepdims=True) >= 0.0, 1.0, -1.0)
    return np.max(np.abs(q - sign * r), axis=-1)


def test_multiply_composes_like_scipy() -> None:
    """``R(p ⊗ q) = R(p) R(q)``: scipy's ``p * q`` applies q first."""
    expected = (Rotation.from_quat(P) * Rotation.from_quat(Q)).as_quat()
    assert np.all(_same_rotation(multiply(P, Q), expected) <= COMPOSE_ATOL)


def test_multiply_broadcasts_one_quaternion_over_a_stack() -> None:
    out = multiply(P[0], Q)
    assert out.shape == Q.shape
    np.testing.assert_array_equal(out, multiply(np.broadcast_to(P[0], Q.shape), Q))


def test_hamilton_on_floats_equals_the_stack_bitwise() -> None:
    stacked = multiply(P, Q)
    for k in range(8):
        one = hamilton(tuple(P[k].tolist()), tuple(Q[k].tolist()))
        assert all(isinstance(x, float) for x in one)
        assert list(one) == stacked[k].tolist()


def test_hamilton_on_high_precision_components() -> None:
    """Any component type with + and ×: mpmath's mpf, as the report's Taylor reference uses."""
    with mp.workdps(40):
        p = [mp.mpf(x) for x in P[3].tolist()]
        q = [mp.mpf(x) for x in Q[3].tolist()]
        out = hamilton(p, q)
        assert all(isinstance(x, mp.mpf) for x in out)
        assert np.max(np.abs(np.array([float(x) for x in out]) - multiply(P[3], Q[3]))) <= EPS


def test_conjugate_is_the_inverse() -> None:
    conj = np.stack(conjugate(np.moveaxis(P, -1, 0)), axis=-1)
    assert np.all(_same_rotation(conj, Rotation.from_quat(P).inv().as_quat()) <= COMPOSE_ATOL)
    identity = multiply(P, conj)
    assert np.all(_same_rotation(identity, np.array([0.0, 0.0, 0.0, 1.0])) <= COMPOSE_ATOL)


def test_rotate_matches_rotation_apply() -> None:
    v = RNG.normal(size=(64, 3)) * 10.0 ** RNG.uniform(-3, 3, size=(64, 1))
    expected = Rotation.from_quat(P).apply(v)
    got = rotate(P, v)
    scale = np.linalg.norm(v, axis=-1, keepdims=True)
    assert np.all(np.abs(got - expected) <= ROTATE_RTOL * scale)


def test_rotate_vector_on_floats_equals_the_stack_bitwise() -> None:
    v = RNG.normal(size=(8, 3))
    stacked = rotate(P[:8], v)
    for k in range(8):
        assert list(rotate_vector(P[k].tolist(), v[k].tolist())) == stacked[k].tolist()


@pytest.mark.parametrize("angle", [0.0, 1e-300, 1e-8, 0.3, -2.0, math.pi, 7.5])
def test_axis_angle_matches_from_rotvec(angle: float) -> None:
    axis = np.array([2.0, -3.0, 6.0]) / 7.0  # a unit vector with exact components
    arr = np.stack(axis_angle(axis, np.array([angle])), axis=-1)[0]
    expected = Rotation.from_rotvec(axis * angle).as_quat()
    assert _same_rotation(arr, expected) <= COMPOSE_ATOL
    floats = axis_angle(tuple(axis.tolist()), angle, sin=math.sin, cos=math.cos)
    assert np.max(np.abs(np.array(floats) - arr)) <= EPS


@pytest.mark.parametrize("exponent", [-1, -3, -8, -12, -50, -150, -300])
def test_geodesic_angle_has_full_relative_accuracy_near_zero(exponent: int) -> None:
    small = 1.7 * 10.0**exponent
    identity = np.array([0.0, 0.0, 0.0, 1.0])
    for axis in (np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.6, 0.8])):
        q = np.array(axis_angle(axis, small, sin=math.sin, cos=math.cos))
        angle = float(geodesic_angle(identity, q))
        assert angle == pytest.approx(small, rel=SMALL_ANGLE_RTOL)
        # the same through a non-trivial but exactly unit quaternion (an axis swap)
        swap = np.array([1.0, 0.0, 0.0, 0.0])
        assert float(geodesic_angle(swap, multiply(swap, q))) == pytest.approx(
            small, rel=SMALL_ANGLE_RTOL
        )


@pytest.mark.parametrize("gap", [0.0, 1e-12, 1e-6, 0.1])
def test_geodesic_angle_near_pi_and_the_double_cover(gap: float) -> None:
    """A rotation by π - gap and by π + gap (the same as π - gap the other way) are both
    π - gap away from the identity; ``q`` and ``-q`` are the same attitude."""
    identity = np.array([0.0, 0.0, 0.0, 1.0])
    axis = np.array([0.0, 0.0, 1.0])
    for angle in (math.pi - gap, math.pi + gap):
        q = np.array(axis_angle(axis, angle, sin=math.sin, cos=math.cos))
        assert float(geodesic_angle(identity, q)) == pytest.approx(math.pi - gap, abs=4 * EPS)
        assert float(geodesic_angle(identity, -q)) == pytest.approx(math.pi - gap, abs=4 * EPS)


def test_geodesic_angle_against_mpmath() -> None:
    """Unnormalised float inputs, exact angle of the same inputs at 50 digits."""
    p = P * RNG.uniform(0.5, 2.0, size=(64, 1))
    q = Q * RNG.uniform(0.5, 2.0, size=(64, 1))
    q[:8] = p[:8] + RNG.normal(size=(8, 4)) * 1e-9  # some close pairs
    got = geodesic_angle(p, q)
    with mp.workdps(50):
        for k in range(64):
            a = [mp.mpf(x) for x in p[k].tolist()]
            b = [mp.mpf(x) for x in q[k].tolist()]
            dot = abs(mp.fsum(x * y for x, y in zip(a, b, strict=True)))
            cos_half = dot / (
                mp.sqrt(mp.fsum(x * x for x in a)) * mp.sqrt(mp.fsum(y * y for y in b))
            )
            exact = 2 * mp.acos(min(cos_half, mp.mpf(1)))
            assert abs(float(got[k]) - float(exact)) <= ANGLE_ATOL, k


def test_geodesic_angle_broadcasts() -> None:
    assert geodesic_angle(P, Q).shape == (64,)
    assert geodesic_angle(P[0], Q).shape == (64,)
    assert geodesic_angle(P[0], Q[0]).shape == ()


# ---- the error measures on known values -----------------------------------------------------


def test_energy_known_values() -> None:
    assert errors.energy((1.0, 2.0, 3.0), (1.0, 1.0, 1.0)) == 3.0
    np.testing.assert_array_equal(
        errors.energy((1.0, 2.0, 3.0), [[2.0, 0.0, 0.0], [0.0, 0.0, -2.0]]), [2.0, 6.0]
    )


def test_angular_momentum_norm_known_values_without_overflow() -> None:
    assert errors.angular_momentum_norm((1.0, 1.0, 1.0), (3.0, 4.0, 0.0)) == 5.0
    assert errors.angular_momentum_norm((2.0, 1.0, 1.0), (0.0, 0.0, -7.0)) == 7.0
    big = errors.angular_momentum_norm((1e154, 1e154, 1.0), (1e154, 1e154, 0.0))
    assert big == pytest.approx(math.sqrt(2.0) * 1e308, rel=4 * EPS)  # the squares overflow


def test_omega_error_known_values() -> None:
    assert errors.omega_error((2.0, 0.0, 0.0), (1.0, 0.0, 0.0)) == 1.0
    np.testing.assert_allclose(
        errors.omega_error([[1.0, 1.0, 0.0], [0.0, 3.0, 4.0]], [[1.0, 0.0, 0.0], [0.0, 3.0, 0.0]]),
        [1.0, 4.0 / 3.0],
        rtol=EPS,
    )


def test_attitude_error_known_values_for_rotations_and_quaternions() -> None:
    a = Rotation.from_rotvec([0.2, -0.1, 0.4])
    b = a * Rotation.from_rotvec([0.0, 0.3, 0.0])
    assert float(errors.attitude_error(a, b)) == pytest.approx(0.3, rel=8 * EPS)
    assert float(errors.attitude_error(a.as_quat(), b.as_quat())) == pytest.approx(0.3, rel=8 * EPS)
    assert float(errors.attitude_error(a, -a.as_quat())) == 0.0  # the double cover


def test_relative_drift_known_values() -> None:
    np.testing.assert_allclose(errors.relative_drift([1.5, 0.5, 1.0], 1.0), [0.5, 0.5, 0.0])
    np.testing.assert_allclose(errors.relative_drift([-3.0], -2.0), [0.5])
