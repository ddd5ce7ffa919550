"""A start pointed at by hand: a ray meets the energy ellipsoid (or Landau's momentum sphere),
and the point it meets becomes the initial ω, at the energy T kept.

Poinsot's energy ellipsoid is ``ω·Iω = 2T`` in the body frame, semi-axes ``√(2T/I_i)``
[FM06 Eq. 7.55]: a point on it is an ω of that energy, and ``D = |Iω|²/(ω·Iω)`` follows from
the point [Pars65 §13.12]. On Landau's picture the body-frame momentum ``L`` lies on the sphere
``|L| = G`` and ``ω = I⁻¹L`` [LL76 §37, Fig. 51]. The separatrix ``D = I₂`` on the ellipsoid is
the pair of planes through the intermediate axis ``I₁(I₂ − I₁) ω₁² = I₃(I₃ − I₂) ω₃²`` (sorted
axes; ``|Iω|² − I₂ ω·Iω = 0`` [LL76 §37, Problem 2]): a point near it is snapped onto it, and
:func:`body_from_start` builds that start as the exact separatrix.

Every function takes whole stacks of rays or points, shape ``(..., 3)``; lengths are in the
units of the semi-axes (ω's units for the ellipsoid, L's for the sphere).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from poinsot.physics.core.free_body import FreeRigidBody
from poinsot.physics.core.initial_state import attitude_checked
from poinsot.physics.core.validation import check_inertia, check_positive, check_vector

__all__ = [
    "body_from_start",
    "energy_parameter",
    "omega_from_momentum",
    "on_energy_ellipsoid",
    "ray_ellipsoid",
    "ray_sphere",
    "momentum_from_ray",
    "snap_momentum_to_separatrix",
    "snap_to_separatrix",
    "start_from_ray",
]

Array = NDArray[np.float64]


def ray_ellipsoid(origin: ArrayLike, direction: ArrayLike, semi_axes: ArrayLike) -> Array:
    """The first point where each ray meets the ellipsoid ``Σ (x_i/a_i)² = 1``.

    Args:
        origin, direction: (..., 3) rays ``origin + s·direction``, ``s ≥ 0`` (the direction
            need not be a unit vector), in the ellipsoid's own axes.
        semi_axes: (3,) the positive semi-axes ``a_i``.

    Returns:
        (..., 3) the nearest point with ``s ≥ 0`` (the far side when the origin is inside);
        NaN rows for a ray that misses it, or has no direction.
    """
    a = np.asarray(semi_axes, dtype=np.float64)
    o = np.asarray(origin, dtype=np.float64) / a
    d = np.asarray(direction, dtype=np.float64) / a
    return _unit_sphere_hit(o, d) * a


def ray_sphere(origin: ArrayLike, direction: ArrayLike, radius: float) -> Array:
    """The first point where each ray meets the sphere ``|x| = radius`` centred at 0.

    Args and result as :func:`ray_ellipsoid`, with ``radius`` > 0 for the three semi-axes.
    """
    r = float(radius)
    o = np.asarray(origin, dtype=np.float64) / r
    d = np.asarray(direction, dtype=np.float64) / r
    return _unit_sphere_hit(o, d) * r


def _unit_sphere_hit(o: Array, d: Array) -> Array:
    """First ``o + s d`` (s ≥ 0) on the unit sphere, NaN where none; a quadratic solved in the
    form that loses no digits to cancellation."""
    o, d = np.broadcast_arrays(o, d)
    a = np.einsum("...i,...i->...", d, d)
    b = np.einsum("...i,...i->...", o, d)
    c = np.einsum("...i,...i->...", o, o) - 1.0
    disc = b * b - a * c
    with np.errstate(invalid="ignore", divide="ignore"):
        root = np.sqrt(disc)
        q = -(b + np.copysign(root, b))  # the root of larger size, without cancellation
        s1, s2 = q / a, c / q
        near, far = np.minimum(s1, s2), np.maximum(s1, s2)
        s = np.where(near >= 0.0, near, far)
        ok = (disc >= 0.0) & (a > 0.0) & (s >= 0.0) & np.isfinite(s)
        return np.where(ok[..., None], o + s[..., None] * d, np.nan)


def on_energy_ellipsoid(inertia: ArrayLike, two_T: float, point: ArrayLike) -> Array:
    """``point`` (..., 3) moved along its own direction onto the ellipsoid ``ω·Iω = 2T``: the
    ω of energy T in that direction (a point already on it moves by a rounding at most)."""
    moments = np.asarray(inertia, dtype=np.float64)
    p = np.asarray(point, dtype=np.float64)
    with np.errstate(invalid="ignore", divide="ignore"):
        return p * np.sqrt(two_T / np.einsum("...i,i,...i->...", p, moments, p))[..., None]


def omega_from_momentum(inertia: ArrayLike, momentum: ArrayLike) -> Array:
    """ω = I⁻¹ L for body-frame momenta ``momentum`` (..., 3) (a point on Landau's sphere)."""
    return np.asarray(momentum, dtype=np.float64) / np.asarray(inertia, dtype=np.float64)


def energy_parameter(inertia: ArrayLike, omega: ArrayLike) -> Array:
    """``D = |Iω|² / ω·Iω`` of each ω (..., 3) [moment units]."""
    moments = np.asarray(inertia, dtype=np.float64)
    m = np.asarray(omega, dtype=np.float64) * moments
    w = np.asarray(omega, dtype=np.float64)
    return np.einsum("...i,...i->...", m, m) / np.einsum("...i,...i->...", w, m)


def snap_to_separatrix(
    inertia: ArrayLike, omega: ArrayLike, tolerance: float
) -> tuple[Array, NDArray[np.bool_]]:
    """Each ω (..., 3) within ``tolerance`` (ω's units) of the separatrix on its own energy
    ellipsoid, moved onto it: onto the nearer plane ``ω₃ = ±κ ω₁`` (sorted axes,
    ``κ = √(I₁(I₂ − I₁)/(I₃(I₃ − I₂)))``), then back onto the ellipsoid along its direction.

    Returns:
        (..., 3) the ω, snapped where it was near; (...,) True where it was snapped. A body
        with two equal moments has no separatrix: nothing is snapped.
    """
    moments = check_inertia(inertia)
    w = np.asarray(omega, dtype=np.float64)
    flat = _onto_separatrix_planes(moments, w, moments)
    if flat is None:
        return w.copy(), np.zeros(w.shape[:-1], dtype=bool)
    two_T = np.einsum("...i,i,...i->...", w, moments, w)
    with np.errstate(invalid="ignore", divide="ignore"):
        snapped = (
            flat * np.sqrt(two_T / np.einsum("...i,i,...i->...", flat, moments, flat))[..., None]
        )
    return _where_near(w, snapped, tolerance)


def snap_momentum_to_separatrix(
    inertia: ArrayLike, momentum: ArrayLike, tolerance: float
) -> tuple[Array, NDArray[np.bool_]]:
    """Each body-frame L (..., 3) within ``tolerance`` (L's units) of the separatrix on its own
    sphere ``|L| = G``, moved onto it at ``|L|`` kept: onto the nearer plane ``L₃ = ±μ L₁``
    (sorted axes, ``μ = √(I₃(I₂ − I₁)/(I₁(I₃ − I₂)))``, the planes ``|L|² = I₂ Σ Lᵢ²/Iᵢ``
    [LL76 §37]), then back onto the sphere along its direction.

    Returns:
        As :func:`snap_to_separatrix`, for L.
    """
    moments = check_inertia(inertia)
    m = np.asarray(momentum, dtype=np.float64)
    flat = _onto_separatrix_planes(moments, m, 1.0 / moments)
    if flat is None:
        return m.copy(), np.zeros(m.shape[:-1], dtype=bool)
    with np.errstate(invalid="ignore", divide="ignore"):
        snapped = flat * (np.linalg.norm(m, axis=-1) / np.linalg.norm(flat, axis=-1))[..., None]
    return _where_near(m, snapped, tolerance)


def _onto_separatrix_planes(moments: Array, v: Array, weights: Array) -> Array | None:
    """``v`` (..., 3) projected onto the nearer of the planes ``Σ wᵢ(Iᵢ − I₂) vᵢ² = 0``, in
    sorted axes ``v₃ = ±κ v₁`` with ``κ² = w₁(I₂ − I₁) / (w₃(I₃ − I₂))``: the separatrix for ω
    (``w = I``) and for L (``w = 1/I``); None without a separatrix (two equal moments)."""
    order = np.argsort(moments, kind="stable")
    I1, I2, I3 = moments[order]
    if not I1 < I2 < I3:
        return None
    w1, w3 = weights[order[0]], weights[order[2]]
    kappa = np.sqrt(w1 * (I2 - I1) / (w3 * (I3 - I2)))
    v1, v3 = v[..., order[0]], v[..., order[2]]
    sign = np.where(v1 * v3 < 0.0, -1.0, 1.0)
    # The plane v3 - sign·κ·v1 = 0 of normal (-sign κ, 1)/√(1 + κ²) in the (v1, v3) plane.
    n1, n3 = -sign * kappa / np.hypot(1.0, kappa), 1.0 / np.hypot(1.0, kappa)
    along = v1 * n1 + v3 * n3
    flat = v.copy()
    flat[..., order[0]] = v1 - along * n1
    flat[..., order[2]] = v3 - along * n3
    return flat


def _where_near(v: Array, snapped: Array, tolerance: float) -> tuple[Array, NDArray[np.bool_]]:
    near = np.linalg.norm(snapped - v, axis=-1) <= tolerance
    near &= np.all(np.isfinite(snapped), axis=-1)
    return np.where(near[..., None], snapped, v), near


def start_from_ray(
    inertia: ArrayLike,
    two_T: float,
    attitude: Rotation,
    origin: ArrayLike,
    direction: ArrayLike,
    scale: float = 1.0,
) -> Array:
    """The ω of energy T where each ray (space frame) meets the energy ellipsoid of the body
    turned by ``attitude`` (body -> space) at that instant.

    Args:
        inertia: (3,) the moments; two_T: ``2T`` > 0, the energy kept.
        attitude: the body's attitude when the ray was cast (one Rotation).
        origin, direction: (..., 3) rays in space, in drawn units: the ellipsoid is drawn
            ``scale`` times its size in ω's units (the point drawn at x is ω = x/scale).

    Returns:
        (..., 3) body-frame ω on ``ω·Iω = 2T`` to rounding; NaN rows where a ray misses.
    """
    moments = check_inertia(inertia)
    t2 = check_positive(two_T, "2T")
    o = attitude.inv().apply(np.reshape(np.asarray(origin, dtype=np.float64), (-1, 3)))
    d = attitude.inv().apply(np.reshape(np.asarray(direction, dtype=np.float64), (-1, 3)))
    shape = np.broadcast_shapes(np.shape(origin), np.shape(direction))
    hit = ray_ellipsoid(o / scale, d / scale, np.sqrt(t2 / moments))
    return np.reshape(on_energy_ellipsoid(moments, t2, hit), shape)


def momentum_from_ray(
    G: float, origin: ArrayLike, direction: ArrayLike, scale: float = 1.0
) -> Array:
    """The body-frame L where each ray meets Landau's sphere ``|L| = G`` [LL76 §37].

    Args:
        G: ``|L|`` > 0, kept.
        origin, direction: (..., 3) rays in the sphere's own axes (the body axes, centred on
            the sphere), in drawn units: the sphere is drawn ``scale`` times its size in L's
            units.

    Returns:
        (..., 3) L with ``|L| = G`` to rounding; NaN rows where a ray misses. Its ω is
        :func:`omega_from_momentum`, and its energy ``T = ½ L·ω`` follows from the point.
    """
    g = check_positive(G, "|L|")
    o = np.asarray(origin, dtype=np.float64) / scale
    d = np.asarray(direction, dtype=np.float64) / scale
    return ray_sphere(o, d, g)


def body_from_start(
    inertia: ArrayLike, omega0: ArrayLike, *, separatrix: bool = False
) -> FreeRigidBody:
    """The body started at ``omega0`` with L along +z (Poinsot's frame); with ``separatrix``
    (a start snapped onto it by :func:`snap_to_separatrix`), the exact separatrix through
    it, ``D == I₂``, as :meth:`FreeRigidBody.from_energy` builds it for ``D = I₂``."""
    moments = check_inertia(inertia)
    w = check_vector(omega0, "the initial angular velocity omega0")
    return FreeRigidBody(moments, w, attitude_checked(moments, w), on_separatrix=separatrix)
