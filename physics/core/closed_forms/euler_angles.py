"""The attitude from the body angular momentum: Z-X-Z Euler angles about L.

In a space frame with ``e_z ∥ L`` the attitude is ``R = Rz(φ) Rx(θ) Rz(ψ)`` with
``m/G = (sinθ sinψ, sinθ cosψ, cosθ)`` [LL76 §37, Eqs. 37.13-37.14]: θ and ψ are algebraic in
ω(t), only the precession angle φ needs an integral. The quaternion is written through the
half-angles, ``(sin(θ/2) cos((φ-ψ)/2), sin(θ/2) sin((φ-ψ)/2), cos(θ/2) sin((φ+ψ)/2),
cos(θ/2) cos((φ+ψ)/2))``, scalar last.

The half-angle of θ is taken from whichever of ``G ± m3`` has no cancellation
(``G - m3 = ρ²/(G + m3)``, ``ρ = hypot(m1, m2)``), so it is accurate at both poles.

Each function has a scalar twin (``*_scalar``) for one sample in plain floats: the same
operations in the same order and numpy's own transcendental functions (on a float they run the
same kernel as on an array, where libm's may differ by an ulp), so both agree to the last bit.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from poinsot.physics.core.closed_forms import Quaternion, ScalarQuaternion

__all__ = ["zxz_from_chi", "zxz_from_chi_scalar", "zxz_from_momentum", "zxz_from_momentum_scalar"]

Array = NDArray[np.float64]


def zxz_from_momentum(
    m1: Array, m2: Array, m3: Array, G: float, phi: Array, psi: Array
) -> Quaternion:
    """Quaternion of ``Rz(φ) Rx(θ) Rz(ψ)`` with θ read off ``m/G``: ``cos θ = m3/G``,
    ``sin θ = ρ/G``; ``ψ = atan2(m1, m2)`` is given by the caller (who may know it more
    accurately than m1, m2 themselves). All arrays (N,)."""
    rho = np.hypot(m1, m2)
    # cos(θ/2) = sqrt((G + m3)/2G), sin(θ/2) = ρ / (2G cos(θ/2)); swap roles when m3 < 0.
    upper = m3 >= 0.0
    big = np.sqrt(0.5 * (G + np.abs(m3)) / G)
    small = rho / (2.0 * G * big)
    cos_half = np.where(upper, big, small)
    sin_half = np.where(upper, small, big)
    sum_half = 0.5 * (phi + psi)
    dif_half = 0.5 * (phi - psi)
    return (
        sin_half * np.cos(dif_half),
        sin_half * np.sin(dif_half),
        cos_half * np.sin(sum_half),
        cos_half * np.cos(sum_half),
    )


def zxz_from_chi(
    m1: Array, m2: Array, m3: Array, G: float, chi: Array, psi_r: Array, sign: Array, upper: bool
) -> Quaternion:
    """:func:`zxz_from_momentum` from the slow angle ``χ = φ + sψ`` (``s = +1`` if ``upper``).

    ``ψ = ψ_r + π(1 - sign)/2`` with ``sign = ±1`` (the parity of the half-period count j),
    ``ψ_r`` from the reduced argument. With the half-angles ``(φ ± ψ)/2`` written through χ,
    a shift of ψ by π only flips the sign of two quaternion components. For ``s = +1`` (pole
    component > 0, θ < π/2): ``(φ+ψ)/2 = χ/2``, ``(φ-ψ)/2 = χ/2 - ψ``; for ``s = -1``:
    ``(φ-ψ)/2 = χ/2``, ``(φ+ψ)/2 = χ/2 + ψ``.
    """
    rho = np.hypot(m1, m2)
    big = np.sqrt(0.5 * (G + np.abs(m3)) / G)  # the larger of cos(θ/2), sin(θ/2)
    small = rho / (2.0 * G * big)
    half = 0.5 * chi
    if upper:  # cos(θ/2) = big
        a = half - psi_r
        sa = sign * small
        return (sa * np.cos(a), sa * np.sin(a), big * np.sin(half), big * np.cos(half))
    b = half + psi_r  # sin(θ/2) = big
    sb = sign * small
    return (big * np.cos(half), big * np.sin(half), sb * np.sin(b), sb * np.cos(b))


def zxz_from_momentum_scalar(
    m1: float, m2: float, m3: float, G: float, phi: float, psi: float
) -> ScalarQuaternion:
    """:func:`zxz_from_momentum` for one sample."""
    rho = float(np.hypot(m1, m2))
    big = math.sqrt(0.5 * (G + abs(m3)) / G)
    small = rho / (2.0 * G * big)
    cos_half, sin_half = (big, small) if m3 >= 0.0 else (small, big)
    sum_half = 0.5 * (phi + psi)
    dif_half = 0.5 * (phi - psi)
    return (
        sin_half * float(np.cos(dif_half)),
        sin_half * float(np.sin(dif_half)),
        cos_half * float(np.sin(sum_half)),
        cos_half * float(np.cos(sum_half)),
    )


def zxz_from_chi_scalar(
    m1: float, m2: float, m3: float, G: float, chi: float, psi_r: float, sign: float, upper: bool
) -> ScalarQuaternion:
    """:func:`zxz_from_chi` for one sample."""
    rho = float(np.hypot(m1, m2))
    big = math.sqrt(0.5 * (G + abs(m3)) / G)
    small = rho / (2.0 * G * big)
    half = 0.5 * chi
    if upper:
        a = half - psi_r
        sa = sign * small
        return (
            sa * float(np.cos(a)),
            sa * float(np.sin(a)),
            big * float(np.sin(half)),
            big * float(np.cos(half)),
        )
    b = half + psi_r
    sb = sign * small
    return (
        big * float(np.cos(half)),
        big * float(np.sin(half)),
        sb * float(np.sin(b)),
        sb * float(np.cos(b)),
    )
