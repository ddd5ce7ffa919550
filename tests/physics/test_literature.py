"""Literature values, measured on the motion rather than read off the implementation's formulas.

* [LL76 §37, Eq. 37.12]: the period of omega is ``4K(m)/lambda`` -- against zero crossings of omega
  measured on a DOP853 integration (no elliptic function involved).
* [FM06 §7.11], [GPS02 §5.6] (axisymmetric body): the symmetry axis precesses about L at
  ``p = G/I`` while the body spins relative to the precessing frame at
  ``s = ((I - J)/I) omega3``; the whole attitude is ``R(t) = Rot(L, p t) R0 Rot(e3, s t)``.
* [LL76 §37, Problem 1]: small oscillations about a stable axis have angular frequency
  ``Omega3 sqrt((I3/I1 - 1)(I3/I2 - 1))`` (and the same with 3 -> 1 about the minor axis).
* Instability of the intermediate axis: a perturbation grows like ``exp(sigma t)``,
  ``sigma = Omega2 sqrt((I2 - I1)(I3 - I2)/(I1 I3))``; the Dzhanibekov flip time (half a period
  of omega near the separatrix) is ``2K/lambda ~ ln(16/(1 - m))/sigma``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from reference import (
    ATTITUDE_ATOL_GENERIC,
    OMEGA_RTOL_GENERIC,
    ReferenceBody,
    as_matrices,
    dop853_zero_crossings,
    exact_complementary_parameter,
    geodesic_angle,
    integrate_dop853,
)
from scipy.spatial.transform import Rotation

from poinsot.physics import FreeRigidBody, Regime

CROSSING_PERIOD_RTOL = 1e-10
"""Period measured as the spacing of DOP853 zero crossings (event roots on the dense output):
DOP853 at rtol 1e-13 plus the event root finder locate a crossing to ~1e-12 relative; 1e-10
leaves margin while any error in K or lambda (or a factor 2 in the period) shows by orders."""

SMALL_OSCILLATION_RTOL = 1e-9
"""Landau's small-oscillation frequency is the linearisation: the exact frequency differs by
O(amplitude^2); at amplitude 1e-5 that is ~1e-10."""

GROWTH_RTOL = 1e-7
"""The measured exponent ``ln(|w1(t)|/w1(0))/t`` differs from sigma by the nonlinear O(amp^2)
term and by the error of the tiny ``w1`` itself (absolute ~1e-16 |omega| on an amplitude 3e-7,
divided by sigma t = 8): ~1e-9 at amplitude 1e-10 e^8; 1e-7 leaves margin."""

FLIP_ASYMPTOTIC_RTOL = 1e-6
"""Flip time vs ``ln(16/(1-m))/sigma``: the asymptotic ``K ~ 1/2 ln(16/(1-m))`` has error
O((1-m) ln(1-m)) and ``lambda/sigma - 1 = O(eps_perturbation^2)``; both ~1e-8 here."""

DOP853_FLIP_RTOL = 1e-7
"""Flip time measured on DOP853 near the separatrix: the passage close to the unstable pole
amplifies DOP853's local errors (measured: no tolerance gets it below ~6e-10 there); measured
3e-9 at 1 - m ~ 1e-8."""

ROT0 = Rotation.from_rotvec([1.1, 0.2, -0.5])


def _crossings_of(body: FreeRigidBody, component: int, t_end: float, n: int = 4000) -> np.ndarray:
    """Upward zero crossings of ``body.omega(t)[component]``, by sampling then bisection."""
    t = np.linspace(0.0, t_end, n)
    w = body.omega(t)[:, component]
    idx = np.nonzero((w[:-1] < 0) & (w[1:] >= 0))[0]
    out = []
    for k in idx:
        a, b = t[k], t[k + 1]
        for _ in range(80):
            mid = 0.5 * (a + b)
            if body.omega(mid)[component] < 0:
                a = mid
            else:
                b = mid
        out.append(0.5 * (a + b))
    return np.array(out)


@pytest.mark.parametrize(
    ("inertia", "omega0", "component"),
    [
        ((1.0, 2.0, 3.0), (0.2, 0.3, 1.0), 0),  # major family: w1 = A1 cn changes sign
        ((1.0, 2.0, 3.0), (1.0, 0.3, 0.5), 2),  # minor family: w3 = A3 cn
        ((1.0, 2.0, 3.0), (1.0, 0.3, 0.5), 1),  # w2 = A2 sn
        ((3.0, 1.0, 2.0), (0.5, 1.0, -0.2), 2),  # unsorted: caller axis 2 is intermediate
        ((1.0, 2.0, 3.5), (0.64, 0.0, 0.6), 1),  # close to the separatrix, starts at w2 = 0
        ((0.7, 5.0, 2.2), (-0.3, 0.8, 1.1), 2),
    ],
)
def test_period_vs_dop853_zero_crossings(inertia, omega0, component) -> None:
    """[LL76 §37, Eq. 37.12]: period of omega = 4K/lambda, measured on an independent integration.
    The measured component is one that changes sign (an sn or cn one, not the pole's dn)."""
    body = FreeRigidBody(inertia=inertia, omega0=omega0)
    ref = ReferenceBody(inertia, omega0)
    assert body.period == pytest.approx(
        ref.period_float, rel=1e-13
    )  # 4K/lambda [LL76 §37, Eq. 37.12]
    crossings = dop853_zero_crossings(inertia, omega0, component, 3.2 * ref.period_float)
    crossings = crossings[crossings > 1e-9 * ref.period_float]  # not the start itself
    assert crossings.size >= 3
    measured = np.diff(crossings)
    assert np.all(np.abs(measured - body.period) <= CROSSING_PERIOD_RTOL * body.period), (
        measured,
        body.period,
    )
    # and the implementation's own omega crosses zero at the same instants
    own = _crossings_of(body, component, 3.2 * body.period)
    assert own.size == crossings.size
    assert np.max(np.abs(own - crossings)) <= CROSSING_PERIOD_RTOL * body.period


@pytest.mark.parametrize(
    ("inertia", "omega0", "axis"),
    [
        ((1.0, 1.0, 3.0), (0.5, 0.2, 1.0), 2),  # oblate (J > I)
        ((1.0, 3.0, 3.0), (1.0, 0.2, 0.5), 0),  # prolate (J < I), symmetry axis first
        ((2.0, 0.5, 2.0), (0.1, 0.9, -0.5), 1),  # prolate, symmetry axis second, w3 < 0
        ((5.0, 5.0, 1.0), (-0.3, 0.1, 2.0), 2),  # prolate rod-like
    ],
)
def test_symmetric_top_precession_and_spin(inertia, omega0, axis) -> None:
    """[FM06 §7.11]: R(t) = Rot(L, G t / I) R0 Rot(e_axis, s t), s = ((I - J)/I) w_axis; the
    transverse omega turns in the body at -s; precession per period = G/I * 2 pi / |s|."""
    ii = np.asarray(inertia)
    w0 = np.asarray(omega0)
    J = ii[axis]
    I = ii[(axis + 1) % 3]  # noqa: E741 - the transverse moment, as in [FM06 §7.11]
    body = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=ROT0)
    assert body.regime is Regime.SYMMETRIC
    G = np.linalg.norm(ii * w0)
    p = G / I
    s = (I - J) / I * w0[axis]
    assert body.period == pytest.approx(2 * np.pi / abs(s), rel=1e-14)
    assert body.precession_per_period == pytest.approx(p * body.period, rel=1e-13)
    t = np.linspace(0.0, 100 * body.period, 51)
    l_hat = ROT0.apply(ii * w0) / G
    e = np.zeros(3)
    e[axis] = 1.0
    expected = (
        Rotation.from_rotvec(np.outer(p * t, l_hat))
        * ROT0
        * Rotation.from_rotvec(np.outer(s * t, e))
    )
    dr = geodesic_angle(as_matrices(body.attitude(t)), as_matrices(expected))
    assert np.max(dr) <= ATTITUDE_ATOL_GENERIC, np.max(dr)
    # body frame: omega_axis constant, the transverse part rotates about e_axis at -s
    w_exp = Rotation.from_rotvec(np.outer(-s * t, e)).apply(w0)
    dw = np.max(np.abs(body.omega(t) - w_exp)) / np.linalg.norm(w0)
    assert dw <= OMEGA_RTOL_GENERIC, dw


