"""Regressions of the fuzz, by root cause: numbers at the ends of the double range, and work
without bound.

Each test names what went wrong before: a product or a square that left the double range on
the way to a finite answer (fixed by exact power-of-two scaling or by dividing one factor at a
time), an answer that itself leaves the range (now a ValueError that says so and what to
change), or a grid, a run or an allocation sized by the input (now bounded, with a ValueError).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from poinsot.physics import FreeRigidBody, box_dimensions, omega_from_energy
from poinsot.physics.integrators import Propagation, integrate
from poinsot.physics.models.dissipation import EnergySink
from poinsot.physics.models.family import PolhodeArc, polhode_curves, polhode_family
from poinsot.physics.models.flip import (
    flip_theory,
    integrated_flip_times,
    measure_flips,
    measure_growth_rate,
)
from poinsot.physics.models.gyroscope import Gyroscope
from poinsot.physics.models.symmetric import measure_precession_rate, symmetric_top

pytestmark = pytest.mark.filterwarnings("error")

BIG = float(np.finfo(float).max)


# -- FreeRigidBody and the initial states ---------------------------------------------------


def test_D_of_moments_at_the_top_of_the_range_is_finite() -> None:
    """G·(G/2T) rounded one ulp above the largest moment, which read back as inf."""
    body = FreeRigidBody([BIG, BIG, BIG], (0.0, 0.0, 0.0144))
    assert body.D == BIG
    body = FreeRigidBody([BIG, 0.5 * BIG, 0.25 * BIG], (0.3, 0.2, 1.0))
    assert 0.25 * BIG <= body.D <= BIG


def test_contact_point_of_a_spin_near_the_top_of_the_range() -> None:
    """R ω was formed in the caller's units: its products overflowed for ω ~ 1e308."""
    body = FreeRigidBody((1.0, 2.0, 3.0), (1.2e308, 3e307, 5e307), Rotation.from_rotvec([1, 2, 0]))
    contact = body.contact_point(np.array([0.0, 4e-309]))
    assert np.all(np.isfinite(contact))
    height = contact @ body.plane_normal / 1e308
    np.testing.assert_allclose(height, body.plane_distance / 1e308, rtol=1e-14)


def test_plane_distance_beyond_the_range_is_refused_when_read() -> None:
    """2T/G <= |ω|, which may pass 1.8e308 with ω0 = (-1.8e308, 0, 1.8e308): it was inf."""
    body = FreeRigidBody((1.9e299, 2.2e300, 2.7e300), (-BIG, 0.0, BIG))
    with pytest.raises(ValueError, match=r"distance 2T/\|L\| of the plane .* shorter time unit"):
        _ = body.plane_distance
    assert np.all(np.isfinite(body.omega(np.array([0.0, 1e-320]))))


def test_a_period_below_the_smallest_double_is_refused() -> None:
    """It underflowed to 0.0, a period that divided by zero downstream."""
    body = FreeRigidBody((3.0, 3.0, 7.4e66), (1.8e305, 1.3e305, 2.2e306))
    with pytest.raises(ValueError, match=r"period of ω .* below the smallest .* shorter time"):
        _ = body.period
    assert np.all(np.isfinite(body.omega(np.array([0.0, 1e-300]))))


def test_omega_from_energy_refuses_moments_beyond_300_decades() -> None:
    """The scaled smallest moment underflowed to 0: NaN and warnings."""
    with pytest.raises(ValueError, match="300 decades"):
        omega_from_energy((1e-300, 1.0, 1e300), 1.0)


def test_from_energy_with_a_momentum_and_a_tiny_scaled_moment() -> None:
    """|J ω| by a norm whose squares underflowed (a division by zero)."""
    body = FreeRigidBody.from_energy((3.0, 1e300, 2.5), 2.5, momentum_norm=2.5)
    assert np.all(np.isfinite(body.omega0)) and np.any(body.omega0)


def test_box_of_moments_near_the_top_of_the_range() -> None:
    """The sum of the moments overflowed."""
    sides = box_dimensions((1e308, 1e308, 1e308), 1.0)
    np.testing.assert_allclose(sides, math.sqrt(6.0) * 1e154, rtol=1e-15)
    with pytest.raises(ValueError, match="sides beyond the double-precision range"):
        box_dimensions((1e306, 1e306, 1e306), 5e-324)  # sides ~1e315


# -- the textbook modules ---------------------------------------------------------------------


