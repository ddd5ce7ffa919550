"""Jacobi's sn, cn, dn accurate up to the separatrix, and the integrals K and F.

Why not ``scipy.special.ellipj``: for ``m > 1 - 1e-9`` it switches to a first-order
tanh/sech expansion that is only valid for small ``u`` (at ``1 - m = 1e-10``, ``u ≈ 39`` it
returns ``|cn| ≈ 1e5``), and it takes ``m`` rather than ``1 - m``, so the complementary
parameter -- the only small quantity near the separatrix -- is rounded away before it starts.

Here the parameter is carried as the pair ``(m, mc)`` with ``mc = 1 - m`` computed by the
caller *without* subtraction, the argument is reduced to ``|r| <= K`` by the half-period
``2K`` [DLMF 22.4], and the reduced argument is evaluated with the descending Landen (AGM)
recurrence [Bul65, algorithm ``sncndn``], [DLMF 22.7], which starts from ``sqrt(mc)`` and
propagates the cotangent (not an arcsine), so no step is ill-conditioned near ``m = 1``.
Each evaluation has a scalar twin for one float with the same operations (the same bits).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from decimal import Decimal, localcontext

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import special

from poinsot.physics.core import precise

__all__ = [
    "JacobiParameter",
    "ellipf_from_angle",
    "ellipk",
    "reduce_argument",
    "reduce_argument_scalar",
    "sncndn",
    "sncndn_reduced",
    "sncndn_reduced_scalar",
    "tanh_sech",
    "tanh_sech_scalar",
]

Array = NDArray[np.float64]

# The AGM stops when |a - b| <= _AGM_TOL * a. Convergence is quadratic, so the next step would
# change a by (_AGM_TOL)^2 / 8 ~ 1e-17 relative: below double rounding (the square root of the
# target accuracy, as in [Bul65]).
_AGM_TOL = 2.0**-27
# The AGM table's first steps are taken in decimal arithmetic while b is below this (a sqrt(mc)
# near the bottom of the double range would lose its digits to gradual underflow).
_AGM_DECIMAL_BELOW = 1e-280
# Below this reduced phase the recurrence would divide by sin(phase) ~ 0 and overflow; the
# Maclaurin series sn = u - (1+m) u³/6, cn = 1 - u²/2, dn = 1 - m u²/2 [DLMF 22.10] is exact
# to rounding there (the first neglected terms are O(u^4) < 1e-32).
_SMALL_U = 1e-8


@dataclass(frozen=True)
class JacobiParameter:
    """One elliptic parameter with everything precomputed for fast evaluation.

    Attributes:
        m: the parameter ``k²`` in ``[0, 1)``.
        mc: the complementary parameter ``1 - m`` in ``(0, 1]``, accurate even when tiny.
        K: the complete integral of the first kind ``K(m)``, the quarter period.
        agm_a: the AGM's ``a_n`` sequence (Bulirsch's ``em``).
        agm_b: the AGM's ``b_n = sqrt(...)`` sequence (Bulirsch's ``en``).
        agm_c: the AGM limit ``π / (2K)``, the factor that maps ``u`` to the Landen phase.
    """

    m: float
    mc: float
    K: float
    agm_a: tuple[float, ...]
    agm_b: tuple[float, ...]
    agm_c: float

    @classmethod
    def from_pair(
        cls,
        m: float,
        mc: float,
        sqrt_mc: float | Decimal | None = None,
        K: float | None = None,
    ) -> JacobiParameter:
        """Precompute the AGM table for ``(m, mc)``; ``mc`` must be the accurate one.

        Args:
            m, mc: the parameter and its complement (``mc`` may underflow to 0.0 when
                ``sqrt_mc`` is given).
            sqrt_mc: ``sqrt(1 - m)`` if known to more range than ``mc`` itself (``1 - m``
                below 1e-308 still has a representable square root, the AGM's first term).
                As a Decimal it may even lie below the double range (``1 - m < 1e-616``,
                a start within 1e-308 of the separatrix): the first AGM steps are then taken
                in decimal arithmetic until ``b`` is a normal double (``b_{k+1} = sqrt(a_k
                b_k)`` squares the distance to the range at each step). The ``b_0`` that
                underflows enters only the last ``dn`` step, as an absolute ~1e-308.
            K: the quarter period if already known more accurately.

        Raises:
            ValueError: unless ``0 <= m <= 1``, ``0 <= mc <= 1`` and ``sqrt(1 - m) > 0``.
        """
        m, mc = float(m), float(mc)
        b = math.sqrt(mc) if sqrt_mc is None else float(sqrt_mc)
        positive = b > 0.0 or (isinstance(sqrt_mc, Decimal) and sqrt_mc > 0)
        # m itself may round to 1.0 when mc is tiny: sqrt(mc) is the one that must be positive.
        if not (0.0 <= m <= 1.0 and 0.0 <= mc <= 1.0 and positive and b <= 1.0):
            raise ValueError(f"elliptic parameter must satisfy 0 <= m < 1, got m={m}, 1-m={mc}")
        agm_a: list[float] = []
        agm_b: list[float] = []
        a = 1.0
        if isinstance(sqrt_mc, Decimal) and b < _AGM_DECIMAL_BELOW:
            a, b = _decimal_agm_start(sqrt_mc, agm_a, agm_b)
        c = 1.0
        for _ in range(16):  # quadratic convergence: 7 steps reach 1 - m = 1e-600
            agm_a.append(a)
            agm_b.append(b)
            c = 0.5 * (a + b)
            if abs(a - b) <= _AGM_TOL * a:
                break
            b = math.sqrt(a * b)
            a = c
        if K is None:
            # K = R_F(0, mc, 1) [DLMF 19.25.1]; never K(m) from m near 1.
            K = float(special.elliprf(0.0, mc, 1.0))
        return cls(m, mc, float(K), tuple(agm_a), tuple(agm_b), c)


def _decimal_agm_start(
    sqrt_mc: Decimal, agm_a: list[float], agm_b: list[float]
) -> tuple[float, float]:
    """The AGM's first steps in decimal arithmetic, appended to ``agm_a``, ``agm_b``, until
    ``b`` is a normal double; returns the ``(a, b)`` the double loop continues from."""
    with localcontext() as ctx:
        ctx.prec = precise.DIGITS
        a_dec, b_dec = Decimal(1), +sqrt_mc
        while b_dec < _AGM_DECIMAL_BELOW:
            agm_a.append(float(a_dec))
            agm_b.append(float(b_dec))
            a_dec, b_dec = (a_dec + b_dec) / 2, (a_dec * b_dec).sqrt()
        return float(a_dec), float(b_dec)


def reduce_argument(u: Array, K: float) -> tuple[Array, Array]:
    """Split (N,) arguments ``u = r + 2K j`` with ``|r| <= K`` and integer ``j`` (as float);
    returns ``(r, j)``, each (N,).

    ``sn(u) = (-1)^j sn(r)``, ``cn(u) = (-1)^j cn(r)``, ``dn(u) = dn(r)`` and
    ``am(u) = am(r) + j π``. The rounding error of ``r`` is ``~eps·|u|``, the unavoidable
    floor once ``u`` itself is a rounded number.
    """
    j = np.round(u / (2.0 * K))
    # Two-term product 2K·j: splitting 2K into a head with 26 significant bits keeps the head
    # product exact for |j| < 2^26, so r is as accurate as u itself (the Cody-Waite reduction
    # of poinsot.physics.core.precise).
    two_k = 2.0 * K
    head = float(np.float32(two_k)) if two_k < 3e38 else two_k
    tail = two_k - head
    r = (u - j * head) - j * tail
    return r, j


def reduce_argument_scalar(u: float, K: float) -> tuple[float, float]:
    """:func:`reduce_argument` for one float ``u``, with the same operations (same result).

    Raises OverflowError or ValueError where ``u / 2K`` is not finite (the array version
    returns NaN there); scalar callers fall back to the array version.
    """
    two_k = 2.0 * K
    j = float(round(u / two_k))
    head = float(np.float32(two_k)) if two_k < 3e38 else two_k
    tail = two_k - head
    return (u - j * head) - j * tail, j


def sncndn_reduced(r: Array, par: JacobiParameter) -> tuple[Array, Array, Array]:
    """``sn, cn, dn`` of an already reduced argument ``|r| <= K`` [Bul65].

    Args:
        r: (N,) arguments with ``|r| <= K``.
        par: the parameter table.

    Returns:
        ``(sn, cn, dn)``, each (N,), with ``cn >= 0`` and ``dn > 0``.
    """
    phase = r * par.agm_c
    small = np.abs(phase) < _SMALL_U
    # Keep the recurrence away from sin(phase) = 0; those entries are overwritten below.
    safe = np.where(small, 1.0, phase)
    s = np.sin(safe)
    a = np.cos(safe) / s
    c = par.agm_c * a
    dn = np.ones_like(r)
    for b, e in zip(reversed(par.agm_a), reversed(par.agm_b), strict=True):
        a = a * c
        c = c * dn
        dn = (e + a) / (b + a)
        a = c / b
    sn = np.copysign(1.0 / np.sqrt(c * c + 1.0), s)
    cn = c * sn
    if small.any():
        rs = r[small]
        r2 = rs * rs
        sn[small] = rs - (1.0 + par.m) * rs * r2 / 6.0
        cn[small] = 1.0 - 0.5 * r2
        dn[small] = 1.0 - 0.5 * par.m * r2
    return sn, cn, dn


def sncndn_reduced_scalar(r: float, par: JacobiParameter) -> tuple[float, float, float]:
    """:func:`sncndn_reduced` for one float ``|r| <= K``: the same recurrence in plain floats.

    A single time costs a few microseconds here instead of ~30 numpy calls on 1-element
    arrays. Every operation is the array version's, in the same order, and the transcendental
    functions are numpy's own (on a float, the same kernel as on an array, where libm's may
    differ by an ulp), so the two agree to the last bit.
    """
    phase = r * par.agm_c
    if abs(phase) < _SMALL_U:
        r2 = r * r
        return r - (1.0 + par.m) * r * r2 / 6.0, 1.0 - 0.5 * r2, 1.0 - 0.5 * par.m * r2
    s = float(np.sin(phase))
    a = float(np.cos(phase)) / s
    c = par.agm_c * a
    dn = 1.0
    for b, e in zip(reversed(par.agm_a), reversed(par.agm_b), strict=True):
        a = a * c
        c = c * dn
        dn = (e + a) / (b + a)
        a = c / b
    sn = math.copysign(1.0 / math.sqrt(c * c + 1.0), s)
    return sn, c * sn, dn


def sncndn(u: ArrayLike, m: float, mc: float | None = None) -> tuple[Array, Array, Array]:
    """Jacobi ``sn(u|m), cn(u|m), dn(u|m)``, accurate to ~1e-15 absolute for all ``0 <= m <= 1``.

    Args:
        u: scalar or array of real arguments (any shape).
        m: the parameter ``k²`` in ``[0, 1]``.
        mc: the complementary parameter ``1 - m``; pass it whenever it is known more
            accurately than ``1 - m`` (near the separatrix). ``mc == 0`` gives the limit
            ``(tanh u, sech u, sech u)``.

    Returns:
        ``(sn, cn, dn)`` with the shape of ``u``.
    """
    u_arr = np.asarray(u, dtype=float)
    if mc is None:
        mc = 1.0 - m
    if mc == 0.0:
        sn, cn = tanh_sech(u_arr)
        return sn, cn, cn.copy()
    par = JacobiParameter.from_pair(m, mc)
    flat = u_arr.reshape(-1)
    r, j = reduce_argument(flat, par.K)
    sn, cn, dn = sncndn_reduced(r, par)
    sign = 1.0 - 2.0 * np.mod(j, 2.0)
    return (
        (sign * sn).reshape(u_arr.shape),
        (sign * cn).reshape(u_arr.shape),
        dn.reshape(u_arr.shape),
    )


def tanh_sech(u: Array) -> tuple[Array, Array]:
    """``(tanh u, sech u)``, each of the shape of ``u``, without overflow warnings for large
    ``|u|`` (the m = 1 limit of sn and cn [DLMF 22.5.ii]).

    ``sech u = 2h/(1 + h²)`` with ``h = e^{-|u|}``: from h itself, not from ``sqrt(e^{-2|u|})``,
    whose argument underflows beyond |u| ~ 372 while sech stays representable to |u| ~ 745
    (a separatrix start 1e-180 off the unstable axis has u0 ~ 414).
    """
    h = np.exp(-np.abs(u))  # in (0, 1], underflows gracefully to 0
    e = h * h
    tanh = np.copysign((1.0 - e) / (1.0 + e), u)
    sech = 2.0 * h / (1.0 + e)
    return tanh, sech


def tanh_sech_scalar(u: float) -> tuple[float, float]:
    """:func:`tanh_sech` for one float (same operations, numpy's ``exp``)."""
    h = float(np.exp(-abs(u)))
    e = h * h
    return math.copysign((1.0 - e) / (1.0 + e), u), 2.0 * h / (1.0 + e)


def ellipk(m: float, mc: float | None = None) -> float:
    """Complete elliptic integral of the first kind ``K(m) = R_F(0, 1-m, 1)``; ``inf`` at m = 1."""
    if mc is None:
        mc = 1.0 - m
    if mc == 0.0:
        return math.inf
    return float(special.elliprf(0.0, mc, 1.0))


def ellipf_from_angle(
    sin_phi: float, cos_phi: float, par: JacobiParameter, sqrt_mc: float | None = None
) -> float:
    """Incomplete ``F(φ|m)`` for ``φ = atan2(sin_phi, cos_phi)`` in ``(-π, π]``.

    ``F(φ) = sinφ R_F(cos²φ, cos²φ + mc sin²φ, 1)`` for ``|φ| <= π/4``; for ``π/4 < |φ| <= π/2``
    the complementary amplitude ``v = K - u`` is used (``sn v = cn u / dn u``,
    ``cn v = sqrt(mc) sn u / dn u``, ``dn v = sqrt(mc) / dn u``), whose Carlson arguments stay
    O(1) even when ``cos φ`` and ``1 - m`` are far below the square root of the smallest
    double; beyond ``π/2``, ``F(φ) = 2K - F(π - φ)`` [DLMF 19.25.5, 19.2.10, 22.6.1].
    Inputs need not be normalised.
    """
    K = par.K
    sq = math.sqrt(par.mc) if sqrt_mc is None else sqrt_mc
    h = math.hypot(sin_phi, cos_phi)
    s, c = sin_phi / h, abs(cos_phi) / h
    if c >= abs(s):
        f = s * float(special.elliprf(c * c, c * c + par.mc * s * s, 1.0))
    else:
        d = math.hypot(c, sq * abs(s))  # dn u
        snv, cnv, dnv = c / d, sq * abs(s) / d, sq / d
        fv = snv * float(special.elliprf(cnv * cnv, dnv * dnv, 1.0))
        f = math.copysign(K - fv, s)
    if cos_phi >= 0.0:
        return f
    return math.copysign(2.0 * K, s) - f
