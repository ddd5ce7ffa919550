"""Every regime, every axis order, against the high-precision reference.

Both polhode families, the exact separatrix, every permanent rotation (including the pure spin
about the intermediate axis, which must stay exactly a pure spin forever), symmetric oblate and
prolate bodies, the sphere, the body at rest; all 6 orders of the moments; a proper relabelling
of the body axes must give the same physical motion; and the ``Regime`` enum values.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from reference import (
    ATTITUDE_ATOL_GENERIC,
    ATTITUDE_ATOL_SEPARATRIX,
    EPS,
    LONG_TIME_EPS_FACTOR,
    OMEGA_ATOL_SEPARATRIX,
    OMEGA_RTOL_GENERIC,
    ReferenceBody,
    as_matrices,
    geodesic_angle,
)
from scipy.spatial.transform import Rotation

from poinsot.physics import FreeRigidBody, Regime

ROT0 = Rotation.from_rotvec([0.4, -0.9, 1.7])

PERMUTATIONS = list(itertools.permutations(range(3)))


def _check_against_reference(
    inertia, omega0, t, rot0=ROT0, w_tol=OMEGA_RTOL_GENERIC, r_tol=ATTITUDE_ATOL_GENERIC
) -> FreeRigidBody:
    body = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=rot0)
    ref = ReferenceBody(inertia, omega0, rot0)
    w = body.omega(t)
    r = as_matrices(body.attitude(t))
    assert np.all(np.isfinite(w)) and np.all(np.isfinite(r))
    scale = np.linalg.norm(omega0)
    dw = np.max(np.abs(w - ref.omega(t))) / scale
    dr = np.max(geodesic_angle(r, ref.attitude(t)))
    assert dw <= w_tol, f"I={inertia}, w0={omega0}: omega error {dw:.3e}"
    assert dr <= r_tol, f"I={inertia}, w0={omega0}: attitude error {dr:.3e} rad"
    return body


# ---- the enum ------------------------------------------------------------------------------


def test_regime_enum_members() -> None:
    names = {r.name for r in Regime}
    assert names == {
        "MAJOR_AXIS",
        "MINOR_AXIS",
        "SEPARATRIX",
        "SYMMETRIC",
        "SPHERE",
        "PERMANENT_ROTATION",
        "REST",
    }
    assert len({r.value for r in Regime}) == len(Regime)  # no aliases


# ---- the two families and the separatrix in all 6 axis orders -------------------------------

FAMILIES = {
    "major": ((1.0, 2.0, 3.0), (0.2, 0.3, 1.0), Regime.MAJOR_AXIS),
    "minor": ((1.0, 2.0, 3.0), (1.0, 0.3, 0.5), Regime.MINOR_AXIS),
    "separatrix": ((2.0, 3.0, 6.0), (3.0, 0.25, 1.0), Regime.SEPARATRIX),
    "separatrix-other-lobe": ((2.0, 3.0, 6.0), (-3.0, 0.25, 1.0), Regime.SEPARATRIX),
    "oblate": ((1.0, 1.0, 3.0), (0.5, 0.2, 1.0), Regime.SYMMETRIC),
    "prolate": ((1.0, 3.0, 3.0), (1.0, 0.2, 0.5), Regime.SYMMETRIC),
}


@pytest.mark.parametrize("perm", PERMUTATIONS)
@pytest.mark.parametrize("key", list(FAMILIES))
def test_all_orders_against_reference(key: str, perm: tuple[int, ...]) -> None:
    """The moments in any order (a plain permutation of the caller's axes: for odd permutations
    a mirror-image problem, still a valid body) match the reference over 10 periods."""
    inertia, omega0, regime = FAMILIES[key]
    ii = tuple(inertia[k] for k in perm)
    ww = tuple(omega0[k] for k in perm)
    ref = ReferenceBody(ii, ww)
    span = 10 * ref.period_float if np.isfinite(ref.period_float) else 30.0 / ref.lam_float
    t = np.linspace(0.0, span, 23)
    sep = regime is Regime.SEPARATRIX
    body = _check_against_reference(
        ii,
        ww,
        t,
        w_tol=OMEGA_ATOL_SEPARATRIX if sep else OMEGA_RTOL_GENERIC,
        r_tol=ATTITUDE_ATOL_SEPARATRIX if sep else ATTITUDE_ATOL_GENERIC,
    )
    assert body.regime is regime
    if np.isfinite(ref.period_float):
        assert body.period == pytest.approx(ref.period_float, rel=1e-13)
    else:
        assert body.period == np.inf


def _proper_relabellings() -> list[np.ndarray]:
    """All 24 signed permutation matrices with det +1."""
    out = []
    for perm in PERMUTATIONS:
        for signs in itertools.product((1.0, -1.0), repeat=3):
            q = np.zeros((3, 3))
            for row, col in enumerate(perm):
                q[row, col] = signs[row]
            if np.linalg.det(q) > 0:
                out.append(q)
    return out


RELABELLINGS = _proper_relabellings()

RELABEL_CASES = {
    **{k: v[:2] for k, v in FAMILIES.items()},
    "permanent-intermediate": ((1.0, 2.0, 3.0), (0.0, -1.5, 0.0)),
    "near-separatrix": ((1.0, 2.0, 3.5), (0.7, 1e-6, 0.4)),
    "sphere": ((2.0, 2.0, 2.0), (0.3, -0.2, 0.9)),
    "no-triangle": ((1.0, 10.0, 1000.0), (0.2, 1.0, 0.03)),
}


@pytest.mark.parametrize("key", list(RELABEL_CASES))
def test_axis_relabelling_gives_same_physical_motion(key: str) -> None:
    """Describe the same body in relabelled right-handed axes ``x' = Q x`` (det Q = +1):
    ``omega'(t) = Q omega(t)``, ``R'(t) = R(t) Q^T``, the same herpolhode, L, T, D, period,
    precession per period and regime. All 12 proper relabellings."""
    inertia, omega0 = RELABEL_CASES[key]
    base = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=ROT0)
    scale = np.linalg.norm(omega0)
    span = 5 * base.period if np.isfinite(base.period) else 20.0 / scale
    t = np.linspace(0.0, span, 17)
    w = base.omega(t)
    r = as_matrices(base.attitude(t))
    p = base.contact_point(t)
    sep = base.regime is Regime.SEPARATRIX
    w_tol = (OMEGA_ATOL_SEPARATRIX if sep else OMEGA_RTOL_GENERIC) * scale
    r_tol = ATTITUDE_ATOL_SEPARATRIX if sep else ATTITUDE_ATOL_GENERIC
    assert len(RELABELLINGS) == 24
    for q in RELABELLINGS:
        ii = np.abs(q) @ np.asarray(inertia)
        rot0 = ROT0 * Rotation.from_matrix(q.T)
        body = FreeRigidBody(inertia=ii, omega0=q @ np.asarray(omega0), attitude0=rot0)
        assert body.regime is base.regime, q
        dw = np.max(np.abs(body.omega(t) - w @ q.T))
        dr = np.max(geodesic_angle(as_matrices(body.attitude(t)), r @ q.T))
        dp = np.max(np.abs(body.contact_point(t) - p))
        assert dw <= w_tol, f"Q={q.tolist()}: omega differs by {dw:.3e}"
        assert dr <= r_tol, f"Q={q.tolist()}: attitude differs by {dr:.3e} rad"
        assert dp <= w_tol, f"Q={q.tolist()}: herpolhode differs by {dp:.3e}"
        assert np.allclose(body.angular_momentum, base.angular_momentum, rtol=1e-14, atol=0)
        assert body.energy == pytest.approx(base.energy, rel=1e-15)
        assert body.D == pytest.approx(base.D, rel=1e-14)
        assert body.period == pytest.approx(base.period, rel=1e-14)
        assert body.precession_per_period == pytest.approx(base.precession_per_period, rel=1e-13)


# ---- permanent rotations ----------------------------------------------------------------------


@pytest.mark.parametrize("perm", PERMUTATIONS)
@pytest.mark.parametrize("axis", ["minor", "intermediate", "major"])
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_permanent_rotations(perm: tuple[int, ...], axis: str, sign: float) -> None:
    """omega along a principal axis of a triaxial body stays there exactly (also the unstable
    intermediate one), and the attitude is a uniform rotation about that axis."""
    sorted_inertia = (1.0, 2.0, 3.0)
    k_sorted = {"minor": 0, "intermediate": 1, "major": 2}[axis]
    inertia = tuple(sorted_inertia[k] for k in perm)
    k = perm.index(k_sorted)
    omega0 = np.zeros(3)
    omega0[k] = sign * 1.7
    body = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=ROT0)
    assert body.regime is Regime.PERMANENT_ROTATION
    assert body.period == np.inf
    assert body.precession_per_period == 0.0
    t = np.array([0.0, 0.3, 17.0, 1234.5])
    assert np.array_equal(body.omega(t), np.tile(omega0, (4, 1)))
    _check_against_reference(inertia, tuple(omega0), t)


def test_pure_intermediate_spin_stays_pure_forever() -> None:
    """The unstable permanent rotation is an exact solution: at t = 1e6 (3.4e5 turns) omega
    is still exactly (0, w, 0), and the attitude is R0 Rot(e2, w t) to 100 eps w t."""
    inertia = (1.0, 2.0, 3.0)
    w2 = 2.1
    omega0 = (0.0, w2, 0.0)
    body = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=ROT0)
    assert body.regime is Regime.PERMANENT_ROTATION
    t = np.array([1e6, 1e6 + 0.5, 3.3e7])
    w = body.omega(t)
    assert np.array_equal(w, np.tile(omega0, (3, 1))), w
    r = as_matrices(body.attitude(t))
    ref = ReferenceBody(inertia, omega0, ROT0)
    dr = geodesic_angle(r, ref.attitude(t))
    assert np.all(dr <= LONG_TIME_EPS_FACTOR * EPS * w2 * t), dr
    # the contact point stays at the tip of the fixed spin axis
    p = body.contact_point(t)
    assert np.allclose(p, np.tile(ROT0.apply(omega0), (3, 1)), rtol=0, atol=1e-12 * w2)


@pytest.mark.parametrize(
    ("inertia", "omega0"),
    [
        ((1.0, 1.0, 3.0), (0.0, 0.0, 2.0)),  # oblate, spin about the symmetry axis
        ((1.0, 3.0, 3.0), (-2.0, 0.0, 0.0)),  # prolate, spin about the symmetry axis
        ((1.0, 1.0, 3.0), (0.6, -0.8, 0.0)),  # oblate, spin in the degenerate plane
        ((3.0, 1.0, 3.0), (0.6, 0.0, 0.8)),  # prolate, degenerate plane, unsorted
    ],
)
def test_symmetric_body_constant_spin(inertia, omega0) -> None:
    """Spin along any axis of the degenerate eigenspace (or the symmetry axis) is constant."""
    body = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=ROT0)
    assert body.regime in (Regime.PERMANENT_ROTATION, Regime.SYMMETRIC)
    t = np.array([0.0, 1.0, 55.5, 1e4])
    assert np.max(np.abs(body.omega(t) - np.asarray(omega0))) <= 2 * EPS * np.linalg.norm(omega0)
    _check_against_reference(inertia, omega0, t[:3])


# ---- symmetric, sphere, rest ----------------------------------------------------------------


@pytest.mark.parametrize(
    ("inertia", "omega0"),
    [
        ((1.0, 1.0, 3.0), (0.5, 0.2, 1.0)),  # oblate
        ((1.0, 3.0, 3.0), (1.0, 0.2, 0.5)),  # prolate
        ((3.0, 1.0, 1.0), (0.4, -0.6, 0.3)),  # oblate, symmetry axis first
        ((2.0, 0.5, 2.0), (0.1, 0.9, -0.5)),  # prolate, symmetry axis second
        ((1.0, 1.0, 1.9), (1e-3, 0.0, 1.0)),  # oblate, close to the axis
    ],
)
def test_symmetric_bodies(inertia, omega0) -> None:
    body = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=ROT0)
    assert body.regime is Regime.SYMMETRIC
    assert body.parameter == 0.0
    assert body.complementary_parameter == 1.0
    t = np.linspace(0.0, 100 * body.period, 41)
    _check_against_reference(inertia, omega0, t)


@pytest.mark.parametrize("omega0", [(0.3, -0.2, 0.9), (0.0, 0.0, 5.0), (1e-3, 2.0, -4.0)])
def test_sphere(omega0) -> None:
    inertia = (2.5, 2.5, 2.5)
    body = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=ROT0)
    assert body.regime is Regime.SPHERE
    assert body.period == np.inf
    assert body.precession_per_period == 0.0
    assert body.second_period == np.inf
    t = np.array([0.0, 0.7, 31.0, 4e3])
    assert np.array_equal(body.omega(t), np.tile(omega0, (4, 1)))
    # within 100 turns: the generic bound; beyond, the double-precision phase floor
    turns = t * np.linalg.norm(omega0) / (2 * np.pi)
    _check_against_reference(inertia, omega0, t[turns <= 100])
    ref = ReferenceBody(inertia, omega0, ROT0)
    dr = geodesic_angle(as_matrices(body.attitude(t)), ref.attitude(t))
    assert np.all(dr <= LONG_TIME_EPS_FACTOR * EPS * np.linalg.norm(omega0) * t + 1e-15), dr


def test_body_at_rest() -> None:
    body = FreeRigidBody(inertia=(1.0, 2.0, 3.0), omega0=(0.0, 0.0, 0.0), attitude0=ROT0)
    assert body.regime is Regime.REST
    t = np.array([0.0, 1.0, 1e9])
    assert np.array_equal(body.omega(t), np.zeros((3, 3)))
    assert np.all(geodesic_angle(as_matrices(body.attitude(t)), as_matrices(ROT0)) <= 4 * EPS)
    assert np.array_equal(body.contact_point(t), np.zeros((3, 3)))
    assert body.energy == 0.0
    assert body.D == 0.0
    assert body.plane_distance == 0.0
    assert np.array_equal(body.plane_normal, [0.0, 0.0, 1.0])
    assert np.array_equal(body.angular_momentum, [0.0, 0.0, 0.0])
    assert body.period == np.inf
    assert body.precession_per_period == 0.0
    assert body.second_period == np.inf
    assert np.array_equal(body.semi_axes, [0.0, 0.0, 0.0])
    poly = body.polhode(16)
    assert poly.shape == (16, 3) and np.array_equal(poly, np.zeros((16, 3)))


@pytest.mark.parametrize(
    ("inertia", "omega0", "regime"),
    [
        ((1.0, 2.0, 3.0), (0.2, 0.3, 1.0), Regime.MAJOR_AXIS),
        ((1.0, 2.0, 3.0), (1.0, 0.3, 0.5), Regime.MINOR_AXIS),
        ((3.0, 2.0, 1.0), (1.0, 0.3, 0.5), Regime.MAJOR_AXIS),  # sorted the other way
        ((2.0, 3.0, 6.0), (3.0, 0.25, 1.0), Regime.SEPARATRIX),
        ((2.0, 3.0, 6.0), (3.0, 0.25, 1.0 + 2**-52), Regime.MAJOR_AXIS),  # one ulp above
        ((2.0, 3.0, 6.0), (3.0, 0.25, 1.0 - 2**-53), Regime.MINOR_AXIS),  # one ulp below
        ((1.0, 1.0, 3.0), (0.5, 0.2, 1.0), Regime.SYMMETRIC),
        ((2.0, 2.0, 2.0), (0.5, 0.2, 1.0), Regime.SPHERE),
        ((1.0, 2.0, 3.0), (0.0, 0.0, 1.0), Regime.PERMANENT_ROTATION),
        ((1.0, 2.0, 3.0), (0.0, 0.0, 0.0), Regime.REST),
        ((1.0, 1.0 + 2**-52, 2.0), (0.05, 0.03, 1.0), Regime.MAJOR_AXIS),  # m ~ 1e-18
    ],
)
def test_regime_classification(inertia, omega0, regime) -> None:
    assert FreeRigidBody(inertia=inertia, omega0=omega0).regime is regime


@pytest.mark.parametrize(
    ("inertia", "omega0"),
    [
        ((2.0, 3.0, 6.0), (3.0, 0.25, 1.0 + 2**-52)),
        ((2.0, 3.0, 6.0), (3.0, 0.25, 1.0 - 2**-53)),
    ],
)
def test_one_ulp_off_the_separatrix(inertia, omega0) -> None:
    """One ulp from the exact separatrix: 1 - m ~ 1e-16; omega still 1e-12 over two flips."""
    ref = ReferenceBody(inertia, omega0, ROT0)
    t = np.linspace(0.0, 1.2 * ref.period_float, 31)
    _check_against_reference(
        inertia, omega0, t, w_tol=OMEGA_ATOL_SEPARATRIX, r_tol=ATTITUDE_ATOL_SEPARATRIX
    )
