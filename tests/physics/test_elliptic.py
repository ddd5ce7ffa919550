"""``physics.core.elliptic.sncndn`` and ``ellipk`` against mpmath at high precision.

The parameter is passed as the float pair ``(m, mc)``; the reference takes the smaller of the
two as exact (``reference.mp_parameter``) and evaluates ``mpmath.ellipfun`` at ``MP_DPS`` digits
after an argument reduction done at high precision. The cases are the hard ones:
``1 - m`` = 1e-2 ... 1e-16 with ``u`` up to and beyond several quarter periods (``u ~ 39`` at
``1 - m = 1e-10`` is where ``scipy.special.ellipj`` returns ``|cn| ~ 1e5``), ``m`` near 0, and
large ``|u|`` (argument reduction).
"""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
from reference import (
    EPS,
    MP_DPS,
    SNCNDN_ATOL,
    SNCNDN_REDUCTION_EPS_FACTOR,
    mp_parameter,
    mp_sncndn,
)

from poinsot.physics.core.elliptic import ellipk, sncndn

ELLIPK_RTOL = 1e-14
"""K(m) relative error: Carlson's ``R_F(0, mc, 1)`` is accurate to a few ulps for every ``mc`` in
(0, 1]; 1e-14 leaves a factor ~20 for the rounding of ``mc`` itself (``K`` depends on ``mc``
only logarithmically near the separatrix)."""

NEAR_ONE = [1e-2, 1e-6, 1e-10, 1e-14, 1e-16, 1e-30]
NEAR_ZERO = [1e-18, 1e-10, 0.0]


def _reference(u: np.ndarray, m: float, mc: float) -> np.ndarray:
    par = mp_parameter(m, mc)
    out = np.empty((3, u.size))
    for k, uk in enumerate(u):
        sn, cn, dn = mp_sncndn(float(uk), par, MP_DPS)
        out[:, k] = float(sn), float(cn), float(dn)
    return out


def _k_float(m: float, mc: float) -> float:
    with mp.workdps(MP_DPS):
        return float(mp.ellipk(mp_parameter(m, mc)))


def _grid(m: float, mc: float, n_quarter: float, n: int, stream: int) -> np.ndarray:
    """Points from -n_quarter K to +n_quarter K: the quarter periods themselves (where sn = +-1
    and cn = 0 change branch), the midpoints, and random points."""
    k = _k_float(m, mc)
    quarters = np.arange(-n_quarter, n_quarter + 1) * k
    rng = np.random.default_rng(stream)
    rand = rng.uniform(-n_quarter * k, n_quarter * k, size=n)
    return np.concatenate([quarters, quarters[:-1] + 0.5 * k, rand, [0.0, 1e-9, -1e-300]])


def _max_err(u: np.ndarray, m: float, mc: float) -> float:
    got = np.array(sncndn(u, m, mc))
    assert got.shape == (3, u.size)
    assert np.all(np.isfinite(got))
    return float(np.max(np.abs(got - _reference(u, m, mc))))


@pytest.mark.parametrize("mc", NEAR_ONE)
def test_sncndn_near_separatrix_several_periods(mc: float) -> None:
    """1 - m down to 1e-16 (and 1e-30), u over +-8 quarter periods (two full periods)."""
    m = 1.0 - mc
    u = _grid(m, mc, 8, 40, stream=int(-math.log10(mc)))
    err = _max_err(u, m, mc)
    assert err <= SNCNDN_ATOL, f"1-m={mc:g}: max |error| {err:.3e} over |u| <= {abs(u).max():.1f}"


def test_sncndn_scipy_trap_u39() -> None:
    """The measured scipy failure point: 1 - m = 1e-10, u ~ 39 (|cn| ~ 1e5 from ellipj)."""
    mc = 1e-10
    u = np.linspace(38.0, 40.0, 21)
    err = _max_err(u, 1.0 - mc, mc)
    assert err <= SNCNDN_ATOL, f"max |error| {err:.3e}"


