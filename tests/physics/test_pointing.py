"""A start pointed at by hand (physics/models/pointing.py): the ray's point, the start on the energy
ellipsoid, the polhode through it, the snap onto the exact separatrix."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from poinsot.physics import FreeRigidBody, Regime
from poinsot.physics.models.pointing import (
    body_from_start,
    energy_parameter,
    momentum_from_ray,
    omega_from_momentum,
    on_energy_ellipsoid,
    ray_ellipsoid,
    ray_sphere,
    snap_momentum_to_separatrix,
    snap_to_separatrix,
    start_from_ray,
)

RNG = np.random.default_rng(19)
INERTIA = np.array([1.0, 2.0, 2.6])


def _visible_targets(semi: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Points on the ellipsoid, and eyes outside it from which each is the first point hit
    (the eye lies on the outer side of the tangent plane at the point)."""
    u = RNG.normal(size=(n, 3))
    target = semi * u / np.linalg.norm(u, axis=1, keepdims=True)
    normal = target / semi**2
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    side = RNG.normal(size=(n, 3))
    side -= np.sum(side * normal, axis=1, keepdims=True) * normal
    eye = target + 3.0 * normal + 0.5 * side
    return target, eye


def test_a_ray_meets_the_ellipsoid_at_the_point_it_was_aimed_at() -> None:
    semi = np.array([0.7, 1.0, 0.4])
    target, eye = _visible_targets(semi, 500)
    hit = ray_ellipsoid(eye, 2.5 * (target - eye), semi)
    np.testing.assert_allclose(hit, target, atol=1e-12)
    assert np.allclose(np.sum((hit / semi) ** 2, axis=1), 1.0, rtol=1e-13)


def test_a_ray_that_misses_gives_nan_rows_only() -> None:
    semi = np.array([1.0, 0.5, 0.5])
    origin = np.array([[0.0, 0.0, 5.0], [0.0, 0.0, 5.0], [0.0, 0.0, 5.0], [0.0, 0.0, 0.0]])
    direction = np.array([[0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 0.0]])
    hit = ray_ellipsoid(origin, direction, semi)
    np.testing.assert_allclose(hit[0], [0.0, 0.0, 0.5])
    assert np.all(np.isnan(hit[1:]))  # passes beside it, points away, has no direction


def test_from_inside_the_sphere_the_ray_meets_its_far_side() -> None:
    hit = ray_sphere([0.2, 0.0, 0.0], [[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]], 2.0)
    np.testing.assert_allclose(hit, [[2.0, 0.0, 0.0], [-2.0, 0.0, 0.0]])


def test_the_start_lies_on_the_energy_ellipsoid_of_the_turned_body() -> None:
    """Rays aimed at known body-frame points of the ellipsoid, the body turned: the start is
    that point (scale 0.8 as drawn), on ω·Iω = 2T to 1e-12 relative."""
    two_T = 3.7
    semi = np.sqrt(two_T / INERTIA)
    target, eye = _visible_targets(semi, 400)
    attitude = Rotation.from_rotvec([0.3, -1.1, 0.7])
    scale = 0.8
    omega = start_from_ray(
        INERTIA,
        two_T,
        attitude,
        attitude.apply(eye * scale),
        attitude.apply((target - eye) * scale),
        scale=scale,
    )
    np.testing.assert_allclose(omega, target, atol=1e-12)
    energy = np.einsum("ij,j,ij->i", omega, INERTIA, omega)
    assert np.max(np.abs(energy / two_T - 1.0)) < 1e-12


