"""The triaxial closed form: ω in Jacobi functions, the attitude through Π.

Both families, in the pole frame (the axis the polhode circles is the third) [LL76 §37,
Eq. 37.10]: ``ω = (A1 cn u, A2 sn u, s A3 dn u)``, ``u = u0 + σ τ``. In the major family the
moments ascend and ``σ = s λ``; in the minor family the pole frame has its moments in
decreasing order, which turns the sign of every right-hand side of Euler's equations
[LL76 §36, Eq. 36.5], so ``σ = -s λ``. The precession angle about L [LL76 §37, Eq. 37.16]
``φ' = G/J3 + c / (1 - N sn²u)``, ``N < 0``, ``c = G (J3 - J1)/(J1 J3)`` integrates to Π
[CFSZ08]: ``Π(N; am u) = (Π(N)/K) u + P(u)`` with P 2K-periodic, so the secular part joins
G/J3 in the mean rate ν and only the periodic part is evaluated, on the reduced argument.

Constants come from the exact integers of the data (:class:`~poinsot.physics.core.exact.ExactState`)
at 45 digits, m and 1 - m correctly rounded (no subtraction near the separatrix), λ, K and the
rates as double-double pairs so that the phases ``u = u0 + σ τ (mod 2K)`` and ``ν τ (mod 2π)``
stay exact to the rounding of τ itself over long runs (:mod:`poinsot.physics.core.precise`).
"""

from __future__ import annotations

import math
from decimal import Decimal, localcontext
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray
from scipy import special

from poinsot.physics.core import elliptic, precise
from poinsot.physics.core.closed_forms import Columns, Quaternion, ScalarQuaternion, Triple
from poinsot.physics.core.closed_forms.euler_angles import zxz_from_chi, zxz_from_chi_scalar
from poinsot.physics.core.closed_forms.sine_series import MIN_POINTS, clenshaw_sine, sine_series
from poinsot.physics.core.exact import ExactState, sqrt_ratio

__all__ = ["Triaxial"]

Array = NDArray[np.float64]

# ν_χ = ν ∓ πλ/(2K) as a difference keeps >= 35 of the 45 digits above this ratio (_slow_rate).
_CANCELLED = Decimal("1e-10")
# Below this sqrt(1 - m), u0 is taken from exact ratios (_u0_beyond_double).
_TINY_SQRT_MC = 1e-280
# Amplitudes above this give sn0 = ω2/A2, cn0 = ω1/A1 in floats (_initial_phase).
_NORMAL_AMPLITUDE = 1e-290


class _Constants(NamedTuple):
    """What the one 45-digit evaluation of a body gives, each rounded once."""

    m: float
    mc: float
    mc_ratio: tuple[int, int]  # 1 - m as an exact ratio of integers
    sqrt_mc: Decimal
    N: float
    K: tuple[float, float]  # double-double pairs from here on
    lam: tuple[float, float]
    nu: tuple[float, float]
    nu_chi: tuple[float, float]
    pi: float  # Π(N|m)
    excess: float  # Π(N|m) - K


