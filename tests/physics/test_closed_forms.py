"""Every closed form keeps the one interface (``physics.core.closed_forms.ClosedForm``).

For each form -- triaxial (both families), separatrix, and the uniform one (symmetric body,
sphere, permanent rotation, rest) -- and on the same dimensionless times:

* ``omega`` and the ω part of ``quat`` are the same numbers;
* the scalar twins ``omega_scalar``/``quat_scalar`` agree with the array forms (to the last bit
  in practice, ``SCALAR_RTOL`` allowed as in ``test_scalar.py``);
* the attitude is a unit quaternion and carries the body momentum to one fixed vector in the
  form's space frame (L is conserved);
* :class:`FreeRigidBody` is that form mapped to the caller's axes, units and attitude:
  ``ω_user = C⁻¹ ω_int · ω_ref`` and ``R_user(t) = R(0) C⁻¹ R_int(0)⁻¹ R_int(τ) C``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from poinsot.physics import FreeRigidBody, Regime
from poinsot.physics.core.closed_forms import ClosedForm
from poinsot.physics.core.closed_forms.separatrix import Separatrix
from poinsot.physics.core.closed_forms.triaxial import Triaxial
from poinsot.physics.core.closed_forms.uniform import Uniform
from poinsot.physics.core.rotations import multiply, rotate

EPS = float(np.finfo(float).eps)

SCALAR_RTOL = 4e-16
"""Scalar twin against the array form, relative to the amplitude (ω) or to 1 (quaternions):
two ulps, as in ``test_scalar.py`` (same operations in the same order)."""

UNIT_ATOL = 8 * EPS
"""``|q| = 1``: the Z-X-Z and axis-angle quaternions are products of sines and cosines."""

MOMENTUM_RTOL = 1e-13
"""The body momentum carried to the form's space frame stays one vector, relative to G: a few
roundings of ω (closed form), of m = J ω and of the rotation, growing mildly with the phase."""

MATCH_RTOL = 1e-14
"""FreeRigidBody against its own form mapped by hand: the anchor ω0 - f(0) (O(eps) of the
amplitude) and one or two extra quaternion roundings."""

ROT0 = Rotation.from_rotvec([0.3, -1.1, 0.7])

CASES = {
    "major": ((1.0, 2.0, 3.0), (0.2, 0.3, 1.0), Regime.MAJOR_AXIS, Triaxial),
    "minor": ((1.0, 2.0, 3.0), (1.0, 0.3, 0.5), Regime.MINOR_AXIS, Triaxial),
    "minor, unsorted": ((13.0, 10.0, 5.0), (0.3, 0.6, 0.9), Regime.MINOR_AXIS, Triaxial),
    "near separatrix": ((2.0, 3.0, 6.0), (3.0, 0.25, 1.0 + 2e-11), Regime.MAJOR_AXIS, Triaxial),
    "separatrix": ((2.0, 3.0, 6.0), (3.0, 0.25, 1.0), Regime.SEPARATRIX, Separatrix),
    "separatrix, unsorted": ((6.0, 2.0, 3.0), (-1.0, 3.0, 0.25), Regime.SEPARATRIX, Separatrix),
    "oblate": ((1.0, 1.0, 3.0), (0.5, 0.2, 1.0), Regime.SYMMETRIC, Uniform),
    "prolate": ((3.0, 1.0, 3.0), (1.0, 0.2, -0.5), Regime.SYMMETRIC, Uniform),
    "sphere": ((2.0, 2.0, 2.0), (0.3, -0.2, 0.7), Regime.SPHERE, Uniform),
    "permanent about I2": ((1.0, 2.0, 3.0), (0.0, 1.3, 0.0), Regime.PERMANENT_ROTATION, Uniform),
    "permanent, symmetric": ((1.0, 1.0, 3.0), (0.0, 0.0, 2.0), Regime.PERMANENT_ROTATION, Uniform),
    "rest": ((1.0, 2.0, 3.0), (0.0, 0.0, 0.0), Regime.REST, Uniform),
}

TAUS = np.array([0.0, 1e-9, 0.37, -1.3, 4.2, 17.0, -250.0, 3.3e3, 1e6])


def _body(key: str) -> FreeRigidBody:
    inertia, omega0, regime, kind = CASES[key]
    body = FreeRigidBody(inertia, omega0, attitude0=ROT0)
    assert body.regime is regime
    assert isinstance(body._form, kind)
    return body


def _internal_moments(body: FreeRigidBody) -> np.ndarray:
    """The moments in the form's body axes (any common scale)."""
    return np.abs(body._eval.frame.matrix) @ body.inertia


