"""The angles a student can read, and the wobble about a stable axis, against references.

* The angles between L and the body axes equal the angles between the space vector L and the
  columns of the attitude's matrix (scipy's rotation of the exact motion).
* The Z-X-Z angles rebuild the attitude with scipy's own ``from_euler("ZXZ")``.
* The wobble frequency read off the exact motion equals that of a DOP853 integration of
  Euler's equations (the zeros of the transverse component), and tends to the small-oscillation
  theory ω_a √((I_a − I_b)(I_a − I_c)/(I_b I_c)) like the amplitude squared; axes in any order.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from poinsot.physics import FreeRigidBody, attitude_with_L_along_z
from poinsot.physics.models.axis_angles import (
    axis_angles,
    measure_wobble,
    wobble_theory,
    zxz_angles,
)

RNG = np.random.default_rng(19)


def _random_body() -> FreeRigidBody:
    inertia = RNG.uniform(0.5, 3.0, 3)
    omega = RNG.normal(size=3)
    return FreeRigidBody(inertia, omega, Rotation.random(random_state=RNG))


@pytest.mark.parametrize("case", range(5))
def test_axis_angles_are_the_angles_of_L_to_the_axes_in_space(case: int) -> None:
    body = _random_body()
    t = np.linspace(0.0, 7.0, 50)
    omega, rotation, _ = body.sample(t)
    L = body.angular_momentum / np.linalg.norm(body.angular_momentum)
    axes = rotation.as_matrix()  # (N, 3, 3): column i is e_i in space
    want = np.arccos(np.clip(np.einsum("nji,j->ni", axes, L), -1.0, 1.0))
    np.testing.assert_allclose(axis_angles(body.inertia, omega), want, atol=1e-7)


@pytest.mark.parametrize("case", range(5))
def test_zxz_angles_rebuild_the_attitude(case: int) -> None:
    inertia, omega0 = RNG.uniform(0.5, 3.0, 3), RNG.normal(size=3)
    body = FreeRigidBody(inertia, omega0, attitude_with_L_along_z(inertia, omega0))
    t = np.linspace(0.0, 9.0, 40)
    omega, rotation, _ = body.sample(t)
    angles = zxz_angles(inertia, omega, rotation.as_quat(), body.angular_momentum)
    rebuilt = Rotation.from_euler("ZXZ", angles)  # intrinsic: Rz(φ) Rx(θ) Rz(ψ)
    assert np.max((rebuilt.inv() * rotation).magnitude()) < 1e-9
    assert np.all((angles[:, 1] >= 0.0) & (angles[:, 1] <= math.pi))


def test_zxz_angles_about_a_tilted_L() -> None:
    body = _random_body()
    t = np.linspace(0.0, 5.0, 30)
    omega, rotation, _ = body.sample(t)
    L = body.angular_momentum
    angles = zxz_angles(body.inertia, omega, rotation.as_quat(), L)
    # the L frame is some rotation R_L taking z to L̂: R = R_L Rz(φ) Rx(θ) Rz(ψ), one R_L for all t
    frames = rotation * Rotation.from_euler("ZXZ", angles).inv()
    assert np.max((frames[0].inv() * frames).magnitude()) < 1e-9
    np.testing.assert_allclose(frames[0].apply([0.0, 0.0, 1.0]), L / np.linalg.norm(L), atol=1e-9)


def _dop853_wobble(inertia: np.ndarray, omega0: np.ndarray, b: int, t_end: float) -> float:
    """π over the mean spacing of the zeros of ω_b in a DOP853 integration of Euler's
    equations (rtol 1e-12)."""
    J = inertia

    def euler(_t: float, w: np.ndarray) -> np.ndarray:
        return np.array(
            [
                (J[1] - J[2]) * w[1] * w[2] / J[0],
                (J[2] - J[0]) * w[2] * w[0] / J[1],
                (J[0] - J[1]) * w[0] * w[1] / J[2],
            ]
        )

    def zero(_t: float, w: np.ndarray) -> float:
        return float(w[b])

    sol = solve_ivp(euler, (0.0, t_end), omega0, "DOP853", rtol=1e-12, atol=1e-14, events=zero)
    times = sol.t_events[0]
    return math.pi / float(np.mean(np.diff(times)))


@pytest.mark.parametrize("order", [(0, 1, 2), (2, 0, 1), (1, 2, 0)])
@pytest.mark.parametrize("stable", ["major", "minor"])
def test_wobble_against_dop853_and_the_small_oscillation_theory(
    order: tuple[int, ...], stable: str
) -> None:
    sorted_J = np.array([1.0, 2.0, 3.0]) if stable == "major" else np.array([3.0, 2.0, 1.0])
    J = sorted_J[list(order)]
    a = int(np.argmax(J)) if stable == "major" else int(np.argmin(J))
    gaps = []
    for amplitude in (0.1, 0.01, 0.001):
        w0 = np.zeros(3)
        w0[a], w0[(a + 1) % 3] = 2.0 * math.cos(amplitude), 2.0 * math.sin(amplitude)
        body = FreeRigidBody(J, w0)
        fit = measure_wobble(body, a)
        assert len(fit.crossings) == 5
        reference = _dop853_wobble(J, w0, (a + 1) % 3, fit.crossings[-1] + 0.1)
        assert fit.frequency == pytest.approx(reference, rel=1e-9)
        spin = float(np.linalg.norm(body.angular_momentum)) / J[a]
        gap = abs(fit.frequency / float(wobble_theory(J, a, spin)) - 1.0)
        assert gap < fit.amplitude**2
        gaps.append(gap)
    assert gaps[1] < 0.02 * gaps[0] and gaps[2] < 0.02 * gaps[1]  # like the amplitude squared


def test_wobble_theory_is_the_textbook_formula_and_refuses_the_middle_axis() -> None:
    I1, I2, I3 = 1.0, 2.0, 3.0
    w = np.array([0.5, 2.0])
    np.testing.assert_allclose(
        wobble_theory((I1, I2, I3), 2, w), w * math.sqrt((I3 - I1) * (I3 - I2) / (I1 * I2))
    )
    np.testing.assert_allclose(
        wobble_theory((I1, I2, I3), 0, w), w * math.sqrt((I2 - I1) * (I3 - I1) / (I2 * I3))
    )
    with pytest.raises(ValueError, match="not strictly the major or the minor"):
        wobble_theory((I1, I2, I3), 1, 1.0)
    with pytest.raises(ValueError, match="no period"):
        measure_wobble(FreeRigidBody.from_energy((I1, I2, I3), I2), 2)
    with pytest.raises(ValueError, match="does not swing"):  # circles the minor axis, not e3
        measure_wobble(FreeRigidBody((I1, I2, I3), (2.0, 0.02, 0.0)), 2)
