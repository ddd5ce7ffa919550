"""The gyroscope under a body-fixed torque (0, M, 0) [FM06 §7.11].

* The closed-form ω(t) solves Euler's equations with the torque (DOP853, rtol 1e-13).
* The Magnus attitude agrees with DOP853 on the quaternion kinematics, converges at order 4,
  keeps the quaternion's norm, and its error estimate tracks its true error.
* Without torque it is the free symmetric top of FreeRigidBody.
* The axis drifts towards the torque at M/((J3 - J) ω3) on average over whole periods.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from poinsot.physics import FreeRigidBody
from poinsot.physics.core import rotations
from poinsot.physics.models.gyroscope import Gyroscope

OMEGA_RTOL = 1e-10
"""Closed-form ω against DOP853 at rtol 1e-13 over ~15 nutation turns (measured ~6e-14)."""

ATTITUDE_ATOL = 1e-9
"""Default Magnus run against DOP853 [rad] over t = 20 (measured ~2e-11)."""

ESTIMATE_FACTOR = 3.0
"""The Richardson estimate |q_h - q_h/2|/15 against the true error of the finer run, where
that error stands well above DOP853's own (~1e-12): within a factor 3 (measured 1.0-2.2)."""

DRIFT_RTOL = 1e-8
"""Mean axis velocity along the torque over whole periods: the mean of a periodic function on
a uniform grid of whole periods is exact; what is left is the 4th-order difference at 1024
samples per turn, ~(2π/1024)^4/30, and the attitude's own error (measured 5e-11)."""

NORM_ATOL = 1e-14
"""|q| - 1 after a prefix product of up to 2^14 exact rotations: log2 N roundings."""

CASES = [
    (1.0, 2.0, 0.3, (0.2, -0.1, 5.0)),  # oblate
    (2.0, 0.5, -0.4, (0.1, 0.3, -4.0)),  # prolate, ω3 < 0, torque < 0
    (1.0, 1.5, 2.0, (0.0, 0.0, 3.0)),  # started on the axis
]
ROT0 = Rotation.from_rotvec([0.2, 0.3, -0.5])


