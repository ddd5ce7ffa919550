"""Extreme scales: omega0 times 1e-200 and 1e150, moments times 1e-100 and 1e100.

Physics: scaling omega0 by c scales time by 1/c, ``omega_c(t) = c omega(c t)``, with the same
attitude path ``R_c(t) = R(c t)``; scaling the moments changes nothing in omega(t) or R(t)
(only T, L, D and the plane scale). The implementation must stay finite (no overflow of
``G^2 ~ I^2 w^2`` nor underflow of ``2T``) and obey these laws.

With ``c`` a power of two the scaled inputs are exact and the laws must hold to rounding; with
decimal factors (1e-200, 1e150, 1e+-100) the scaled inputs are rounded
(relative 1e-16), which moves the motion by at most ~1e-16 times its condition number over the
compared span (a few periods here).
"""

from __future__ import annotations

import numpy as np
import pytest
from reference import as_matrices, geodesic_angle
from scipy.spatial.transform import Rotation

from poinsot.physics import FreeRigidBody

SCALE_RTOL = 1e-12
"""omega and attitude under a change of units, over 3 periods: the rounded scaled inputs
perturb the motion by ~1e-16 times its condition number (~lambda t ~ 20 here) plus the
implementation's own 1e-13 at each scale."""

SCALAR_RTOL = 1e-13
"""T, D, |L|, h, semi-axes, period under a change of units: a few roundings."""

ROT0 = Rotation.from_rotvec([0.2, 1.3, -0.6])

CASES = {
    "major": ((1.0, 2.0, 3.0), (0.2, 0.3, 1.0)),
    "minor": ((1.0, 2.0, 3.0), (1.0, 0.3, 0.5)),
    "near-separatrix": ((1.0, 2.0, 3.5), (0.7, 1e-6, 0.4)),
    "oblate": ((1.0, 1.0, 3.0), (0.5, 0.2, 1.0)),
    "no-triangle": ((1.0, 10.0, 1000.0), (0.2, 1.0, 0.03)),
    "permanent": ((1.0, 2.0, 3.0), (0.0, 1.5, 0.0)),
    "sphere": ((2.0, 2.0, 2.0), (0.3, -0.2, 0.9)),
}
# the exact separatrix survives only exact (power-of-two) scalings
EXACT_ONLY = {"separatrix": ((2.0, 3.0, 6.0), (3.0, 0.25, 1.0))}

OMEGA_SCALES = [1e-200, 1e150, 2.0**-664, 2.0**498]
INERTIA_SCALES = [1e-100, 1e100, 2.0**-332, 2.0**332]


def _span(body: FreeRigidBody) -> np.ndarray:
    scale = float(np.max(np.abs(body.omega0)))
    period = body.period if np.isfinite(body.period) else 10.0 / scale
    return np.linspace(0.0, 3.0 * period, 13)


def _cases(scales: list[float]) -> list[tuple[str, float]]:
    out = [(k, c) for k in CASES for c in scales]
    out += [(k, c) for k in EXACT_ONLY for c in scales if np.log2(c) == round(np.log2(c))]
    return out


def _case(key: str) -> tuple:
    return CASES.get(key) or EXACT_ONLY[key]


@pytest.mark.parametrize(("key", "c"), _cases(OMEGA_SCALES))
def test_omega_scaling(key: str, c: float) -> None:
    inertia, omega0 = _case(key)
    base = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=ROT0)
    scaled = FreeRigidBody(inertia=inertia, omega0=np.asarray(omega0) * c, attitude0=ROT0)
    assert scaled.regime is base.regime
    t = _span(base)
    w = scaled.omega(t / c)
    r = as_matrices(scaled.attitude(t / c))
    p = scaled.contact_point(t / c)
    assert np.all(np.isfinite(w)) and np.all(np.isfinite(r)) and np.all(np.isfinite(p))
    nw = np.max(np.abs(omega0))
    dw = np.max(np.abs(w / c - base.omega(t))) / nw
    dr = np.max(geodesic_angle(r, as_matrices(base.attitude(t))))
    dp = np.max(np.abs(p / c - base.contact_point(t))) / nw
    assert dw <= SCALE_RTOL, f"omega_c(t/c)/c - omega(t): {dw:.3e}"
    assert dr <= SCALE_RTOL, f"R_c(t/c) vs R(t): {dr:.3e} rad"
    assert dp <= SCALE_RTOL, f"contact point: {dp:.3e}"
    # the scalars scale as they must, and stay finite
    assert scaled.period == pytest.approx(base.period / c, rel=SCALAR_RTOL) or (
        base.period == scaled.period == np.inf
    )
    assert scaled.frequency == pytest.approx(base.frequency * c, rel=SCALAR_RTOL)
    assert scaled.parameter == pytest.approx(base.parameter, rel=SCALAR_RTOL, abs=1e-300)
    assert scaled.complementary_parameter == pytest.approx(
        base.complementary_parameter, rel=SCALAR_RTOL, abs=1e-300
    )
    assert scaled.D == pytest.approx(base.D, rel=SCALAR_RTOL)
    assert scaled.precession_per_period == pytest.approx(
        base.precession_per_period, rel=SCALAR_RTOL, abs=1e-300
    )
    assert scaled.plane_distance == pytest.approx(base.plane_distance * c, rel=SCALAR_RTOL)
    assert np.allclose(scaled.plane_normal, base.plane_normal, rtol=0, atol=1e-15)
    assert np.allclose(scaled.angular_momentum / c, base.angular_momentum, rtol=SCALAR_RTOL, atol=0)
    assert np.allclose(scaled.semi_axes / c, base.semi_axes, rtol=SCALAR_RTOL, atol=0), (
        scaled.semi_axes,
        base.semi_axes * c,
    )
    energy = base.energy * c * c  # may under/overflow in the test itself: then only finite
    assert np.isfinite(scaled.energy)
    if 1e-300 < energy < 1e300:
        assert scaled.energy == pytest.approx(energy, rel=SCALAR_RTOL)
    poly = scaled.polhode(64)
    assert np.all(np.isfinite(poly))
    assert np.allclose(poly / c, base.polhode(64), rtol=0, atol=SCALE_RTOL * nw)