def test_polhodes_of_moments_far_apart_are_finite() -> None:
    """Products of scaled moments ~1e-221 underflowed: a ZeroDivisionError."""
    curves = polhode_family((1.25e-25, 14.8, 7.2e222), [3.0], momentum=2.4)
    assert all(np.all(np.isfinite(c.omega)) for c in curves)
    two_T = curves[0].two_T
    for c in curves:
        np.testing.assert_allclose(np.sum(c.momentum * c.omega, axis=1), two_T, rtol=1e-13)


def test_polhodes_beyond_the_range_are_refused() -> None:
    with pytest.raises(ValueError, match="2T for this D is beyond"):
        polhode_curves((1.0, 2.0, 3.0), 2.5, energy=1e308)
    with pytest.raises(ValueError, match="at most 4,000,000"):
        polhode_family((1.0, 2.0, 3.0), np.linspace(1.0, 3.0, 5000), n=1000)


def test_arc_length_scales_with_omega() -> None:
    """|dω/dt| squared ω: ω ~ 1e200 overflowed, ω ~ 1e-200 gave an arc of 0."""
    inertia, w0 = (1.0, 2.0, 3.0), np.array([0.3, 0.2, 1.0])
    unit = PolhodeArc(FreeRigidBody(inertia, w0))
    for k in (200, -200):
        scale = 2.0**k  # exact: the same motion in another time unit
        arc = PolhodeArc(FreeRigidBody(inertia, w0 * scale))
        assert arc.circuit_length == unit.circuit_length * scale
        t = np.array([0.3, 7.0]) / scale
        np.testing.assert_array_equal(arc.arc_length(t), unit.arc_length(t * scale) * scale)


def test_flip_clock_of_extreme_spins() -> None:
    """Δᵢ squared ω: ω ~ 1e200 overflowed; the clock scales exactly with the time unit."""
    inertia, w0 = (1.0, 2.0, 3.0), np.array([1e-3, 1.0, 0.0])
    unit = flip_theory(inertia, w0)
    fast = flip_theory(inertia, w0 * 2.0**600)
    assert fast.time_between_flips == unit.time_between_flips * 2.0**-600
    assert fast.complementary_parameter == unit.complementary_parameter
    # A perturbation 1e-161 off e3, on subnormal moments: a NaN first flip (0 times inf).
    clock = flip_theory((1.2e-320, 2.3e-320, 7.8e-320), (0.0, -1.5e-161, 1.6))
    assert all(map(math.isfinite, (clock.first_flip_time, clock.time_between_flips)))


def test_growth_from_a_subnormal_perturbation() -> None:
    """hi/p0 overflowed (a warning) for a start p0 ~1e-319 off e2; the growth is measurable."""
    inertia = np.array([1.06544994e150, 2.63342978e150, 3.00559270e150])
    w0 = np.array([3.765205e-318, -26.53780275071176, 0.0])
    I1, I2, I3 = inertia / inertia[2]
    sigma = abs(w0[1]) * math.sqrt((I2 - I1) * (I3 - I2) / (I1 * I3))
    fit = measure_growth_rate(FreeRigidBody(inertia, w0))
    assert fit.rate == pytest.approx(sigma, rel=1e-3) and fit.e_folds > 700


def test_measuring_grids_are_bounded() -> None:
    """A grid sized by the input: a MemoryError (738 TiB) or a run of hours."""
    body = FreeRigidBody((1.0, 2.0, 3.0), (1e-3, 1.0, 0.0))
    with pytest.raises(ValueError, match="more than 10,000,000"):
        measure_flips(body, 1e9)
    with pytest.raises(ValueError, match="e2 is not the intermediate axis"):
        measure_growth_rate(FreeRigidBody((2.0, 1.0, 3.0), (1e-6, 1.0, 0.0)))
    top = FreeRigidBody((0.449, 0.0011, 0.0011), (1000.0, -0.001, -1.0))
    with pytest.raises(ValueError, match="more than 10,000,000"):
        measure_precession_rate(top, 13.0)


def test_dop853_flips_check_their_tolerance_and_length() -> None:
    """scipy raised a tolerance below 100 eps with a warning; a long run never ended."""
    with pytest.raises(ValueError, match="rtol must lie between"):
        integrated_flip_times((1.0, 2.0, 3.0), (1e-3, 1.0, 0.0), 10.0, rtol=1e-300)
    with pytest.raises(ValueError, match="radians"):
        integrated_flip_times((1.0, 2.0, 3.0), (1e-3, 1.0, 0.0), 1e9)
    assert integrated_flip_times((1.0, 2.0, 3.0), (0.0, 0.0, 0.0), 10.0).size == 0
    fast = integrated_flip_times((1.0, 2.0, 3.0), (2.0**500, 2.0**510, 0.0), 30.0 * 2.0**-510)
    slow = integrated_flip_times((1.0, 2.0, 3.0), (2.0**-10, 1.0, 0.0), 30.0)
    np.testing.assert_array_equal(fast, slow * 2.0**-510)


