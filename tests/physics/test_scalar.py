"""The single-time path: a scalar ``t`` against the same time in a 1-element array.

``omega``, ``attitude``, ``state``, ``sample`` and ``contact_point`` evaluate one float time
with plain-float code (no numpy arrays); an array of times takes the vectorised path. Both
must give the same numbers in every regime, at t = 0, negative, tiny and huge times, with and
without an ``attitude0``: to ``SCALAR_RTOL`` (they use the same operations in the same order
and numpy's transcendental functions, so in practice they agree to the last bit). Also: the
exact helpers of the construction (integer square root, the one-loop K and Π) against
independent high-precision values.
"""

from __future__ import annotations

import math
from decimal import Decimal, localcontext
from fractions import Fraction

import mpmath as mp
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from poinsot.physics import FreeRigidBody, Regime
from poinsot.physics.core import elliptic, precise
from poinsot.physics.core.exact import sqrt_ratio

SCALAR_RTOL = 4e-16
"""Scalar against array path, relative to |ω| (ω, contact point) or to 1 (quaternions):
two ulps. The paths share every operation; the margin covers a numpy build whose kernels
differ between a float and a 1-element array."""

ROT0 = Rotation.from_rotvec([0.4, -0.9, 1.7])

REGIMES = {
    "major": ((1.0, 2.0, 3.0), (0.2, 0.3, 1.0), Regime.MAJOR_AXIS),
    "minor": ((1.0, 2.0, 3.0), (1.0, 0.3, 0.5), Regime.MINOR_AXIS),
    "report generic": ((13.0, 10.0, 5.0), (0.3, 0.6, 0.9), Regime.MINOR_AXIS),
    "near separatrix 1e-10": ((2.0, 3.0, 6.0), (3.0, 0.25, 1.0 + 2e-11), Regime.MAJOR_AXIS),
    "one ulp above separatrix": ((2.0, 3.0, 6.0), (3.0, 0.25, 1.0 + 2**-52), Regime.MAJOR_AXIS),
    "one ulp below separatrix": ((2.0, 3.0, 6.0), (3.0, 0.25, 1.0 - 2**-53), Regime.MINOR_AXIS),
    "separatrix": ((2.0, 3.0, 6.0), (3.0, 0.25, 1.0), Regime.SEPARATRIX),
    "separatrix other lobe": ((2.0, 3.0, 6.0), (-3.0, 0.25, 1.0), Regime.SEPARATRIX),
    "oblate": ((1.0, 1.0, 3.0), (0.5, 0.2, 1.0), Regime.SYMMETRIC),
    "prolate": ((1.0, 3.0, 3.0), (1.0, 0.2, 0.5), Regime.SYMMETRIC),
    "sphere": ((2.0, 2.0, 2.0), (0.3, -0.2, 0.7), Regime.SPHERE),
    "permanent about I2": ((1.0, 2.0, 3.0), (0.0, 1.3, 0.0), Regime.PERMANENT_ROTATION),
    "permanent, unsorted": ((3.0, 1.0, 2.0), (-2.0, 0.0, 0.0), Regime.PERMANENT_ROTATION),
    "rest": ((1.0, 2.0, 3.0), (0.0, 0.0, 0.0), Regime.REST),
    "extreme 1:10:1000": ((1.0, 10.0, 1000.0), (1.0, 0.1, 0.5), Regime.MAJOR_AXIS),
    "m ~ 1e-18": ((1.0, 1.0 + 2**-52, 2.0), (0.05, 0.03, 1.0), Regime.MAJOR_AXIS),
    "hair off an axis": ((1.0, 2.0, 3.0), (1e-200, 0.0, 1.0), Regime.MAJOR_AXIS),
    "scaled 1e100, 1e-200": ((2e100, 1e100, 3e100), (1e-200, 3e-201, 5e-201), Regime.MAJOR_AXIS),
}

TIMES = [0.0, -0.0, 1e-12, -1e-9, 0.7, -2.5, 3.7, 123.456, -1e4, 1e4, 1e9, -1e12, 1e15, 1e20]


