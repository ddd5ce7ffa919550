"""Poinsot's construction: polhode, invariable plane, precession per period, helpers.

* ``polhode(n)`` lies on the energy ellipsoid ``x.I.x = 2T`` and on the momentum sphere
  ``|I x| = G``, and it is the curve omega(t) actually traces;
* ``plane_distance == 2T/|L|``, ``plane_normal == L/|L|``;
* ``precession_per_period`` is the angle the attitude really turns about L in one period of
  omega (``R(t + P) R(t)^T = Rot(L, angle)``), and equals the reference [LL76 §37, Eq. 37.16];
* ``omega_from_energy`` and ``attitude_with_L_along_z`` do what they say.
"""

from __future__ import annotations

import numpy as np
import pytest
from reference import (
    ATTITUDE_ATOL_GENERIC,
    EPS,
    GEOMETRY_RTOL,
    ReferenceBody,
    as_matrices,
    geodesic_angle,
)
from scipy.spatial.transform import Rotation

from poinsot.physics import FreeRigidBody, Regime, attitude_with_L_along_z, omega_from_energy

ROT0 = Rotation.from_rotvec([-0.7, 0.4, 1.2])

CASES = {
    "major": ((1.0, 2.0, 3.0), (0.2, 0.3, 1.0)),
    "minor": ((1.0, 2.0, 3.0), (1.0, 0.3, 0.5)),
    "unsorted": ((3.0, 1.0, 2.0), (0.5, 1.0, -0.2)),
    "near-separatrix": ((1.0, 2.0, 3.5), (0.7, 1e-6, 0.4)),
    "separatrix": ((2.0, 3.0, 6.0), (3.0, 0.25, 1.0)),
    "oblate": ((1.0, 1.0, 3.0), (0.5, 0.2, 1.0)),
    "prolate": ((1.0, 3.0, 3.0), (1.0, 0.2, 0.5)),
    "six-decades": ((1e-3, 1.0, 1e3), (1.0, 0.3, 0.01)),
    "no-triangle": ((1.0, 10.0, 1000.0), (0.2, 1.0, 0.03)),
    "permanent": ((1.0, 2.0, 3.0), (0.0, 0.0, 2.0)),
    "sphere": ((2.0, 2.0, 2.0), (0.3, -0.2, 0.9)),
}
PERIODIC = [
    "major",
    "minor",
    "unsorted",
    "near-separatrix",
    "oblate",
    "prolate",
    "six-decades",
    "no-triangle",
]


@pytest.mark.parametrize("key", list(CASES))
def test_polhode_on_ellipsoid_and_sphere(key: str) -> None:
    inertia, omega0 = CASES[key]
    ii = np.asarray(inertia)
    body = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=ROT0)
    n = 257
    poly = body.polhode(n)
    assert poly.shape == (n, 3)
    assert np.all(np.isfinite(poly))
    two_t = 2.0 * body.energy
    g = float(np.linalg.norm(body.angular_momentum))
    energy = np.einsum("ij,j,ij->i", poly, ii, poly)
    assert np.max(np.abs(energy - two_t)) <= GEOMETRY_RTOL * two_t
    sphere = np.linalg.norm(poly * ii, axis=1)
    assert np.max(np.abs(sphere - g)) <= GEOMETRY_RTOL * g


@pytest.mark.parametrize("key", PERIODIC)
def test_polhode_is_the_curve_omega_traces(key: str) -> None:
    """Every omega(t) over a period is close to the polhode polyline, and the polhode has no
    point far from omega(t) (same curve, both ways), within the polyline's own spacing."""
    inertia, omega0 = CASES[key]
    body = FreeRigidBody(inertia=inertia, omega0=omega0)
    poly = body.polhode(512)
    closed = np.vstack([poly, poly[:1]])
    spacing = np.max(np.linalg.norm(np.diff(closed, axis=0), axis=1))
    w = body.omega(np.linspace(0.0, body.period, 4001))
    d_w_to_poly = np.min(np.linalg.norm(w[:, None, :] - poly[None, :, :], axis=2), axis=1)
    assert np.max(d_w_to_poly) <= spacing
    d_poly_to_w = np.min(np.linalg.norm(poly[:, None, :] - w[None, :, :], axis=2), axis=1)
    step = np.max(np.linalg.norm(np.diff(w, axis=0), axis=1))
    assert np.max(d_poly_to_w) <= step
    # a closed loop without gaps: no segment longer than 5% of the curve's extent
    extent = np.linalg.norm(poly.max(axis=0) - poly.min(axis=0))
    assert spacing <= 0.05 * extent


@pytest.mark.parametrize("key", list(CASES))
def test_invariable_plane(key: str) -> None:
    inertia, omega0 = CASES[key]
    ref = ReferenceBody(inertia, omega0, ROT0)
    body = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=ROT0)
    L = ref.angular_momentum
    g = float(np.linalg.norm(L))
    two_t = 2.0 * ref.energy
    assert body.plane_distance == pytest.approx(two_t / g, rel=GEOMETRY_RTOL)
    assert np.allclose(body.plane_normal, L / g, rtol=0, atol=4 * EPS)
    assert np.allclose(body.angular_momentum, L, rtol=0, atol=4 * EPS * g)
    assert np.allclose(body.semi_axes, np.sqrt(two_t / np.asarray(inertia)), rtol=4 * EPS)


