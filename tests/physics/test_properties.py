"""Property tests (hypothesis) over random bodies, random initial spins and attitudes.

Moments log-uniform over six decades (so many break the triangle inequality), with equal
moments mixed in (symmetric bodies, spheres); omega0 with random magnitude, sometimes with
zero components (permanent rotations, the exact separatrix of exact inputs); random attitude0.
For each example, at random times:

* energy and |L| conserved; ``L = R(t) I omega(t)`` fixed in space (1e-12 relative);
* ``R(t)`` is a proper rotation; ``omega(0) == omega0``; ``attitude(0) == attitude0``;
* ``dR/dt = R [omega]x`` (4th-order finite differences);
* the contact point ``R omega`` lies on the invariable plane ``x.L = 2T`` and the ellipsoid's
  normal there (``R I omega`` in space) is parallel to L; ``contact_point == R omega``;
* ``plane_normal``, ``plane_distance`` and ``D`` agree with their definitions; no NaN.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from reference import (
    ATTITUDE_ATOL_GENERIC,
    EPS,
    GEOMETRY_RTOL,
    INVARIANT_RTOL,
    ROTATION_ORTHO_ATOL,
    as_matrices,
    geodesic_angle,
    hat,
)
from scipy.spatial.transform import Rotation

from poinsot.physics import FreeRigidBody, Regime

FD_STEP = 0.05
"""Finite-difference step for ``dR/dt``, in units of the fastest time scale ``1/rate``."""


def fd_tolerance(rate_ratio: float) -> float:
    """Allowed ``|dR/dt - R [w]x| / |w|`` for the 6th-order central difference of step
    ``h = FD_STEP / rate``.

    Truncation: for a component ``exp(i nu t)`` the stencil errs by ``(nu h)^6 / 140``
    relative; the attitude mixes the precession and the body rates, so ``nu`` reaches ``2 rate``:
    ``(2 FD_STEP)^6 / 140``, times 3 for safety. Rounding: the attitude may carry its allowed
    error ``ATTITUDE_ATOL_GENERIC`` as noise from one time to the next, amplified by the stencil
    (``sum |c_k| / h ~ 1.9 / h``) and taken relative to ``|w|``:
    ``2 * ATTITUDE_ATOL_GENERIC * (rate / |w|) / FD_STEP``. A wrong sign, frame (``[w]x R``)
    or factor in omega gives O(1).
    """
    return 3 * (2 * FD_STEP) ** 6 / 140 + 2 * ATTITUDE_ATOL_GENERIC * rate_ratio / FD_STEP


SETTINGS = settings(max_examples=400, deadline=None, derandomize=True)

#: 400 examples a test: seconds each, so not in ``make test-fast``'s inner loop.
pytestmark = pytest.mark.slow


@st.composite
def bodies(draw: st.DrawFn) -> tuple[np.ndarray, np.ndarray, Rotation]:
    logs = draw(st.lists(st.floats(-3.0, 3.0), min_size=3, max_size=3))
    inertia = [10.0**x for x in logs]
    pattern = draw(st.sampled_from(["none"] * 6 + ["12", "23", "13", "all"]))
    if pattern == "12":
        inertia[1] = inertia[0]
    elif pattern == "23":
        inertia[2] = inertia[1]
    elif pattern == "13":
        inertia[2] = inertia[0]
    elif pattern == "all":
        inertia = [inertia[0]] * 3
    scale = 10.0 ** draw(st.floats(-3.0, 3.0))
    # components spanning six decades (extreme magnitudes are test_scaling.py's job)
    mags = draw(st.lists(st.floats(-6.0, 0.0), min_size=3, max_size=3))
    signs = draw(st.lists(st.sampled_from([-1.0, 1.0]), min_size=3, max_size=3))
    zero = draw(st.sampled_from([None] * 8 + [0, 1, 2, (0, 1), (1, 2), (0, 2)]))
    omega0 = np.array(signs) * 10.0 ** np.array(mags) * scale
    if zero is not None:
        omega0[np.array(zero)] = 0.0
    q = draw(st.lists(st.floats(-1.0, 1.0), min_size=4, max_size=4))
    if np.linalg.norm(q) < 1e-3:
        q = [0.0, 0.0, 0.0, 1.0]
    return np.array(inertia), omega0, Rotation.from_quat(q)


def _rate(body: FreeRigidBody) -> float:
    """The fastest rate of the motion [1/time]: |omega|, |omega'|/|omega| from Euler, lambda
    and the precession rate; the attitude's higher derivatives scale with it."""
    w = body.omega0
    i1, i2, i3 = body.inertia
    dw = np.array(
        [(i2 - i3) * w[1] * w[2] / i1, (i3 - i1) * w[2] * w[0] / i2, (i1 - i2) * w[0] * w[1] / i3]
    )
    nw = _norm(w)
    # the precession rate phi' [LL76 §37, Eq. 37.16] is a weighted mean of G/I_i: at most G/min(I)
    precession = _norm(body.inertia * w) / float(np.min(body.inertia))
    return max(nw, _norm(dw) / nw, body.frequency, precession)


