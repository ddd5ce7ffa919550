"""The racket's twist [VMS17; VMS20]: the separatrix formula against the twist read off the exact
attitude of tosses ever closer to the middle axis, its bounds, and the ideal-racket limit."""

from __future__ import annotations

import math

import numpy as np
import pytest

from poinsot.physics import FreeRigidBody, attitude_with_L_along_z
from poinsot.physics.flip import flip_initial_omega
from poinsot.physics.racket import LIMIT_ACCURACY, measure_twist, separatrix_twist

BRODY = (0.00121, 0.01638, 0.01748)
BODIES = [BRODY, (0.077, 0.925, 1.0), (1.0, 2.0, 3.0), (0.3, 0.5, 1.0)]


def toss(inertia: tuple[float, float, float], epsilon: float, azimuth: float) -> FreeRigidBody:
    w0 = flip_initial_omega(epsilon, 2.0, azimuth)
    return FreeRigidBody(inertia, w0, attitude_with_L_along_z(inertia, w0))


@pytest.mark.parametrize("inertia", BODIES)
@pytest.mark.parametrize("azimuth", [0.0, 1.0, math.pi / 2])
def test_measured_twist_tends_to_the_formula(
    inertia: tuple[float, float, float], azimuth: float
) -> None:
    theory = separatrix_twist(inertia)
    gaps = []
    for epsilon in (1e-2, 1e-3, 1e-5):
        body = toss(inertia, epsilon, azimuth)
        m = measure_twist(body)
        assert m.handle_turn == pytest.approx(2 * math.pi, abs=1e-12)
        assert m.start < m.flip < m.end
        gap = abs(m.twist - float(theory.twist))
        bound = LIMIT_ACCURACY * body.complementary_parameter * math.cosh(float(theory.tau)) ** 2
        assert gap <= bound
        gaps.append(gap)
    assert gaps[-1] < 1e-8
    # Inside the bounds once the toss is close enough to e2.
    m = measure_twist(toss(inertia, 1e-5, azimuth))
    assert float(theory.defect_low) <= m.defect <= float(theory.defect_high)


def test_bounds_bracket_the_formula_and_a_stack_is_vectorised() -> None:
    th = separatrix_twist(np.array(BODIES))
    assert th.twist.shape == (4,)
    assert np.all(th.defect_low <= th.defect) and np.all(th.defect <= th.defect_high)
    single = separatrix_twist(BRODY)
    assert float(single.defect) == pytest.approx(float(th.defect[0]), rel=1e-15)
    # tau solves tau - A(tanh tau) = pi r: the handle's turn integrated by quadrature is 2 pi.
    from scipy import integrate

    I1, I2, I3 = BRODY
    a = (I3 - I2) / (I3 - I1)
    b = I1 / I2 * a

    def rate(t: float) -> float:
        s = 1 / math.cosh(t) ** 2
        return (1 - a * s) / (1 - b * s)

    turn, _ = integrate.quad(rate, -float(single.tau), float(single.tau), epsabs=1e-14)
    assert turn / float(single.ratio) == pytest.approx(2 * math.pi, rel=1e-12)


def test_ideal_racket_twists_perfectly() -> None:
    """I1 -> 0 (a massless handle): the defect vanishes like 4 c3 exp(-pi r)."""
    defects = [float(separatrix_twist((x, 0.9, 1.0)).defect) for x in (1e-1, 1e-2, 1e-3, 1e-4)]
    assert all(a > b for a, b in zip(defects, defects[1:], strict=False))
    assert defects[-1] < 1e-12


def test_bad_moments_are_refused() -> None:
    with pytest.raises(ValueError, match="distinct"):
        separatrix_twist((1.0, 1.0, 2.0))
