"""Accuracy of ``FreeRigidBody`` against the high-precision reference and against DOP853.

* Generic bodies within 100 periods: omega to 1e-13 of |omega0|, attitude to 1e-12 rad, against
  the mpmath closed form (exact for the float inputs); and, formula-independent, against DOP853
  over three periods (where DOP853's own error is ~1e-12, measured in
  ``test_reference.py``).
* Near the separatrix (``1 - m`` = 1e-2 ... 1e-16, both families) and on it exactly: omega to
  1e-12 absolute with omega scaled to 1, over at least two flips.
* Near-symmetric bodies (``m`` down to 1e-18).
* Long times (1e6 periods): error within ``100 eps lambda t``.
* The scalar constants (``parameter``, ``complementary_parameter``, ``frequency``, ``period``,
  ``precession_per_period``, ``D``, ``energy``, ``L``) against their exact values.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest
from reference import (
    ATTITUDE_ATOL_GENERIC,
    ATTITUDE_ATOL_SEPARATRIX,
    DOP853_FEW_PERIODS_ATOL,
    EPS,
    LONG_TIME_EPS_FACTOR,
    OMEGA_ATOL_SEPARATRIX,
    OMEGA_RTOL_GENERIC,
    ReferenceBody,
    as_matrices,
    exact_complementary_parameter,
    geodesic_angle,
    integrate_dop853,
    omega0_with_complementary_parameter,
)
from scipy.spatial.transform import Rotation

from poinsot.physics import FreeRigidBody

CONSTANT_RTOL = 1e-13
"""``m``, ``1 - m``, ``lambda``, ``4K/lambda``, ``D``, ``T``: each is a handful of roundings of
cancellation-free sums and products (``Δi = G² - 2T Ii`` as sums of same-signed terms), i.e.
~10 eps; a formula with a subtraction near the separatrix or near symmetry loses all digits and
fails by orders."""

PRECESSION_RTOL = 1e-12
"""Precession angle per period ([LL76 §37, Eq. 37.16] integrated over 4K): a sum of ``G P / I``
and a ``Pi(N|m)`` term of opposite-sign-free parts, a few tens of roundings."""

GENERIC = {
    "minor-123": ((1.0, 2.0, 3.0), (1.0, 0.3, 0.5)),
    "major-123": ((1.0, 2.0, 3.0), (0.2, 0.3, 1.0)),
    "unsorted-odd": ((3.0, 1.0, 2.0), (0.5, 1.0, -0.2)),
    "unsorted-desc": ((2.5, 1.2, 0.4), (0.9, -0.4, 0.2)),
    "generic": ((0.7, 5.0, 2.2), (-0.3, 0.8, 1.1)),
    "six-decades": ((1e-3, 1.0, 1e3), (1.0, 0.3, 0.01)),
    "no-triangle": ((1.0, 10.0, 1000.0), (0.2, 1.0, 0.03)),
    "fast-small": ((4e-7, 9e-7, 2e-6), (-300.0, 120.0, 80.0)),
}

SEPARATRIX_INERTIA = [(1.0, 2.0, 3.5), (0.31, 1.7, 2.05)]
SEPARATRIX_MC = [1e-2, 1e-6, 1e-10, 1e-14, 1e-16]
EXACT_SEPARATRIX = {
    "236": ((2.0, 3.0, 6.0), (3.0, 0.25, 1.0)),
    "236-signs": ((2.0, 3.0, 6.0), (-3.0, -0.25, 1.0)),
    "159": ((1.0, 5.0, 9.0), (3.0, -2.0, 1.0)),
    "permuted": ((6.0, 2.0, 3.0), (1.0, 3.0, -0.25)),
    "1-2-2.25": ((1.0, 2.0, 2.25), (0.75, 0.1, -1.0)),
}


def _attitude0(key: str) -> Rotation:
    stream = sum(map(ord, key))
    return Rotation.from_rotvec(np.random.default_rng(stream).normal(size=3))


@functools.cache
def _reference(inertia: tuple, omega0: tuple, key: str) -> ReferenceBody:
    return ReferenceBody(inertia, omega0, _attitude0(key))


def _errors(body: FreeRigidBody, ref: ReferenceBody, t: np.ndarray) -> tuple[np.ndarray, ...]:
    """Per-time omega error (absolute) and attitude geodesic angle."""
    w = body.omega(t)
    r = as_matrices(body.attitude(t))
    assert w.shape == (t.size, 3) and r.shape == (t.size, 3, 3)
    assert np.all(np.isfinite(w)) and np.all(np.isfinite(r))
    dw = np.max(np.abs(w - ref.omega(t)), axis=1)
    dr = geodesic_angle(r, ref.attitude(t))
    return dw, dr


def _times(period: float, n_periods: float, stream: int, n_random: int = 14) -> np.ndarray:
    rng = np.random.default_rng(stream)
    return np.sort(
        np.concatenate(
            [
                np.linspace(0.0, 2.0 * period, 9),
                rng.uniform(0.0, n_periods * period, n_random),
                [n_periods * period],
            ]
        )
    )


@pytest.mark.parametrize("key", list(GENERIC))
def test_generic_within_100_periods(key: str) -> None:
    inertia, omega0 = GENERIC[key]
    ref = _reference(inertia, omega0, key)
    body = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=_attitude0(key))
    t = _times(ref.period_float, 100.0, stream=len(key))
    dw, dr = _errors(body, ref, t)
    scale = np.linalg.norm(omega0)
    k, j = int(np.argmax(dw)), int(np.argmax(dr))
    assert dw[k] <= OMEGA_RTOL_GENERIC * scale, (
        f"{key}: |omega error|/|omega0| = {dw[k] / scale:.3e} at t = {t[k] / ref.period_float:.2f}"
        " periods"
    )
    assert dr[j] <= ATTITUDE_ATOL_GENERIC, (
        f"{key}: attitude error {dr[j]:.3e} rad at t = {t[j] / ref.period_float:.2f} periods"
    )


@pytest.mark.parametrize("key", list(GENERIC))
def test_generic_vs_dop853_three_periods(key: str) -> None:
    """Formula-independent: Euler + R' = R[w]x integrated by DOP853 (rtol 1e-13)."""
    inertia, omega0 = GENERIC[key]
    rot0 = _attitude0(key)
    body = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=rot0)
    t = np.linspace(0.0, 3.0 * body.period, 31)
    w_num, r_num = integrate_dop853(inertia, omega0, t, rot0)
    dw = np.max(np.abs(body.omega(t) - w_num)) / np.linalg.norm(omega0)
    dr = np.max(geodesic_angle(as_matrices(body.attitude(t)), r_num))
    assert dw <= DOP853_FEW_PERIODS_ATOL, f"{key}: omega vs DOP853 {dw:.3e}"
    assert dr <= DOP853_FEW_PERIODS_ATOL, f"{key}: attitude vs DOP853 {dr:.3e} rad"