def test_the_polhode_of_the_start_passes_through_it_and_keeps_T() -> None:
    two_T = 2.0
    semi = np.sqrt(two_T / INERTIA)
    target, eye = _visible_targets(semi, 12)
    for omega0 in start_from_ray(INERTIA, two_T, Rotation.identity(), eye, target - eye):
        body = body_from_start(INERTIA, omega0)
        np.testing.assert_allclose(body.omega(0.0), omega0, rtol=1e-14, atol=1e-15)
        assert body.energy == pytest.approx(two_T / 2.0, rel=1e-12)
        assert body.D == pytest.approx(float(energy_parameter(INERTIA, omega0)), rel=1e-12)
        assert body.plane_normal == pytest.approx([0.0, 0.0, 1.0], abs=1e-12)
        curve = body.polhode(4096)
        gaps = np.linalg.norm(np.diff(curve, axis=0), axis=1)
        # The start is on the drawn curve: within a chord of it, and on both of its surfaces.
        assert np.min(np.linalg.norm(curve - omega0, axis=1)) <= np.max(gaps)
        m = curve * INERTIA
        np.testing.assert_allclose(np.einsum("ij,ij->i", curve, m), two_T, rtol=1e-11)
        np.testing.assert_allclose(np.einsum("ij,ij->i", m, m), two_T * body.D, rtol=1e-11)


def test_a_point_near_the_separatrix_snaps_onto_the_exact_separatrix() -> None:
    """A start a little off the separatrix (D = I₂ ± 1e-4): snapped, the body is the exact
    separatrix (its regime, D == I₂), with the energy kept; one farther off is left alone."""
    two_T = 2.0
    for sign, pole in ((1.0, 1.0), (-1.0, 1.0), (1.0, -1.0)):
        exact = FreeRigidBody.from_energy(INERTIA, 2.0, pole_sign=pole).omega0
        exact = exact * np.sqrt(two_T / (exact @ (INERTIA * exact)))
        exact[0] *= sign
        near = on_energy_ellipsoid(INERTIA, two_T, exact + np.array([0.0, 0.0, 2e-4]))
        snapped, moved = snap_to_separatrix(INERTIA, near, tolerance=1e-3)
        assert moved
        assert float(energy_parameter(INERTIA, snapped)) == pytest.approx(2.0, rel=1e-12)
        body = body_from_start(INERTIA, snapped, separatrix=True)
        assert body.regime is Regime.SEPARATRIX
        assert body.D == 2.0
        assert body.energy == pytest.approx(two_T / 2.0, rel=1e-12)
        far = on_energy_ellipsoid(INERTIA, two_T, exact + np.array([0.0, 0.0, 0.05]))
        kept, moved = snap_to_separatrix(INERTIA, far, tolerance=1e-3)
        assert not moved and np.array_equal(kept, far)
        assert body_from_start(INERTIA, far).regime is not Regime.SEPARATRIX


def test_a_snapped_start_off_the_middle_plane_moves_along_its_own_separatrix() -> None:
    """A start snapped onto the separatrix where ω₂ ≠ 0 (most points a hand reaches): the exact
    separatrix through that very point, its energy kept, Euler's equations obeyed."""
    two_T = 2.0
    kappa = np.sqrt(
        INERTIA[0] * (INERTIA[1] - INERTIA[0]) / (INERTIA[2] * (INERTIA[2] - INERTIA[1]))
    )
    for w2 in (0.4, -0.7):
        start = on_energy_ellipsoid(INERTIA, two_T, np.array([1.0, w2, kappa]))
        body = body_from_start(INERTIA, start, separatrix=True)
        assert body.regime is Regime.SEPARATRIX and body.D == INERTIA[1]
        assert body.energy == pytest.approx(two_T / 2.0, rel=1e-12)
        np.testing.assert_allclose(body.omega(0.0), start, rtol=1e-12)
        curve = body.polhode(4096)
        gaps = np.linalg.norm(np.diff(curve, axis=0), axis=1)
        assert np.min(np.linalg.norm(curve - start, axis=1)) <= np.max(gaps)
        t = np.linspace(-3.0, 3.0, 7)
        w = body.omega(t)
        np.testing.assert_allclose(np.einsum("ij,j,ij->i", w, INERTIA, w), two_T, rtol=1e-12)
        eps = 1e-6  # the rate of ω against Euler's equations, by a central difference
        rate = (body.omega(t + eps) - body.omega(t - eps)) / (2.0 * eps)
        euler = np.array([_euler(0.0, x) for x in w])
        np.testing.assert_allclose(rate, euler, atol=1e-7)


