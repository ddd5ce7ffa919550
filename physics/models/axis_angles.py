"""The angles a student can read off the motion, and the wobble about a stable axis
[LL76 §37, Eqs. 37.13-37.14 and Problem 1].

* :func:`axis_angles`: the angle between L and each body axis, ``θᵢ = ∠(L, eᵢ)``, from the body
  momentum ``m = I ω`` (L in the body frame): ``θᵢ = atan2(|m × eᵢ|, mᵢ)``. The intermediate
  axis's flip is ``θ₂`` swinging through 90° (from near 0 to near 180°).
* :func:`zxz_angles`: the Z-X-Z Euler angles of the attitude about L (``R = R_L Rz(φ) Rx(θ)
  Rz(ψ)``, ``R_L`` a fixed frame whose z is L̂): ``cos θ = m3/G`` and ``ψ = atan2(m1, m2)``
  [LL76 Eq. 37.13], and φ, the precession, read off body axis 3 in space, whose components in
  the L frame are ``(sin θ sin φ, −sin θ cos φ, cos θ)``.
* :func:`wobble_theory`: the small oscillations about a stable axis ``a`` (major or minor) have
  the angular frequency ``Ω = ω_a √((I_a − I_b)(I_a − I_c)/(I_b I_c))`` [LL76 §37, Problem 1]
  (``b, c`` the other two axes): about the major axis ``ω₃ √((I₃−I₁)(I₃−I₂)/(I₁I₂))``, about the
  minor one ``ω₁ √((I₂−I₁)(I₃−I₁)/(I₂I₃))``; here ``ω_a = G/I_a``. It is the stable twin of the
  growth rate σ at the intermediate axis (the same product with one factor of the other sign).
* :func:`measure_wobble`: the wobble read off the motion: the angle between L and a transverse
  axis ``e_b`` swings about 90° at the wobble's frequency (the angle between L and ``e_a``
  itself, the tilt, at twice it), so the frequency is π over the spacing of its crossings of
  90°, each located on a grid and refined by Brent's method. The exact motion wobbles at
  ``πλ/(2K)``, which tends to Ω as the amplitude goes to 0 (relative gap O(amplitude²)).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import optimize

from poinsot.physics.core.free_body import FreeRigidBody
from poinsot.physics.core.validation import check_count, check_inertia
from poinsot.physics.models.flip_growth import check_body

__all__ = ["WobbleFit", "axis_angles", "measure_wobble", "wobble_theory", "zxz_angles"]

#: Grid samples per period of ω in measure_wobble (a crossing of 90° every half period).
_SAMPLES_PER_PERIOD = 64


def axis_angles(inertia: ArrayLike, omega: ArrayLike) -> NDArray[np.float64]:
    """The angles [rad, 0..π] between L and the body axes e₁, e₂, e₃.

    Args:
        inertia: (3,) principal moments (the body's axes). omega: (N, 3) or (3,) body-frame ω.

    Returns:
        (N, 3) or (3,): ``θᵢ = atan2(|m × eᵢ|, mᵢ)`` with ``m = I ω``; 0 where ``m = 0``.
    """
    J = np.asarray(check_inertia(inertia), dtype=np.float64)
    m = np.asarray(omega, dtype=np.float64) * J
    sq = m * m
    total = np.sum(sq, axis=-1, keepdims=True)
    across = np.sqrt(np.maximum(total - sq, 0.0))
    return np.asarray(np.arctan2(across, m), dtype=np.float64)


def zxz_angles(
    inertia: ArrayLike, omega: ArrayLike, quat_xyzw: ArrayLike, L: ArrayLike
) -> NDArray[np.float64]:
    """The Z-X-Z Euler angles (φ, θ, ψ) [rad] of the attitude about L (see the module
    docstring): φ and ψ in (−π, π], θ in [0, π].

    Args:
        inertia: (3,) moments. omega: (N, 3) body-frame ω. quat_xyzw: (N, 4) attitudes (body to
            space, scalar last). L: (3,) the angular momentum in space (its direction only).

    Returns:
        (N, 3). φ is measured from a fixed direction ⊥ L (space x when L is along +z).
    """
    J = np.asarray(check_inertia(inertia), dtype=np.float64)
    m = np.atleast_2d(np.asarray(omega, dtype=np.float64)) * J
    q = np.atleast_2d(np.asarray(quat_xyzw, dtype=np.float64))
    theta = np.arctan2(np.hypot(m[:, 0], m[:, 1]), m[:, 2])
    psi = np.arctan2(m[:, 0], m[:, 1])
    a, b, _ = _frame_about(np.asarray(L, dtype=np.float64))
    e3 = _third_column(q)
    phi = np.arctan2(e3 @ a, -(e3 @ b))
    return np.stack([phi, theta, psi], axis=1)


def _frame_about(L: NDArray[np.float64]) -> tuple[NDArray[np.float64], ...]:
    """A right-handed orthonormal (a, b, L̂): a = x, b = y when L is along +z."""
    norm = float(np.linalg.norm(L))
    if not (norm > 0.0 and math.isfinite(norm)):
        raise ValueError(f"L = {L.tolist()} has no direction (a body at rest has no Euler angles)")
    z = L / norm
    x = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    a = x - (x @ z) * z
    a /= np.linalg.norm(a)
    return a, np.cross(z, a), z


def _third_column(q: NDArray[np.float64]) -> NDArray[np.float64]:
    """Body axis 3 in space, R e₃, for quaternions (N, 4) scalar last."""
    x, y, z, w = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    return np.stack([2.0 * (x * z + w * y), 2.0 * (y * z - w * x), 1.0 - 2.0 * (x * x + y * y)], 1)


def wobble_theory(inertia: ArrayLike, axis: int, spin: ArrayLike) -> NDArray[np.float64]:
    """Ω = ω_a √((I_a − I_b)(I_a − I_c)/(I_b I_c)) [rad/time] for spins ``ω_a`` about ``axis``.

    Raises:
        ValueError: unless ``axis`` has the largest or the smallest moment, strictly (the
            intermediate axis grows instead: σ; a symmetric pair precesses at another rate).
    """
    J = check_inertia(inertia)
    a = check_count(axis, "axis (0, 1 or 2)", 0, 2)
    Ia, Ib, Ic = J[a], J[(a + 1) % 3], J[(a + 2) % 3]
    product = (Ia - Ib) * (Ia - Ic)
    if not product > 0.0:
        raise ValueError(
            f"axis {a} (I = {Ia:g}) is not strictly the major or the minor axis of {list(J)}: "
            "no wobble (the intermediate axis is unstable)"
        )
    return np.asarray(spin, dtype=np.float64) * math.sqrt(product / (Ib * Ic))


@dataclass(frozen=True)
class WobbleFit:
    """The wobble read off a motion: ``frequency`` [rad/time] (π over the mean spacing of the
    crossings), the ``crossings`` of 90° it used [time], and the ``amplitude`` [rad], the
    largest angle between L and the axis over them."""

    frequency: float
    crossings: NDArray[np.float64]
    amplitude: float


def measure_wobble(body: FreeRigidBody, axis: int, swings: int = 4) -> WobbleFit:
    """The frequency of the wobble about the stable ``axis`` of ``body``, from ``swings + 1``
    crossings of 90° by the angle between L and the next axis (see the module docstring).

    Raises:
        ValueError: the motion does not circle ``axis`` (no period, or that angle never
            crosses 90°: the body is not wobbling about it).
    """
    check_body(body, "measure_wobble")
    a = check_count(axis, "axis (0, 1 or 2)", 0, 2)
    n = check_count(swings, "swings", 1, 1000)
    period = body.period
    if not (math.isfinite(period) and period > 0.0):
        raise ValueError("the motion has no period: it does not wobble about an axis")
    b = (a + 1) % 3
    J = body.inertia
    t = np.linspace(0.0, (0.5 * n + 0.75) * period, int(_SAMPLES_PER_PERIOD * (0.5 * n + 1)))
    angles = axis_angles(J, body.omega(t))
    off = angles[:, b] - 0.5 * math.pi
    brackets = np.flatnonzero(np.sign(off[:-1]) * np.sign(off[1:]) < 0.0)[: n + 1]
    if len(brackets) < n + 1:
        raise ValueError(f"the angle between L and e{b + 1} does not swing about 90°")

    def swing(x: float) -> float:
        return float(axis_angles(J, body.omega(float(x)))[b]) - 0.5 * math.pi

    crossings = np.array(
        [optimize.brentq(swing, t[i], t[i + 1], xtol=1e-15, rtol=1e-15) for i in brackets]
    )  # one root per crossing: a loop over the swings, not over the samples
    spacing = float(np.mean(np.diff(crossings)))
    amplitude = float(np.max(angles[: brackets[-1] + 2, a]))
    return WobbleFit(math.pi / spacing, crossings, amplitude)