@pytest.mark.parametrize("m", NEAR_ZERO)
def test_sncndn_near_circular(m: float) -> None:
    """m -> 0: sn, cn, dn -> sin, cos, 1 (the near-symmetric body)."""
    mc = 1.0 - m
    u = _grid(m, mc, 8, 40, stream=7)
    err = _max_err(u, m, mc)
    assert err <= SNCNDN_ATOL, f"m={m:g}: max |error| {err:.3e}"


@pytest.mark.parametrize("m", [0.1, 0.5, 0.9, 0.999])
def test_sncndn_generic(m: float) -> None:
    mc = 1.0 - m
    u = _grid(m, mc, 8, 30, stream=3)
    err = _max_err(u, m, mc)
    assert err <= SNCNDN_ATOL, f"m={m:g}: max |error| {err:.3e}"


@pytest.mark.parametrize("mc", [0.5, 1e-6, 1e-16])
@pytest.mark.parametrize("umax", [1e3, 1e5, 1e7])
def test_sncndn_large_argument(mc: float, umax: float) -> None:
    """Argument reduction for large |u|: error within SNCNDN_ATOL + c eps |u| (the float K
    carries ~eps relative error, so a reduction in double cannot do better)."""
    m = 1.0 - mc
    rng = np.random.default_rng(11)
    u = np.concatenate([rng.uniform(-umax, umax, 12), [umax, -umax]])
    got = np.array(sncndn(u, m, mc))
    ref = _reference(u, m, mc)
    tol = SNCNDN_ATOL + SNCNDN_REDUCTION_EPS_FACTOR * EPS * np.abs(u)
    err = np.abs(got - ref)
    worst = int(np.argmax(np.max(err / tol, axis=0)))
    assert np.all(err <= tol), (
        f"1-m={mc:g}: u={u[worst]!r}: error {err[:, worst].max():.3e} > {tol[worst]:.3e}"
    )


def test_sncndn_separatrix_limit() -> None:
    """mc == 0 exactly: (tanh, sech, sech), including huge |u| without overflow."""
    u = np.array([-800.0, -40.0, -1.0, 0.0, 0.5, 3.0, 39.0, 800.0])
    got = np.array(sncndn(u, 1.0, 0.0))
    ref = _reference(u, 1.0, 0.0)
    assert np.all(np.isfinite(got))
    assert np.max(np.abs(got - ref)) <= SNCNDN_ATOL


def test_sncndn_shapes_and_identities() -> None:
    """Vectorised over any shape; sn^2 + cn^2 = 1 and dn^2 - cn^2 = mc sn^2 hold."""
    mc = 1e-12
    m = 1.0 - mc
    u = np.linspace(-60, 60, 24).reshape(4, 6)
    sn, cn, dn = sncndn(u, m, mc)
    assert sn.shape == cn.shape == dn.shape == (4, 6)
    assert np.max(np.abs(sn**2 + cn**2 - 1)) <= 4 * EPS
    # dn^2 - cn^2 = mc sn^2 exactly: a sharp test of dn near the separatrix (dn ~ cn ~ 1e-6).
    assert np.max(np.abs(dn**2 - cn**2 - mc * sn**2)) <= 4 * EPS
    s0, c0, d0 = sncndn(0.5, 0.3, 0.7)
    assert np.shape(s0) == np.shape(c0) == np.shape(d0) == ()


@pytest.mark.parametrize("mc", [1.0, 0.5, 1e-2, 1e-6, 1e-10, 1e-14, 1e-16, 1e-30, 1e-300])
def test_ellipk(mc: float) -> None:
    m = 1.0 - mc
    got = ellipk(m, mc)
    ref = _k_float(m, mc)
    assert abs(got - ref) <= ELLIPK_RTOL * ref, f"1-m={mc:g}: K={got!r} vs {ref!r}"


def test_ellipk_near_zero() -> None:
    for m in (1e-18, 1e-10, 0.0):
        got = ellipk(m, 1.0 - m)
        ref = _k_float(m, 1.0 - m)
        assert abs(got - ref) <= ELLIPK_RTOL * ref