def test_a_symmetric_body_has_nothing_to_snap_to() -> None:
    omega, moved = snap_to_separatrix([1.0, 2.0, 2.0], [[0.3, 0.4, 0.5]], tolerance=10.0)
    assert not moved.any() and np.array_equal(omega, [[0.3, 0.4, 0.5]])


def test_a_point_of_the_momentum_sphere_is_omega_of_that_momentum() -> None:
    L = ray_sphere([0.0, 0.0, 4.0], [0.1, 0.2, -1.0], 1.5)
    omega = omega_from_momentum(INERTIA, L)
    np.testing.assert_allclose(np.linalg.norm(omega * INERTIA), 1.5, rtol=1e-14)


def test_a_ray_at_landaus_sphere_gives_a_start_of_its_own_energy_at_g_kept() -> None:
    G, scale = 2.3, 0.62 / 2.3
    target, eye = _visible_targets(np.full(3, G), 300)  # L on the sphere, eyes outside it
    L = momentum_from_ray(G, eye * scale, 1.7 * (target - eye) * scale, scale=scale)
    np.testing.assert_allclose(L, target, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(L, axis=1), G, rtol=1e-12)
    omega = omega_from_momentum(INERTIA, L)
    for w in omega[:20]:
        body = body_from_start(INERTIA, w)
        two_T = float(w @ (INERTIA * w))  # the energy follows from the point
        assert 2.0 * body.energy == pytest.approx(two_T, rel=1e-12)
        assert float(np.linalg.norm(body.angular_momentum)) == pytest.approx(G, rel=1e-12)
        # The point lies on the energy ellipsoid of its own T, and ω(t) keeps |L| (DOP853).
        curve = body.polhode(400)
        assert np.min(np.linalg.norm(curve - w, axis=1)) <= np.max(
            np.linalg.norm(np.diff(curve, axis=0), axis=1)
        )
        reference = solve_ivp(_euler, (0.0, 3.0), w, method="DOP853", rtol=1e-12, atol=1e-13)
        np.testing.assert_allclose(body.omega(3.0), reference.y[:, -1], rtol=1e-8, atol=1e-9)
    assert np.all(np.isnan(momentum_from_ray(G, [0.0, 0.0, 5.0], [1.0, 0.0, 0.0])))


def _euler(_t: float, w: np.ndarray) -> np.ndarray:
    """Euler's equations, torque-free, body frame [LL76 §36]."""
    I1, I2, I3 = INERTIA
    return np.array(
        [(I2 - I3) * w[1] * w[2] / I1, (I3 - I1) * w[2] * w[0] / I2, (I1 - I2) * w[0] * w[1] / I3]
    )


def test_a_momentum_near_the_separatrix_snaps_onto_it_at_g_kept() -> None:
    I1, I2, I3 = INERTIA
    G = 1.9
    mu = np.sqrt(I3 * (I2 - I1) / (I1 * (I3 - I2)))
    on = np.array([1.0, 0.8, mu])  # L3 = mu L1: on the separatrix (independent form)
    on *= G / np.linalg.norm(on)
    near = on + np.array([0.0, 0.0, 2e-3])
    near *= G / np.linalg.norm(near)
    far = on + np.array([0.0, 0.0, 0.2])
    far *= G / np.linalg.norm(far)
    L, snapped = snap_momentum_to_separatrix(INERTIA, np.stack([near, far, -near]), 1e-2)
    assert snapped.tolist() == [True, False, True]
    np.testing.assert_allclose(np.linalg.norm(L, axis=1), G, rtol=1e-14)
    np.testing.assert_allclose(L[0], on, rtol=1e-3)
    np.testing.assert_array_equal(L[1], far)  # not near: untouched
    w = omega_from_momentum(INERTIA, L[0])
    assert energy_parameter(INERTIA, w) == pytest.approx(I2, rel=1e-14)
    body = body_from_start(INERTIA, w, separatrix=True)
    assert body.regime is Regime.SEPARATRIX and body.D == I2