@pytest.mark.parametrize("key", PERIODIC)
def test_precession_per_period_is_what_the_attitude_does(key: str) -> None:
    """R(t0 + P) R(t0)^T is the rotation about L by ``precession_per_period`` (mod 2 pi), for
    any t0; and the unwrapped angle equals the reference's integral of [LL76 §37, Eq. 37.16]."""
    inertia, omega0 = CASES[key]
    body = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=ROT0)
    ref = ReferenceBody(inertia, omega0, ROT0)
    p = body.period
    t0 = np.array([0.0, 0.3 * p, 2.71 * p])
    r0 = as_matrices(body.attitude(t0))
    r1 = as_matrices(body.attitude(t0 + p))
    turn = Rotation.from_rotvec(body.precession_per_period * body.plane_normal).as_matrix()
    expected = np.einsum("ij,njk->nik", turn, r0)
    dr = geodesic_angle(r1, expected)
    assert np.max(dr) <= ATTITUDE_ATOL_GENERIC, dr
    assert body.precession_per_period == pytest.approx(float(ref.phi_per_period), rel=1e-12)
    assert body.precession_per_period > 0.0
    assert body.second_period == pytest.approx(
        2 * np.pi * p / body.precession_per_period, rel=1e-14
    )


def test_precession_zero_where_no_period() -> None:
    for key in ("separatrix", "permanent", "sphere"):
        body = FreeRigidBody(*CASES[key])
        assert body.period == np.inf
        assert body.precession_per_period == 0.0
        assert body.second_period == np.inf


@pytest.mark.parametrize("key", list(CASES))
def test_herpolhode_between_two_circles(key: str) -> None:
    """The contact point stays on the plane, at a distance from the foot of L that oscillates
    between two radii (circles), reached at the turning points of the polhode."""
    inertia, omega0 = CASES[key]
    body = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=ROT0)
    scale = np.linalg.norm(omega0)
    span = 3 * body.period if np.isfinite(body.period) else 20.0 / scale
    t = np.linspace(0.0, span, 601)
    p = body.contact_point(t)
    foot = body.plane_distance * body.plane_normal
    rho = np.linalg.norm(p - foot, axis=1)
    # |omega|^2 = h^2 + rho^2 in space, and |omega| is a body-frame quantity
    w2 = np.sum(body.omega(t) ** 2, axis=1)
    assert np.allclose(
        rho**2 + body.plane_distance**2, w2, rtol=0, atol=GEOMETRY_RTOL * 10 * scale**2
    )


@pytest.mark.parametrize(
    "inertia",
    [(1.0, 2.0, 3.0), (3.0, 1.0, 2.0), (0.1, 10.0, 5.0), (1.0, 1.0, 2.0), (2.0, 2.0, 2.0)],
)
@pytest.mark.parametrize("frac", [0.0, 0.1, 0.5, 0.9, 1.0])
@pytest.mark.parametrize("pole_sign", [1.0, -1.0])
def test_omega_from_energy(inertia, frac: float, pole_sign: float) -> None:
    lo, hi = min(inertia), max(inertia)
    D = lo + frac * (hi - lo)
    w = omega_from_energy(inertia, D, omega_norm=2.5, pole_sign=pole_sign)
    ii = np.asarray(inertia)
    assert w.shape == (3,) and np.all(np.isfinite(w))
    assert np.linalg.norm(w) == pytest.approx(2.5, rel=1e-14)
    got_d = float(np.sum((ii * w) ** 2) / np.sum(ii * w * w))
    assert got_d == pytest.approx(D, rel=1e-13)
    body = FreeRigidBody(inertia=inertia, omega0=w)
    if lo < hi and D not in (lo, hi):
        srt = np.argsort(ii, kind="stable")
        mid = ii[srt[1]]
        if D > mid:
            assert np.sign(w[srt[2]]) == pole_sign
        elif D < mid:
            assert np.sign(w[srt[0]]) == pole_sign
    if lo < np.median(ii) < hi and D == np.median(ii):
        assert body.regime in (Regime.SEPARATRIX, Regime.MAJOR_AXIS, Regime.MINOR_AXIS)


@pytest.mark.parametrize("key", [k for k in CASES if k != "sphere"] + ["sphere"])
def test_attitude_with_L_along_z(key: str) -> None:  # noqa: N802
    inertia, omega0 = CASES[key]
    rot = attitude_with_L_along_z(inertia, omega0)
    assert isinstance(rot, Rotation) and rot.single
    L = rot.apply(np.asarray(inertia) * np.asarray(omega0))
    g = np.linalg.norm(L)
    assert np.allclose(L, [0.0, 0.0, g], rtol=0, atol=4 * EPS * g)
    body = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=rot)
    assert np.allclose(body.plane_normal, [0.0, 0.0, 1.0], rtol=0, atol=4 * EPS)
