"""The polhode family, Landau's momentum picture, and the arc travelled along a polhode.

* Every point of every curve lies on both quadrics (energy ellipsoid and momentum sphere).
* The label of each curve is the regime FreeRigidBody finds when started on it.
* The separatrix arcs run from -e2 to +e2 and are FreeRigidBody's separatrix polhode.
* The arc length read by PolhodeArc equals the arc length of the densely sampled ω(t).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import special

from poinsot.physics import FreeRigidBody, Regime
from poinsot.physics.models.family import (
    PolhodeArc,
    family_D_values,
    momentum_view,
    polhode_curves,
    polhode_family,
    polhode_points,
    polhode_progress,
)

SURFACE_RTOL = 1e-12
"""The closed form puts points on the quadrics to a few roundings of the amplitudes (measured
2e-15 relative); 1e-12 as the brief requires."""

ARC_RTOL = 1e-9
"""Arc length against the chord sum of 400k samples of ω(t), Richardson-extrapolated from two
grids (its O(h^2) error cancels; the remainder O(h^4) ~ 1e-16): what is left is the rounding
of the long chord sum (~1e-12) and of the Fourier series (1e-15); 1e-9 leaves margin."""

BODIES = [(1.0, 2.0, 3.0), (2.0, 3.0, 6.0), (0.3, 1.7, 1.9), (1.0, 1.0001, 50.0)]


def _on_surfaces(curve, inertia) -> tuple[float, float]:
    w = curve.omega
    J = np.asarray(inertia)
    energy = np.abs((w * w) @ J - curve.two_T) / curve.two_T
    sphere = np.abs(np.linalg.norm(w * J, axis=1) - curve.G) / curve.G
    return float(energy.max()), float(sphere.max())


@pytest.mark.parametrize("inertia", BODIES)
@pytest.mark.parametrize("scale", [{"energy": 0.5}, {"energy": 7e3}, {"momentum": 2.5}])
def test_every_point_lies_on_both_surfaces(inertia, scale):
    D_values = np.concatenate([[inertia[0]], family_D_values(inertia, 6), [inertia[2]]])
    curves = polhode_family(inertia, D_values, n=97, **scale)
    assert len(curves) == 2 * len(D_values) + 2  # the separatrix has four arcs
    for curve in curves:
        energy, sphere = _on_surfaces(curve, inertia)
        assert energy <= SURFACE_RTOL and sphere <= SURFACE_RTOL, (curve.D, curve.regime)
        # the momentum array is the same curve mapped by I, and D = G²/2T holds
        np.testing.assert_allclose(curve.momentum, curve.omega * np.asarray(inertia), rtol=0)
        assert curve.G**2 / curve.two_T == pytest.approx(curve.D, rel=1e-14)
        if "energy" in scale:
            assert curve.two_T == pytest.approx(2.0 * scale["energy"], rel=1e-15)
        else:
            assert curve.G == pytest.approx(scale["momentum"], rel=1e-15)


@pytest.mark.parametrize("inertia", BODIES)
def test_label_is_the_regime_of_the_motion_started_on_the_curve(inertia):
    for curve in polhode_family(inertia, family_D_values(inertia, 5), n=41):
        if curve.regime is Regime.SEPARATRIX:
            continue  # a float point is on the separatrix only to rounding: tested exactly below
        for k in (0, 7, 20):
            body = FreeRigidBody(inertia, curve.omega[k])
            assert body.regime is curve.regime, (curve.D, k)
            assert body.D == pytest.approx(curve.D, rel=1e-13)
            # and the motion stays on the pole side of that curve
            w = body.omega(np.linspace(0.0, 30.0, 50))
            pole = 0 if curve.regime is Regime.MINOR_AXIS else 2
            assert np.all(np.sign(w[:, pole]) == curve.signs[pole])


def test_pure_spins_are_points():
    curves = polhode_curves((1.0, 2.0, 3.0), 3.0, energy=1.5)
    assert [c.regime for c in curves] == [Regime.PERMANENT_ROTATION] * 2
    np.testing.assert_allclose(curves[0].omega, [[0.0, 0.0, 1.0]])
    np.testing.assert_allclose(curves[1].omega, [[0.0, 0.0, -1.0]])
    body = FreeRigidBody((1.0, 2.0, 3.0), curves[0].omega[0])
    assert body.regime is Regime.PERMANENT_ROTATION


def test_separatrix_arcs_pass_through_the_intermediate_poles_and_match_the_motion():
    # I = (2, 3, 6), ω0 = (±3, ω2, ±1) has Δ2 = G² - 2T I2 = 0 exactly: the true separatrix.
    inertia = (2.0, 3.0, 6.0)
    arcs = polhode_curves(inertia, 3.0, energy=12.0, n=129)
    assert [c.regime for c in arcs] == [Regime.SEPARATRIX] * 4
    pole = math.sqrt(2 * 12.0 / 3.0)
    for arc in arcs:
        np.testing.assert_allclose(arc.omega[0], [0.0, -pole, 0.0], atol=1e-15)
        np.testing.assert_allclose(arc.omega[-1], [0.0, pole, 0.0], atol=1e-15)
        assert not arc.closed
    for s1, s3 in ((1, 1), (1, -1), (-1, 1), (-1, -1)):
        body = FreeRigidBody(inertia, (3.0 * s1, 0.4, 1.0 * s3))
        assert body.regime is Regime.SEPARATRIX
        assert body.energy == pytest.approx(12.0 + 0.5 * 3.0 * 0.16)
        mine = polhode_curves(inertia, 3.0, energy=body.energy, n=129)
        match = [c for c in mine if c.signs == (s1, 1, s3)]
        assert len(match) == 1
        np.testing.assert_allclose(match[0].omega, body.polhode(129), rtol=0, atol=1e-14)
        # the motion itself approaches the poles along that arc
        w = body.omega(np.array([-80.0, 80.0]))
        assert np.abs(np.abs(w[:, 1]) - match[0].omega[-1, 1]).max() < 1e-12


def test_two_separatrix_ellipses_cross_at_the_poles():
    arcs = polhode_curves((1.0, 2.0, 3.0), 2.0, n=201)
    # (s1, s3) and (-s1, -s3) form one planar ellipse: ω3/ω1 constant on it
    for a, b in ((0, 3), (1, 2)):
        w = np.concatenate([arcs[a].omega[1:-1], arcs[b].omega[1:-1]])
        ratio = w[:, 2] / w[:, 0]
        assert np.ptp(ratio) < 1e-13


def test_landau_momentum_view():
    inertia = (1.0, 2.0, 3.0)
    for D in (1.3, 2.0, 2.7):
        view = momentum_view(inertia, D, momentum=2.0, n=65)
        assert view.sphere_radius == 2.0
        np.testing.assert_allclose(
            view.ellipsoid_semi_axes, np.sqrt(view.two_T * np.array(inertia))
        )
        assert view.two_T == pytest.approx(4.0 / D)
        for curve in view.curves:
            m = curve.momentum
            sphere = np.abs(np.linalg.norm(m, axis=1) - 2.0) / 2.0
            ellipsoid = np.abs(np.sum(m * m / np.array(inertia), axis=1) - view.two_T) / view.two_T
            assert sphere.max() <= SURFACE_RTOL and ellipsoid.max() <= SURFACE_RTOL


@pytest.mark.parametrize(
    "bad",
    [
        dict(inertia=(2.0, 1.0, 3.0), D=2.0),
        dict(inertia=(1.0, 1.0, 3.0), D=2.0),
        dict(inertia=(0.0, 1.0, 3.0), D=2.0),
        dict(inertia=(1.0, 2.0, math.nan), D=2.0),
        dict(inertia=(1.0, 2.0, 3.0), D=3.5),
        dict(inertia=(1.0, 2.0, 3.0), D=math.nan),
        dict(inertia=(1.0, 2.0, 3.0), D=2.0, n=2),
        dict(inertia=(1.0, 2.0, 3.0), D=2.0, energy=-1.0),
        dict(inertia=(1.0, 2.0, 3.0), D=2.0, energy=1.0, momentum=1.0),
    ],
)
def test_bad_input_is_a_readable_value_error(bad):
    with pytest.raises(ValueError, match=r"\w+ \w+"):
        polhode_curves(**bad)


# ---------------------------------------------------------------------------------------------
# Arc travelled along the polhode.
# ---------------------------------------------------------------------------------------------


def _sampled_arc(body: FreeRigidBody, t_end: float, n: int = 400_000) -> tuple[np.ndarray, ...]:
    """Chord sums of ω(t) on grids of n and 2n intervals, Richardson-extrapolated (O(h²))."""
    t = np.linspace(0.0, t_end, 2 * n + 1)
    w = body.omega(t)
    fine = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(w, axis=0), axis=1))])
    coarse = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(w[::2], axis=0), axis=1))])
    return t[::2], (4.0 * fine[::2] - coarse) / 3.0


@pytest.mark.parametrize(
    "inertia, omega0",
    [
        ((1.0, 2.0, 3.0), (1.0, 0.3, 0.2)),  # minor-axis family
        ((1.0, 2.0, 3.0), (0.2, 0.3, 1.0)),  # major-axis family
        ((3.0, 1.0, 2.0), (0.1, 0.4, -1.0)),  # unsorted axes
        ((1.0, 2.0, 3.0), (1e-9, 1.0, 0.0)),  # next to the separatrix, 1 - m = 1e-18
        ((1.0, 1.0, 0.2), (1.0, 0.2, 0.05)),  # long cylinder spun near a diametral axis
        ((2.0, 2.0, 3.0), (0.5, 0.1, 1.0)),  # oblate symmetric
    ],
)
def test_arc_length_equals_the_sampled_polhode(inertia, omega0):
    body = FreeRigidBody(inertia, omega0)
    arc = PolhodeArc(body)
    assert arc.circuit_time == body.period
    t, reference = _sampled_arc(body, 2.6 * body.period)
    measured = arc.arc_length(t)
    assert np.abs(measured - reference).max() <= ARC_RTOL * arc.circuit_length
    # one circuit: the closed polhode's own length (chord sum of its sampled points)
    poly = body.polhode(200_000)
    closed = np.linalg.norm(np.diff(np.vstack([poly, poly[:1]]), axis=0), axis=1).sum()
    assert arc.circuit_length == pytest.approx(closed, rel=1e-8)
    frac = arc.fraction(t)
    assert frac.min() >= 0.0 and frac.max() < 1.0
    expected = np.mod(reference / arc.circuit_length, 1.0)
    wrapped = np.minimum(np.abs(frac - expected), 1.0 - np.abs(frac - expected))
    assert wrapped.max() <= ARC_RTOL
    # negative times run backwards along the curve
    assert arc.arc_length(np.array([-0.3 * body.period]))[0] < 0.0


def test_separatrix_arc_and_constant_motion():
    body = FreeRigidBody((2.0, 3.0, 6.0), (3.0, 0.5, 1.0))
    arc = PolhodeArc(body)
    assert arc.circuit_time == math.inf
    t, reference = _sampled_arc(body, 40.0)
    assert np.abs(arc.arc_length(t) - reference).max() <= ARC_RTOL * arc.circuit_length
    # from pole to pole the tip travels the whole arc: fraction -> 1 - (its start fraction)
    start = arc.fraction(np.array([-200.0, 200.0]))
    assert start[1] - start[0] == pytest.approx(1.0, abs=1e-12)
    spin = FreeRigidBody((1.0, 2.0, 3.0), (0.0, 0.0, 2.0))
    frac, period = polhode_progress(spin, np.linspace(0, 10, 5))
    assert period == math.inf and np.all(frac == 0.0)


def test_arc_rejects_non_bodies_and_bad_times():
    with pytest.raises(ValueError, match="FreeRigidBody"):
        PolhodeArc((1.0, 2.0, 3.0))  # type: ignore[arg-type]
    arc = PolhodeArc(FreeRigidBody((1.0, 2.0, 3.0), (1.0, 0.3, 0.2)))
    with pytest.raises(ValueError, match="finite"):
        arc.fraction([0.0, math.inf])


def test_polhode_points_are_the_curves_at_any_amplitude():
    inertia = (1.0, 2.0, 3.0)
    rng = np.random.default_rng(7)
    phi = rng.uniform(-4.0, 4.0, 200)
    for D in (1.0, 1.4, 2.0, 2.6, 3.0):
        for curve in polhode_curves(inertia, D, energy=0.8, n=16):
            w = polhode_points(inertia, D, phi, curve.signs, energy=0.8)
            J = np.asarray(inertia)
            assert np.abs((w * w) @ J / curve.two_T - 1.0).max() <= SURFACE_RTOL
            assert np.abs(np.linalg.norm(w * J, axis=1) / curve.G - 1.0).max() <= SURFACE_RTOL
            if curve.omega.shape[0] > 1:
                grid = (
                    np.linspace(-0.5 * math.pi, 0.5 * math.pi, 16)
                    if curve.regime is Regime.SEPARATRIX
                    else np.linspace(0.0, 2.0 * math.pi, 16, endpoint=False)
                )
                np.testing.assert_allclose(
                    polhode_points(inertia, D, grid, curve.signs, energy=0.8), curve.omega
                )
    with pytest.raises(ValueError, match="signs"):
        polhode_points(inertia, 1.5, [0.0], (1, -1, 1))


@pytest.mark.parametrize("tilt", [1e-12, 1e-150, 1e-300])
def test_arc_next_to_the_separatrix_tends_to_two_separatrix_arcs(tilt):
    # 1 - m ~ tilt²: the closed polhode hugs the two separatrix arcs on the e1 side, and the
    # speed along it is a burst twice per circuit (a mean far below its peak). For I = (1, 2, 3)
    # and 2T = 2 each arc runs from -e2 to +e2 on (A1 cos φ, A2 sin φ, A3 cos φ) with A1² = 1,
    # A2² = 1, A3² = 1/3: its length is 2 A2 E(1 - (A1² + A3²)/A2²) = 2 E(-1/3).
    body = FreeRigidBody((1.0, 2.0, 3.0), (tilt, 1.0, 0.0))
    arc = PolhodeArc(body)
    expected = 2.0 * 2.0 * special.ellipe(1.0 - (1.0 + 1.0 / 3.0))
    assert arc.circuit_length == pytest.approx(expected, rel=1e-12)
    # by symmetry the quarter periods are the quarter arcs
    frac = arc.fraction(np.array([0.25, 0.5, 0.75]) * arc.circuit_time)
    np.testing.assert_allclose(frac, [0.25, 0.5, 0.75], atol=1e-12)
