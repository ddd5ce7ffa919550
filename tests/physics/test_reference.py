"""The references themselves, proved against each other before they judge ``physics/``.

* The mpmath closed form (``ReferenceBody``) satisfies Euler's equations and ``R' = R [w]x`` to
  ~30 digits (high-precision central differences) and the initial conditions exactly: by
  uniqueness of ODE solutions it *is* the motion, whatever the derivation.
* Its precision is what it claims: ``MP_DPS`` and ``MP_DPS + 20`` digits agree, also at 1e6
  periods.
* Its ``ellippi`` precession angle equals a direct quadrature of [LL76 §37, Eq. 37.16].
* It agrees with DOP853 (no elliptic function at all) over a few periods to what DOP853 itself
  achieves at rtol 1e-13, and the separatrix constructions hit exactly ``Delta_2 = 0``.
"""

from __future__ import annotations

import mpmath as mp
import numpy as np
import pytest
from reference import (
    DOP853_FEW_PERIODS_ATOL,
    MP_DPS,
    ReferenceBody,
    exact_complementary_parameter,
    exact_invariants,
    family,
    geodesic_angle,
    integrate_dop853,
    omega0_with_complementary_parameter,
)
from scipy.spatial.transform import Rotation

ODE_RESIDUAL_RTOL = 1e-28
"""Residual of Euler's equations / the kinematics for the mpmath reference, relative to the
natural scale (|w|^2 times the inertia ratio). Central differences of 4th order with step 1e-12
at ``MP_DPS + 25`` digits are exact to ~1e-45; 1e-28 proves >= 28 correct digits."""

MP_SELF_ATOL = 1e-32
"""``MP_DPS`` vs ``MP_DPS + 20`` digits: the reference is exact far below double precision."""

CASES = [
    ((1.0, 2.0, 3.0), (1.0, 0.3, 0.5)),  # minor family
    ((1.0, 2.0, 3.0), (0.2, 0.3, 1.0)),  # major family
    ((3.0, 1.0, 2.0), (0.5, 1.0, -0.2)),  # unsorted, odd permutation
    ((1.0, 1.0, 3.0), (0.5, 0.2, 1.0)),  # symmetric oblate, m = 0
    ((1.0, 3.0, 3.0), (1.0, 0.2, 0.5)),  # symmetric prolate, m = 0
    ((2.0, 3.0, 6.0), (3.0, 0.25, 1.0)),  # exact separatrix
    ((6.0, 2.0, 3.0), (1.0, -3.0, 0.25)),  # exact separatrix, permuted
    ((1e-3, 1.0, 1e3), (1.0, 0.3, 0.01)),  # six decades
    ((5.0, 2.0, 2.5), (0.1, -1.0, 0.7)),
]


def _fd(f, t: mp.mpf, h: mp.mpf):
    """4th-order central difference of a vector/matrix valued mpmath function."""
    return (f(t - 2 * h) - 8 * f(t - h) + 8 * f(t + h) - f(t + 2 * h)) / (12 * h)


