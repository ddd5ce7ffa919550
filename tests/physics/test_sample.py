"""``FreeRigidBody.sample``: ω, R and the contact point from one evaluation."""

import numpy as np
import pytest

from poinsot.physics import FreeRigidBody

CASES = [
    ((1.0, 2.0, 3.0), (1.0, 0.1, 0.5)),  # minor family, sine-series path for long arrays
    ((3.0, 1.0, 2.0), (0.2, 0.3, 1.0)),
    ((2.0, 3.0, 6.0), (3.0, 0.25, 1.0)),  # exact separatrix
    ((1.0, 1.0, 2.0), (1.0, 0.1, 0.5)),  # symmetric
    ((1.0, 2.0, 3.0), (0.0, 1.3, 0.0)),  # permanent rotation
]


@pytest.mark.parametrize(("inertia", "omega0"), CASES)
@pytest.mark.parametrize("n", [1, 7, 300, 20000])
def test_sample_matches_the_separate_calls(inertia, omega0, n):
    body = FreeRigidBody(inertia, omega0)
    t = np.linspace(-3.0, 40.0, n)
    w, rot, contact = body.sample(t)
    assert np.array_equal(w, body.omega(t))
    assert (rot * body.attitude(t).inv()).magnitude().max() < 1e-14
    assert np.allclose(contact, rot.apply(w), rtol=0, atol=1e-14 * np.linalg.norm(omega0))
    assert np.allclose(contact @ body.plane_normal, body.plane_distance, rtol=1e-13)


def test_sample_scalar_shapes():
    body = FreeRigidBody((1.0, 2.0, 3.0), (1.0, 0.1, 0.5))
    w, rot, contact = body.sample(2.5)
    assert w.shape == (3,) and contact.shape == (3,) and rot.single
