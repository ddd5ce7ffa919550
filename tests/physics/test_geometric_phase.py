"""Montgomery's geometric phase [Mon91]: the closed form of Ω against an independent quadrature
of the cone's solid angle (mpmath, no elliptic function at all), against a quadrature over the
motion (scipy), Montgomery's sum against the turn read off the attitude, and the separatrix
limit.

The mpmath reference parametrises the cone of L by its azimuth α about the pole: the direction
``l = (sin θ cos α, sin θ sin α, cos θ)`` (pole e3) lies on the cone when
``Σ lᵢ²/Iᵢ = 1/D``, which gives ``sin²θ(α)`` in closed form, and ``Ω = ∫₀^{2π} (1 − cos θ) dα``.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest

from poinsot.physics import FreeRigidBody, Regime
from poinsot.physics.models.geometric_phase import (
    montgomery_phase,
    separatrix_solid_angles,
    solid_angle,
    solid_angle_quadrature,
)

mpmath.mp.dps = 30


def reference_solid_angle(inertia: tuple[float, float, float], D: float) -> float:
    """Ω by mpmath quadrature over the azimuth (pole e3 for D > I2, e1 for D < I2, negative)."""
    I1, I2, I3 = (mpmath.mpf(x) for x in sorted(inertia))
    d = mpmath.mpf(D)
    if d > I2:
        a, b, pole, sign = I1, I2, I3, 1
    else:
        a, b, pole, sign = I3, I2, I1, -1

    def cap(alpha: mpmath.mpf) -> mpmath.mpf:
        c, s = mpmath.cos(alpha), mpmath.sin(alpha)
        sin2 = (1 / d - 1 / pole) / (c * c / a + s * s / b - 1 / pole)
        return 1 - mpmath.sqrt(1 - sin2)

    quarter = mpmath.quad(cap, [0, mpmath.pi / 4, mpmath.pi / 2])
    return float(sign * 4 * quarter)


CASES = [
    ((1.0, 2.0, 2.6), 2.3),
    ((1.0, 2.0, 2.6), 2.59),
    ((1.0, 2.0, 2.6), 2.0 + 1e-6),
    ((1.0, 2.0, 2.6), 1.5),
    ((1.0, 2.0, 2.6), 1.0001),
    ((1.0, 2.0, 2.6), 2.0 - 1e-9),
    ((0.077, 0.925, 1.0), 0.95),
    ((0.00121, 0.01638, 0.01748), 0.0170),
    ((3.0, 1.0, 2.0), 1.4),  # any order of the moments
    ((1.0, 1.001, 50.0), 30.0),
]


@pytest.mark.parametrize(("inertia", "D"), CASES)
def test_closed_form_against_mpmath_quadrature(
    inertia: tuple[float, float, float], D: float
) -> None:
    assert float(solid_angle(inertia, D)) == pytest.approx(
        reference_solid_angle(inertia, D), abs=1e-10
    )


def test_vectorised_over_D_and_signs() -> None:
    inertia = (1.0, 2.0, 2.6)
    Ds = np.array([1.0, 1.3, 1.9, 2.1, 2.5, 2.6])
    omega = solid_angle(inertia, Ds)
    assert omega.shape == (6,)
    assert omega[0] == 0.0 and omega[-1] == 0.0  # the poles
    assert np.all(omega[1:3] < 0.0) and np.all(omega[3:5] > 0.0)
    for D, value in zip(Ds[1:-1], omega[1:-1], strict=True):
        assert value == pytest.approx(reference_solid_angle(inertia, D), abs=1e-10)


@pytest.mark.parametrize("D", [0.99, 2.0, 2.7, math.nan])
def test_bad_D_is_refused(D: float) -> None:
    with pytest.raises(ValueError, match="D must lie"):
        solid_angle((1.0, 2.0, 2.6), D)


def test_quadrature_over_the_motion_agrees() -> None:
    for inertia, D in CASES[:6]:
        for sign in (1.0, -1.0):
            body = FreeRigidBody.from_energy(inertia, D, omega_norm=1.3, pole_sign=sign)
            assert solid_angle_quadrature(body, 0.7) == pytest.approx(
                reference_solid_angle(inertia, D), abs=1e-10
            )


def test_montgomery_sum_is_the_turn_of_the_attitude() -> None:
    """43 random bodies and starts: 2TP/|L| − Ω equals the turn about L over one period."""
    rng = np.random.default_rng(21)
    worst = 0.0
    for _ in range(43):
        inertia = rng.uniform(0.2, 5.0, 3)
        w0 = rng.normal(size=3)
        body = FreeRigidBody(inertia, w0)
        if body.regime not in (Regime.MAJOR_AXIS, Regime.MINOR_AXIS):
            continue
        phase = montgomery_phase(body, float(rng.uniform(0.0, 10.0)))
        worst = max(worst, abs(phase.gap))
        assert phase.dynamic == pytest.approx(
            2 * body.energy * body.period / np.linalg.norm(body.angular_momentum)
        )
    assert worst < 1e-12


def test_separatrix_limit() -> None:
    """Ω tends to the lunes' solid angles on each side of D = I2, at the rate 1 − m → 0."""
    inertia = (1.0, 2.0, 2.6)
    major, minor = separatrix_solid_angles(inertia)
    assert major - minor == pytest.approx(2 * math.pi, abs=1e-15)
    # The lune about e3 between the planes l3 = ±t l1, t = sqrt(I3 (I2-I1)/(I1 (I3-I2))).
    t = math.sqrt(2.6 * 1.0 / (1.0 * 0.6))
    assert major == pytest.approx(4 * (math.pi / 2 - math.atan(t)), abs=1e-15)
    gaps = [abs(float(solid_angle(inertia, 2.0 + h)) - major) for h in (1e-2, 1e-4, 1e-8, 1e-12)]
    assert all(a > b for a, b in zip(gaps, gaps[1:], strict=False))
    assert gaps[-1] < 1e-9
    assert abs(float(solid_angle(inertia, 2.0 - 1e-12)) - minor) < 1e-9
    assert reference_solid_angle(inertia, 2.0 + 1e-10) == pytest.approx(major, abs=1e-7)