@pytest.mark.parametrize("key", list(CASES))
def test_the_form_keeps_the_protocol(key: str) -> None:
    form = _body(key)._form
    assert isinstance(form, ClosedForm)
    assert 0.0 <= form.parameter <= 1.0
    assert form.parameter + form.complementary_parameter == pytest.approx(1.0, abs=EPS)
    assert all(math.isfinite(x) for x in form.rates)
    assert form.lam >= 0.0 and math.isfinite(form.nu)
    num, rate = form.period_pair
    assert rate >= 0.0 and (rate == 0.0 or num > 0.0)


@pytest.mark.parametrize("key", list(CASES))
def test_omega_and_quat_agree_with_their_scalar_twins(key: str) -> None:
    form = _body(key)._form
    cols = form.omega(TAUS)
    q_cols, q = form.quat(TAUS)
    for k in range(3):
        np.testing.assert_array_equal(cols[k], q_cols[k])
    scale = max(form.amplitude, float(np.max(np.abs(cols))))
    for i, tau in enumerate(TAUS.tolist()):
        w_s = form.omega_scalar(tau)
        qw_s, q_s = form.quat_scalar(tau)
        assert len(w_s) == 3 and len(q_s) == 4
        assert all(isinstance(x, float) for x in (*w_s, *q_s))
        assert w_s == qw_s
        for k in range(3):
            assert abs(w_s[k] - cols[k][i]) <= SCALAR_RTOL * scale, (tau, k)
        for k in range(4):
            assert abs(q_s[k] - q[k][i]) <= SCALAR_RTOL, (tau, k)


@pytest.mark.parametrize("key", list(CASES))
def test_the_attitude_carries_the_momentum_to_one_vector(key: str) -> None:
    body = _body(key)
    form = body._form
    cols, q = form.quat(TAUS)
    quats = np.stack(q, axis=-1)
    assert np.all(np.abs(np.linalg.norm(quats, axis=-1) - 1.0) <= UNIT_ATOL)
    m = _internal_moments(body) * np.stack(cols, axis=-1)
    L = rotate(quats, m)
    G = float(np.linalg.norm(L[0]))
    assert np.all(np.abs(L - L[0]) <= MOMENTUM_RTOL * max(G, EPS))
    if isinstance(form, Triaxial | Separatrix):  # the Z-X-Z frame: L along +z
        np.testing.assert_allclose(L[0], [0.0, 0.0, G], atol=MOMENTUM_RTOL * G)


@pytest.mark.parametrize("key", list(CASES))
def test_free_rigid_body_is_the_form_in_the_callers_frame(key: str) -> None:
    body = _body(key)
    form, frame, w_ref = body._form, body._eval.frame, body._w_ref
    t = TAUS / w_ref
    w, attitude = body.state(t)
    cols, q = form.quat(TAUS)
    expected_w = frame.to_user_columns(cols) * w_ref
    scale = max(float(np.max(np.abs(body.omega0))), form.amplitude * w_ref)
    assert np.all(np.abs(w - expected_w) <= MATCH_RTOL * scale)
    # R_user(t) = R(0) C⁻¹ R_int(0)⁻¹ R_int(τ) C, C the caller -> internal relabelling.
    q_int = np.stack(q, axis=-1)
    inv = np.array([-1.0, -1.0, -1.0, 1.0])
    start = multiply(ROT0.as_quat(), multiply(frame.quat * inv, q_int[0] * inv))
    expected = Rotation.from_quat(multiply(start, multiply(q_int, frame.quat)))
    assert np.all((attitude * expected.inv()).magnitude() <= MATCH_RTOL)
    # one float time takes the scalar twins: the same values
    w1, r1 = body.state(float(t[4]))
    assert np.all(np.abs(w1 - w[4]) <= SCALAR_RTOL * scale)
    assert (r1 * attitude[4].inv()).magnitude() <= 2 * SCALAR_RTOL
