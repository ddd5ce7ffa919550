"""Jacobi elliptic functions and elliptic integrals, accurate up to the separatrix.

Why not ``scipy.special.ellipj``: for ``m > 1 - 1e-9`` it switches to a first-order
tanh/sech expansion that is only valid for small ``u`` (at ``1 - m = 1e-10``, ``u ≈ 39`` it
returns ``|cn| ≈ 1e5``), and it takes ``m`` rather than ``1 - m``, so the complementary
parameter -- the only small quantity near the separatrix -- is rounded away before it starts.

Here the parameter is carried as the pair ``(m, mc)`` with ``mc = 1 - m`` computed by the
caller *without* subtraction, the argument is reduced to ``|r| <= K`` by the half-period
``2K``, and the reduced argument is evaluated with Bulirsch's descending Landen (AGM)
recurrence, which starts from ``sqrt(mc)`` and propagates the cotangent (not an arcsine), so
no step is ill-conditioned near ``m = 1`` (R. Bulirsch, Numer. Math. 7 (1965) 78-90, algorithm
``sncndn``; Press et al., Numerical Recipes, §6.11).

Complete and incomplete integrals use Carlson's symmetric forms (``scipy.special.elliprf``,
``elliprj``), written so that every argument is a sum of non-negative terms
(DLMF 19.25.1, 19.25.14): ``1 - m sin²φ`` becomes ``dn²`` or ``cos²φ + mc sin²φ``.

Everything here is vectorised over the argument ``u`` for one scalar parameter.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from decimal import Decimal, localcontext

import numpy as np
from poinsot.physics import precise
from scipy import special

# The AGM stops when |a - b| <= _AGM_TOL * a. Convergence is quadratic, so the next step would
# change a by (_AGM_TOL)^2 / 8 ~ 1e-17 relative: below double rounding (Numerical Recipes uses
# the square root of the target accuracy, as here).
_AGM_TOL = 2.0**-27
# The AGM table's first steps are taken in decimal arithmetic while b is below this (a sqrt(mc)
# near the bottom of the double range would lose its digits to gradual underflow).
_AGM_DECIMAL_BELOW = 1e-280
# Below this reduced phase the recurrence would divide by sin(phase) ~ 0 and overflow; the
# Maclaurin series sn = u - (1+m) u³/6, cn = 1 - u²/2, dn = 1 - m u²/2 is exact to rounding
# there (the first neglected terms are O(u^4) < 1e-32).
_SMALL_U = 1e-8
# sech²(r) stays above the smallest normal double for |r| below this (e^-600 ~ 1e-261).
_UNDERFLOW_REACH = 300.0
# The complementary branch of the periodic Π (v = K - |r|) is used only for v below this, so
# that cn²v, dn²v >= 4e^-300 ~ 2e-130: scipy's elliprj returns NaN once all of x, y and p fall
# below ~1e-154 (measured with scipy 1.17: elliprj(1e-160, 1e-160, 1, 1e-160) is NaN). Beyond
# it, 1 - m is invisible to rounding (mc·e^{2|r|} < 16 e^-300) and the m = 1 form is exact.
_COMPLEMENT_REACH = 150.0
# Convergence test of the 45-digit AGM loops (three digits of margin on the working precision).
_DECIMAL_TOL = Decimal(10) ** (3 - precise.DIGITS)
# ThirdKindConstants: below this |m/n|, Π(n) - π/(2q) is taken from a series, not a difference.
_TINY_DUAL = Decimal("-1e-10")


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
        a = 1.0
        agm_a: list[float] = []
        agm_b: list[float] = []
        if isinstance(sqrt_mc, Decimal) and b < _AGM_DECIMAL_BELOW:
            with localcontext() as ctx:
                ctx.prec = precise.DIGITS
                a_dec, b_dec = Decimal(1), +sqrt_mc
                while b_dec < _AGM_DECIMAL_BELOW:
                    agm_a.append(float(a_dec))
                    agm_b.append(float(b_dec))
                    a_dec, b_dec = (a_dec + b_dec) / 2, (a_dec * b_dec).sqrt()
                a, b = float(a_dec), float(b_dec)
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
            # K = R_F(0, mc, 1) (DLMF 19.25.1); never K(m) from m near 1.
            K = float(special.elliprf(0.0, mc, 1.0))
        return cls(m, mc, float(K), tuple(agm_a), tuple(agm_b), c)


def reduce_argument(u: np.ndarray, K: float) -> tuple[np.ndarray, np.ndarray]:
    """Split ``u = r + 2K j`` with ``|r| <= K`` and integer ``j`` (as float).

    ``sn(u) = (-1)^j sn(r)``, ``cn(u) = (-1)^j cn(r)``, ``dn(u) = dn(r)`` and
    ``am(u) = am(r) + j π``. The rounding error of ``r`` is ``~eps·|u|``, the unavoidable
    floor once ``u`` itself is a rounded number.
    """
    j = np.round(u / (2.0 * K))
    # Two-term product 2K·j: splitting 2K into a head with 26 significant bits keeps the head
    # product exact for |j| < 2^26, so r is as accurate as u itself (Cody-Waite reduction).
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


@dataclass(frozen=True)
class ThirdKindConstants:
    """Complete integrals of a body's precession, each free of cancellation (45 digits).

    Attributes:
        K: ``K(m)``.
        pi: ``Π(n|m)``.
        excess: ``Π(n|m) - K`` (straight from the series for ``-1 <= n < 0``).
        pole: ``Π(n|m) - π/(2q)``, ``q = sqrt((1 - n)(1 - m/n))``. By DLMF 19.7.9 at
            ``φ = π/2`` it equals ``K - Π(m/n|m)``, taken from the series in ``m/n`` whenever
            ``m/n >= -1`` (where ``Π(n)`` and ``π/(2q)`` nearly cancel).
        copole: ``K - pole = π/(2q) - (Π(n|m) - K)``, equal to ``Π(m/n|m)`` in the same cases.

    ``pole`` and ``copole`` are both >= 0 and each is formed without cancellation.
    """

    K: Decimal
    pi: Decimal
    excess: Decimal
    pole: Decimal
    copole: Decimal


def third_kind_constants(n: Decimal, sqrt_mc: Decimal, m: Decimal) -> ThirdKindConstants:
    """:class:`ThirdKindConstants` of ``n < 0`` and ``m = 1 - sqrt_mc²`` (exact decimals).

    The series of DLMF 19.8.6-19.8.8 needs ``-1 <= n < 0``; the transformation ``n -> m/n``
    (:func:`complete_integrals_excess_decimal`) maps the rest into that range.
    ``Π(n) - π/(2q)`` as a difference loses about ``log10(1/|m/n|)`` digits (it is
    ``~|m/n| K``): fine down to ``|m/n| = 1e-10`` (35 digits left for a double-double); below,
    ``K - Π(m/n)`` comes from a second series, on the same AGM.
    """
    with localcontext() as ctx:
        ctx.prec = precise.DIGITS
        one = Decimal(1)
        n_dual = m / n
        q = ((one - n) * (one - n_dual)).sqrt()
        pole_term = precise.PI / (2 * q)
        if n < -one:
            K, (excess_dual,) = _k_and_pi_excesses((n_dual,), +sqrt_mc)
            pi = pole_term - excess_dual
            return ThirdKindConstants(K, pi, pi - K, -excess_dual, K + excess_dual)
        if n_dual >= _TINY_DUAL:
            K, (excess, excess_dual) = _k_and_pi_excesses((n, n_dual), +sqrt_mc)
            return ThirdKindConstants(K, K + excess, excess, -excess_dual, K + excess_dual)
        K, (excess,) = _k_and_pi_excesses((n,), +sqrt_mc)
        pi = K + excess
        return ThirdKindConstants(K, pi, excess, pi - pole_term, pole_term - excess)


def complete_integrals_excess_decimal(
    n: Decimal, sqrt_mc: Decimal, m: Decimal | None = None
) -> tuple[Decimal, Decimal, Decimal]:
    """``(K(m), Π(n|m), Π(n|m) - K)`` to 45 digits from one AGM, given ``n < 1`` and
    ``sqrt(1 - m) > 0`` (decimals at the working precision; ``m`` itself, exact if the caller
    has it, is only needed for ``n < -1``).

    The AGM ``a_k, g_k`` with ``a0 = 1``, ``g0 = sqrt(1 - m)`` gives ``K = π/(2M)``, M its
    limit, and with ``p0² = 1 - n``, ``p_{k+1} = (p_k² + a_k g_k)/(2 p_k)``,
    ``ε_k = (p_k² - a_k g_k)/(p_k² + a_k g_k)``, ``Q0 = 1``, ``Q_{k+1} = Q_k ε_k / 2`` also
    ``Π - K = π/(4M) n/(1-n) Σ Q_k`` (DLMF 19.8.6-19.8.8): both come out of a single loop.
    ``Π - K`` is taken straight from that series for ``-1 <= n < 1`` (``Π - K ~ n K`` is tiny
    for a tiny ``n``, where a subtraction would cancel).

    For ``n < -1`` the series cancels: ``Π(n|m) ~ π/(2 sqrt(-n))`` while its terms are O(K),
    so a moment ratio of 1e90 (``n ~ -1e90``) would lose all 45 digits. There the
    transformation ``n -> m/n`` (DLMF 19.7.9 at ``φ = π/2``), ``Π(n|m) = π/(2q) - (Π(m/n|m) -
    K)`` with ``q = sqrt((1 - n)(1 - m/n))``, is used: ``m/n`` lies in ``(-1, 0]``, where
    ``Π(m/n|m) - K`` comes straight out of the series, cancellation free.
    """
    with localcontext() as ctx:
        ctx.prec = precise.DIGITS
        one = Decimal(1)
        if n < -one:
            if m is None:
                m = one - sqrt_mc * sqrt_mc
            n_dual = m / n
            K, (excess,) = _k_and_pi_excesses((n_dual,), +sqrt_mc)
            q = ((one - n) * (one - n_dual)).sqrt()
            pi = precise.PI / (2 * q) - excess
            return K, pi, pi - K
        K, (excess,) = _k_and_pi_excesses((n,), +sqrt_mc)
        return K, K + excess, excess


def _k_and_pi_excesses(
    ns: tuple[Decimal, ...], sqrt_mc: Decimal
) -> tuple[Decimal, tuple[Decimal, ...]]:
    """``K(m)`` and ``Π(n|m) - K(m)`` for each ``-1 <= n < 1``, from one AGM (DLMF 19.8.6-8).

    ``Π - K = π/(4M) · n/(1-n) · Σ Q_k``, computed as it stands (no difference of O(K) terms);
    the AGM ``a_k, g_k`` is shared, each ``n`` has its own ``p_k`` and ``Q_k``.
    """
    one = Decimal(1)
    a, g = one, sqrt_mc
    count = len(ns)
    ps = [(one - n).sqrt() for n in ns]
    qs = [one] * count
    totals = [Decimal(0)] * count
    for _ in range(200):
        ag = a * g
        converged = True
        for i in range(count):
            totals[i] += qs[i]
            p = ps[i]
            pp = p * p
            eps = (pp - ag) / (pp + ag)
            ps[i] = (pp + ag) / (2 * p)
            qs[i] = qs[i] * eps / 2
            converged = converged and abs(qs[i]) <= _DECIMAL_TOL * abs(totals[i])
        a, g = (a + g) / 2, ag.sqrt()
        if converged and abs(a - g) <= _DECIMAL_TOL * a:
            break
    quarter = precise.PI / (4 * a)
    return 2 * quarter, tuple(
        quarter * (n / (one - n) * total) for n, total in zip(ns, totals, strict=True)
    )


def sncndn_reduced(
    r: np.ndarray, par: JacobiParameter
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``sn, cn, dn`` of an already reduced argument ``|r| <= K`` (Bulirsch's recurrence).

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


def sncndn(u, m: float, mc: float | None = None):
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


def tanh_sech(u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(tanh u, sech u)`` without overflow warnings for large ``|u|`` (m = 1 limit).

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


def ellippi_from_jacobi(
    n: float, sn: np.ndarray, cn: np.ndarray, dn: np.ndarray, m: float = 0.0
) -> np.ndarray:
    """Incomplete ``Π(n; am u | m)`` from ``sn, cn, dn`` of a reduced argument (``cn >= 0``).

    With ``φ = am u``: ``sin φ = sn``, ``cos φ = cn`` and ``1 - m sin²φ = dn²``, so Carlson's
    form (DLMF 19.25.14) needs no subtraction: ``Π = sn R_F(cn², dn², 1)
    + (n/3) sn³ R_J(cn², dn², 1, 1 - n sn²)``. Valid for ``|φ| <= π/2`` and ``n <= 0``
    (where ``1 - n sn² >= 1``).

    For ``n < -1`` the two terms nearly cancel (``Π ~ atan(sqrt(-n) tan φ)/sqrt(-n)`` while each
    term is O(F)): a body with moments 1e6 apart would lose six digits, one with 1e90 all of
    them. There the transformation ``n -> m/n`` (DLMF 19.7.9, with ``c = 1/sn²``) is used,
    ``Π(n; φ) = F(φ) - Π(m/n; φ) + atan2(q sn, cn dn)/q``, ``q = sqrt((1 - n)(1 - m/n))``, and
    ``F - Π(m/n; φ) = -(m/(3n)) sn³ R_J(cn², dn², 1, 1 - (m/n) sn²)``: two terms of different
    sizes, no cancellation (``m`` is needed only here).
    """
    c2 = cn * cn
    d2 = dn * dn
    s2 = sn * sn
    if n < -1.0:
        n_dual = m / n
        q = math.sqrt((1.0 - n) * (1.0 - n_dual))
        return np.arctan2(q * sn, cn * dn) / q - (n_dual / 3.0) * sn * s2 * special.elliprj(
            c2, d2, 1.0, 1.0 - n_dual * s2
        )
    return sn * special.elliprf(c2, d2, 1.0) + (n / 3.0) * sn * s2 * special.elliprj(
        c2, d2, 1.0, 1.0 - n * s2
    )


def _ellippi_from_jacobi_scalar(n: float, m: float, sn: float, cn: float, dn: float) -> float:
    """:func:`ellippi_from_jacobi` for one sample (same branches and operations)."""
    c2, d2, s2 = cn * cn, dn * dn, sn * sn
    if n < -1.0:
        n_dual = m / n
        q = math.sqrt((1.0 - n) * (1.0 - n_dual))
        return float(np.arctan2(q * sn, cn * dn)) / q - (n_dual / 3.0) * sn * s2 * float(
            special.elliprj(c2, d2, 1.0, 1.0 - n_dual * s2)
        )
    return sn * float(special.elliprf(c2, d2, 1.0)) + (n / 3.0) * sn * s2 * float(
        special.elliprj(c2, d2, 1.0, 1.0 - n * s2)
    )


def ellipf_from_angle(
    sin_phi: float, cos_phi: float, par: JacobiParameter, sqrt_mc: float | None = None
) -> float:
    """Incomplete ``F(φ|m)`` for ``φ = atan2(sin_phi, cos_phi)`` in ``(-π, π]``.

    ``F(φ) = sinφ R_F(cos²φ, cos²φ + mc sin²φ, 1)`` for ``|φ| <= π/4``; for ``π/4 < |φ| <= π/2``
    the complementary amplitude ``v = K - u`` is used (``sn v = cn u / dn u``,
    ``cn v = sqrt(mc) sn u / dn u``, ``dn v = sqrt(mc) / dn u``), whose Carlson arguments stay
    O(1) even when ``cos φ`` and ``1 - m`` are far below the square root of the smallest
    double; beyond ``π/2``, ``F(φ) = 2K - F(π - φ)`` (DLMF 19.25.5, 19.2.10, 22.6.1).
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


