"""How hard a case is in itself, whatever the method: the condition number of the motion, and
the flips that make errors saturate near the separatrix.

**Condition number.** kappa is the largest amplification, over the horizon, of a relative
perturbation of omega0 into a relative change of omega(t). It is estimated with the exact
solution itself: each component of omega0 is moved by a few ulps either way and the perturbed
motions are compared with the unperturbed one on the output grid. ``kappa u`` (u = 2^-53) is
then the omega error that rounding omega0 alone can cause; an integrator carries its state in
floating point and commits errors at least that size at every step, so errors near or above
kappa u are the problem's conditioning, not the method's truncation. Near the separatrix
kappa grows like 1 / (1 - m), since the period 4K(m)/lambda does [LL76 §37, Prob. 2].

**Flips.** Near the separatrix the motion is a sequence of half-turns of the body (the
Dzhanibekov effect [ACC91]): omega stays near +-(the intermediate axis) and flips between the
two. A run on the other side of one flip from the exact motion has omega reversed, an omega
error of exactly 2, and (L being fixed in space) an attitude error of pi. Which side of the
separatrix a motion is on is the sign of ``d = 1 - I2 / D``, ``D = G^2 / 2T`` [Pars65 §13.12]:
positive around the major axis, negative around the minor axis, zero on the separatrix.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from poinsot.physics import FreeRigidBody
from poinsot.physics.core import errors

__all__ = [
    "UNIT_ROUNDOFF",
    "Conditioning",
    "FlipCounter",
    "condition_number",
    "separatrix_distance",
]

#: u = 2^-53, the relative rounding of a double.
UNIT_ROUNDOFF = 2.0**-53
#: Perturbations of omega0 [ulps of its largest component], tried from the largest down: the
#: first whose response stays in the linear range (below LINEAR_RESPONSE) gives kappa. A large
#: perturbation keeps the exact solution's own rounding (~1e-16) out of the estimate.
PERTURBATION_ULPS = (2**20, 2**10, 1)
#: A relative change of omega below this is taken as the linear response to the perturbation.
LINEAR_RESPONSE = 1e-2
#: |d| below this is rounding (d is a difference of two O(1) sums of squares): the motion is on
#: the separatrix to working precision.
SEPARATRIX_TOLERANCE = 16 * UNIT_ROUNDOFF


@dataclass(frozen=True)
class Conditioning:
    """A case's condition number and its distance to the separatrix."""

    kappa: float
    lower_bound: bool
    """True when even a one-ulp perturbation left the linear range: kappa is at least this."""
    separatrix_distance: float
    """d = 1 - I2 / D of the initial state (signed; 0 on the separatrix)."""

    @property
    def floor(self) -> float:
        """kappa u: the omega error that rounding omega0 alone can cause."""
        return self.kappa * UNIT_ROUNDOFF


def separatrix_distance(inertia: ArrayLike, omega: ArrayLike) -> NDArray[np.float64]:
    """``d = 1 - I2 / D = (G^2 - 2T I2) / G^2`` for each row of omega ``(..., 3)``, I2 the
    intermediate moment: > 0 around the major axis, < 0 around the minor axis."""
    i = np.asarray(inertia, dtype=float)
    w = np.asarray(omega, dtype=float)
    g2 = errors.angular_momentum_norm(i, w) ** 2
    two_t = 2.0 * errors.energy(i, w)
    return np.asarray((g2 - two_t * float(np.median(i))) / g2, dtype=float)


def condition_number(
    inertia: ArrayLike,
    omega0: ArrayLike,
    t_eval: NDArray[np.float64],
    omega: NDArray[np.float64],
) -> Conditioning:
    """kappa of the motion over ``t_eval``, given the exact ``omega`` on it."""
    w0 = np.asarray(omega0, dtype=float)
    d0 = float(separatrix_distance(inertia, w0))
    kappa = math.nan
    for ulps in PERTURBATION_ULPS:
        response, kappa = _response(inertia, w0, t_eval, omega, ulps)
        if response <= LINEAR_RESPONSE:
            return Conditioning(kappa, False, d0)
    return Conditioning(kappa, True, d0)


def _response(
    inertia: ArrayLike,
    w0: NDArray[np.float64],
    t_eval: NDArray[np.float64],
    omega: NDArray[np.float64],
    ulps: int,
) -> tuple[float, float]:
    """(largest relative change of omega, largest change / relative perturbation) over the six
    perturbations of omega0 by +-ulps along each axis."""
    step = ulps * float(np.spacing(np.max(np.abs(w0))))
    size = float(np.linalg.norm(w0))
    response, kappa = 0.0, 0.0
    for axis in range(3):
        for sign in (1.0, -1.0):
            perturbed = w0.copy()
            perturbed[axis] += sign * step
            delta = float(np.linalg.norm(perturbed - w0)) / size
            moved = FreeRigidBody(inertia, perturbed).omega(t_eval)
            change = float(np.max(errors.omega_error(moved, omega)))
            response, kappa = max(response, change), max(kappa, change / delta)
    return response, kappa


@dataclass(frozen=True)
class FlipCounter:
    """Counts the half-turns of a motion on the output grid: passages of the intermediate-axis
    component of omega from above +threshold to below -threshold or back."""

    axis: int
    """Index of the intermediate moment (the caller's axes)."""
    threshold: float
    """Half the largest |omega| along that axis in the exact motion: a hysteresis band that
    rounding and small oscillations about zero do not cross."""

    @staticmethod
    def for_motion(inertia: ArrayLike, omega: NDArray[np.float64]) -> FlipCounter:
        """The counter for a case, from its exact omega on the grid."""
        axis = int(np.argsort(np.asarray(inertia, dtype=float), kind="stable")[1])
        return FlipCounter(axis, 0.5 * float(np.max(np.abs(omega[:, axis]))))

    def count(self, omega: NDArray[np.float64]) -> int:
        values = omega[:, self.axis]
        sides = np.where(values > self.threshold, 1, np.where(values < -self.threshold, -1, 0))
        sides = sides[sides != 0]
        return int(np.count_nonzero(np.diff(sides)))