def _assert_same(body: FreeRigidBody, t: float) -> None:
    w_s, r_s, c_s = body.sample(t)
    w_v, r_v, c_v = body.sample(np.array([t]))
    assert w_s.shape == (3,) and c_s.shape == (3,) and r_s.single
    scale = float(np.linalg.norm(w_v[0]))
    tol = SCALAR_RTOL * scale
    assert np.all(np.abs(w_s - w_v[0]) <= tol), (t, w_s, w_v[0])
    assert np.all(np.abs(c_s - c_v[0]) <= 2 * tol), (t, c_s, c_v[0])
    q_s, q_v = r_s.as_quat(), r_v.as_quat()[0]
    q_s = q_s if q_s @ q_v >= 0.0 else -q_s
    assert np.all(np.abs(q_s - q_v) <= SCALAR_RTOL), (t, q_s, q_v)
    # The other entry points take the same scalar path.
    assert np.array_equal(body.omega(t), w_s)
    assert np.array_equal(body.attitude(t).as_quat(), r_s.as_quat())
    w_state, r_state = body.state(t)
    assert np.array_equal(w_state, w_s)
    assert np.array_equal(r_state.as_quat(), r_s.as_quat())
    assert np.array_equal(body.contact_point(t), c_s)


@pytest.mark.parametrize("rot0", [None, ROT0], ids=["identity", "rotated"])
@pytest.mark.parametrize("key", list(REGIMES))
def test_scalar_time_matches_the_array_path(key: str, rot0: Rotation | None) -> None:
    inertia, omega0, regime = REGIMES[key]
    body = FreeRigidBody(inertia, omega0, attitude0=rot0)
    assert body.regime is regime
    span = body.period if math.isfinite(body.period) else 10.0
    times = TIMES + list(np.random.default_rng(7).uniform(-50.0, 50.0, 12) * span)
    for t in times:
        _assert_same(body, float(t))


@pytest.mark.parametrize("key", list(REGIMES))
def test_scalar_time_zero_returns_the_initial_state(key: str) -> None:
    inertia, omega0, _ = REGIMES[key]
    body = FreeRigidBody(inertia, omega0, attitude0=ROT0)
    w, rot = body.state(0.0)
    assert np.allclose(w, omega0, rtol=4 * np.finfo(float).eps, atol=0.0)
    assert (rot * ROT0.inv()).magnitude() < 1e-15


@pytest.mark.parametrize(
    "t", [5, np.float64(5.0), np.float32(5.0), np.int64(5), np.array(5.0)], ids=repr
)
def test_scalar_time_types(t) -> None:
    body = FreeRigidBody((1.0, 2.0, 3.0), (1.0, 0.3, 0.5))
    w, rot, contact = body.sample(t)
    assert w.shape == (3,) and contact.shape == (3,) and rot.single
    w_v, rot_v, _ = body.sample(np.array([float(t)]))
    assert np.allclose(w, w_v[0], rtol=SCALAR_RTOL, atol=0.0)
    assert (rot * rot_v[0].inv()).magnitude() <= 1e-15
    assert body.omega([float(t)]).shape == (1, 3) and len(body.attitude([float(t)])) == 1


@pytest.mark.parametrize("t", [math.nan, math.inf, -math.inf, np.float64(math.nan)])
def test_scalar_time_must_be_finite(t) -> None:
    body = FreeRigidBody((1.0, 2.0, 3.0), (1.0, 0.3, 0.5))
    for call in (body.omega, body.attitude, body.state, body.sample, body.contact_point):
        with pytest.raises(ValueError, match="finite"):
            call(t)


@pytest.mark.parametrize("t", [True, np.bool_(False), 1j, np.complex128(2.0), "1.5", None])
def test_scalar_time_must_be_a_real_number(t) -> None:
    """A bool, a complex number or a text is refused (a TypeError, also a ValueError), not
    read as 1.0, cut to its real part or parsed."""
    body = FreeRigidBody((1.0, 2.0, 3.0), (1.0, 0.3, 0.5))
    for call in (body.omega, body.attitude, body.state, body.sample, body.contact_point):
        with pytest.raises(TypeError, match="time must be a number or a 1-D array of numbers"):
            call(t)


