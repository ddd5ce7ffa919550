"""Two starts side by side: the lag between the first flips of twins [ACC91; LL76 §37;
FM06 Theorem 7.3; DLMF 19.12.1].

Twins are the same body (sorted moments ``I1 < I2 < I3``) spun at the same rate ``Ω`` at two
angles ``ε`` and ``ε′`` from the intermediate axis, both tilted towards the minor axis
(:func:`poinsot.physics.models.flip.flip_initial_omega` with ``β = 0``):

    ``ω0 = Ω (sin ε, cos ε, 0)``.

Such a start has ``ω3 = 0``, so its first flip is a quarter of the period of ω after the
start, ``t1 = K(m)/λ`` (``δ = 0`` in :func:`~poinsot.physics.models.flip.flip_theory`), with (minor
family, ``Δ3 = G² − 2T I3 < 0``)

    ``−Δ3 = I1 (I3 − I1) ω1² + I2 (I3 − I2) ω2²``,
    ``λ² = (I2 − I1)(−Δ3) / (I1 I2 I3)``,
    ``1 − m = I1 (I3 − I1) ω1² / (−Δ3)``,

every term of one sign (no cancellation, down to ``ε = 1e-12``). :func:`first_flip_times`
evaluates this on a whole array of angles at once, and the lag of the twin is
``t1(ε′) − t1(ε)``.

As ``ε → 0``, ``K = ln(4/√(1 − m)) + O((1 − m) ln(1 − m))`` [DLMF 19.12.1] and ``λ → σ``, the
growth rate ``σ = Ω √((I2 − I1)(I3 − I2)/(I1 I3))`` [LL76 §37; FM06 Theorem 7.3], so

    ``t1(ε) ≈ [ln(4/ε) + ½ ln(I2 (I3 − I2)/(I1 (I3 − I1)))]/σ``  and
    ``t1(ε′) − t1(ε) → ln(ε/ε′)/σ`` (:func:`lag_limit`):

a start ten times closer to the axis buys only ``ln(10)/σ`` more time, whatever ``ε``.
:func:`measured_lag` reads the lag off two motions (the first zero of ω2 of each).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import special

from poinsot.physics.core.free_body import FreeRigidBody
from poinsot.physics.core.validation import check_positive, check_vector
from poinsot.physics.models.family import sorted_moments
from poinsot.physics.models.flip import measure_flips

__all__ = [
    "TwinClock",
    "first_flip_times",
    "lag_limit",
    "measured_lag",
    "neighbour_start",
    "twin_clock",
]


def _angles(epsilon: ArrayLike, what: str) -> NDArray[np.float64]:
    """Angles [rad] as a float array, each in (0, π/2), else a ValueError."""
    try:
        eps = np.asarray(epsilon, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(
            f"{what} must be a number or an array of numbers, got {epsilon!r}"
        ) from None
    if not np.all((eps > 0.0) & (eps < 0.5 * math.pi)):
        raise ValueError(
            f"{what} must lie in (0, π/2) rad, got {epsilon!r} (0 is a spin exactly about e2, "
            "which never flips)"
        )
    return eps


def growth_rate(inertia: ArrayLike, spin: float = 1.0) -> float:
    """``σ = Ω √((I2 − I1)(I3 − I2)/(I1 I3))`` [1/time]: the rate of the linear instability
    at ``e2`` for the spin ``Ω`` [rad/time] (the limit of λ as ``ε → 0``)."""
    I1, I2, I3 = sorted_moments(inertia)
    omega = check_positive(spin, "the spin rate")
    return omega * math.sqrt((I2 - I1) / I1) * math.sqrt((I3 - I2) / I3)


def first_flip_times(
    inertia: ArrayLike, epsilon: ArrayLike, spin: float = 1.0
) -> NDArray[np.float64]:
    """The first flip ``K(m)/λ`` [time] of ``ω0 = Ω (sin ε, cos ε, 0)`` for every angle.

    Args:
        inertia: (3,) sorted distinct moments ``I1 < I2 < I3``.
        epsilon: (N,) or scalar angles [rad] from ``e2``, each in ``(0, π/2)``.
        spin: ``Ω = |ω0|`` [rad/time], > 0.

    Returns:
        (N,) times (a 0-d array for a scalar ``epsilon``).
    """
    I1, I2, I3 = sorted_moments(inertia)
    omega = check_positive(spin, "the spin rate")
    eps = _angles(epsilon, "the angle ε from the intermediate axis")
    J1, J2 = I1 / I3, I2 / I3  # the shape only: λ and 1 − m do not depend on the scale
    s, c = np.sin(eps), np.cos(eps)
    a = J1 * (1.0 - J1) * s * s  # I1 (I3 − I1) (ω1/Ω)²
    b = J2 * (1.0 - J2) * c * c  # I2 (I3 − I2) (ω2/Ω)²
    minus_d3 = a + b
    lam = omega * np.sqrt((J2 - J1) / (J1 * J2)) * np.sqrt(minus_d3)
    mc = a / minus_d3
    return np.asarray(special.ellipkm1(mc) / lam, dtype=np.float64)


def lag_limit(
    inertia: ArrayLike, epsilon: ArrayLike, epsilon2: ArrayLike, spin: float = 1.0
) -> NDArray[np.float64]:
    """``ln(ε/ε′)/σ`` [time]: the lag of the twin at ``ε′`` behind the one at ``ε`` in the
    limit of small angles (arrays broadcast)."""
    eps = _angles(epsilon, "the angle ε from the intermediate axis")
    eps2 = _angles(epsilon2, "the twin's angle ε′ from the intermediate axis")
    return np.asarray(np.log(eps / eps2) / growth_rate(inertia, spin), dtype=np.float64)


@dataclass(frozen=True)
class TwinClock:
    """The first flips of twins at ``ε`` and ``ε′`` (times in the caller's unit).

    Attributes:
        first_flip: ``K/λ`` of the body at ``ε``. second_flip: that of the twin at ``ε′``.
        lag: ``second_flip − first_flip``. limit: ``ln(ε/ε′)/σ``, the small-angle lag.
        growth_rate: σ [1/time].
    """

    first_flip: float
    second_flip: float
    lag: float
    limit: float
    growth_rate: float


def twin_clock(inertia: ArrayLike, epsilon: float, epsilon2: float, spin: float = 1.0) -> TwinClock:
    """The theory of the twins at ``ε`` and ``ε′`` [rad] (see the module docstring)."""
    t1, t2 = first_flip_times(inertia, [epsilon, epsilon2], spin)
    limit = float(lag_limit(inertia, epsilon, epsilon2, spin))
    return TwinClock(float(t1), float(t2), float(t2 - t1), limit, growth_rate(inertia, spin))


def measured_lag(first: FreeRigidBody, second: FreeRigidBody, t_end: float) -> float:
    """The lag read off two motions: the first zero of ω2 of ``second`` minus that of
    ``first`` (each found by :func:`~poinsot.physics.models.flip.measure_flips` up to ``t_end``);
    NaN if either has not flipped by then."""
    a, b = measure_flips(first, t_end), measure_flips(second, t_end)
    if len(a) == 0 or len(b) == 0:
        return math.nan
    return float(b[0] - a[0])


def neighbour_start(omega0: ArrayLike, angle: float) -> NDArray[np.float64]:
    """``omega0`` (3,) [rad/time] turned by ``angle`` [rad] (same length): a neighbour's start.

    The turn is about the unit axis ``n = ω0 × e_j / |ω0 × e_j|``, ``e_j`` the body axis of
    ω0's smallest component (never parallel to ω0), by Rodrigues' formula; for ω0 near a
    principal axis it tilts ω0 towards or away from another one.
    """
    w = check_vector(omega0, "omega0")
    eps = float(_angles(angle, "the neighbour's angle ε′"))
    j = int(np.argmin(np.abs(w)))
    n = np.cross(w, np.eye(3)[j])
    norm = float(np.linalg.norm(n))
    if norm == 0.0:
        raise ValueError("omega0 = 0 has no neighbour at an angle: the body is at rest")
    n /= norm
    return np.asarray(w * math.cos(eps) + np.cross(n, w) * math.sin(eps), dtype=np.float64)
