"""The separatrix closed form: the limiting polhode, ``Δ2 = 0`` exactly.

``ω = (s1 A1 sech u, A2 tanh u, s3 A3 sech u)``, ``u = u0 + s1 s3 λ τ`` [LL76 §37, Problem 2],
[FM06 Eq. 7.79], [Pars65 §13.12, Eqs. 13.12.19-20]: the body leaves the unstable intermediate
axis and reaches its opposite in infinite time. With m = 1 the precession integral is
elementary [LL76 §37, Eq. 37.16]:
``∫ du / (1 - N tanh²u) = (u + a atan(a tanh u))/(1 - N)`` with ``a = sqrt(-N)``.
"""

from __future__ import annotations

import math
from decimal import localcontext

import numpy as np
from numpy.typing import NDArray

from poinsot.physics.core import elliptic, precise
from poinsot.physics.core.closed_forms import Columns, Quaternion, ScalarQuaternion, Triple
from poinsot.physics.core.closed_forms.euler_angles import (
    zxz_from_momentum,
    zxz_from_momentum_scalar,
)
from poinsot.physics.core.exact import ExactState, asinh_sqrt_ratio, sqrt_ratio

__all__ = ["Separatrix"]

Array = NDArray[np.float64]

_HALF_PI = 0.5 * math.pi


def _mean_precession(exact: ExactState) -> tuple[float, float]:
    """ν = G/J3 + c/(1 - N), ``c = G (J3 - J1)/(J1 J3)``, to double-double from the exact data
    (as the triaxial rates)."""
    n1, n2, n3 = exact.Jn
    S = exact.S
    ratio = precise.ratio
    with localcontext() as ctx:
        ctx.prec = precise.DIGITS
        G = exact.G_decimal()
        N = ratio(-n3 * (n2 - n1), n1 * (n3 - n2))
        nu = G / ratio(n3, 1 << S) + G * ratio((n3 - n1) << S, n1 * n3) / (1 - N)
        return precise.double_double(nu)


class Separatrix:
    """The limiting polhode in the sorted frame (``J1 < J2 < J3``).

    Args:
        J: (3,) scaled sorted moments.
        exact: the same data as exact integers, with ``Δ2 = 0``.

    The internal space frame has ``e_z ∥ L`` (Z-X-Z angles, as the triaxial form).
    """

    def __init__(self, J: Triple, exact: ExactState) -> None:
        J1, J2, J3 = J
        n1, n2, n3 = exact.Jn
        self.J = J
        self.A = exact.amplitudes()
        # λ² = (J3-J2)Δ1/(J1 J2 J3), rounded once from the exact data (as the triaxial form).
        self.lam = sqrt_ratio(*exact.lam_squared())
        self.s1 = exact.sign(0)
        self.s3 = exact.sign(2)
        self.sigma = self.s1 * self.s3 * self.lam
        # tanh u0 = ω2/A2 and sech u0 = |ω1|/A1, so sinh²u0 = (ω2/A2)² / (ω1/A1)², exactly.
        self.u0 = exact.sign(1) * asinh_sqrt_ratio(
            exact.unit_ratio_sq(1)[0], exact.unit_ratio_sq(0)[0]
        )
        self.G = exact.G_float()
        # ψ = atan2(J1 s1 A1 sech, J2 A2 tanh) = atan2(k s1 sech, tanh), k = J1 A1/(J2 A2) a
        # ratio of the moments (as in the triaxial form): exact where m1, m2 are subnormal.
        self.k_psi = sqrt_ratio(n1 * (n3 - n2), n2 * (n3 - n1))
        N = -J3 / J1 * ((J2 - J1) / (J3 - J2))
        self.a = math.sqrt(-N)
        c = self.G * ((J3 - J1) / J1 / J3)
        nu = _mean_precession(exact)
        self.nu = nu[0]
        self.precession = precise.angle_phase(nu)
        self.amp = c * self.a / (self.sigma * (1.0 - N))
        self.period = math.inf
        self.atan0 = math.atan(self.a * math.tanh(self.u0))
        self.parameter, self.complementary_parameter = 1.0, 0.0
        self.period_pair = (0.0, 0.0)  # never repeats
        self.rates = (self.sigma, self.nu, 0.0)
        self.amplitude = max(self.A)

    def omega(self, tau: Array) -> Columns:
        th, sech = elliptic.tanh_sech(self.u0 + self.sigma * tau)
        A1, A2, A3 = self.A
        return ((self.s1 * A1) * sech, A2 * th, (self.s3 * A3) * sech)

    def quat(self, tau: Array) -> tuple[Columns, Quaternion]:
        th, sech = elliptic.tanh_sech(self.u0 + self.sigma * tau)
        A1, A2, A3 = self.A
        w = ((self.s1 * A1) * sech, A2 * th, (self.s3 * A3) * sech)
        phi = self.precession.reduce(tau)[0] + self.amp * (np.arctan(self.a * th) - self.atan0)
        J1, J2, J3 = self.J
        psi = np.arctan2((self.s1 * self.k_psi) * sech, th)
        return w, zxz_from_momentum(J1 * w[0], J2 * w[1], J3 * w[2], self.G, phi, psi)

    def omega_scalar(self, tau: float) -> Triple:
        th, sech = elliptic.tanh_sech_scalar(self.u0 + self.sigma * tau)
        A1, A2, A3 = self.A
        return ((self.s1 * A1) * sech, A2 * th, (self.s3 * A3) * sech)

    def quat_scalar(self, tau: float) -> tuple[Triple, ScalarQuaternion]:
        th, sech = elliptic.tanh_sech_scalar(self.u0 + self.sigma * tau)
        A1, A2, A3 = self.A
        w = ((self.s1 * A1) * sech, A2 * th, (self.s3 * A3) * sech)
        phi = self.precession.reduce_scalar(tau)[0] + self.amp * (
            float(np.arctan(self.a * th)) - self.atan0
        )
        J1, J2, J3 = self.J
        psi = float(np.arctan2((self.s1 * self.k_psi) * sech, th))
        return w, zxz_from_momentum_scalar(J1 * w[0], J2 * w[1], J3 * w[2], self.G, phi, psi)

    def polhode(self, n: int) -> Columns:
        # The heteroclinic arc from -e2 to +e2: with φ = gd(u), tanh u = sin φ, sech u = cos φ.
        ang = np.linspace(-_HALF_PI, _HALF_PI, n)
        c, s = np.cos(ang), np.sin(ang)
        A1, A2, A3 = self.A
        return ((self.s1 * A1) * c, A2 * s, (self.s3 * A3) * c)