def _norm(x: np.ndarray) -> float:
    """Euclidean norm without underflow for tiny vectors."""
    s = float(np.max(np.abs(x)))
    return s * float(np.linalg.norm(x / s)) if s > 0 else 0.0


def _times(body: FreeRigidBody, taus: list[float]) -> np.ndarray:
    """Times in units of the motion's own time scale ``1/max(|omega|, lambda)``."""
    return np.array(taus) / max(_norm(body.omega0), body.frequency)


TAUS = st.lists(st.floats(0.0, 300.0), min_size=3, max_size=6)


@SETTINGS
@given(bodies(), TAUS)
@example(
    (np.array([1.0, 10.0, 1000.0]), np.array([0.2, 1.0, 0.03]), Rotation.identity()),
    [0.0, 1.0, 250.0],
)
@example(
    (np.array([2.0, 3.0, 6.0]), np.array([3.0, 0.25, 1.0]), Rotation.from_rotvec([1, 2, 3])),
    [0.5, 30.0, 299.0],
)
def test_invariants(case, taus) -> None:
    inertia, omega0, rot0 = case
    body = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=rot0)
    if np.all(omega0 == 0):
        assert body.regime is Regime.REST
        return
    t = _times(body, taus)
    w = body.omega(t)
    r = as_matrices(body.attitude(t))
    assert np.all(np.isfinite(w)) and np.all(np.isfinite(r))
    m = inertia * w
    energy = 0.5 * np.einsum("ij,ij->i", w, m)
    g = float(np.linalg.norm(inertia * omega0))
    assert np.all(np.abs(energy - body.energy) <= INVARIANT_RTOL * body.energy), energy
    assert np.all(np.abs(np.linalg.norm(m, axis=1) - g) <= INVARIANT_RTOL * g)
    L = np.einsum("nij,nj->ni", r, m)
    assert np.all(np.abs(L - body.angular_momentum) <= INVARIANT_RTOL * g), (
        np.max(np.abs(L - body.angular_momentum)) / g
    )
    # proper rotation
    rtr = np.einsum("nji,njk->nik", r, r)
    assert np.max(np.abs(rtr - np.eye(3))) <= ROTATION_ORTHO_ATOL
    assert np.max(np.abs(np.linalg.det(r) - 1.0)) <= ROTATION_ORTHO_ATOL


@SETTINGS
@given(bodies())
def test_initial_state(case) -> None:
    inertia, omega0, rot0 = case
    body = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=rot0)
    assert np.array_equal(body.omega(0.0), omega0)
    assert np.array_equal(body.omega(np.array([0.0]))[0], omega0)
    assert geodesic_angle(as_matrices(body.attitude(0.0)), as_matrices(rot0)) <= 4 * EPS
    assert np.array_equal(body.inertia, inertia)
    assert np.array_equal(body.omega0, omega0)
    m0 = inertia * omega0
    assert np.allclose(
        body.angular_momentum, rot0.apply(m0), rtol=0, atol=4 * EPS * np.linalg.norm(m0)
    )
    assert (
        body.energy == 0.5 * float(omega0 @ m0)
        or abs(body.energy - 0.5 * float(omega0 @ m0)) <= 4 * EPS * body.energy
    )


@SETTINGS
@given(bodies(), TAUS)
def test_no_attitude_is_the_identity_bit_for_bit(case, taus) -> None:
    """``attitude0=None`` takes a shortcut (no scipy call for the identity); a Rotation that
    is the identity, made by the caller, takes the general path: the same bits everywhere."""
    inertia, omega0, _ = case
    short = FreeRigidBody(inertia=inertia, omega0=omega0)
    general = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=Rotation.identity())
    t = _times(short, taus) if np.any(omega0 != 0) else np.array(taus)
    for name in ("omega", "contact_point"):
        assert np.array_equal(getattr(short, name)(t), getattr(general, name)(t)), name
        assert np.array_equal(getattr(short, name)(t[-1]), getattr(general, name)(t[-1])), name
    assert np.array_equal(short.attitude(t).as_quat(), general.attitude(t).as_quat())
    for name in ("angular_momentum", "plane_normal", "semi_axes"):
        assert np.array_equal(getattr(short, name), getattr(general, name)), name
    assert (short.D, short.energy) == (general.D, general.energy)