@pytest.mark.parametrize("key", ["report generic", "separatrix", "oblate", "rest"])
@pytest.mark.parametrize("t", [1e300, -1.7e308])
def test_scalar_time_beyond_the_phase_range_matches_the_array_path(key: str, t: float) -> None:
    """Near the end of the float range both paths give the same ω; where a phase rate·t would
    pass 1e300 rad both refuse the time with the same ValueError (never a NaN)."""
    inertia, omega0, _ = REGIMES[key]
    body = FreeRigidBody(inertia, omega0)
    try:
        scalar = body.omega(t)
    except ValueError as exc:
        assert "too far in time" in str(exc)
        with pytest.raises(ValueError, match="too far in time"):
            body.omega(np.array([t]))
        return
    assert np.all(np.isfinite(scalar))
    assert np.array_equal(scalar, body.omega(np.array([t]))[0])


@settings(max_examples=300, deadline=None, derandomize=True)
@given(
    logs=st.lists(st.floats(-3.0, 3.0), min_size=3, max_size=3),
    equal=st.sampled_from([None] * 6 + [(0, 1), (1, 2), (0, 2)]),
    mags=st.lists(st.floats(-6.0, 0.0), min_size=3, max_size=3),
    signs=st.lists(st.sampled_from([-1.0, 1.0]), min_size=3, max_size=3),
    zero=st.sampled_from([None] * 6 + [0, 1, 2, (0, 1)]),
    t=st.floats(-1e6, 1e6),
)
def test_scalar_time_matches_the_array_path_random(logs, equal, mags, signs, zero, t) -> None:
    """Random bodies as in physics/test_properties.py (components over six decades)."""
    inertia = [10.0**x for x in logs]
    if equal is not None:
        inertia[equal[1]] = inertia[equal[0]]
    omega0 = np.array(signs) * 10.0 ** np.array(mags)
    if zero is not None:
        omega0[np.array(zero)] = 0.0
    _assert_same(FreeRigidBody(inertia, omega0, attitude0=ROT0), t)


# ---- the exact helpers of the construction ----------------------------------------------------


def test_sqrt_ratio_is_correctly_rounded() -> None:
    rng = np.random.default_rng(11)
    cases = [(1, 1), (2, 1), (1, 3), (9, 4), (-8, -2), (0, 5), (1, 10**600), (10**600 + 1, 7)]
    for _ in range(3000):
        bits = rng.integers(1, 700, size=2)
        cases.append((int(rng.integers(1, 2**62)) << int(bits[0]), int(rng.integers(1, 2**62))))
        cases.append((int(rng.integers(1, 2**62)), int(rng.integers(1, 2**62)) << int(bits[1])))
    for num, den in cases:
        with localcontext() as ctx:
            ctx.prec = 120
            exact = (Decimal(num) / Decimal(den)).sqrt()
        assert sqrt_ratio(num, den) == float(exact), (num, den)


@pytest.mark.parametrize("mc", ["0.62", "0.5", "1e-10", "1e-16", "1e-300", "0.999999", "1"])
@pytest.mark.parametrize("n", ["-0.7142857", "-3", "-1e6", "0"])
def test_complete_integrals_decimal_against_mpmath(mc: str, n: str) -> None:
    """K(m) and Π(n|m) from one 45-digit AGM against mpmath (m = 1 - mc carried exactly).

    K to 1e-44 relative. Π to 1e-42 times sqrt(1 - n): for large -n, Π ~ π/(2 sqrt(-n)) comes
    out of ``2 + n/(1-n) Σ`` with that much cancellation (DLMF 19.8.6-19.8.8).
    """
    mc_q, n_q = Fraction(mc), Fraction(n)
    with localcontext() as ctx:
        ctx.prec = precise.DIGITS
        sqrt_mc = precise.ratio(mc_q.numerator, mc_q.denominator).sqrt()
        n_dec = precise.ratio(n_q.numerator, n_q.denominator)
        K, Pi, _ = elliptic.complete_integrals_excess_decimal(n_dec, sqrt_mc)
    with mp.workdps(60 + int(-math.log10(mc_q))):  # 1 - 1e-300 must not round to 1
        m = 1 - mp.mpf(mc_q.numerator) / mc_q.denominator
        nn = mp.mpf(n_q.numerator) / n_q.denominator
        K_ref, Pi_ref = mp.ellipk(m), mp.ellippi(nn, m)
        assert abs(mp.mpf(str(K)) / K_ref - 1) < mp.mpf("1e-44")
        tol = mp.mpf("1e-42") * mp.sqrt(1 - nn)
        assert abs(mp.mpf(str(Pi)) / Pi_ref - 1) < tol
