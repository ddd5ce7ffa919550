"""Extra precision where a long run needs it: constants in double-double, exact linear phases.

A closed form evaluated at a large time ``t`` is limited by its *phase*: ``u = u0 + λ t`` or
the precession angle ``ν t``. Computed naively, the rounding of λ (a few ulps) and of the
product ``λ t`` give an error ``~eps·λt`` that grows with time, and reducing the phase modulo a
period known to only 16 digits adds ``~eps·u`` more. Here the rates and periods are computed
once, at 45 significant digits from the exact rational value of the data (``decimal``), kept
as ``hi + lo`` double pairs, and the phase is formed with Dekker's error-free product
(Veltkamp's split) [Dek71] and reduced with a three-part Cody-Waite constant [CW80]. What is
left is the rounding of ``t`` itself.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from decimal import Decimal, localcontext
from typing import TypeVar

import numpy as np
from numpy.typing import NDArray

#: Working digits of the one-off constant evaluations (double-double needs ~32).
DIGITS = 45
#: π to 60 digits.
PI = Decimal("3.14159265358979323846264338327950288419716939937510582097494")
#: 2^27 + 1: Veltkamp's constant that splits a double into two 26-bit halves.
_VELTKAMP = 134217729.0
#: Beyond this |τ| the Veltkamp split would overflow; the phase is pure noise there anyway.
_SPLIT_LIMIT = 1e290
#: Phases beyond this many periods get a second reduction (LinearPhase.reduce).
_REDUCE_LIMIT = 2.0**50

#: A float or an array of them (split works on both).
T = TypeVar("T", float, NDArray[np.float64])


def ratio(numerator: int, denominator: int) -> Decimal:
    """``numerator / denominator`` of two exact integers, rounded once to the context precision
    (not reduced first: a gcd of large integers costs more than the division)."""
    return Decimal(numerator) / Decimal(denominator)


def double_double(x: Decimal) -> tuple[float, float]:
    """``(hi, lo)`` with ``hi = round(x)`` and ``lo = round(x - hi)``."""
    hi = float(x)
    if not math.isfinite(hi):
        return hi, 0.0
    return hi, float(x - Decimal(hi))


def split(x: T) -> tuple[T, T]:
    """Veltkamp split ``x = hi + lo`` with 26-bit halves, so products of halves are exact."""
    c = _VELTKAMP * x
    hi = c - (c - x)
    return hi, x - hi


@dataclass(frozen=True)
class LinearPhase:
    """``u(τ) = offset + rate·τ`` reduced modulo ``period``: ``u = r + period·j``.

    Attributes:
        offset: the phase at τ = 0 (a double; its rounding does not grow with τ).
        rate_hi, rate_lo: the rate as a double-double pair.
        period_hi, period_lo: the period as a double-double pair.

    ``rate·τ`` is formed exactly (Dekker's product) and ``period·j`` exactly for
    ``|j| < 2^26`` (three-part constant), so ``r`` is accurate to a few ulps of ``period``
    for every τ whose phase is below ~2^26 periods, and degrades gracefully (``~eps·u``) beyond.
    """

    offset: float
    rate_hi: float
    rate_lo: float
    period_hi: float
    period_lo: float = 0.0

    def reduce(self, tau: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``(r, j)`` for (N,) dimensionless times τ: ``|r| <= period/2``, j as floats."""
        p = self.rate_hi * tau
        j = np.round((p + self.offset) / self.period_hi)
        c1, c2 = split(self.period_hi)
        c3 = self.period_lo
        t_max = float(np.abs(tau).max()) if tau.size else 0.0
        err: NDArray[np.float64] | float
        if t_max < _SPLIT_LIMIT:
            rh, rl = split(self.rate_hi)
            th, tl = split(tau)
            err = ((rh * th - p) + rh * tl + rl * th) + rl * tl  # p + err == rate_hi·τ exactly
            err = err + self.rate_lo * tau
        else:
            err = 0.0
        r = ((p - j * c1) - j * c2) + ((self.offset - j * c3) + err)
        if t_max * abs(self.rate_hi) > _REDUCE_LIMIT * self.period_hi:
            # Beyond ~2^50 periods j·c1 is no longer exact and r can come out as large as the
            # rounding of p itself (1e27 for p ~ 1e43): the phase is noise there anyway, but
            # every caller assumes |r| <= period/2. fmod is exact, and so is the final step
            # (Sterbenz), whatever the size of r.
            r = np.fmod(r, self.period_hi)
            j2 = np.round(r / self.period_hi)
            r = r - j2 * self.period_hi
            j = j + j2
        return r, j

    def reduce_scalar(self, tau: float) -> tuple[float, float]:
        """:meth:`reduce` for one float τ: the same operations in plain floats (same result).

        Raises OverflowError or ValueError where the phase is not finite (the array version
        returns NaN there); scalar callers fall back to the array version.
        """
        p = self.rate_hi * tau
        j = float(round((p + self.offset) / self.period_hi))
        c1, c2 = split(self.period_hi)
        t_abs = abs(tau)
        if t_abs < _SPLIT_LIMIT:
            rh, rl = split(self.rate_hi)
            th, tl = split(tau)
            err = ((rh * th - p) + rh * tl + rl * th) + rl * tl
            err = err + self.rate_lo * tau
        else:
            err = 0.0
        r = ((p - j * c1) - j * c2) + ((self.offset - j * self.period_lo) + err)
        if t_abs * abs(self.rate_hi) > _REDUCE_LIMIT * self.period_hi:
            r = math.fmod(r, self.period_hi)
            j2 = float(round(r / self.period_hi))
            r = r - j2 * self.period_hi
            j = j + j2
        return r, j


def angle_phase(rate: tuple[float, float], offset: float = 0.0) -> LinearPhase:
    """A phase reduced modulo 2π (for angles such as the precession φ = ν τ)."""
    return LinearPhase(offset, rate[0], rate[1], _TWO_PI[0], _TWO_PI[1])


def _two_pi() -> tuple[float, float]:
    with localcontext() as ctx:
        ctx.prec = DIGITS
        return double_double(2 * PI)


#: 2π as a double-double pair (computed once: every angle phase shares it).
_TWO_PI = _two_pi()
