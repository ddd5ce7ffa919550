"""Exact arithmetic for the construction: powers of two, dyadic integers, correctly rounded
square roots of ratios, and the exact state of a body (:class:`ExactState`).

Every finite double is a dyadic rational ``n / 2^e``. The few numbers that decide a motion
(three moments, three components of ω) are therefore exact integers once scaled, and so is
every polynomial in them: the classification ``Δ2 == 0`` and the constants of the closed forms
are those of the caller's own numbers, each rounded once at the end.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from decimal import Decimal, localcontext

from poinsot.physics.core import precise

__all__ = ["ExactState", "asinh_sqrt_ratio", "dyadic", "ldexp", "pow2_below", "sqrt_ratio"]


def ldexp(x: float, e: int) -> float:
    """``x · 2^e`` exactly (as math.ldexp), inf (not an OverflowError) beyond the range."""
    try:
        return math.ldexp(x, e)
    except OverflowError:
        return math.copysign(math.inf, x)


def pow2_below(x: float) -> float:
    """The power of two nearest below ``x > 0`` (scaling by it is exact)."""
    return math.ldexp(1.0, math.frexp(x)[1] - 1)


def dyadic(values: Iterable[float], exp2: int = 0) -> tuple[tuple[int, ...], int]:
    """Exact integers ``n_k`` and one shift ``e >= 0`` with ``values[k] / 2^exp2 = n_k / 2^e``.

    A few doubles share a power-of-two denominator; the shift is the smallest that serves them
    all, which keeps the integers (and every product of them below) as short as the data allow.
    ``exp2`` divides the values by an exact power of two (a change of units) without rounding
    them first.
    """
    ratios = [float(x).as_integer_ratio() for x in values]
    bits = [d.bit_length() - 1 for _, d in ratios]  # each denominator is 2^bits
    top = max(bits)
    ints = tuple(n << (top - b) for (n, _), b in zip(ratios, bits, strict=True))
    shift = top + exp2
    if shift < 0:
        return tuple(n << -shift for n in ints), 0
    return ints, shift


def sqrt_ratio(num: int, den: int) -> float:
    """``sqrt(num/den)`` correctly rounded, for integers of the same sign (or ``num = 0``).

    ``q = isqrt(floor(num·4^k/den)) = floor(sqrt(num/den)·2^k)`` with k chosen so that q has
    ~64 bits; when the root is inexact its lowest bit is set (a sticky bit below the rounding
    position), so rounding q to a double rounds the exact root. A result outside the normal
    range (not met by the amplitudes of scaled data) is left to decimal arithmetic.
    """
    if den < 0:
        num, den = -num, -den
    if num <= 0:
        return 0.0 if num == 0 else math.nan
    k = (128 - num.bit_length() + den.bit_length()) // 2
    if k >= 0:
        x, rem = divmod(num << (2 * k), den)
    else:
        x, rem = divmod(num, den << (-2 * k))
    q = math.isqrt(x)
    if rem or q * q != x:
        q |= 1
    if not -1020 <= q.bit_length() - k <= 1023:
        with localcontext() as ctx:
            ctx.prec = precise.DIGITS
            return float(precise.ratio(num, den).sqrt())
    return math.ldexp(float(q), -k)


def asinh_sqrt_ratio(num: int, den: int) -> float:
    """``asinh(sqrt(num/den))`` for integers of the same sign (or ``num = 0``), no overflow.

    Beyond ``sqrt(num/den) = 2^500`` (a separatrix start within 1e-150 of the unstable axis),
    ``asinh x = ln(2x) + O(1/x²)`` is taken in decimal arithmetic from the exact ratio.
    """
    if den < 0:
        num, den = -num, -den
    if num < den << 1000:
        return math.asinh(sqrt_ratio(num, den))
    with localcontext() as ctx:
        ctx.prec = precise.DIGITS
        return float((4 * precise.ratio(num, den)).ln() / 2)


def _sgn(n: int) -> int:
    return (n > 0) - (n < 0)


class ExactState:
    """Scaled moments and the squares of ω in one body frame as exact integers, and the exact
    ``Δi = G² - 2T·Ii``.

    Attributes:
        Jn, S: the moments, ``J_k = Jn_k / 2^S``.
        w2, den: the squares of ω, ``ω_k² = w2_k / den`` (``den > 0``).
        sgn: the sign of each ``ω_k`` as -1, 0 or +1.
        D: ``Δ_i · 4^S · den``, with ``Δi = Σ_j Jj ωj² (Jj - Ji)`` written as a sum of terms
            that cannot cancel against a large common part [LL76 §37]. Δ2 is the small
            difference that decides the regime and gives ``1 - m``; near the separatrix its two
            terms cancel, and in integers they do so exactly.
        G2: ``G² · 4^S · den`` (``G = |m|``).

    Each constant of a closed form is a quotient of such integers, divided once, correctly
    rounded (Python's ``int / int``, or :func:`poinsot.physics.core.precise.ratio` at 45 digits).
    Only the squares of ω enter (and its signs), so a state need not have rational components:
    :meth:`on_separatrix` builds one exactly on the limiting polhode.
    """

    __slots__ = ("D", "G2", "Jn", "S", "den", "sgn", "w2")

    def __init__(
        self,
        Jn: tuple[int, ...],
        S: int,
        w2: tuple[int, ...],
        den: int,
        sgn: tuple[int, ...],
    ) -> None:
        self.Jn, self.S, self.w2, self.den, self.sgn = Jn, S, w2, den, sgn
        jw2 = [Jn[k] * w2[k] for k in range(3)]
        self.D = (
            jw2[1] * (Jn[1] - Jn[0]) + jw2[2] * (Jn[2] - Jn[0]),
            jw2[0] * (Jn[0] - Jn[1]) + jw2[2] * (Jn[2] - Jn[1]),
            jw2[0] * (Jn[0] - Jn[2]) + jw2[1] * (Jn[1] - Jn[2]),
        )
        self.G2 = sum(Jn[k] * jw2[k] for k in range(3))

    @classmethod
    def from_floats(cls, J: Iterable[float], w: Iterable[float], w_exp: int = 0) -> ExactState:
        """The exact state of moments ``J`` and of ``ω = w / 2^w_exp``.

        ``w`` is ω in the caller's units: the scaled floats may have lost a component to
        underflow (ω0 = (1e150, 0, 1e-300) scales to (~1, 0, 0)), their integers lose nothing.
        """
        Jn, S = dyadic(J)
        wn, T = dyadic(w, w_exp)
        return cls(Jn, S, tuple(n * n for n in wn), 1 << (2 * T), tuple(map(_sgn, wn)))

    @classmethod
    def on_separatrix(cls, J: Iterable[float], w: Iterable[float], w_exp: int = 0) -> ExactState:
        """The state on the separatrix nearest ``ω = w / 2^w_exp``, for sorted ``J1 < J2 < J3``
        and ``ω = (ω1, ω2, ω3)`` with ω1, ω3 nonzero.

        Δ2 = 0 reads ``J1 (J2 - J1) ω1² = J3 (J3 - J2) ω3²`` (ω2 does not enter it): ω2 and the
        larger of ``|ω1|, |ω3|`` are kept and the other square set by this ratio (a rational,
        in general not the square of a double: no float ω lies exactly on the separatrix).
        The signs are those of ``w``.
        """
        Jn, S = dyadic(J)
        wn, T = dyadic(w, w_exp)
        a1 = Jn[0] * (Jn[1] - Jn[0])
        a3 = Jn[2] * (Jn[2] - Jn[1])
        keep = 0 if abs(wn[0]) >= abs(wn[2]) else 2
        square = wn[keep] * wn[keep]
        a_kept = a3 if keep == 0 else a1
        w2 = (square * a3, wn[1] * wn[1] * a_kept, square * a1)
        return cls(Jn, S, w2, a_kept << (2 * T), tuple(map(_sgn, wn)))

    def reversed(self) -> ExactState:
        """The same data in the minor family's pole frame ``x'' = (x3, x2, -x1)``."""
        out = object.__new__(ExactState)
        out.Jn, out.S, out.den = self.Jn[::-1], self.S, self.den
        out.w2 = self.w2[::-1]
        out.sgn = (self.sgn[2], self.sgn[1], -self.sgn[0])
        out.D, out.G2 = self.D[::-1], self.G2
        return out

    def amplitudes(self) -> tuple[float, float, float]:
        """``(A1, A2, A3)`` of [LL76 §37, Eq. 37.10] in this frame.

        ``A1² = Δ3/(J1(J1-J3))``, ``A2² = Δ3/(J2(J2-J3))``, ``A3² = Δ1/(J3(J3-J1))``: each a
        quotient of same-signed quantities in both families, whose square root is taken
        exactly (:func:`sqrt_ratio`), so that a spin a hair off an axis, with Δ ~ 1e-600,
        still gets its representable amplitude ~1e-300 instead of 0/0.
        """
        (J1, J2, J3), (D1, _, D3), den = self.Jn, self.D, self.den
        return (
            sqrt_ratio(D3, J1 * (J1 - J3) * den),
            sqrt_ratio(D3, J2 * (J2 - J3) * den),
            sqrt_ratio(D1, J3 * (J3 - J1) * den),
        )

    def lam_squared(self) -> tuple[int, int]:
        """``λ² = (J3 - J2) Δ1 / (J1 J2 J3)`` [LL76 §37, Eq. 37.10] as an exact ratio."""
        n1, n2, n3 = self.Jn
        return (n3 - n2) * self.D[0], n1 * n2 * n3 * self.den

    def G_decimal(self) -> Decimal:
        """``G = |m|`` at the context precision."""
        return precise.ratio(self.G2, self.den << (2 * self.S)).sqrt()

    def G_float(self) -> float:
        """``G = |m|`` (no underflow of ``G²`` when a moment is ~1e-300)."""
        g2 = self.G2 / (self.den << (2 * self.S))  # int / int: correctly rounded
        if g2 > 1e-300:
            return math.sqrt(g2)
        return sqrt_ratio(self.G2, self.den << (2 * self.S))

    def sign(self, k: int) -> float:
        """The sign of ``ω_k`` (+1 for zero), from the exact data."""
        return -1.0 if self.sgn[k] < 0 else 1.0

    def unit_ratio_sq(self, k: int) -> tuple[int, int]:
        """``(ω_k / A_k)²`` as an exact ratio of integers, for ``k`` = 0 or 1.

        ``A_k² = Δ3/(J_k(J_k - J3))``, so ``(ω_k/A_k)² = ω_k² J_k (J_k - J3)/Δ3`` (the scales
        cancel); on the polhode the two add up to exactly 1 (``cn² + sn²``).
        """
        n = self.Jn
        return self.w2[k] * n[k] * (n[k] - n[2]), self.D[2]