@functools.cache
def _near_separatrix_omega0(inertia: tuple, mc: float, fam: str) -> tuple:
    return tuple(omega0_with_complementary_parameter(inertia, mc, fam))


@pytest.mark.parametrize("inertia", SEPARATRIX_INERTIA)
@pytest.mark.parametrize("fam", ["major", "minor"])
@pytest.mark.parametrize("mc", SEPARATRIX_MC)
def test_near_separatrix(inertia: tuple, fam: str, mc: float) -> None:
    """1 - m down to 1e-16: omega within 1e-12 (|omega| = 1) over 1.6 periods (>= 3 flips)."""
    omega0 = _near_separatrix_omega0(inertia, mc, fam)
    key = f"sep-{fam}-{mc}"
    ref = _reference(inertia, omega0, key)
    assert ref.kind == fam
    body = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=_attitude0(key))
    exact_mc = float(exact_complementary_parameter(inertia, omega0))
    assert abs(body.complementary_parameter - exact_mc) <= CONSTANT_RTOL * exact_mc, (
        f"1-m: {body.complementary_parameter!r} vs exact {exact_mc!r}"
    )
    t = np.concatenate(
        [np.linspace(0.0, 1.6 * ref.period_float, 33), ref.period_float * np.array([0.25, 0.75])]
    )
    dw, dr = _errors(body, ref, t)
    scale = np.linalg.norm(omega0)
    assert np.max(dw) / scale <= OMEGA_ATOL_SEPARATRIX, (
        f"1-m={exact_mc:.3g} ({fam}): omega error {np.max(dw) / scale:.3e} at "
        f"t/P = {t[np.argmax(dw)] / ref.period_float:.3f}"
    )
    assert np.max(dr) <= ATTITUDE_ATOL_SEPARATRIX, (
        f"1-m={exact_mc:.3g} ({fam}): attitude error {np.max(dr):.3e} rad at "
        f"t/P = {t[np.argmax(dr)] / ref.period_float:.3f}"
    )


