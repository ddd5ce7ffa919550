"""The free symmetric top: precession p = G/I, spin s = ((I - J)/I) ω3, and the cones.

* p and s measured on the exact motion (the azimuth of the axis about L, of ω about e3) equal
  the theory; the same measurement on an independent DOP853 integration agrees too.
* The body cone (drawn with the attitude) and the space cone touch along ω, are tangent there
  (e3, ω, L coplanar), and ω lies between e3 and L for a prolate body, L between e3 and ω for
  an oblate one.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from reference import integrate_dop853
from scipy.spatial.transform import Rotation

from poinsot.physics import FreeRigidBody, Regime
from poinsot.physics.models.symmetric import (
    measure_precession_rate,
    measure_spin_rate,
    symmetric_top,
)

RATE_RTOL = 1e-10
"""Measured p and s on the exact motion against G/I and ((I-J)/I) ω3: the angles are exact to
rounding and the rate is (angle swept)/(time), tens of radians over t = 60 (measured ~1e-16)."""

DOP853_RATE_RTOL = 1e-9
"""The same measurement on DOP853 (rtol 1e-13) of Euler's equations and R' = R[ω]x: its phase
error grows to ~1e-11 over t = 60."""

CONE_ATOL = 1e-12
"""Angles [rad] and the coplanarity determinant at the contact generator: rounding of unit
vectors and one arctan (measured ~1e-15)."""

TOPS = [
    (2.0, 3.0, (0.5, 0.2, 1.0)),  # oblate
    (3.0, 1.0, (0.5, 0.2, 1.0)),  # prolate
    (3.0, 1.0, (0.5, 0.2, -1.0)),  # prolate, spun the other way
    (2.0, 3.0, (0.5, -0.2, -1.3)),  # oblate, ω3 < 0
    (1.0, 10.0, (1.0, 0.0, 0.05)),  # flat disc, nearly a flat spin
    (10.0, 0.5, (0.05, 0.0, 3.0)),  # long rod, nearly along its axis
]
ROT0 = Rotation.from_rotvec([0.3, -1.0, 0.4])


@pytest.mark.parametrize("It, J, w0", TOPS)
def test_measured_rates_equal_the_theory(It, J, w0):
    top = symmetric_top(It, J, w0, ROT0)
    body = top.body()
    assert body.regime is Regime.SYMMETRIC
    G = math.hypot(It * math.hypot(w0[0], w0[1]), J * w0[2])
    assert top.precession_rate == pytest.approx(G / It, rel=1e-15)
    assert top.spin_rate == pytest.approx((It - J) / It * w0[2], rel=1e-15)
    assert top.shape == ("oblate" if J > It else "prolate")
    p = measure_precession_rate(body, 60.0)
    s = measure_spin_rate(body, 60.0)
    assert p == pytest.approx(top.precession_rate, rel=RATE_RTOL)
    assert s == pytest.approx(top.spin_rate, rel=RATE_RTOL)
    # s has the sign of ω3 for a prolate body, the opposite for an oblate one
    assert math.copysign(1.0, s) == math.copysign(1.0, w0[2]) * (1 if J < It else -1)


@pytest.mark.parametrize("It, J, w0", TOPS[:4])
def test_the_same_measurement_on_dop853(It, J, w0):
    top = symmetric_top(It, J, w0, ROT0)
    t = np.linspace(0.0, 60.0, 6001)
    w, R = integrate_dop853(top.inertia, w0, t, attitude0=ROT0, rtol=1e-13, atol=1e-15)
    Lhat = top.angular_momentum / np.linalg.norm(top.angular_momentum)
    u = np.cross(Lhat, [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(Lhat, u)
    axis = R[:, :, 2]  # R e3
    phi = np.unwrap(np.arctan2(axis @ v, axis @ u))
    assert (phi[-1] - phi[0]) / 60.0 == pytest.approx(top.precession_rate, rel=DOP853_RATE_RTOL)
    psi = np.unwrap(np.arctan2(w[:, 1], w[:, 0]))
    assert -(psi[-1] - psi[0]) / 60.0 == pytest.approx(top.spin_rate, rel=DOP853_RATE_RTOL)


def _angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    cross = np.linalg.norm(np.cross(a, b), axis=-1)
    return np.arctan2(cross, np.sum(a * b, axis=-1))


@pytest.mark.parametrize("It, J, w0", TOPS)
def test_body_cone_rolls_on_the_space_cone(It, J, w0):
    top = symmetric_top(It, J, w0, ROT0)
    body = top.body()
    t = np.linspace(0.0, 20.0, 41)
    w, R = body.state(t)
    Lhat = top.angular_momentum / np.linalg.norm(top.angular_momentum)
    g = R.apply(w)  # the instantaneous axis in space: the shared generator
    axis = R.apply([0.0, 0.0, 1.0])
    assert np.abs(_angle(g, Lhat) - top.space_cone_half_angle).max() < CONE_ATOL
    assert np.abs(_angle(g, axis) - top.body_cone_half_angle).max() < CONE_ATOL
    assert np.abs(_angle(axis, Lhat) - top.nutation_angle).max() < CONE_ATOL
    # e3, ω and L coplanar: the cones are tangent along g (no crossing, rolling contact)
    det = np.einsum("ij,ij->i", np.cross(axis, g), np.broadcast_to(Lhat, g.shape))
    assert np.abs(det).max() < CONE_ATOL * np.linalg.norm(w0)
    # prolate: ω between e3 and L; oblate: L between e3 and ω (angles from the side of ω3)
    ab, as_, th = top.body_cone_half_angle, top.space_cone_half_angle, top.nutation_angle
    if w0[2] < 0:
        ab, th = math.pi - ab, math.pi - th
    if top.shape == "prolate":
        assert th == pytest.approx(ab + as_, abs=CONE_ATOL)
    else:
        assert th == pytest.approx(ab - as_, abs=CONE_ATOL)
    # the generator is on both drawn cones: on the body cone carried by R(t), on the space cone
    rim_b = top.body_cone(720)
    rim_s = top.space_cone(720)
    assert np.allclose(np.linalg.norm(rim_b, axis=1), top.omega_norm)
    for k in (0, 17, 40):
        on_body = R[k].apply(rim_b)
        closest_b = np.min(np.linalg.norm(on_body - g[k], axis=1))
        closest_s = np.min(np.linalg.norm(rim_s - g[k], axis=1))
        step = 2.0 * math.pi / 720 * top.omega_norm  # rim spacing bound
        assert closest_b <= step and closest_s <= step
    # the points of the contact generator are at rest: velocity ω_space × g = 0
    omega_space = top.precession_rate * Lhat + top.spin_rate * axis
    np.testing.assert_allclose(omega_space, g, atol=1e-12)


def test_measurement_refuses_what_it_cannot_see():
    spin = symmetric_top(2.0, 3.0, (0.0, 0.0, 1.0)).body()
    with pytest.raises(ValueError, match="along L"):
        measure_precession_rate(spin, 10.0)
    with pytest.raises(ValueError, match="along the symmetry axis"):
        measure_spin_rate(spin, 10.0)
    with pytest.raises(ValueError, match="not a symmetric top"):
        measure_spin_rate(FreeRigidBody((1.0, 2.0, 3.0), (1.0, 0.0, 1.0)), 10.0)


@pytest.mark.parametrize(
    "args",
    [
        (2.0, 2.0, (1.0, 0.0, 1.0)),
        (0.0, 2.0, (1.0, 0.0, 1.0)),
        (2.0, math.inf, (1.0, 0.0, 1.0)),
        (2.0, 3.0, (0.0, 0.0, 0.0)),
        (2.0, 3.0, (1.0, 0.0)),
        (2.0, 3.0, (1.0, math.nan, 0.0)),
    ],
)
def test_bad_input_is_a_readable_value_error(args):
    with pytest.raises(ValueError, match=r"\w+ \w+"):
        symmetric_top(*args)
