"""Reference solutions for the physics tests, independent of the closed forms they check.

Three references, each built without any closed form or elliptic function from ``physics/``
(they share only its error measure, :mod:`poinsot.physics.core.errors`):

* :class:`ReferenceBody` -- the closed form of [LL76 §37, Eqs. 37.10, 37.13-37.16],
  re-derived here in mpmath at ``MP_DPS`` significant digits *from the float inputs*: the
  invariants ``2T``, ``G^2`` and ``Delta_i = G^2 - 2T I_i`` are computed exactly as rationals
  (:mod:`fractions`), so the regime (including the exact separatrix ``Delta_2 == 0``) is decided
  exactly and no digit is lost to cancellation near the separatrix. Jacobi functions come from
  ``mpmath.ellipfun`` after an explicit argument reduction modulo ``2K`` done at high precision;
  the precession angle from ``mpmath.ellippi`` ([LL76 §37, Eq. 37.16] integrated in closed form).
  ``tests/physics/test_reference.py`` proves this reference by (a) plugging it into Euler's
  equations and ``R' = R [omega]x`` with high-precision numerical derivatives, (b) comparing it
  with DOP853, and (c) comparing the ``ellippi`` precession angle with a direct quadrature.
* :func:`integrate_dop853` -- scipy's DOP853 on Euler's equations plus the rotation-matrix
  kinematics ``R' = R [omega]x`` (body -> space), written in the caller's axes, with no
  elliptic function anywhere.
* :func:`mp_sncndn` -- Jacobi sn, cn, dn at high precision, argument-reduced.

Tolerances used by several test files are named here, each with the reason for its value.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from fractions import Fraction

import mpmath as mp
import numpy as np
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from poinsot.physics.core.errors import attitude_error

EPS = float(np.finfo(float).eps)

# --------------------------------------------------------------------------------------------
# Named tolerances
# --------------------------------------------------------------------------------------------

MP_DPS = 40
"""Significant digits of the mpmath reference (>= 30 as required). Internally every evaluation
adds ``MP_GUARD_DPS`` guard digits plus the digits lost to argument reduction, so the rounded
float results are exact to the last bit; the self-tests compare against ``MP_DPS + 20``."""

MP_GUARD_DPS = 25
"""Guard digits added on top of ``MP_DPS`` inside the reference (covers the digits lost when
reducing ``u`` modulo ``2K`` and in the Euler-angle products)."""

SNCNDN_ATOL = 1e-13
"""Absolute error allowed for sn, cn, dn (all bounded by 1) for ``|u|`` up to ~100. A double
result carries ~1e-16; an evaluation on the complementary parameter (descending Landen / AGM
[Bul65] or the nome route) measured ~1e-13 down to ``1 - m = 1e-16``.
scipy.special.ellipj misses this by up to 18 orders of magnitude near ``m = 1``."""

SNCNDN_REDUCTION_EPS_FACTOR = 8.0
"""For large ``|u|`` the float ``K`` itself is off by ~eps relative, so any reduction of ``u``
modulo ``4K`` done in double carries an absolute phase error ~``eps |u|`` (and ``|d sn/du| <=
1``). The tolerance there is ``SNCNDN_ATOL + SNCNDN_REDUCTION_EPS_FACTOR * eps * |u|``: the
factor 8 covers the few roundings in ``K`` and in ``u - 4 j K``; an implementation that does
not reduce (or reduces in a lossy way) fails by orders of magnitude."""

OMEGA_RTOL_GENERIC = 1e-13
"""Generic regimes within 100 periods: ``max |omega - omega_ref| / |omega0|`` (the accuracy
the product promises)."""

ATTITUDE_ATOL_GENERIC = 1e-12
"""Generic regimes within 100 periods: geodesic angle [rad] between the attitude and the
reference (the accuracy the product promises)."""

OMEGA_ATOL_SEPARATRIX = 1e-12
"""Near and on the separatrix (``1 - m`` down to 1e-16 and exactly 0): absolute omega error with
omega scaled to 1, over at least two flips (the accuracy the product promises). Looser than the
generic 1e-13 because the motion itself is ill-conditioned there (it spends a time
~ln(1/(1-m)) next to the unstable pole, where a phase error is amplified)."""

ATTITUDE_ATOL_SEPARATRIX = 1e-12
"""Near and on the separatrix: geodesic angle [rad] over at least two flips. No number is promised
here; the generic 1e-12 is kept (measured: 1.5e-13 at ``1 - m = 1e-16``), although the
precession angle accumulates over a flip time ~ln(1/(1-m)) longer than a generic period."""

LONG_TIME_EPS_FACTOR = 100.0
"""At ``t`` = 1e6 periods the float inputs themselves limit the phase: ``lambda`` rounded to
double is off by ~eps, so ``u = lambda t`` is off by ~``eps lambda t`` [vZS07]. Allowed:
``LONG_TIME_EPS_FACTOR * eps * lambda * t`` (relative to ``|omega0|``, as promised); for the
attitude, whose fastest angle is the precession ``~|omega| t``, the same factor times
``eps * (lambda + |omega0|) * t`` [rad]."""

INVARIANT_RTOL = 1e-12
"""Property tests: energy, ``|L|`` and the space vector ``L = R I omega`` conserved to 1e-12
relative (as promised), over inertia ratios up to 1e6."""

ROTATION_ORTHO_ATOL = 1e-13
"""``R^T R = 1`` and ``det R = 1`` to 1e-13: a rotation assembled from a handful of unit
quaternion / matrix products in double stays within ~1e-15 of SO(3)."""

GEOMETRY_RTOL = 1e-12
"""Poinsot geometry (contact point on ``x.L = 2T``, normal parallel to L, polhode on the
ellipsoid and the sphere, ``h = 2T/G``): relative to the natural scale of each quantity."""

DOP853_RTOL = 1e-13
"""DOP853 relative tolerance for the formula-independent cross-checks (as required)."""

DOP853_ATOL = 1e-16
"""DOP853 absolute tolerance on the non-dimensional state (omega scaled to |omega0| = 1, time
scaled by |omega0|, R entries <= 1)."""

DOP853_FEW_PERIODS_ATOL = 3e-11
"""What DOP853 at rtol 1e-13 actually achieves over ~3 periods on a generic body, measured
against the mpmath reference (self-test ``physics/test_reference.py``): a few 1e-12 growing with
t (like t^2, as any non-geometric method's). Omega relative to |omega0| and attitude in rad."""


# --------------------------------------------------------------------------------------------
# Small helpers
# --------------------------------------------------------------------------------------------


def hat(w: np.ndarray) -> np.ndarray:
    """The skew matrix ``[w]x`` with ``[w]x v = w x v``."""
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def geodesic_angle(ra: np.ndarray, rb: np.ndarray) -> np.ndarray:
    """Angle [rad] of ``ra^T rb`` for (3, 3) or (N, 3, 3) rotation matrices (broadcasting):
    the project's one attitude error measure, :func:`poinsot.physics.core.errors.attitude_error`,
    on their quaternions (accurate near 0 and near pi)."""
    return attitude_error(Rotation.from_matrix(ra), Rotation.from_matrix(rb))


def as_matrices(rot: Rotation) -> np.ndarray:
    """Rotation (single or stack) -> (3, 3) or (N, 3, 3) float matrices."""
    return np.asarray(rot.as_matrix(), dtype=float)


def exact_invariants(inertia: Sequence[float], omega: Sequence[float]) -> dict[str, object]:
    """``2T``, ``G^2`` and ``Delta_i = G^2 - 2T I_i`` as exact rationals of the float inputs."""
    ii = [Fraction(float(x)) for x in inertia]
    ww = [Fraction(float(x)) for x in omega]
    two_t = sum(i * w * w for i, w in zip(ii, ww, strict=True))
    g2 = sum(i * i * w * w for i, w in zip(ii, ww, strict=True))
    return {"I": ii, "w": ww, "2T": two_t, "G2": g2, "Delta": [g2 - two_t * i for i in ii]}


def _mpf(x: Fraction | float | int) -> mp.mpf:
    if isinstance(x, Fraction):
        return mp.mpf(x.numerator) / x.denominator
    return mp.mpf(x)


def _rz(a: mp.mpf) -> mp.matrix:
    c, s = mp.cos(a), mp.sin(a)
    return mp.matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def _rodrigues(axis: Sequence[mp.mpf], angle: mp.mpf) -> mp.matrix:
    """Rotation by ``angle`` about the unit ``axis`` (mpmath)."""
    x, y, z = axis
    c, s = mp.cos(angle), mp.sin(angle)
    k = 1 - c
    return mp.matrix(
        [
            [c + x * x * k, x * y * k - z * s, x * z * k + y * s],
            [y * x * k + z * s, c + y * y * k, y * z * k - x * s],
            [z * x * k - y * s, z * y * k + x * s, c + z * z * k],
        ]
    )


# --------------------------------------------------------------------------------------------
# Jacobi elliptic functions at high precision
# --------------------------------------------------------------------------------------------


def mp_parameter(m: float, mc: float) -> mp.mpf:
    """The exact parameter the float pair ``(m, mc)`` stands for.

    A double cannot hold ``m`` and ``1 - m`` both exactly: near ``m = 1`` the complementary
    ``mc`` carries the information (``1 - 1e-16`` rounds to 1), near ``m = 0`` the parameter
    does (``1 - 1e-18`` rounds to 1). The smaller of the two is authoritative.
    """
    with mp.workdps(MP_DPS + MP_GUARD_DPS):
        if mc <= m:
            return 1 - mp.mpf(mc)
        return +mp.mpf(m)


def mp_sncndn(u: float | mp.mpf, m: mp.mpf, dps: int = MP_DPS) -> tuple[mp.mpf, mp.mpf, mp.mpf]:
    """sn, cn, dn(u | m) at ``dps`` digits, reducing ``u`` modulo ``2K`` at high precision.

    mpmath's theta-function route loses digits for large ``u`` near ``m = 1`` (measured: 1e-15
    at ``1 - m = 1e-30``, ``u = 1000`` with 40 digits), so the reduction ``u = 2 j K + r``,
    ``|r| <= K``, is done here with enough extra digits for ``|u| / K``, then
    ``sn(u) = (-1)^j sn(r)``, ``cn(u) = (-1)^j cn(r)``, ``dn(u) = dn(r)``.
    """
    with mp.workdps(dps + MP_GUARD_DPS):
        u = mp.mpf(u)
        m = mp.mpf(m)
        extra = int(max(0.0, float(mp.log10(abs(u) + 1)))) + 5
    with mp.workdps(dps + MP_GUARD_DPS + extra):
        u = mp.mpf(u)
        if m == 1:
            return mp.tanh(u), mp.sech(u), mp.sech(u)
        k = mp.ellipk(m)
        j = int(mp.nint(u / (2 * k)))
        r = u - 2 * j * k
        sign = -1 if j % 2 else 1
        sn = mp.ellipfun("sn", r, m)
        cn = mp.ellipfun("cn", r, m)
        dn = mp.ellipfun("dn", r, m)
        return +sign * sn, +sign * cn, +dn


# --------------------------------------------------------------------------------------------
# The closed-form reference [LL76 §37] in mpmath
# --------------------------------------------------------------------------------------------


def _proper_sort(inertia: Sequence[float]) -> np.ndarray:
    """Signed permutation Q (det +1) with ``Q diag(I) Q^T`` ascending: ``omega_sorted = Q omega``.

    An odd permutation of body axes would turn a right-handed frame into a left-handed one, for
    which Euler's equations change sign; one axis is negated to keep det = +1.
    """
    order = sorted(range(3), key=lambda i: (float(inertia[i]), i))
    q = np.zeros((3, 3))
    for row, col in enumerate(order):
        q[row, col] = 1.0
    if round(np.linalg.det(q)) < 0:
        q[0] = -q[0]
    return q


_SWAP_POLE = np.array([[0.0, 0.0, 1.0], [0.0, -1.0, 0.0], [1.0, 0.0, 0.0]])
"""Proper relabelling (1, 2, 3) -> (3, -2, 1): puts the minor axis into the pole slot."""


class ReferenceBody:
    """Torque-free rigid body in closed form at high precision ([LL76 §37], re-derived).

    Frames: the caller's body axes; the *pole frame* ``(a, b, c)`` obtained by a proper signed
    permutation ``P`` so that ``I_b`` is the intermediate moment and the conserved-sign
    component (the pole of the polhode) is ``c``. With ``Delta_i = G^2 - 2T I_i`` (exact):

    * ``A_a^2 = -Delta_c / (I_a (I_c - I_a))``, ``A_b^2 = -Delta_c / (I_b (I_c - I_b))``,
      ``A_c^2 = Delta_a / (I_c (I_c - I_a))`` [LL76 §37, Eq. 37.10];
    * ``lambda^2 = (I_c - I_b) Delta_a / (I_a I_b I_c)``,
      ``m = (I_b - I_a)(-Delta_c) / ((I_c - I_b) Delta_a)``,
      ``1 - m = Delta_b (I_c - I_a) / (Delta_a (I_c - I_b))`` (exact, no cancellation);
    * ``omega = (A_a cn u, A_b sn u, s A_c dn u)``, ``u = u0 + sigma lambda t``, ``s = sign
      omega_c(0)``, ``sigma = s sign(I_c - I_b)`` (from Euler's equations: the minor family in
      the relabelled frame has ``I_c < I_b``), ``u0 = F(atan2(omega_b/A_b, omega_a/A_a) | m)``;
    * separatrix (``Delta_b = 0``): ``omega = (s_a A_a sech u, A_b tanh u, s_c A_c sech u)``,
      ``sigma = s_a s_c``, ``u0 = atanh(omega_b(0)/A_b)`` [LL76 §37, Problem 2];
    * attitude: Z-X-Z Euler angles about ``L = G e_z`` [LL76 §37, Eqs. 37.13-37.16]:
      ``m/G = (sin th sin psi, sin th cos psi, cos th)`` in the pole frame, and
      ``phi' = G (m_a^2/I_a + m_b^2/I_b) / (m_a^2 + m_b^2)
      = G/I_c + G (I_c - I_a)/(I_a I_c) / (1 - N sn^2 u)``, ``N = -I_c (I_b - I_a)/(I_a (I_c
      - I_b))``, integrated with ``Pi(N; am u | m)`` (``mpmath.ellippi``), or on the separatrix
      with ``int du / (1 - N tanh^2 u) = (u + n atan(n tanh u)) / (1 + n^2)``, ``n^2 = -N``.
    * constant omega (rest, sphere, permanent rotation): ``R(t) = R0 Rot(omega, |omega| t)``.

    ``R(t) = R0 M(0)^T M(t)`` with ``M = Rz(phi) Rx(theta) Rz(psi) P``, ``phi(0) = 0``.
    """

    def __init__(
        self,
        inertia: Sequence[float],
        omega0: Sequence[float],
        attitude0: Rotation | None = None,
        dps: int = MP_DPS,
    ) -> None:
        self.inertia = np.array(inertia, dtype=float)
        self.omega0 = np.array(omega0, dtype=float)
        self.dps = dps
        self.R0 = np.eye(3) if attitude0 is None else as_matrices(attitude0)
        self.work = dps + MP_GUARD_DPS
        inv = exact_invariants(self.inertia, self.omega0)
        self.exact = inv
        q = _proper_sort(self.inertia)
        with mp.workdps(self.work):
            self._setup(inv, q)

    # ---- construction --------------------------------------------------------------------
    def _setup(self, inv: dict, q: np.ndarray) -> None:
        w = self.omega0
        ii = self.inertia
        self.two_t = _mpf(inv["2T"])
        self.g2 = _mpf(inv["G2"])
        self.G = mp.sqrt(self.g2)
        self.R0_mp = mp.matrix(self.R0.tolist())
        nz = [i for i in range(3) if w[i] != 0.0]
        if not nz:
            self.kind = "rest"
        elif all(ii[i] == ii[j] for i in nz for j in nz):
            self.kind = "constant"  # I omega parallel to omega: sphere or permanent rotation
        else:
            d_sorted = [inv["Delta"][int(np.argmax(np.abs(q[r])))] for r in range(3)]
            if d_sorted[1] > 0:
                self.kind, p = "major", q
            elif d_sorted[1] < 0:
                self.kind, p = "minor", _SWAP_POLE @ q
            else:
                self.kind, p = "separatrix", q
        if self.kind in ("rest", "constant"):
            self.P = np.eye(3)
            self.period = mp.inf
            self.lam = mp.mpf(0)
            self.m = mp.mpf(0)
            self.mc = mp.mpf(1)
            self.phi_per_period = mp.mpf(0)
            return
        self.P = p
        idx = [int(np.argmax(np.abs(p[r]))) for r in range(3)]
        ia, ib, ic = (_mpf(Fraction(float(ii[k]))) for k in idx)
        da, db, dc = (_mpf(inv["Delta"][k]) for k in idx)
        wp = p @ w  # exact: a signed permutation
        wa, wb, wc = (mp.mpf(float(x)) for x in wp)
        self.Ip = (ia, ib, ic)
        self.A = (
            mp.sqrt(-dc / (ia * (ic - ia))),
            mp.sqrt(-dc / (ib * (ic - ib))),
            mp.sqrt(da / (ic * (ic - ia))),
        )
        self.lam = mp.sqrt((ic - ib) * da / (ia * ib * ic))
        self.N = -ic * (ib - ia) / (ia * (ic - ib))
        self.s_c = mp.sign(wc)
        if self.kind == "separatrix":
            self.m, self.mc = mp.mpf(1), mp.mpf(0)
            self.s_a = mp.sign(wa)
            self.sigma = self.s_a * self.s_c
            self.u0 = mp.atanh(wb / self.A[1])
            self.period = mp.inf
            self.phi_per_period = mp.mpf(0)
            self.nn = mp.sqrt(-self.N)
        else:
            self.m = (ib - ia) * (-dc) / ((ic - ib) * da)
            self.mc = db * (ic - ia) / (da * (ic - ib))
            self.sigma = self.s_c * mp.sign(ic - ib)
            self.K = mp.ellipk(self.m)
            self.Pi_c = mp.ellippi(self.N, self.m)
            amp0 = mp.atan2(wb / self.A[1], wa / self.A[0])
            self.u0 = mp.ellipf(amp0, self.m)
            self.period = 4 * self.K / self.lam
            self.phi_per_period = (
                self.G * self.period / ic
                + self.G * (ic - ia) / (ia * ic * self.lam) * 4 * self.Pi_c
            )
        self.M0T = self._euler_matrix(mp.mpf(0), self._m_pole(mp.mpf(0))).T

    # ---- evaluation ----------------------------------------------------------------------
    def _u(self, t: mp.mpf) -> mp.mpf:
        return self.u0 + self.sigma * self.lam * t

    def _omega_pole(self, t: mp.mpf) -> list[mp.mpf]:
        aa, ab, ac = self.A
        u = self._u(t)
        if self.kind == "separatrix":
            sech = mp.sech(u)
            return [self.s_a * aa * sech, ab * mp.tanh(u), self.s_c * ac * sech]
        sn, cn, dn = mp_sncndn(u, self.m, self.dps)
        return [aa * cn, ab * sn, self.s_c * ac * dn]

    def _m_pole(self, t: mp.mpf) -> list[mp.mpf]:
        wa, wb, wc = self._omega_pole(t)
        ia, ib, ic = self.Ip
        return [ia * wa, ib * wb, ic * wc]

    def _pi_am(self, u: mp.mpf) -> mp.mpf:
        """``Pi(N; am u | m)`` for any real u (quasi-periodic continuation)."""
        extra = int(max(0.0, float(mp.log10(abs(u) + 1)))) + 5
        with mp.workdps(self.work + extra):
            if self.kind == "separatrix":
                n = self.nn
                return (u + n * mp.atan(n * mp.tanh(u))) / (1 + n * n)
            j = int(mp.nint(u / (2 * self.K)))
            r = u - 2 * j * self.K
            sn, cn, _ = mp_sncndn(r, self.m, self.dps + extra)
            amp = mp.atan2(sn, cn)  # |am r| <= pi/2 since |r| <= K
            return 2 * j * self.Pi_c + mp.ellippi(self.N, amp, self.m)

    def _phi(self, t: mp.mpf) -> mp.mpf:
        ia, ib, ic = self.Ip
        coef = self.G * (ic - ia) / (ia * ic * self.sigma * self.lam)
        return self.G * t / ic + coef * (self._pi_am(self._u(t)) - self._pi_am(self.u0))

    def _euler_matrix(self, phi: mp.mpf, m_pole: list[mp.mpf]) -> mp.matrix:
        """``M = Rz(phi) Rx(theta) Rz(psi) P`` (pole-frame body coords -> L frame)."""
        ma, mb, mc = (x / self.G for x in m_pole)
        st = mp.sqrt(ma * ma + mb * mb)
        ct = mc
        sp, cp = ma / st, mb / st
        rx = mp.matrix([[1, 0, 0], [0, ct, -st], [0, st, ct]])
        rz_psi = mp.matrix([[cp, -sp, 0], [sp, cp, 0], [0, 0, 1]])
        return _rz(phi) * rx * rz_psi * mp.matrix(self.P.tolist())

    def omega_mp(self, t: float | mp.mpf) -> mp.matrix:
        """Body-frame omega (caller axes) at time ``t`` as an mpmath column."""
        with mp.workdps(self.work):
            t = mp.mpf(t)
            if self.kind in ("rest", "constant"):
                return mp.matrix([mp.mpf(float(x)) for x in self.omega0])
            wp = mp.matrix(self._omega_pole(t))
            return mp.matrix(self.P.T.tolist()) * wp

    def attitude_mp(self, t: float | mp.mpf) -> mp.matrix:
        """Body -> space rotation matrix at time ``t`` (mpmath)."""
        with mp.workdps(self.work):
            t = mp.mpf(t)
            if self.kind == "rest":
                return self.R0_mp
            if self.kind == "constant":
                w = [mp.mpf(float(x)) for x in self.omega0]
                nw = mp.sqrt(sum(x * x for x in w))
                extra = int(max(0.0, float(mp.log10(abs(nw * t) + 1)))) + 5
                with mp.workdps(self.work + extra):
                    rot = _rodrigues([x / nw for x in w], nw * t)
                return self.R0_mp * rot
            m_t = self._euler_matrix(self._phi(t), self._m_pole(t))
            return self.R0_mp * self.M0T * m_t

    def omega(self, t: float | Sequence[float] | np.ndarray) -> np.ndarray:
        """Float omega at each time: (3,) for a scalar t, (N, 3) for an array."""
        ts = np.atleast_1d(np.asarray(t, dtype=float))
        out = np.array([[float(x) for x in self.omega_mp(float(tk))] for tk in ts])
        return out[0] if np.ndim(t) == 0 else out

    def attitude(self, t: float | Sequence[float] | np.ndarray) -> np.ndarray:
        """Float rotation matrices at each time: (3, 3) or (N, 3, 3)."""
        ts = np.atleast_1d(np.asarray(t, dtype=float))
        out = np.array([np.array(self.attitude_mp(float(tk)).tolist(), dtype=float) for tk in ts])
        return out[0] if np.ndim(t) == 0 else out

    # ---- scalar properties as floats -----------------------------------------------------
    @property
    def period_float(self) -> float:
        return math.inf if self.period == mp.inf else float(self.period)

    @property
    def lam_float(self) -> float:
        return float(self.lam)

    @property
    def m_float(self) -> float:
        return float(self.m)

    @property
    def mc_float(self) -> float:
        return float(self.mc)

    @property
    def energy(self) -> float:
        return float(self.two_t / 2)

    @property
    def D(self) -> float:  # noqa: N802 - the physics name
        return float(self.g2 / self.two_t) if self.two_t != 0 else 0.0

    @property
    def angular_momentum(self) -> np.ndarray:
        """Space-frame L = R0 I omega0 (float)."""
        with mp.workdps(self.work):
            mvec = mp.matrix(
                [
                    _mpf(Fraction(float(i)) * Fraction(float(w)))
                    for i, w in zip(self.inertia, self.omega0, strict=True)
                ]
            )
            return np.array([float(x) for x in self.R0_mp * mvec])


# --------------------------------------------------------------------------------------------
# Exact construction of initial conditions
# --------------------------------------------------------------------------------------------


def exact_complementary_parameter(inertia: Sequence[float], omega: Sequence[float]) -> Fraction:
    """Exact ``1 - m`` (a rational) of the float inputs; 0 on the separatrix."""
    inv = exact_invariants(inertia, omega)
    q = _proper_sort(inertia)
    idx = [int(np.argmax(np.abs(q[r]))) for r in range(3)]
    ii = [inv["I"][k] for k in idx]
    d = [inv["Delta"][k] for k in idx]
    if d[1] > 0:  # major family, pole = largest moment
        return d[1] * (ii[2] - ii[0]) / (d[0] * (ii[2] - ii[1]))
    if d[1] < 0:  # minor family, pole = smallest moment
        return d[1] * (ii[2] - ii[0]) / (d[2] * (ii[1] - ii[0]))
    return Fraction(0)


def family(inertia: Sequence[float], omega: Sequence[float]) -> str:
    """'major', 'minor' or 'separatrix' from the exact sign of ``Delta_2``."""
    inv = exact_invariants(inertia, omega)
    q = _proper_sort(inertia)
    k = int(np.argmax(np.abs(q[1])))
    d2 = inv["Delta"][k]
    return "major" if d2 > 0 else "minor" if d2 < 0 else "separatrix"


def omega0_with_complementary_parameter(
    inertia: Sequence[float],
    mc_target: float,
    fam: str,
    mix: float = 0.3,
    search: int = 12,
) -> np.ndarray:
    """A float ``omega0`` (|omega0| ~ 1) whose *exact* ``1 - m`` is as close as possible to
    ``mc_target`` in the family ``fam`` ('major' or 'minor').

    ``inertia`` must be strictly ascending. The target ``D`` is solved in mpmath from
    ``1 - m(D)``, a point of that polhode with ``omega_2 = mix`` (relative) is built and rounded
    to double, then the neighbouring doubles (+-``search`` ulps in the two free components)
    are scanned for the exact rational ``1 - m`` closest to the target (log distance): a plain
    rounding can move ``1 - m = 1e-16`` by O(1) or even across the separatrix.
    """
    i1, i2, i3 = (float(x) for x in inertia)
    assert i1 < i2 < i3
    with mp.workdps(60):
        a, b, c = mp.mpf(i1), mp.mpf(i2), mp.mpf(i3)
        mc = mp.mpf(mc_target)
        if fam == "major":
            # mc = (c - a)(D - b) / ((c - b)(D - a))
            d = (b * (c - a) - mc * (c - b) * a) / ((c - a) - mc * (c - b))
        else:
            # mc = (c - a)(b - D) / ((b - a)(c - D))
            d = (b * (c - a) - mc * (b - a) * c) / ((c - a) - mc * (b - a))
        # sum I_i (I_i - D) w_i^2 = 0 with w_2 = mix * (scale); solve the pole component.
        w2 = mp.mpf(mix)
        if fam == "major":
            w1 = mp.mpf(1)
            w3sq = (a * (d - a) * w1**2 + b * (d - b) * w2**2) / (c * (c - d))
            w = [w1, w2, mp.sqrt(w3sq)]
        else:
            w3 = mp.mpf(1)
            w1sq = (c * (c - d) * w3**2 + b * (b - d) * w2**2) / (a * (d - a))
            w = [mp.sqrt(w1sq), w2, w3]
        nrm = mp.sqrt(sum(x * x for x in w))
        w0 = np.array([float(x / nrm) for x in w])
    free = (0, 2)
    best, best_err = w0, math.inf
    log_target = math.log(mc_target)
    for k0 in range(-search, search + 1):
        for k2 in range(-search, search + 1):
            w = w0.copy()
            for k, f in zip((k0, k2), free, strict=True):
                w[f] = w[f] + k * math.ulp(w[f])
            if family((i1, i2, i3), w) != fam:
                continue
            mcx = exact_complementary_parameter((i1, i2, i3), w)
            if mcx <= 0:
                continue
            err = abs(math.log(mcx.numerator) - math.log(mcx.denominator) - log_target)
            if err < best_err:
                best, best_err = w, err
    return best


# --------------------------------------------------------------------------------------------
# DOP853 on Euler's equations + attitude kinematics
# --------------------------------------------------------------------------------------------


def _euler_rhs(inertia: np.ndarray):
    i1, i2, i3 = inertia

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        w1, w2, w3 = y[0], y[1], y[2]
        r = y[3:].reshape(3, 3)
        dw = [(i2 - i3) * w2 * w3 / i1, (i3 - i1) * w3 * w1 / i2, (i1 - i2) * w1 * w2 / i3]
        dr = r @ np.array([[0.0, -w3, w2], [w3, 0.0, -w1], [-w2, w1, 0.0]])
        return np.concatenate([dw, dr.ravel()])

    return rhs


def integrate_dop853(
    inertia: Sequence[float],
    omega0: Sequence[float],
    t_eval: Sequence[float] | np.ndarray,
    attitude0: Rotation | None = None,
    rtol: float = DOP853_RTOL,
    atol: float = DOP853_ATOL,
) -> tuple[np.ndarray, np.ndarray]:
    """Euler's equations ``I1 w1' = (I2 - I3) w2 w3`` (cyclic) and ``R' = R [w]x`` with DOP853.

    Written in the caller's axes (no sorting, no relabelling, no elliptic functions). The state
    is made non-dimensional (``w / |w0|``, time ``|w0| t``) so ``atol`` means the same for every
    scale. Returns omega (N, 3) and R (N, 3, 3) at ``t_eval`` (ascending, >= 0).
    """
    ii = np.asarray(inertia, dtype=float) / max(inertia)
    w0 = np.asarray(omega0, dtype=float)
    scale = float(np.linalg.norm(w0))
    r0 = np.eye(3) if attitude0 is None else as_matrices(attitude0)
    y0 = np.concatenate([w0 / scale, r0.ravel()])
    tau = np.asarray(t_eval, dtype=float) * scale
    sol = solve_ivp(
        _euler_rhs(ii),
        (0.0, float(tau[-1])),
        y0,
        method="DOP853",
        t_eval=tau,
        rtol=rtol,
        atol=atol,
    )
    assert sol.success, sol.message
    w = sol.y[:3].T * scale
    r = sol.y[3:].T.reshape(-1, 3, 3)
    return w, r


def dop853_zero_crossings(
    inertia: Sequence[float],
    omega0: Sequence[float],
    component: int,
    t_end: float,
    direction: float = 1.0,
) -> np.ndarray:
    """Times at which ``omega[component]`` crosses zero in ``direction`` (DOP853 events,
    located by scipy's root finder on the dense output to ~1e-15 relative)."""
    ii = np.asarray(inertia, dtype=float) / max(inertia)
    w0 = np.asarray(omega0, dtype=float)
    scale = float(np.linalg.norm(w0))
    y0 = np.concatenate([w0 / scale, np.eye(3).ravel()])

    def event(_t: float, y: np.ndarray) -> float:
        return y[component]

    event.direction = direction  # type: ignore[attr-defined]
    sol = solve_ivp(
        _euler_rhs(ii),
        (0.0, t_end * scale),
        y0,
        method="DOP853",
        events=event,
        rtol=DOP853_RTOL,
        atol=DOP853_ATOL,
    )
    assert sol.success, sol.message
    return np.asarray(sol.t_events[0]) / scale