def _dop853(gyro: Gyroscope, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Euler's equations with the torque and q' = ½ q ⊗ (ω, 0), DOP853 at rtol 1e-13."""
    J, J3, M = gyro.transverse, gyro.axial, gyro.torque

    def rhs(_t, y):
        w, q = y[:3], y[3:]
        dw = [(J - J3) * w[1] * w[2] / J, ((J3 - J) * w[2] * w[0] + M) / J, 0.0]
        dq = 0.5 * np.array(rotations.hamilton(q, (w[0], w[1], w[2], 0.0)))
        return np.concatenate([dw, dq])

    y0 = np.concatenate([gyro.omega0, gyro.attitude0.as_quat()])
    sol = solve_ivp(rhs, (0.0, t[-1]), y0, method="DOP853", t_eval=t, rtol=1e-13, atol=1e-15)
    assert sol.success
    return sol.y[:3].T, sol.y[3:].T


@pytest.mark.parametrize("J, J3, M, w0", CASES)
def test_closed_form_omega_solves_euler_with_torque(J, J3, M, w0):
    gyro = Gyroscope(J, J3, M, w0, ROT0)
    t = np.linspace(0.0, 15.0 * gyro.nutation_period, 301)
    w, _ = _dop853(gyro, t)
    err = np.linalg.norm(gyro.omega(t) - w, axis=1) / np.linalg.norm(w, axis=1)
    assert err.max() <= OMEGA_RTOL
    # the stated structure: ω3 constant, (ω1 - ω1*, ω2) on a circle of radius C
    assert gyro.nutation_center == pytest.approx(-M / ((J3 - J) * w0[2]))
    assert gyro.nutation_rate == pytest.approx((J3 - J) / J * w0[2])
    radius = np.hypot(w[:, 0] - gyro.nutation_center, w[:, 1])
    assert np.ptp(radius) <= 1e-10 * np.linalg.norm(w0)
    np.testing.assert_allclose(gyro.omega(0.0), w0, atol=1e-15)


@pytest.mark.parametrize("J, J3, M, w0", CASES)
def test_attitude_against_dop853_and_its_error_estimate(J, J3, M, w0):
    gyro = Gyroscope(J, J3, M, w0, ROT0)
    t = np.linspace(0.0, 20.0, 201)
    _, q_ref = _dop853(gyro, t)
    run = gyro.attitude(t)
    err = rotations.geodesic_angle(run.quaternions, q_ref)
    assert err.max() <= ATTITUDE_ATOL
    assert np.abs(np.linalg.norm(run.quaternions, axis=1) - 1.0).max() <= NORM_ATOL
    np.testing.assert_allclose(run.quaternions[0], ROT0.as_quat(), atol=1e-15)
    # a coarser run, whose error stands above DOP853's: the estimate tracks it
    coarse = gyro.attitude(t, step=0.02)
    true = rotations.geodesic_angle(coarse.quaternions, q_ref)[-1]
    estimate = coarse.error_estimate[-1]
    assert true > 100 * 1e-12
    assert true / ESTIMATE_FACTOR <= estimate <= true * ESTIMATE_FACTOR


def test_magnus_converges_at_order_four():
    gyro = Gyroscope(1.0, 2.0, 0.3, (0.2, -0.1, 5.0), ROT0)
    t = np.array([10.0])
    _, q_ref = _dop853(gyro, np.array([0.0, 10.0]))
    errors = [
        float(rotations.geodesic_angle(gyro.attitude(t, step=h).quaternions[0], q_ref[1]))
        for h in (0.08, 0.04, 0.02)
    ]
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all((ratios > 12.0) & (ratios < 20.0)), ratios


@pytest.mark.parametrize("J, J3, w0", [(1.0, 2.0, (0.3, 0.1, 2.0)), (3.0, 1.0, (0.4, -0.2, -1.5))])
def test_without_torque_it_is_the_free_symmetric_top(J, J3, w0):
    gyro = Gyroscope(J, J3, 0.0, w0, ROT0)
    free = FreeRigidBody((J, J, J3), w0, ROT0)
    t = np.linspace(0.0, 30.0, 151)
    w, R = free.state(t)
    np.testing.assert_allclose(gyro.omega(t), w, atol=1e-13)
    err = rotations.geodesic_angle(gyro.attitude(t).quaternions, R.as_quat())
    assert err.max() <= ATTITUDE_ATOL
    assert gyro.drift_rate == 0.0


@pytest.mark.parametrize("J, J3, M, w0", CASES)
@pytest.mark.parametrize("periods, t_start", [(1, 0.0), (3, 0.7), (8, 5.0)])
def test_axis_drifts_towards_the_torque(J, J3, M, w0, periods, t_start):
    gyro = Gyroscope(J, J3, M, w0, ROT0)
    drift = gyro.measure_drift(periods=periods, t_start=t_start)
    assert gyro.drift_rate == pytest.approx(M / ((J3 - J) * w0[2]))
    assert drift.along_torque == pytest.approx(gyro.drift_rate, rel=DRIFT_RTOL)
    assert abs(drift.across) <= DRIFT_RTOL * abs(gyro.drift_rate)
    assert drift.window[1] - drift.window[0] == pytest.approx(periods * gyro.nutation_period)
    # the drawn vectors: unit axis and torque direction, perpendicular
    axis, torque = gyro.axis_and_torque(np.linspace(0.0, 3.0, 7))
    np.testing.assert_allclose(np.linalg.norm(axis, axis=1), 1.0, atol=1e-14)
    np.testing.assert_allclose(np.sum(axis * torque, axis=1), 0.0, atol=1e-14)


@pytest.mark.parametrize(
    "args",
    [
        (1.0, 1.0, 0.3, (0.1, 0.0, 2.0)),  # J3 = J
        (1.0, 2.0, 0.3, (0.1, 0.2, 0.0)),  # ω3 = 0
        (0.0, 2.0, 0.3, (0.1, 0.2, 1.0)),
        (1.0, math.nan, 0.3, (0.1, 0.2, 1.0)),
        (1.0, 2.0, math.inf, (0.1, 0.2, 1.0)),
        (1.0, 2.0, 0.3, (0.1, 0.2)),
    ],
)
def test_bad_input_is_a_readable_value_error(args):
    with pytest.raises(ValueError, match=r"\w+ \w+"):
        Gyroscope(*args)


def test_bad_times_are_refused():
    gyro = Gyroscope(1.0, 2.0, 0.3, (0.2, -0.1, 5.0))
    with pytest.raises(ValueError, match="non-negative"):
        gyro.attitude([1.0, 0.5])
    with pytest.raises(ValueError, match="finite"):
        gyro.attitude([0.0, math.nan])
    with pytest.raises(ValueError, match="step"):
        gyro.attitude([1.0], step=-0.1)
    with pytest.raises(ValueError, match="periods"):
        gyro.measure_drift(periods=0)
