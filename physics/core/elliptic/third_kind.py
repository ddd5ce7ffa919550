"""The incomplete integral of the third kind Π(n; φ | m) and its periodic part.

The precession angle of the free body is ``φ(t) ∝ Π(N; am u | m)`` [LL76 §37, Eq. 37.16],
[CFSZ08]. Carlson's symmetric form [DLMF 19.25.14], [Car95] (``scipy.special.elliprf``,
``elliprj``) is written so that every argument is a sum of non-negative terms: ``1 - m sin²φ``
becomes ``dn²``. The secular part of Π, ``(Π(n|m)/K) u``, is taken out (it joins the mean
precession rate); :func:`periodic_third_kind` evaluates what is left on the reduced argument,
by whichever of three forms has no cancellation and no underflow there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import special

from poinsot.physics.core.elliptic.jacobi import (
    JacobiParameter,
    sncndn_reduced,
    sncndn_reduced_scalar,
    tanh_sech,
    tanh_sech_scalar,
)

__all__ = [
    "PeriodicPi",
    "ellippi_from_jacobi",
    "periodic_third_kind",
    "periodic_third_kind_scalar",
]

Array = NDArray[np.float64]

# sech²(r) stays above the smallest normal double for |r| below this (e^-600 ~ 1e-261).
_UNDERFLOW_REACH = 300.0
# The complementary branch of the periodic Π (v = K - |r|) is used only for v below this, so
# that cn²v, dn²v >= 4e^-300 ~ 2e-130: scipy's elliprj returns NaN once all of x, y and p fall
# below ~1e-154 (measured with scipy 1.17: elliprj(1e-160, 1e-160, 1, 1e-160) is NaN). Beyond
# it, 1 - m is invisible to rounding (mc·e^{2|r|} < 16 e^-300) and the m = 1 form is exact.
_COMPLEMENT_REACH = 150.0


def ellippi_from_jacobi(n: float, sn: Array, cn: Array, dn: Array, m: float = 0.0) -> Array:
    """Incomplete ``Π(n; am u | m)`` from ``sn, cn, dn`` (each (N,)) of a reduced argument
    (``cn >= 0``); returns (N,).

    With ``φ = am u``: ``sin φ = sn``, ``cos φ = cn`` and ``1 - m sin²φ = dn²``, so Carlson's
    form [DLMF 19.25.14] needs no subtraction: ``Π = sn R_F(cn², dn², 1)
    + (n/3) sn³ R_J(cn², dn², 1, 1 - n sn²)``. Valid for ``|φ| <= π/2`` and ``n <= 0``
    (where ``1 - n sn² >= 1``).

    For ``n < -1`` the two terms nearly cancel (``Π ~ atan(sqrt(-n) tan φ)/sqrt(-n)`` while each
    term is O(F)): a body with moments 1e6 apart would lose six digits, one with 1e90 all of
    them. There the transformation ``n -> m/n`` [DLMF 19.7.9] (with ``c = 1/sn²``) is used,
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
    pp: PeriodicPi, par: JacobiParameter, r: Array, sn: Array, cn: Array, dn: Array
) -> Array:
    """``P(r) = Π(n; am r | m) - slope·r`` with ``slope = Π(n|m)/K``, ``|r| <= K``, ``n < 0``.

    Args:
        pp, par: the constants of P and of the parameter.
        r: (N,) reduced arguments; sn, cn, dn: (N,) their Jacobi functions.

    Returns:
        (N,) values of P. Three forms share the range of r:

    * ``|r| <= K/2`` (and ``|r| <= 300``): Carlson's form in ``(sn, cn, dn)`` of r
      (:class:`PeriodicPi`);
    * ``|r| > K/2``: the complementary argument ``v = K - |r|``, with ``sn(K - v) = cd v``
      [DLMF 22.4.iii], ``1/(1 - n cd²v) = [m/n' + (1 - m/n')/(1 - n' sn²v)]/(1 - n)``,
      ``n' = (m - n)/(1 - n)``, so ``Π(n; am(K - v)) = Π(n) - m v/(m - n) + n mc Π(n'; am v)
      /((1 - n)(m - n))``. Its Carlson arguments are O(1) where ``cn² r`` and ``dn² r`` would
      underflow near the separatrix, and ``Π(n) - (Π(n)/K) K`` cancels exactly by
      construction (for ``n >= -1`` the coefficient ``slope - m/(m - n)`` is formed as
      ``(slope - 1) - n/(m - n)``);
    * only when ``K > 300`` (``1 - m < 1e-260``) a middle stretch remains,
      ``min(K/2, 300) < |r| < K - 150``, where the first form would underflow and the second
      would feed scipy's ``elliprj`` arguments below 1e-154 (where it returns NaN); there
      ``1 - m`` is invisible (``mc e^{2|r|} < 16 e^{-300}``) and the m = 1 form
      ``Π = (r + a atan(a tanh r))/(1 - n)``, ``a = sqrt(-n)``, is exact to rounding.
    """
    out = np.empty_like(r)
    reach = min(0.5 * par.K, _UNDERFLOW_REACH)
    near = np.abs(r) <= reach
    if near.any():
        out[near] = _near(pp, par, r[near], sn[near], cn[near], dn[near])
    middle = (np.abs(r) > reach) & (par.K - np.abs(r) > _COMPLEMENT_REACH)
    if middle.any():
        out[middle] = _middle(pp, r[middle])
    far = ~(near | middle)
    if far.any():
        out[far] = _far(pp, par, r[far])
    return out


