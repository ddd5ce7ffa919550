"""Complete integrals K(m) and Π(n|m) to 45 digits, each free of cancellation.

Computed once per body (in :mod:`decimal`), so that the rates of the closed forms are known to
double-double precision (:mod:`poinsot.physics.core.precise`). One AGM gives both K and ``Π - K``
[DLMF 19.8.6-19.8.8]; the transformation ``n -> m/n`` [DLMF 19.7.9] takes a characteristic
``n < -1``, where the series cancels, into ``(-1, 0]``, where it does not.
"""

from __future__ import annotations

from dataclasses import dataclass
from decimal import Decimal, localcontext

from poinsot.physics.core import precise

__all__ = ["ThirdKindConstants", "complete_integrals_excess_decimal", "third_kind_constants"]

# Convergence test of the 45-digit AGM loops (three digits of margin on the working precision).
_DECIMAL_TOL = Decimal(10) ** (3 - precise.DIGITS)
# ThirdKindConstants: below this |m/n|, Π(n) - π/(2q) is taken from a series, not a difference.
_TINY_DUAL = Decimal("-1e-10")


@dataclass(frozen=True)
class ThirdKindConstants:
    """Complete integrals of a body's precession, each free of cancellation (45 digits).

    Attributes:
        K: ``K(m)``.
        pi: ``Π(n|m)``.
        excess: ``Π(n|m) - K`` (straight from the series for ``-1 <= n < 0``).
        pole: ``Π(n|m) - π/(2q)``, ``q = sqrt((1 - n)(1 - m/n))``. By [DLMF 19.7.9] at
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

    The series [DLMF 19.8.6-19.8.8] needs ``-1 <= n < 0``; the transformation ``n -> m/n``
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
    ``Π - K = π/(4M) n/(1-n) Σ Q_k`` [DLMF 19.8.6-19.8.8]: both come out of a single loop.
    ``Π - K`` is taken straight from that series for ``-1 <= n < 1`` (``Π - K ~ n K`` is tiny
    for a tiny ``n``, where a subtraction would cancel).

    For ``n < -1`` the series cancels: ``Π(n|m) ~ π/(2 sqrt(-n))`` while its terms are O(K),
    so a moment ratio of 1e90 (``n ~ -1e90``) would lose all 45 digits. There the
    transformation ``n -> m/n`` [DLMF 19.7.9] at ``φ = π/2``, ``Π(n|m) = π/(2q) - (Π(m/n|m) -
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
    """``K(m)`` and ``Π(n|m) - K(m)`` for each ``-1 <= n < 1``, from one AGM [DLMF 19.8.6-19.8.8].

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