def test_symmetric_top_of_extreme_units() -> None:
    """G = |I ω| overflowed; the space cone divided 0 by 0 for a subnormal L."""
    top = symmetric_top(2.0, 0.0078, (0.0, -3.67e-318, 0.0))
    assert np.all(np.isfinite(top.space_cone(16)))
    big = symmetric_top(1e300, 2e300, (1e7, 0.0, 3e7))
    assert math.isfinite(big.precession_rate)
    with pytest.raises(ValueError, match="angular momentum of this top lie beyond"):
        symmetric_top(1e300, 2e300, (1e10, 0.0, 3e10))


def test_gyroscope_constants_and_runs_are_bounded() -> None:
    """ν underflowed to 0 (a ZeroDivisionError), the Magnus run and the drift samples were
    sized by the input (MemoryError: 29.8 GiB)."""
    with pytest.raises(ValueError, match="nutation of this gyroscope lies beyond"):
        Gyroscope(3.8e-318, 2.0, -0.35, (0.0, 0.0, 0.85))
    gyro = Gyroscope(1.0, 2.0, 0.3, (0.2, -0.1, 5.0))
    with pytest.raises(ValueError, match="Magnus"):
        gyro.attitude([0.0, 1e9])
    with pytest.raises(ValueError, match="samples"):
        gyro.measure_drift(2, 10**9)
    # A step of 5e300 rad squared the angles in the cross product: an overflow warning.
    fast = Gyroscope(0.19, 2.2e-308, -2e-139, (2.7e299, 0.0, -5.0e300))
    with pytest.raises(ValueError, match="more than half a turn"):
        fast.attitude([2.5], 2.0)


def test_energy_sink_windows_and_ranges() -> None:
    """Windows sized by t_end/window; |L|² overflowed; I2 I3 underflowed to 0/0."""
    with pytest.raises(ValueError, match="more than 20,000"):
        EnergySink((1.0, 2.0, 3.0), (1.0, 0.15, 0.1), 0.05, 1e6)
    with pytest.raises(ValueError, match=r"\|L\|²"):
        EnergySink((1.0, 2.0, 3.0), (0.0, 1e200, 1e200), 0.05, 1.0)
    sink = EnergySink((1.6e-150, 2.5e-150, 4.1e-150), (1.0, 0.15, 0.1), 1.0, 0.1)
    assert math.isfinite(sink.crossing_time)
    sink = EnergySink((5.4e149, 8.6e149, 4.3e150), (1.0, 0.15, 0.1), 0.58, 0.3, 0.0014)
    assert np.all(np.isfinite(sink.omega([0.0, 0.29])))


def test_integrators_in_scaled_units() -> None:
    """Euler's equations squared ω: ω ~ 1e200 overflowed; steps and runs were unbounded."""
    t, scale = np.array([0.0, 0.5, 1.0]), 2.0**700  # the same motion in another time unit
    for method in ("RK45", "DOP853", "splitting", "midpoint"):
        h = None if method in ("RK45", "DOP853") else 0.01
        unit = integrate(method, (1.0, 2.0, 3.0), (0.3, 0.2, 1.0), None, t, h)
        w0, hs = np.array([0.3, 0.2, 1.0]) * scale, None if h is None else h / scale
        fast = integrate(method, (1.0, 2.0, 3.0), w0, None, t / scale, hs)
        np.testing.assert_array_equal(fast.omega / scale, unit.omega)
    with pytest.raises(ValueError, match="steps"):
        integrate("splitting", (1.0, 2.0, 3.0), (0.3, 0.2, 1.0), None, [0.0, 1e300], 1e-3)
    with pytest.raises(ValueError, match="radians"):
        integrate("RK45", (1.0, 2.0, 3.0), (0.3, 0.2, 1.0), None, [0.0, 1e300])
    with pytest.raises(ValueError, match="relative tolerance"):
        integrate("DOP853", (1.0, 2.0, 3.0), (0.3, 0.2, 1.0), None, [0.0, 1.0], 1e-300)
    with pytest.raises(ValueError, match="non-decreasing"):  # the check subtracted: overflow
        integrate("splitting", (1.0, 2.0, 3.0), (0.3, 0.2, 1.0), None, [1e308, -1e308])
    with pytest.raises(ValueError, match="more than"):
        Propagation("splitting", (1.0, 2.0, 3.0), (0.3, 0.2, 1.0)).advance(1e300)