def _near(pp: PeriodicPi, par: JacobiParameter, r: Array, sn: Array, cn: Array, dn: Array) -> Array:
    """P by Carlson's form on the argument itself (``|r| <= K/2``)."""
    n = pp.n
    if n < -1.0:
        return ellippi_from_jacobi(n, sn, cn, dn, par.m) - pp.slope * r
    c2, d2, s2 = cn * cn, dn * dn, sn * sn
    pi_minus_f = (n / 3.0) * sn * s2 * special.elliprj(c2, d2, 1.0, 1.0 - n * s2)
    return pi_minus_f - pp.slope_m1 * r


def _middle(pp: PeriodicPi, r: Array) -> Array:
    """P by the m = 1 form (``1 - m`` below rounding on this stretch)."""
    n = pp.n
    a = math.sqrt(-n)
    th, _ = tanh_sech(r)
    if n < -1.0:
        return (r + a * np.arctan(a * th)) / (1.0 - n) - pp.slope * r
    return (n * r + a * np.arctan(a * th)) / (1.0 - n) - pp.slope_m1 * r


def _far(pp: PeriodicPi, par: JacobiParameter, r: Array) -> Array:
    """P through the complementary argument ``v = K - |r|`` (odd in r)."""
    n, m, mc = pp.n, par.m, par.mc
    v = par.K - np.abs(r)
    snv, cnv, dnv = sncndn_reduced(v, par)
    coef = pp.slope - m / (m - n) if n < -1.0 else pp.slope_m1 - n / (m - n)
    body = coef * v
    if mc > 0.0:  # the Π(n') term carries a factor 1 - m: exactly nothing when it underflows
        n_prime = (m - n) / (1.0 - n)
        c2, d2, s2 = cnv * cnv, dnv * dnv, snv * snv
        # 1 - n' sn² = (1 - n') + n' cn² with 1 - n' = mc/(1 - n): no cancellation.
        p = mc / (1.0 - n) + n_prime * c2
        pi_v = snv * special.elliprf(c2, d2, 1.0) + (n_prime / 3.0) * snv * s2 * special.elliprj(
            c2, d2, 1.0, p
        )
        body = body + (n * mc / ((1.0 - n) * (m - n))) * pi_v
    return np.copysign(body, r)


def periodic_third_kind_scalar(
    pp: PeriodicPi, par: JacobiParameter, r: float, sn: float, cn: float, dn: float
) -> float:
    """:func:`periodic_third_kind` for one float ``r`` (same branches, same operations)."""
    reach = min(0.5 * par.K, _UNDERFLOW_REACH)
    ar = abs(r)
    if ar <= reach:
        return _near_scalar(pp, par, r, sn, cn, dn)
    if par.K - ar > _COMPLEMENT_REACH:
        return _middle_scalar(pp, r)
    return _far_scalar(pp, par, r)


def _near_scalar(
    pp: PeriodicPi, par: JacobiParameter, r: float, sn: float, cn: float, dn: float
) -> float:
    n = pp.n
    if n < -1.0:
        return _ellippi_from_jacobi_scalar(n, par.m, sn, cn, dn) - pp.slope * r
    c2, d2, s2 = cn * cn, dn * dn, sn * sn
    pi_minus_f = (n / 3.0) * sn * s2 * float(special.elliprj(c2, d2, 1.0, 1.0 - n * s2))
    return pi_minus_f - pp.slope_m1 * r


def _middle_scalar(pp: PeriodicPi, r: float) -> float:
    n = pp.n
    a = math.sqrt(-n)
    th, _ = tanh_sech_scalar(r)
    if n < -1.0:
        return (r + a * float(np.arctan(a * th))) / (1.0 - n) - pp.slope * r
    return (n * r + a * float(np.arctan(a * th))) / (1.0 - n) - pp.slope_m1 * r


def _far_scalar(pp: PeriodicPi, par: JacobiParameter, r: float) -> float:
    n, m, mc = pp.n, par.m, par.mc
    v = par.K - abs(r)
    snv, cnv, dnv = sncndn_reduced_scalar(v, par)
    coef = pp.slope - m / (m - n) if n < -1.0 else pp.slope_m1 - n / (m - n)
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