@pytest.mark.parametrize("key", list(EXACT_SEPARATRIX))
def test_exact_separatrix(key: str) -> None:
    """Delta_2 == 0 exactly: sech/tanh, from one unstable pole to the other (one flip), up to
    lambda t = 40 where omega is within 1e-17 of the pole."""
    inertia, omega0 = EXACT_SEPARATRIX[key]
    ref = _reference(inertia, omega0, key)
    assert ref.kind == "separatrix"
    body = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=_attitude0(key))
    assert body.complementary_parameter == 0.0
    assert body.parameter == 1.0
    t = np.linspace(0.0, 40.0 / ref.lam_float, 41)
    dw, dr = _errors(body, ref, t)
    scale = np.linalg.norm(omega0)
    assert np.max(dw) / scale <= OMEGA_ATOL_SEPARATRIX, f"omega error {np.max(dw) / scale:.3e}"
    assert np.max(dr) <= ATTITUDE_ATOL_SEPARATRIX, f"attitude error {np.max(dr):.3e} rad"


def _near_symmetric_cases() -> dict[str, tuple]:
    """Two nearly equal moments (a few ulps apart) and a polhode close to the odd axis, so
    ``m = (I_b - I_a)(...)/(...)`` goes down to ~1e-18; both families."""
    one_ulp = np.spacing(1.0)
    return {
        # pole = I3 (major family), I1 ~ I2
        "oblate-m1e-6": ((1.0, 1.0 + 2**-20, 2.0), (0.6, 0.5, 0.9)),
        "oblate-m1e-12": ((1.0, 1.0 + 2**-40, 2.0), (0.6, 0.5, 0.9)),
        "oblate-m1e-16": ((1.0, 1.0 + 2 * one_ulp, 2.0), (0.6, 0.5, 0.9)),
        "oblate-m1e-18": ((1.0, 1.0 + one_ulp, 2.0), (0.05, 0.03, 1.0)),
        # pole = I1 (minor family), I2 ~ I3
        "prolate-m1e-12": ((0.5, 2.0, 2.0 + 2**-39), (0.9, 0.5, 0.6)),
        "prolate-m1e-18": ((0.5, 2.0, 2.0 + 2 * one_ulp), (1.0, 0.02, 0.03)),
    }


NEAR_SYMMETRIC = _near_symmetric_cases()


@pytest.mark.parametrize("key", list(NEAR_SYMMETRIC))
def test_near_symmetric(key: str) -> None:
    inertia, omega0 = NEAR_SYMMETRIC[key]
    ref = _reference(inertia, omega0, key)
    assert ref.kind in ("major", "minor")
    body = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=_attitude0(key))
    m_exact = float(ref.m)
    assert abs(body.parameter - m_exact) <= CONSTANT_RTOL * m_exact, (body.parameter, m_exact)
    t = _times(ref.period_float, 100.0, stream=5)
    dw, dr = _errors(body, ref, t)
    scale = np.linalg.norm(omega0)
    assert np.max(dw) <= OMEGA_RTOL_GENERIC * scale, (
        f"{key} (m={m_exact:.2e}): omega error {np.max(dw) / scale:.3e}"
    )
    assert np.max(dr) <= ATTITUDE_ATOL_GENERIC, f"{key}: attitude error {np.max(dr):.3e}"