@pytest.mark.parametrize("pole", ["major", "minor"])
def test_small_oscillation_frequency(pole: str) -> None:
    """[LL76 §37, Problem 1] (about I3), and its mirror about I1."""
    i1, i2, i3 = 1.0, 2.0, 3.0
    omega_pole = 1.3
    amp = 1e-5
    if pole == "major":
        omega0 = (amp, 0.5 * amp, omega_pole)
        freq = omega_pole * math.sqrt((i3 / i1 - 1) * (i3 / i2 - 1))
        comp = 0
    else:
        omega0 = (omega_pole, 0.5 * amp, amp)
        freq = omega_pole * math.sqrt((i1 / i3 - 1) * (i1 / i2 - 1))
        comp = 2
    body = FreeRigidBody(inertia=(i1, i2, i3), omega0=omega0)
    assert body.regime is (Regime.MAJOR_AXIS if pole == "major" else Regime.MINOR_AXIS)
    measured = 2 * np.pi / body.period
    assert measured == pytest.approx(freq, rel=SMALL_OSCILLATION_RTOL)
    # the same frequency measured on DOP853
    cr = dop853_zero_crossings((i1, i2, i3), omega0, comp, 3.5 * 2 * np.pi / freq)
    assert 2 * np.pi / np.mean(np.diff(cr)) == pytest.approx(freq, rel=SMALL_OSCILLATION_RTOL)