def _constants(exact: ExactState) -> _Constants:
    """λ, m, 1 - m, K and the mean precession rates from the exact rationals of the data.

    Each is a quotient of integers [LL76 §37, Eq. 37.10]: ``λ² = (J3-J2)Δ1/(J1 J2 J3)``,
    ``m = (J1-J2)Δ3/((J3-J2)Δ1)``, ``1 - m = (J3-J1)Δ2/((J3-J2)Δ1)``,
    ``N = -J3(J2-J1)/(J1(J3-J2))``, scales as in :class:`ExactState`.
    """
    (n1, n2, n3), (e1, e2, e3), S = exact.Jn, exact.D, exact.S
    ratio = precise.ratio
    mc_num, mc_den = (n3 - n1) * e2, (n3 - n2) * e1
    N_num, N_den = -n3 * (n2 - n1), n1 * (n3 - n2)
    with localcontext() as ctx:
        ctx.prec = precise.DIGITS
        sqrt_mc = ratio(mc_num, mc_den).sqrt()
        N = ratio(N_num, N_den)
        dual = N < -1  # m itself is needed only then (the n -> m/n transformation)
        m = ratio((n1 - n2) * e3, (n3 - n2) * e1) if dual else None
        K, pi, excess = elliptic.complete_integrals_excess_decimal(N, sqrt_mc, m)
        G = exact.G_decimal()
        c = G * ratio((n3 - n1) << S, n1 * n3)
        if dual:
            nu = G / ratio(n3, 1 << S) + c * pi / K
        else:
            # G/J3 + c = G/J1 exactly: with a pole moment far below the others (J3 ~ 1e-77 J1
            # in the minor family) G/J3 and c·Π/K are both huge and nearly cancel.
            nu = G / ratio(n1, 1 << S) + c * excess / K
        lam = ratio(*exact.lam_squared()).sqrt()
        nu_chi = _slow_rate(exact, G, K, nu, lam, N, sqrt_mc)
        return _Constants(
            m=(n1 - n2) * e3 / ((n3 - n2) * e1),  # int / int: correctly rounded
            mc=mc_num / mc_den,
            mc_ratio=(mc_num, mc_den),
            sqrt_mc=sqrt_mc,
            N=N_num / N_den,
            K=precise.double_double(K),
            lam=precise.double_double(lam),
            nu=precise.double_double(nu),
            nu_chi=precise.double_double(nu_chi),
            pi=float(pi),
            excess=float(excess),
        )


def _slow_rate(
    exact: ExactState,
    G: Decimal,
    K: Decimal,
    nu: Decimal,
    lam: Decimal,
    N: Decimal,
    sqrt_mc: Decimal,
) -> Decimal:
    """The mean rate of the slow angle ``χ = φ + sψ`` (s = sign of the pole component), in the
    caller's 45-digit context.

    ``ν_χ = ν - π σ s/(2K) = ν - d π λ/(2K)`` (d = +1 in the major family, -1 in the minor).
    Near the pole of a body with moments 1e200 apart, ν and πλ/(2K) are ~1e225 while ν_χ ~ |ω|:
    φ and ψ separately are noise there, χ is not; the difference would cancel all digits. Then
    (cost ~30 µs, so only then) ``ν_χ = G/J3 + c (Π(N) - π/(2q))/K``, using ``c/q = ±λ``
    exactly (``q² = (1 - N)(1 - m/N)``, an identity of the data), with ``c = G/J1 - G/J3``:
    ``ν_χ = [G/J3 · copole + G/J1 · pole]/K``, two terms >= 0 (:class:`ThirdKindConstants`).
    """
    (n1, n2, n3), (e1, _, e3), S = exact.Jn, exact.D, exact.S
    ratio = precise.ratio
    drift = precise.PI * lam / (2 * K)
    nu_chi = nu - drift if n3 > n1 else nu + drift
    if abs(nu_chi) >= _CANCELLED * max(abs(nu), drift):
        return nu_chi
    third = elliptic.third_kind_constants(N, sqrt_mc, ratio((n1 - n2) * e3, (n3 - n2) * e1))
    return (G / ratio(n3, 1 << S) * third.copole + G / ratio(n1, 1 << S) * third.pole) / K


def _initial_phase(
    w: Triple,
    A: Triple,
    exact: ExactState,
    par: elliptic.JacobiParameter,
    sqrt_mc: float,
    mc_ratio: tuple[int, int],
) -> float:
    """``u0 = F(φ0 | m)``, ``φ0 = atan2(sn0, cn0)`` [LL76 §37], ``sn0 = ω2/A2``, ``cn0 = ω1/A1``.

    From the scaled floats where both amplitudes are normal doubles (a scaled ω component lost
    to underflow is then ~1e-308 of its amplitude, invisible in u0), else from their exact
    squares: an amplitude may underflow (A1 ~ 1e-400 for a spin a hair off the pole) where the
    ratio is still O(1).
    """
    if min(A[0], A[1]) > _NORMAL_AMPLITUDE:
        sn0, cn0 = w[1] / A[1], w[0] / A[0]
    else:
        sn0 = exact.sign(1) * sqrt_ratio(*exact.unit_ratio_sq(1))
        cn0 = exact.sign(0) * sqrt_ratio(*exact.unit_ratio_sq(0))
    if sqrt_mc < _TINY_SQRT_MC and sn0 * sn0 > cn0 * cn0:
        return _u0_beyond_double(exact, *mc_ratio, par)
    return elliptic.ellipf_from_angle(sn0, cn0, par, sqrt_mc)


