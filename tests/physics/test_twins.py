"""The lag between the first flips of twins, against independent references.

* DOP853 integrations of Euler's equations from both starts give the same lag (ε = 1e-2 and
  1e-3, where an integrator is still accurate).
* 50-digit mpmath K(m)/λ of each start gives the same first flips down to ε = 1e-12.
* The whole array of angles at once equals the one-start theory (flip_theory) angle by angle.
* The lag tends to ln(ε/ε′)/σ: ten times closer is ln(10)/σ later, whatever ε.
* The lag measured from the two exact motions (zeros of ω2) equals the theory.
"""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest

from poinsot.physics import FreeRigidBody
from poinsot.physics.models.flip import flip_initial_omega, flip_theory, integrated_flip_times
from poinsot.physics.models.twins import (
    first_flip_times,
    growth_rate,
    lag_limit,
    measured_lag,
    neighbour_start,
    twin_clock,
)

BODIES = ((1.0, 2.0, 3.0), (0.3, 0.55, 0.9), (2.0, 2.1, 7.0))
DOP853_RTOL = 1e-8
"""DOP853 at rtol 1e-12 keeps the flip times to ~1e-10 relative at these ε (measured ~3e-11)."""
MPMATH_RTOL = 1e-13
"""scipy's ellipkm1 and the one-sign sums against 50 digits: a few roundings (measured ~4e-16)."""


@pytest.mark.parametrize("inertia", BODIES)
@pytest.mark.parametrize(("eps", "eps2"), [(1e-2, 1e-3), (1e-3, 1e-4)])
def test_lag_against_dop853(inertia: tuple[float, float, float], eps: float, eps2: float) -> None:
    clock = twin_clock(inertia, eps, eps2, spin=2.0)
    t_end = 1.1 * clock.second_flip
    first = integrated_flip_times(inertia, flip_initial_omega(eps, 2.0), t_end)[0]
    second = integrated_flip_times(inertia, flip_initial_omega(eps2, 2.0), t_end)[0]
    assert clock.first_flip == pytest.approx(first, rel=DOP853_RTOL)
    assert clock.lag == pytest.approx(second - first, rel=DOP853_RTOL)


def _mp_first_flip(inertia: tuple[float, float, float], w: np.ndarray) -> mp.mpf:
    """K(m)/λ at 50 digits from the exact rationals of the float data."""
    with mp.workdps(50):
        I1, I2, I3 = (mp.mpf(x) for x in inertia)
        w1, w2 = mp.mpf(float(w[0])), mp.mpf(float(w[1]))
        minus_d3 = I1 * (I3 - I1) * w1**2 + I2 * (I3 - I2) * w2**2
        lam = mp.sqrt((I2 - I1) * minus_d3 / (I1 * I2 * I3))
        m = 1 - I1 * (I3 - I1) * w1**2 / minus_d3
        return mp.ellipk(m) / lam


@pytest.mark.parametrize("inertia", BODIES)
def test_first_flips_against_mpmath(inertia: tuple[float, float, float]) -> None:
    eps = 10.0 ** -np.arange(1, 13)
    got = first_flip_times(inertia, eps, spin=2.0)
    for e, t in zip(eps, got, strict=True):
        want = float(_mp_first_flip(inertia, flip_initial_omega(float(e), 2.0)))
        assert t == pytest.approx(want, rel=MPMATH_RTOL)


def test_array_equals_one_start_theory() -> None:
    eps = np.geomspace(0.5, 1e-12, 40)
    got = first_flip_times((1.0, 2.0, 3.0), eps, spin=0.7)
    want = [flip_theory((1.0, 2.0, 3.0), flip_initial_omega(e, 0.7)).first_flip_time for e in eps]
    np.testing.assert_allclose(got, want, rtol=1e-13)
    assert got.shape == (40,)


def test_lag_tends_to_its_limit() -> None:
    inertia = (1.0, 2.0, 3.0)
    sigma = growth_rate(inertia, 2.0)
    assert sigma == pytest.approx(2.0 * math.sqrt(1.0 * 1.0 / 3.0))
    gaps = []
    for eps in (1e-2, 1e-4, 1e-6, 1e-8):
        clock = twin_clock(inertia, eps, eps / 10.0, spin=2.0)
        assert clock.limit == pytest.approx(math.log(10.0) / sigma)
        gaps.append(abs(clock.lag / clock.limit - 1.0))
    # O(ε²) (the correction of λ and of K's logarithm): 100 times smaller per factor 10 in ε
    assert gaps[0] > 1e-5 and gaps[1] < 1e-7 and gaps[2] < 1e-11
    # vectorised limit, broadcast
    np.testing.assert_allclose(
        lag_limit(inertia, 1e-3, [1e-4, 1e-5]), np.log([10.0, 100.0]) / growth_rate(inertia)
    )


def test_lag_measured_from_two_motions() -> None:
    inertia = (0.3, 0.55, 0.9)
    clock = twin_clock(inertia, 1e-6, 1e-7, spin=2.0)
    bodies = [FreeRigidBody(inertia, flip_initial_omega(e, 2.0)) for e in (1e-6, 1e-7)]
    assert measured_lag(*bodies, 1.1 * clock.second_flip) == pytest.approx(clock.lag, rel=1e-10)
    assert math.isnan(measured_lag(*bodies, 0.5 * clock.first_flip))


@pytest.mark.parametrize("bad", [0.0, -1e-3, 2.0, math.nan, "x"])
def test_bad_angles_refused(bad: object) -> None:
    with pytest.raises(ValueError, match="angle"):
        twin_clock((1.0, 2.0, 3.0), 1e-3, bad)  # type: ignore[arg-type]


@pytest.mark.parametrize("angle", [1e-8, 1e-3, 0.3])
def test_a_neighbour_starts_at_the_angle_with_the_same_spin(angle: float) -> None:
    for w in ([0.0, 2.0, 0.0], [0.3, -1.2, 0.7], [1e-9, 0.0, 3.0]):
        w0 = np.asarray(w)
        w1 = neighbour_start(w0, angle)
        assert np.linalg.norm(w1) == pytest.approx(np.linalg.norm(w0), rel=1e-15)
        # the angle from atan2(|a × b|, a·b): accurate for tiny angles too
        between = math.atan2(np.linalg.norm(np.cross(w0, w1)), float(w0 @ w1))
        assert between == pytest.approx(angle, rel=1e-9)
    with pytest.raises(ValueError, match="rest"):
        neighbour_start([0.0, 0.0, 0.0], 1e-3)