def _unstable_mode(inertia, omega2: float, amp: float) -> tuple[np.ndarray, float]:
    """omega0 on the growing eigenvector of the linearisation about (0, Omega2, 0):
    ``I1 d1' = (I2 - I3) Omega2 d3``, ``I3 d3' = (I1 - I2) Omega2 d1``."""
    i1, i2, i3 = inertia
    sigma = omega2 * math.sqrt((i2 - i1) * (i3 - i2) / (i1 * i3))
    d3 = amp * i1 * sigma / ((i2 - i3) * omega2)
    return np.array([amp, omega2, d3]), sigma


@pytest.mark.parametrize("inertia", [(1.0, 2.0, 3.0), (0.4, 1.0, 7.0)])
def test_growth_rate_near_intermediate_axis(inertia) -> None:
    omega2 = 0.9
    amp = 1e-10
    omega0, sigma = _unstable_mode(inertia, omega2, amp)
    body = FreeRigidBody(inertia=inertia, omega0=omega0)
    t = np.array([4.0, 6.0, 8.0]) / sigma
    w1 = body.omega(t)[:, 0]
    rate = np.log(w1 / amp) / t
    assert np.all(np.abs(rate - sigma) <= GROWTH_RTOL * sigma), (rate, sigma)
    # the same growth on DOP853
    w_num, _ = integrate_dop853(inertia, omega0, np.concatenate([[0.0], t]))
    rate_num = np.log(w_num[1:, 0] / amp) / t
    assert np.all(np.abs(rate_num - sigma) <= GROWTH_RTOL * sigma), (rate_num, sigma)


@pytest.mark.parametrize("eps_rel", [1e-3, 1e-4])
def test_dzhanibekov_flip_time(eps_rel: float) -> None:
    """A spin about I2 slightly perturbed flips (omega2 -> -omega2) every half period; the
    flip time is 2K/lambda ~ ln(16/(1-m))/sigma (K's logarithmic asymptote at the separatrix),
    and it is what DOP853 measures."""
    inertia = (1.0, 2.0, 3.0)
    omega2 = 1.0
    omega0 = (eps_rel * omega2, omega2, 0.3 * eps_rel * omega2)
    i1, i2, i3 = inertia
    sigma = omega2 * math.sqrt((i2 - i1) * (i3 - i2) / (i1 * i3))
    body = FreeRigidBody(inertia=inertia, omega0=omega0)
    mc = float(exact_complementary_parameter(inertia, omega0))
    flip = 0.5 * body.period
    assert flip == pytest.approx(math.log(16.0 / mc) / sigma, rel=FLIP_ASYMPTOTIC_RTOL)
    # measured flips on DOP853: omega2 crosses zero downward, then upward, half a period apart
    down = dop853_zero_crossings(inertia, omega0, 1, 2.6 * flip, direction=-1.0)
    up = dop853_zero_crossings(inertia, omega0, 1, 2.6 * flip, direction=1.0)
    assert down.size >= 1 and up.size >= 1
    assert up[0] - down[0] == pytest.approx(flip, rel=DOP853_FLIP_RTOL)
    # and the body really is upside down in between: omega2 ~ -omega2(0)
    w_mid = body.omega(0.5 * (up[0] + down[0]))
    assert w_mid[1] < -0.99 * omega2