def _u0_beyond_double(
    exact: ExactState, mc_num: int, mc_den: int, par: elliptic.JacobiParameter
) -> float:
    """``u0 = F(φ0 | m)`` for ``|sin φ0| > |cos φ0|`` when ``sqrt(1 - m)`` leaves the double range.

    :func:`poinsot.physics.core.elliptic.ellipf_from_angle` takes the complementary amplitude there,
    with ``sn v = c/d``, ``cn v = sqrt(mc)|s|/d``, ``dn v = sqrt(mc)/d``,
    ``d = hypot(c, sqrt(mc)|s|)`` (``s = sin φ0``, ``c = cos φ0``): ratios of numbers that may
    all underflow (a spin within 1e-320 of the intermediate axis). Here they come from the exact
    ratio ``ρ² = c²/(mc s²)``: ``cn²v = 1/(1 + ρ²)``, ``dn²v = 1/(s²(1 + ρ²))``,
    ``sn²v = ρ²/(1+ρ²)``, and ``F = K - F(v)``. Where ``ρ² > 1e40`` the m = 1 limit
    ``F = atanh s = ln((1 + |s|)/c)`` is exact to rounding (the correction is O(1/ρ²)) and is
    taken in decimal arithmetic, since ``c`` itself may be far below the double range.
    """
    C, D3 = exact.unit_ratio_sq(0)  # c² = C/D3
    S, _ = exact.unit_ratio_sq(1)  # s² = S/D3
    if D3 < 0:
        C, S, D3 = -C, -S, -D3
    K = par.K
    sign_s = exact.sign(1)
    with localcontext() as ctx:
        ctx.prec = precise.DIGITS
        if C == 0:
            f = K  # at the turning point itself
        elif C * mc_den > S * mc_num * 10**40:
            s_dec = precise.ratio(S, D3).sqrt()
            f = float((1 + s_dec).ln() - precise.ratio(C, D3).ln() / 2)
        else:
            rho2 = precise.ratio(C * mc_den, S * mc_num)
            cnv2 = float(1 / (1 + rho2))
            dnv2 = float(precise.ratio(D3, S) / (1 + rho2))
            snv = float((rho2 / (1 + rho2)).sqrt())
            f = K - snv * float(special.elliprf(cnv2, dnv2, 1.0))
    f = math.copysign(f, sign_s)
    if exact.sgn[0] >= 0:  # cos φ0 >= 0
        return f
    return math.copysign(2.0 * K, sign_s) - f