@SETTINGS
@given(bodies(), TAUS)
def test_kinematics_finite_differences(case, taus) -> None:
    """dR/dt = R [omega]x (body-frame angular velocity), by a 4th-order central difference."""
    inertia, omega0, rot0 = case
    if np.all(omega0 == 0):
        return
    body = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=rot0)
    rate = _rate(body)
    nw = _norm(omega0)
    h = FD_STEP / rate
    t = _times(body, taus) + 4 * h
    stencil = np.array([-3.0, -2.0, -1.0, 1.0, 2.0, 3.0])
    coef = np.array([-1.0, 9.0, -45.0, 45.0, -9.0, 1.0]) / 60.0
    tt = (t[:, None] + h * stencil[None, :]).ravel()
    rr = as_matrices(body.attitude(tt)).reshape(t.size, 6, 3, 3)
    dr = np.einsum("k,nkij->nij", coef, rr) / h
    r = as_matrices(body.attitude(t))
    w = body.omega(t)
    expected = np.einsum("nij,njk->nik", r, np.array([hat(x) for x in w]))
    err = np.max(np.abs(dr - expected)) / nw
    assert err <= fd_tolerance(rate / nw), (err, fd_tolerance(rate / nw))


@SETTINGS
@given(bodies(), TAUS)
def test_poinsot_geometry(case, taus) -> None:
    """The contact point is on the invariable plane and the ellipsoid is tangent there."""
    inertia, omega0, rot0 = case
    if np.all(omega0 == 0):
        return
    body = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=rot0)
    t = _times(body, taus)
    L = body.angular_momentum
    g = float(np.linalg.norm(L))
    two_t = 2.0 * body.energy
    n_hat = body.plane_normal
    assert np.allclose(n_hat, L / g, rtol=0, atol=4 * EPS)
    assert abs(body.plane_distance - two_t / g) <= GEOMETRY_RTOL * two_t / g
    assert abs(body.D - g * g / two_t) <= GEOMETRY_RTOL * body.D
    lo, hi = inertia.min(), inertia.max()
    assert lo * (1 - GEOMETRY_RTOL) <= body.D <= hi * (1 + GEOMETRY_RTOL)
    p = body.contact_point(t)
    r = as_matrices(body.attitude(t))
    w = body.omega(t)
    rw = np.einsum("nij,nj->ni", r, w)
    assert np.max(np.abs(p - rw)) <= GEOMETRY_RTOL * np.linalg.norm(omega0)
    # on the plane x.L = 2T  (|p| |L| is the scale of p.L)
    pl = p @ L
    assert np.all(np.abs(pl - two_t) <= GEOMETRY_RTOL * np.linalg.norm(p, axis=1) * g)
    # distance of the plane from the fixed point along its normal
    assert np.all(
        np.abs(p @ n_hat - body.plane_distance) <= GEOMETRY_RTOL * np.linalg.norm(p, axis=1)
    )
    # the ellipsoid x.I.x = 2T has normal ~ I x at x = omega: in space R I omega, parallel to L
    normal = np.einsum("nij,nj->ni", r, inertia * w)
    cross = np.cross(normal, L)
    assert np.all(np.linalg.norm(cross, axis=1) <= GEOMETRY_RTOL * g * g)
    assert np.all(normal @ L > 0)
    # the tip of omega is on the energy ellipsoid whose semi-axes are reported
    semi = body.semi_axes
    assert np.allclose(semi, np.sqrt(two_t / inertia), rtol=4 * EPS, atol=0)
    assert np.all(np.abs(np.sum((w / semi) ** 2, axis=1) - 1) <= GEOMETRY_RTOL)


@SETTINGS
@given(bodies())
def test_no_nan_anywhere(case) -> None:
    inertia, omega0, rot0 = case
    body = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=rot0)
    scalars = [
        body.energy,
        body.D,
        body.plane_distance,
        body.parameter,
        body.complementary_parameter,
        body.frequency,
        body.precession_per_period,
    ]
    assert all(np.isfinite(x) for x in scalars), scalars
    for x in (body.period, body.second_period):
        assert not np.isnan(x) and x > 0
    assert 0.0 <= body.parameter <= 1.0 and 0.0 <= body.complementary_parameter <= 1.0
    for arr in (body.angular_momentum, body.plane_normal, body.semi_axes, body.polhode(32)):
        assert np.all(np.isfinite(arr))
    t = np.array([0.0, 1.0, 1e3, 1e8]) / max(np.linalg.norm(omega0), 1e-300)
    assert np.all(np.isfinite(body.omega(t)))
    assert np.all(np.isfinite(body.contact_point(t)))
    assert np.all(np.isfinite(body.attitude(t).as_quat()))
