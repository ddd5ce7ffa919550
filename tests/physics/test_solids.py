"""Real bodies: the triangle inequality and the box with given principal moments."""

import numpy as np
import pytest

from poinsot.physics import FreeRigidBody, box_dimensions, check_real_body


def _box_moments(sides, mass):
    """Principal moments of a homogeneous box, from its definition (independent of the code)."""
    a1, a2, a3 = sides
    return mass / 12.0 * np.array([a2**2 + a3**2, a3**2 + a1**2, a1**2 + a2**2])


@pytest.mark.parametrize(
    "sides", [(1.0, 2.0, 3.0), (0.1, 5.0, 0.3), (2.0, 2.0, 2.0), (1.0, 1.0, 0.0)]
)
@pytest.mark.parametrize("mass", [1.0, 0.25, 40.0])
def test_box_dimensions_round_trip(sides, mass):
    inertia = _box_moments(sides, mass)
    assert np.allclose(box_dimensions(inertia, mass), sides, rtol=1e-12, atol=1e-7)


def test_box_dimensions_keep_the_callers_axis_order():
    inertia = _box_moments((3.0, 1.0, 2.0), 1.0)
    assert np.allclose(box_dimensions(inertia), (3.0, 1.0, 2.0))


@pytest.mark.parametrize("inertia", [(1.0, 10.0, 1000.0), (5.0, 1.0, 1.0), (1.0, 3.0, 1.0)])
def test_moments_no_real_body_has_are_refused_with_the_axis_named(inertia):
    with pytest.raises(ValueError, match=r"no real body.*I\d") as info:
        check_real_body(inertia)
    assert "sum of the" in str(info.value)
    with pytest.raises(ValueError):
        box_dimensions(inertia)
    # ... while the mathematics still accepts them
    assert np.all(np.isfinite(FreeRigidBody(inertia, (0.3, 0.2, 1.0)).omega([0.0, 1.0])))


def test_a_flat_plate_is_a_real_body_even_with_rounding():
    a, b = 0.1, 0.7  # I3 = I1 + I2 for a lamina in the 1-2 plane; rounding may exceed by an ulp
    inertia = _box_moments((a, b, 0.0), 1.0)
    check_real_body(inertia)
    assert box_dimensions(inertia)[2] == pytest.approx(0.0, abs=1e-6)


@pytest.mark.parametrize("mass", [0.0, -1.0, np.nan, np.inf])
def test_bad_mass(mass):
    with pytest.raises(ValueError, match="mass"):
        box_dimensions((1.0, 1.0, 1.0), mass)


def test_bad_moments_get_the_usual_message():
    with pytest.raises(ValueError, match="positive"):
        check_real_body((1.0, 0.0, 1.0))