class Triaxial:
    """Major- or minor-axis family in the pole frame (pole = axis 3) [LL76 §37, Eq. 37.10].

    Args:
        J: (3,) scaled moments in the pole frame.
        w: (3,) scaled ω in the pole frame (floats; a component may have underflowed).
        exact: the same data as exact integers.

    The internal space frame has ``e_z ∥ L``; the attitude is read off the Z-X-Z angles of
    :mod:`~poinsot.physics.core.closed_forms.euler_angles`.
    """

    def __init__(self, J: Triple, w: Triple, exact: ExactState) -> None:
        J1, J2, J3 = J
        self.J = J
        # Exact square roots of exact ratios: a spin a hair off an axis (Δ ~ 1e-600) still
        # gets its amplitude ~1e-300.
        self.A = exact.amplitudes()
        c = _constants(exact)
        sqrt_mc = float(c.sqrt_mc)
        # sqrt(1 - m) as a Decimal: below ~1e-308 (a start within 1e-308 of the separatrix)
        # the AGM's first steps are taken in decimal arithmetic (JacobiParameter.from_pair).
        self.par = elliptic.JacobiParameter.from_pair(
            c.m, c.mc, sqrt_mc=c.sqrt_mc if sqrt_mc < _TINY_SQRT_MC else sqrt_mc, K=c.K[0]
        )
        self.s = exact.sign(2)
        direction = 1.0 if J3 > J1 else -1.0
        self.lam = c.lam[0]
        self.sigma = direction * self.s * self.lam
        self.u0 = _initial_phase(w, self.A, exact, self.par, sqrt_mc, c.mc_ratio)
        self.phase = precise.LinearPhase(
            self.u0, self.sigma, direction * self.s * c.lam[1], 2.0 * c.K[0], 2.0 * c.K[1]
        )
        self._init_precession(exact, c)
        self.parameter, self.complementary_parameter = self.par.m, self.par.mc
        self.period_pair = (4.0 * self.par.K, self.lam)
        self.rates = (self.sigma, self.nu, self.nu_chi)
        self.amplitude = max(self.A)

    def _init_precession(self, exact: ExactState, c: _Constants) -> None:
        """The constants of φ [LL76 §37, Eq. 37.16] and of the slow angle χ = φ + sψ."""
        J1, _, J3 = self.J
        n1, n2, n3 = exact.Jn
        K = self.par.K
        self.G = exact.G_float()
        self.N = c.N
        # Π/K and (Π - K)/K: quotients of correctly rounded doubles, no cancellation.
        self.pp = elliptic.PeriodicPi(self.N, c.pi / K, c.excess / K)
        self.c = self.G * ((J3 - J1) / J1 / J3)
        self.nu = c.nu[0]
        self.nu_chi = c.nu_chi[0]
        self.chi = precise.angle_phase(c.nu_chi)
        # ψ = atan2(m1, m2) = atan2(k cn, sn) (times the sign (-1)^j of both): the ratio
        # k = J1 A1/(J2 A2) of the data, so that ψ stays exact where m1, m2 are subnormal.
        self.k_psi = sqrt_ratio(n1 * (n3 - n2), n2 * (n3 - n1))
        self.half_pi_over_K = 0.5 * math.pi / K
        self.period = 4.0 * K / self.lam
        self.phase_scale = self.c / self.sigma
        self.P0 = self._periodic_pi_scalar(self.u0)
        self._series: Array | None = None
        self._series_built = False  # on the first long evaluation

    @property
    def sine_series(self) -> Array | None:
        """Sine coefficients of the precession wobble, or None where they converge too slowly.

        Built lazily (512 samples, ~0.2 ms): a body evaluated only at a few times never pays it.
        """
        if not self._series_built:
            self._series = sine_series(
                lambda u: self.phase_scale * self._periodic_pi(u), self.par.K
            )
            self._series_built = True
        return self._series

    def _reduced(self, tau: Array) -> tuple[Array, Array, Array, Array, Array]:
        r, j = self.phase.reduce(tau)
        sn, cn, dn = elliptic.sncndn_reduced(r, self.par)
        sign = 1.0 - 2.0 * np.mod(j, 2.0)
        return r, sign, sn, cn, dn

    def _periodic_pi(self, u: Array) -> Array:
        r, _ = elliptic.reduce_argument(u, self.par.K)
        sn, cn, dn = elliptic.sncndn_reduced(r, self.par)
        return elliptic.periodic_third_kind(self.pp, self.par, r, sn, cn, dn)

    def _periodic_pi_scalar(self, u: float) -> float:
        r, _ = elliptic.reduce_argument_scalar(u, self.par.K)
        sn, cn, dn = elliptic.sncndn_reduced_scalar(r, self.par)
        return elliptic.periodic_third_kind_scalar(self.pp, self.par, r, sn, cn, dn)

    def omega(self, tau: Array) -> Columns:
        _, sign, sn, cn, dn = self._reduced(tau)
        A1, A2, A3 = self.A
        return (A1 * sign * cn, A2 * sign * sn, (self.s * A3) * dn)

    def quat(self, tau: Array) -> tuple[Columns, Quaternion]:
        """ω and the Z-X-Z quaternion from the slow angle χ = φ + sψ.

        With ``u = r + 2Kj``: ``φ = ν τ + W(r)`` and ``ψ = ψ_r(r) + π j`` (ψ_r from the
        reduced sn, cn), ``ν τ = ν_χ τ + s(π/2K)(u - u0)``, so modulo 2π (and up to the
        constant ``-s(π/2K) u0``, absorbed by the fixed space rotation)
        ``χ = ν_χ τ + W(r) + s(ψ_r(r) + (π/2K) r)``: every term but the slow ``ν_χ τ`` is
        bounded, and nothing depends on the parity of j.
        """
        r, sign, sn, cn, dn = self._reduced(tau)
        A1, A2, A3 = self.A
        w = (A1 * sign * cn, A2 * sign * sn, (self.s * A3) * dn)
        J1, J2, J3 = self.J
        psi_r = np.arctan2(self.k_psi * cn, sn)
        chi = (
            self.chi.reduce(tau)[0]
            + self.precession_wobble(r, sn, cn, dn)
            + self.s * (psi_r + self.half_pi_over_K * r)
        )
        return w, zxz_from_chi(
            J1 * w[0], J2 * w[1], J3 * w[2], self.G, chi, psi_r, sign, self.s > 0.0
        )

    # One time in plain floats: the operations of omega/quat above, in the same order.

    def _reduced_scalar(self, tau: float) -> tuple[float, float, float, float, float]:
        r, j = self.phase.reduce_scalar(tau)
        sn, cn, dn = elliptic.sncndn_reduced_scalar(r, self.par)
        return r, 1.0 - 2.0 * (j % 2.0), sn, cn, dn

    def omega_scalar(self, tau: float) -> Triple:
        _, sign, sn, cn, dn = self._reduced_scalar(tau)
        A1, A2, A3 = self.A
        return (A1 * sign * cn, A2 * sign * sn, (self.s * A3) * dn)

    def quat_scalar(self, tau: float) -> tuple[Triple, ScalarQuaternion]:
        r, sign, sn, cn, dn = self._reduced_scalar(tau)
        A1, A2, A3 = self.A
        w = (A1 * sign * cn, A2 * sign * sn, (self.s * A3) * dn)
        J1, J2, J3 = self.J
        P = elliptic.periodic_third_kind_scalar(self.pp, self.par, r, sn, cn, dn)
        psi_r = float(np.arctan2(self.k_psi * cn, sn))
        chi = (
            self.chi.reduce_scalar(tau)[0]
            + self.phase_scale * (P - self.P0)
            + self.s * (psi_r + self.half_pi_over_K * r)
        )
        return w, zxz_from_chi_scalar(
            J1 * w[0], J2 * w[1], J3 * w[2], self.G, chi, psi_r, sign, self.s > 0.0
        )

    def precession_wobble(self, r: Array, sn: Array, cn: Array, dn: Array) -> Array:
        """The periodic part of φ: ``(c/σ) (P(u) - P(u0))`` at the reduced argument ``r``.

        By its sine series (:mod:`~poinsot.physics.core.closed_forms.sine_series`) where that
        converges in a few terms and enough times are asked for; else ``Π`` directly per point.
        """
        series = None if r.shape[0] < MIN_POINTS else self.sine_series
        if series is None:
            P = elliptic.periodic_third_kind(self.pp, self.par, r, sn, cn, dn)
            return self.phase_scale * (P - self.P0)
        theta = r * (math.pi / self.par.K)
        return clenshaw_sine(series, theta) - self.phase_scale * self.P0

    def polhode(self, n: int) -> Columns:
        # Uniform in the amplitude φ = am u: sn = sin φ, cn = cos φ, dn² = cos²φ + mc sin²φ.
        ang = np.linspace(0.0, 2.0 * math.pi, n, endpoint=False)
        s, c = np.sin(ang), np.cos(ang)
        dn = np.sqrt(c * c + self.par.mc * s * s)
        A1, A2, A3 = self.A
        return (A1 * c, A2 * s, (self.s * A3) * dn)