@dataclass(frozen=True)
class PeriodicPi:
    """Constants of ``P(r) = Π(n; am r | m) - (Π(n|m)/K) r`` (:func:`periodic_third_kind`).

    Attributes:
        n: the characteristic, ``n < 0``.
        slope: ``Π(n|m)/K``.
        slope_m1: ``(Π(n|m) - K)/K``, from the series difference (accurate for tiny ``n``).

    ``P`` is evaluated in one of two cancellation-free ways. For ``-1 <= n < 0``,
    ``P = [Π(n; am r) - r] - (slope - 1) r`` with ``Π - F = (n/3) sn³ R_J(cn², dn², 1,
    1 - n sn²)``: both terms are O(n), where ``Π - slope·r`` would be a difference of two O(r)
    numbers (a pole moment 1e-77 of the largest gives ``n ~ -1e-62`` and a precession factor
    ~1e31 that multiplies the lost digits). For ``n < -1``, ``Π`` itself is small
    (``~1/sqrt(-n)``) and ``P = Π - slope·r`` directly, Π by the ``n -> m/n`` transformation
    (:func:`ellippi_from_jacobi`).
    """

    n: float
    slope: float
    slope_m1: float


def periodic_third_kind(
    pp: PeriodicPi,
    par: JacobiParameter,
    r: np.ndarray,
    sn: np.ndarray,
    cn: np.ndarray,
    dn: np.ndarray,
) -> np.ndarray:
    """``P(r) = Π(n; am r | m) - slope·r`` with ``slope = Π(n|m)/K``, ``|r| <= K``, ``n < 0``.

    For ``|r| <= K/2`` Carlson's form with ``(sn, cn, dn)`` of r (see :class:`PeriodicPi`).
    For ``|r| > K/2`` the complementary argument ``v = K - |r|``: with ``sn(K - v) = cd v``,
    ``1/(1 - n cd²v) = [m/n' + (1 - m/n')/(1 - n' sn²v)]/(1 - n)``, ``n' = (m - n)/(1 - n)``,
    so ``Π(n; am(K - v)) = Π(n) - m v/(m - n) + n mc Π(n'; am v)/((1 - n)(m - n))``. Its
    Carlson arguments are O(1) where ``cn² r`` and ``dn² r`` would underflow near the
    separatrix, and ``Π(n) - (Π(n)/K) K`` cancels exactly by construction (for ``n >= -1`` the
    coefficient ``slope - m/(m - n)`` is formed as ``(slope - 1) - n/(m - n)``).
    Only when ``K > 300`` (``1 - m < 1e-260``) does a middle stretch remain,
    ``min(K/2, 300) < |r| < K - 150``, where the first form would underflow and the second
    would feed scipy's ``elliprj`` arguments below 1e-154 (where it returns NaN); there
    ``1 - m`` is invisible (``mc e^{2|r|} < 16 e^{-300}``) and the m = 1 form
    ``Π = (r + a atan(a tanh r))/(1 - n)``, ``a = sqrt(-n)``, is exact to rounding.
    """
    n = pp.n
    dual = n < -1.0
    out = np.empty_like(r)
    reach = min(0.5 * par.K, _UNDERFLOW_REACH)
    near = np.abs(r) <= reach
    if near.any():
        rn, sn_n, cn_n, dn_n = r[near], sn[near], cn[near], dn[near]
        if dual:
            out[near] = ellippi_from_jacobi(n, sn_n, cn_n, dn_n, par.m) - pp.slope * rn
        else:
            c2, d2, s2 = cn_n * cn_n, dn_n * dn_n, sn_n * sn_n
            pi_minus_f = (n / 3.0) * sn_n * s2 * special.elliprj(c2, d2, 1.0, 1.0 - n * s2)
            out[near] = pi_minus_f - pp.slope_m1 * rn
    middle = (np.abs(r) > reach) & (par.K - np.abs(r) > _COMPLEMENT_REACH)
    if middle.any():
        a = math.sqrt(-n)
        rm = r[middle]
        th, _ = tanh_sech(rm)
        if dual:
            out[middle] = (rm + a * np.arctan(a * th)) / (1.0 - n) - pp.slope * rm
        else:
            out[middle] = (n * rm + a * np.arctan(a * th)) / (1.0 - n) - pp.slope_m1 * rm
    far = ~(near | middle)
    if far.any():
        m, mc = par.m, par.mc
        v = par.K - np.abs(r[far])
        snv, cnv, dnv = sncndn_reduced(v, par)
        coef = pp.slope - m / (m - n) if dual else pp.slope_m1 - n / (m - n)
        body = coef * v
        if mc > 0.0:  # the Π(n') term carries a factor 1 - m: exactly nothing when it underflows
            n_prime = (m - n) / (1.0 - n)
            c2, d2, s2 = cnv * cnv, dnv * dnv, snv * snv
            # 1 - n' sn² = (1 - n') + n' cn² with 1 - n' = mc/(1 - n): no cancellation.
            p = mc / (1.0 - n) + n_prime * c2
            pi_v = snv * special.elliprf(c2, d2, 1.0) + (
                n_prime / 3.0
            ) * snv * s2 * special.elliprj(c2, d2, 1.0, p)
            body = body + (n * mc / ((1.0 - n) * (m - n))) * pi_v
        out[far] = np.copysign(body, r[far])
    return out