@pytest.mark.parametrize(("inertia", "omega0"), CASES)
def test_reference_solves_euler_and_kinematics(inertia, omega0) -> None:
    rot0 = Rotation.from_rotvec([0.3, -1.1, 0.7])
    ref = ReferenceBody(inertia, omega0, rot0)
    ii = [mp.mpf(x) for x in inertia]
    with mp.workdps(ref.work):
        w0 = ref.omega_mp(0)
        assert max(abs(w0[k] - omega0[k]) for k in range(3)) < mp.mpf(10) ** (-MP_DPS)
        r0 = ref.attitude_mp(0)
        assert mp.mnorm(r0 - mp.matrix(ref.R0.tolist()), 1) < mp.mpf(10) ** (-MP_DPS)
        scale = float(np.linalg.norm(omega0))
        per = ref.period_float if np.isfinite(ref.period_float) else 8.0 / ref.lam_float
        h = mp.mpf(10) ** -12 / scale
        ratio = max(inertia) / min(inertia)
        r0_inv = mp.inverse(mp.matrix(ref.R0.tolist()))
        for t in (0.0, 0.37 * per, 1.9 * per):
            t = mp.mpf(t)
            w = ref.omega_mp(t)
            dw = _fd(ref.omega_mp, t, h)
            res = [
                ii[0] * dw[0] - (ii[1] - ii[2]) * w[1] * w[2],
                ii[1] * dw[1] - (ii[2] - ii[0]) * w[2] * w[0],
                ii[2] * dw[2] - (ii[0] - ii[1]) * w[0] * w[1],
            ]
            euler = max(abs(x) / i for x, i in zip(res, ii, strict=True))
            assert euler <= ODE_RESIDUAL_RTOL * scale**2 * ratio, (t, euler)
            r = ref.attitude_mp(t)
            dr = _fd(ref.attitude_mp, t, h)
            skew = mp.matrix([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
            kin = mp.mnorm(dr - r * skew, 1)
            assert kin <= ODE_RESIDUAL_RTOL * scale, (t, kin)
            q = r0_inv * r  # R0^-1 R(t): exactly orthogonal (R0 itself is a rounded matrix)
            ortho = mp.mnorm(q.T * q - mp.eye(3), 1)
            assert ortho < mp.mpf(10) ** (-MP_DPS)


@pytest.mark.parametrize("mc", [1e-6, 1e-16])
@pytest.mark.parametrize("fam", ["major", "minor"])
def test_reference_solves_euler_near_separatrix(mc: float, fam: str) -> None:
    inertia = (1.0, 2.0, 3.5)
    w0 = omega0_with_complementary_parameter(inertia, mc, fam)
    ref = ReferenceBody(inertia, w0)
    assert ref.kind == fam
    ii = [mp.mpf(x) for x in inertia]
    with mp.workdps(ref.work):
        h = mp.mpf(10) ** -12
        for t in (0.49 * ref.period_float, 1.3 * ref.period_float):
            t = mp.mpf(t)
            w = ref.omega_mp(t)
            dw = _fd(ref.omega_mp, t, h)
            res = ii[1] * dw[1] - (ii[2] - ii[0]) * w[2] * w[0]
            assert abs(res) <= ODE_RESIDUAL_RTOL * 10


@pytest.mark.parametrize(("inertia", "omega0"), CASES[:3] + CASES[5:6])
def test_reference_precision_is_what_it_claims(inertia, omega0) -> None:
    rot0 = Rotation.from_rotvec([0.1, 0.2, -0.3])
    lo = ReferenceBody(inertia, omega0, rot0, dps=MP_DPS)
    hi = ReferenceBody(inertia, omega0, rot0, dps=MP_DPS + 20)
    per = lo.period_float if np.isfinite(lo.period_float) else 10.0 / lo.lam_float
    with mp.workdps(hi.work):
        for t in (0.3 * per, 1e6 * per + 0.123):
            dw = max(abs(a - b) for a, b in zip(lo.omega_mp(t), hi.omega_mp(t), strict=True))
            dr = mp.mnorm(lo.attitude_mp(t) - hi.attitude_mp(t), 1)
            assert dw < MP_SELF_ATOL and dr < MP_SELF_ATOL, (t, dw, dr)


@pytest.mark.slow
@pytest.mark.parametrize(("inertia", "omega0"), [CASES[0], CASES[1], CASES[5], CASES[7]])
def test_reference_precession_angle_matches_quadrature(inertia, omega0) -> None:
    """``phi`` from ``ellippi`` (or the separatrix atan form) vs quadrature of
    [LL76 §37, Eq. 37.16]."""
    ref = ReferenceBody(inertia, omega0, dps=30)
    ia, ib, _ = ref.Ip
    per = ref.period_float if np.isfinite(ref.period_float) else 12.0 / ref.lam_float
    with mp.workdps(30):

        def rate(t):
            ma, mb, _ = ref._m_pole(t)
            return ref.G * (ma * ma / ia + mb * mb / ib) / (ma * ma + mb * mb)

        t_end = mp.mpf(0.7 * per)
        nodes = [t_end * k / 32 for k in range(33)]
        quad = mp.quad(rate, nodes, method="gauss-legendre")
        closed = ref._phi(t_end)
        assert abs(quad - closed) < mp.mpf(10) ** -25, (quad, closed)
        if np.isfinite(ref.period_float):
            nodes = [mp.mpf(ref.period) * k / 32 for k in range(33)]
            one = mp.quad(rate, nodes, method="gauss-legendre")
            assert abs(one - ref.phi_per_period) < mp.mpf(10) ** -25


@pytest.mark.parametrize(("inertia", "omega0"), CASES)
def test_reference_matches_dop853_few_periods(inertia, omega0) -> None:
    rot0 = Rotation.from_rotvec([-0.4, 0.9, 2.0])
    ref = ReferenceBody(inertia, omega0, rot0)
    if np.isfinite(ref.period_float):
        t = np.linspace(0.0, 3.0 * ref.period_float, 13)
    else:  # separatrix: DOP853 drifts off like exp(lambda t) from ~1e-16; stop at lambda t = 8
        t = np.linspace(0.0, 8.0 / ref.lam_float, 13)
    w_ref, r_ref = ref.omega(t), ref.attitude(t)
    w_num, r_num = integrate_dop853(inertia, omega0, t, rot0)
    dw = np.max(np.abs(w_ref - w_num)) / np.linalg.norm(omega0)
    dr = np.max(geodesic_angle(r_ref, r_num))
    assert dw <= DOP853_FEW_PERIODS_ATOL and dr <= DOP853_FEW_PERIODS_ATOL, (dw, dr)


def test_exact_separatrix_constructions() -> None:
    for inertia, omega0 in [
        ((2.0, 3.0, 6.0), (3.0, 0.25, 1.0)),
        ((1.0, 5.0, 9.0), (3.0, -2.0, 1.0)),
        ((1.0, 2.0, 2.25), (0.75, 0.1, -1.0)),
    ]:
        inv = exact_invariants(inertia, omega0)
        assert inv["Delta"][1] == 0
        assert family(inertia, omega0) == "separatrix"
        # also in floating point, for these small integers
        i = np.array(inertia)
        w = np.array(omega0)
        assert (i * i * w * w).sum() - (i * w * w).sum() * i[1] == 0.0


@pytest.mark.parametrize("mc", [1e-2, 1e-6, 1e-10, 1e-14, 1e-16])
@pytest.mark.parametrize("fam", ["major", "minor"])
def test_requested_complementary_parameter_is_hit(mc: float, fam: str) -> None:
    """The constructed float omega0 has an exact 1 - m within a factor 2 of the request."""
    w0 = omega0_with_complementary_parameter((1.0, 2.0, 3.5), mc, fam)
    got = float(exact_complementary_parameter((1.0, 2.0, 3.5), w0))
    assert family((1.0, 2.0, 3.5), w0) == fam
    assert 0.5 * mc <= got <= 2.0 * mc, got