def test_near_symmetric_reaches_m_1e18() -> None:
    ms = [ReferenceBody(*NEAR_SYMMETRIC[k]).m_float for k in ("oblate-m1e-18", "prolate-m1e-18")]
    assert all(1e-19 < m < 1e-17 for m in ms), ms


LONG = {
    "minor-123": GENERIC["minor-123"],
    "major-123": GENERIC["major-123"],
    "six-decades": GENERIC["six-decades"],
    "unsorted-odd": GENERIC["unsorted-odd"],
    "near-separatrix-1e-10": None,  # filled below
    "oblate-symmetric": ((1.0, 1.0, 3.0), (0.5, 0.2, 1.0)),
}


@pytest.mark.parametrize("key", list(LONG))
def test_long_time_1e6_periods(key: str) -> None:
    """t ~ 1e6 periods: error <= 100 eps lambda t (omega, relative to |omega0|) and
    100 eps (lambda + |omega0|) t for the attitude, against the exact solution of the same
    float inputs."""
    if LONG[key] is None:
        inertia = SEPARATRIX_INERTIA[0]
        omega0 = _near_separatrix_omega0(inertia, 1e-10, "major")
    else:
        inertia, omega0 = LONG[key]
    ref = _reference(inertia, omega0, key)
    body = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=_attitude0(key))
    p = ref.period_float
    t = 1e6 * p + p * np.array([0.0, 0.13, 0.5, 0.77])
    dw, dr = _errors(body, ref, t)
    scale = float(np.linalg.norm(omega0))
    lam = ref.lam_float
    tol_w = LONG_TIME_EPS_FACTOR * EPS * lam * t * scale
    tol_r = LONG_TIME_EPS_FACTOR * EPS * (lam + scale) * t
    assert np.all(dw <= tol_w), f"{key}: omega error {dw / scale} vs allowed {tol_w / scale}"
    assert np.all(dr <= tol_r), f"{key}: attitude error {dr} rad vs allowed {tol_r}"


@pytest.mark.parametrize(
    "key", list(GENERIC) + ["near-sep-1e-14", "oblate-m1e-18", "prolate-m1e-12"]
)
def test_constants_against_exact(key: str) -> None:
    if key in GENERIC:
        inertia, omega0 = GENERIC[key]
    elif key in NEAR_SYMMETRIC:
        inertia, omega0 = NEAR_SYMMETRIC[key]
    else:
        inertia = SEPARATRIX_INERTIA[0]
        omega0 = _near_separatrix_omega0(inertia, 1e-14, "minor")
    rot0 = _attitude0(key)
    ref = ReferenceBody(inertia, omega0, rot0)
    body = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=rot0)

    def close(name: str, got: float, want: float, rtol: float = CONSTANT_RTOL) -> None:
        assert abs(got - want) <= rtol * abs(want), f"{key}: {name} = {got!r}, exact {want!r}"

    close("parameter", body.parameter, ref.m_float)
    close("complementary_parameter", body.complementary_parameter, ref.mc_float)
    close("frequency", body.frequency, ref.lam_float)
    close("period", body.period, ref.period_float)
    close("energy", body.energy, ref.energy)
    close("D", body.D, ref.D)
    close(
        "precession_per_period",
        body.precession_per_period,
        float(ref.phi_per_period),
        PRECESSION_RTOL,
    )
    close(
        "second_period",
        body.second_period,
        2 * np.pi * ref.period_float / float(ref.phi_per_period),
        PRECESSION_RTOL,
    )
    lref = ref.angular_momentum
    assert np.max(np.abs(body.angular_momentum - lref)) <= CONSTANT_RTOL * np.linalg.norm(lref)