@pytest.mark.parametrize(("key", "c"), _cases(INERTIA_SCALES))
def test_inertia_scaling(key: str, c: float) -> None:
    inertia, omega0 = _case(key)
    base = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=ROT0)
    scaled = FreeRigidBody(inertia=np.asarray(inertia) * c, omega0=omega0, attitude0=ROT0)
    assert scaled.regime is base.regime
    t = _span(base)
    w = scaled.omega(t)
    r = as_matrices(scaled.attitude(t))
    assert np.all(np.isfinite(w)) and np.all(np.isfinite(r))
    nw = np.max(np.abs(omega0))
    assert np.max(np.abs(w - base.omega(t))) <= SCALE_RTOL * nw
    assert np.max(geodesic_angle(r, as_matrices(base.attitude(t)))) <= SCALE_RTOL
    assert np.max(np.abs(scaled.contact_point(t) - base.contact_point(t))) <= SCALE_RTOL * nw
    assert scaled.period == pytest.approx(base.period, rel=SCALAR_RTOL) or (
        base.period == scaled.period == np.inf
    )
    assert scaled.energy == pytest.approx(base.energy * c, rel=SCALAR_RTOL)
    assert scaled.D == pytest.approx(base.D * c, rel=SCALAR_RTOL)
    assert scaled.plane_distance == pytest.approx(base.plane_distance, rel=SCALAR_RTOL)
    assert np.allclose(scaled.angular_momentum / c, base.angular_momentum, rtol=SCALAR_RTOL, atol=0)
    assert np.allclose(scaled.semi_axes, base.semi_axes, rtol=SCALAR_RTOL, atol=0)  # sqrt(2T/I)


@pytest.mark.parametrize(
    ("wc", "ic"), [(1e-200, 1e-100), (1e-200, 1e100), (1e150, 1e-100), (1e150, 1e100)]
)
def test_combined_extremes_stay_finite(wc: float, ic: float) -> None:
    """Both at once (|L| up to 1e250, 2T from 1e-500 to 1e400: not representable): omega and
    the attitude are still exact and finite; energy may underflow to 0 where the true value
    does, and where it exceeds the double range reading it raises a ValueError (no inf, no NaN)."""
    inertia, omega0 = CASES["major"]
    base = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=ROT0)
    scaled = FreeRigidBody(
        inertia=np.asarray(inertia) * ic, omega0=np.asarray(omega0) * wc, attitude0=ROT0
    )
    t = _span(base)
    w = scaled.omega(t / wc)
    assert np.all(np.isfinite(w))
    assert np.max(np.abs(w / wc - base.omega(t))) <= SCALE_RTOL
    r = as_matrices(scaled.attitude(t / wc))
    assert np.max(geodesic_angle(r, as_matrices(base.attitude(t)))) <= SCALE_RTOL
    assert scaled.D == pytest.approx(base.D * ic, rel=SCALAR_RTOL)
    assert scaled.frequency == pytest.approx(base.frequency * wc, rel=SCALAR_RTOL)
    try:
        energy = scaled.energy
    except ValueError as exc:  # 2T ~ 1e400: refused with a message rather than returned as inf
        assert "energy" in str(exc) and "1e400" in str(exc)
    else:
        assert np.isfinite(energy)
    assert np.all(np.isfinite(scaled.contact_point(t / wc)))