def periodic_third_kind_scalar(
    pp: PeriodicPi, par: JacobiParameter, r: float, sn: float, cn: float, dn: float
) -> float:
    """:func:`periodic_third_kind` for one float ``r`` (same branches, same operations)."""
    n = pp.n
    dual = n < -1.0
    reach = min(0.5 * par.K, _UNDERFLOW_REACH)
    ar = abs(r)
    if ar <= reach:
        if dual:
            return _ellippi_from_jacobi_scalar(n, par.m, sn, cn, dn) - pp.slope * r
        c2, d2, s2 = cn * cn, dn * dn, sn * sn
        pi_minus_f = (n / 3.0) * sn * s2 * float(special.elliprj(c2, d2, 1.0, 1.0 - n * s2))
        return pi_minus_f - pp.slope_m1 * r
    if par.K - ar > _COMPLEMENT_REACH:
        a = math.sqrt(-n)
        th, _ = tanh_sech_scalar(r)
        if dual:
            return (r + a * float(np.arctan(a * th))) / (1.0 - n) - pp.slope * r
        return (n * r + a * float(np.arctan(a * th))) / (1.0 - n) - pp.slope_m1 * r
    m, mc = par.m, par.mc
    v = par.K - ar
    snv, cnv, dnv = sncndn_reduced_scalar(v, par)
    coef = pp.slope - m / (m - n) if dual else pp.slope_m1 - n / (m - n)
    body = coef * v
    if mc > 0.0:
        n_prime = (m - n) / (1.0 - n)
        c2, d2, s2 = cnv * cnv, dnv * dnv, snv * snv
        p = mc / (1.0 - n) + n_prime * c2
        pi_v = snv * float(special.elliprf(c2, d2, 1.0)) + (n_prime / 3.0) * snv * s2 * float(
            special.elliprj(c2, d2, 1.0, p)
        )
        body = body + (n * mc / ((1.0 - n) * (m - n))) * pi_v
    return math.copysign(body, r)
