"""The scenes' physics, checked on what they send (the websocket probe's model of the scene, at
times set on the session's clock): what each model conserves stays conserved in the poses,
positions and arrows sent, and each readout's theoretical value matches the value measured from
that sent motion (or from the plot the scene shows)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import wait_until
from scene_probing import (
    arrow_tip,
    drawn_traces,
    number_in,
    plot_data,
    readout_table,
    rotation,
    segments,
    sent_at,
    start,
    trail_points,
    wait_readouts,
)

from poinsot.app.construction.geometry import POLHODE_INFLATE
from poinsot.app.lessons import dzhanibekov, explorer_1, gyroscope_torque, scene_by_name
from poinsot.app.lessons import polhode_family as family_scene


def body_frame_omega(nodes) -> np.ndarray:
    """The tip of ω (the contact point) carried back into the body frame, display units."""
    return rotation(nodes["/space/body"]).inv().apply(np.asarray(nodes["/space/tip"].position))


def assert_conserved(values, rtol: float, what: str) -> None:
    values = np.asarray(values, dtype=float)
    spread = float(np.max(np.abs(values / values[0] - 1.0)))
    assert spread < rtol, f"{what} drifts by {spread:.2e}"


def construction_invariants(samples, inertia) -> None:
    """Energy and |L| of the sent ω, the tip on the plane and on the ellipsoid."""
    J = np.asarray(inertia, dtype=float)
    x = np.array([body_frame_omega(nodes) for _, nodes in samples])
    assert_conserved(np.sum(J * x * x, axis=1), 1e-6, "the energy")  # float32 positions
    assert_conserved(np.linalg.norm(J * x, axis=1), 1e-6, "|L|")
    for _, nodes in samples:
        assert nodes["/space/tip"].position[2] == pytest.approx(
            nodes["/space/plane"].position[2], rel=1e-6
        )  # positions travel as float32
        a = np.asarray(nodes["/space/body/ellipsoid"].props["scale"], dtype=float)
        assert np.sum((body_frame_omega(nodes) / a) ** 2) == pytest.approx(1.0, abs=1e-6)


def zero_crossings(t, y) -> np.ndarray:
    """Linearly interpolated times where ``y`` changes sign."""
    t, y = np.asarray(t), np.asarray(y)
    k = np.flatnonzero(np.sign(y[:-1]) * np.sign(y[1:]) < 0)
    return t[k] - y[k] * (t[k + 1] - t[k]) / (y[k + 1] - y[k])


def sample(session, probe, times):
    return [sent_at(session, probe, float(t)) for t in times]


def test_polhode_family_conserves_and_its_period_reads_off_the_motion(make_app, make_probe):
    spec = scene_by_name("polhode-family")
    _, session, probe = start(make_app, make_probe, spec)
    model = session.showcase.showcase.model
    period = model.body.period
    samples = sample(session, probe, np.linspace(0.0, 1.3 * period, 72))
    construction_invariants(samples, model.body.inertia)
    curve = segments(samples[0][1]["/space/body/current_polhode"])[:, 0] / POLHODE_INFLATE
    radius = family_scene.LANDAU_RADIUS
    for _, nodes in samples:
        x = body_frame_omega(nodes)
        assert np.min(np.linalg.norm(curve - x, axis=1)) < 0.01  # on the highlighted curve
        m = np.asarray(nodes["/space/landau/m"].position)
        e = np.asarray(nodes["/space/landau/ellipsoid"].props["scale"], dtype=float)
        assert np.linalg.norm(m) == pytest.approx(radius, rel=1e-9)  # on the sphere
        assert np.sum((m / e) ** 2) == pytest.approx(1.0, rel=1e-9)  # and on the ellipsoid
    t = [f.t for f, _ in samples]
    zeros = zero_crossings(t, [body_frame_omega(n)[1] for _, n in samples])
    rows = wait_readouts(probe, spec.readouts)
    theory = number_in(rows["period of ω (4K/λ)"][0])
    assert 2.0 * float(np.mean(np.diff(zeros))) == pytest.approx(theory, rel=5e-3)
    assert rows["family"][0] == "around the minor axis"


def test_the_D_slider_sweeps_the_family(make_app, make_probe):
    spec = scene_by_name("polhode-family")
    _, session, probe = start(make_app, make_probe, spec)
    uuid, _ = probe.widget("D = |L|²/2T")
    for D, family in ((2.3, "around the major axis"), (2.0, "separatrix")):
        probe.set_value(uuid, D)
        assert wait_until(lambda d=D: session.showcase.showcase.model.D == d, 10)
        assert probe.wait_for(lambda p, f=family: wait_readouts(p, spec.readouts)["family"][0] == f)
        rows = wait_readouts(probe, spec.readouts)  # the table that names the new family
        body = session.showcase.showcase.model.body
        assert body.D == pytest.approx(D, abs=1e-15)
        _, nodes = sent_at(session, probe, 1.0)
        curve = segments(nodes["/space/body/current_polhode"])[:, 0] / POLHODE_INFLATE
        x = body_frame_omega(nodes)
        assert np.min(np.linalg.norm(curve - x, axis=1)) < 0.01
        assert number_in(rows["D = |L|²/2T"][0]) == pytest.approx(D, rel=1e-6)


def test_dzhanibekov_flips_and_growth_read_off_the_plot(make_app, make_probe):
    spec = scene_by_name("dzhanibekov")
    _, session, probe = start(make_app, make_probe, spec)
    uuid, _ = probe.widget("ε from the intermediate axis")
    before = session.generation
    probe.set_value(uuid, "1e-12")
    assert wait_until(lambda: session.generation > before, 10)
    model = session.showcase.showcase.model
    assert model.epsilon == 1e-12
    samples = sample(session, probe, np.linspace(0.0, 30.0, 12))
    construction_invariants(samples, model.body.inertia)
    span = float(model.times[-1])
    sent_at(session, probe, span + 1.0)  # past the plot's span: the whole plot is shown
    title = spec.plots[0].title
    assert probe.wait_for(lambda p: len(plot_data(p, title)[0]) == dzhanibekov.PLOT_SAMPLES, 10)
    t, log_p, _, twin_log_p = plot_data(probe, title)
    step = t[1] - t[0]

    def peaks_of(y: np.ndarray) -> list[float]:
        return [
            t[k]
            for k in range(1, len(t) - 1)
            if y[k] > -0.05 and y[k] >= y[k - 1] and y[k] >= y[k + 1]
        ]

    peaks, twin_peaks = peaks_of(log_p), peaks_of(twin_log_p)
    rows = wait_readouts(probe, spec.readouts)
    first = number_in(rows["first flip, (K ± δ)/λ"][0])
    between = number_in(rows["time between flips, 2K(k)/λ"][0])
    assert peaks[0] == pytest.approx(first, abs=step)
    assert float(np.mean(np.diff(peaks))) == pytest.approx(between, abs=step)
    stretch = (log_p > -10.0) & (log_p < -3.0) & (t < first)
    slope = np.polyfit(t[stretch], log_p[stretch], 1)[0] * math.log(10.0)
    assert slope == pytest.approx(number_in(rows["growth rate σ"][0]), rel=2e-3)
    assert number_in(rows["growth rate σ"][1]) == pytest.approx(slope, rel=2e-3)
    # the twin (ε′ = ε/10 by default) flips later by the lag the readouts give
    lag = number_in(rows["lag of the twin, t₁(ε′) − t₁(ε)"][0])
    assert twin_peaks[0] - peaks[0] == pytest.approx(lag, abs=2.0 * step)
    asymptote = number_in(rows["… its asymptote ln(16/(1−k²))/λ"][0])
    assert asymptote == pytest.approx(between, rel=1e-12)  # exact at 1e-12


def test_symmetric_top_rates_and_cones_read_off_the_motion(make_app, make_probe):
    spec = scene_by_name("symmetric-top")
    _, session, probe = start(make_app, make_probe, spec)
    uuid, _ = probe.widget("Body")
    for shape in ("prolate (a rod)", "oblate (a disc)"):
        if session.showcase.showcase.model.shape != shape:
            before = session.generation
            probe.set_value(uuid, shape)
            assert wait_until(lambda b=before: session.generation > b, 10)
        model = session.showcase.showcase.model
        top = model.top
        samples = sample(
            session, probe, np.linspace(0.0, 1.2 * 2 * math.pi / top.precession_rate, 40)
        )
        construction_invariants(samples, model.body.inertia)
        t = np.array([f.t for f, _ in samples])
        axis = np.array([rotation(n["/space/body"]).apply([0, 0, 1]) for _, n in samples])
        x = np.array([body_frame_omega(n) for _, n in samples])
        p = np.polyfit(t, np.unwrap(np.arctan2(axis[:, 1], axis[:, 0])), 1)[0]
        s = -np.polyfit(t, np.unwrap(np.arctan2(x[:, 1], x[:, 0])), 1)[0]
        rows = wait_readouts(probe, spec.readouts)
        assert rows["shape"][0] == top.shape
        assert p == pytest.approx(number_in(rows["precession p = G/I"][0]), rel=1e-7)
        assert s == pytest.approx(number_in(rows["spin s = ((I − J)/I) ω₃"][0]), rel=1e-7)
        tips = np.array([n["/space/tip"].position for _, n in samples])
        alpha_s = np.degrees(np.arctan2(np.hypot(tips[:, 0], tips[:, 1]), tips[:, 2]))
        alpha_b = np.degrees(np.arctan2(np.hypot(x[:, 0], x[:, 1]), x[:, 2]))
        assert alpha_b == pytest.approx(number_in(rows["body cone α_b (ω to e₃)"][0]), abs=1e-6)
        assert alpha_s == pytest.approx(number_in(rows["space cone α_s (ω to L)"][0]), abs=1e-6)


def test_gyroscope_conserves_omega3_and_drifts_as_stated(make_app, make_probe):
    spec = scene_by_name("gyroscope-torque")
    _, session, probe = start(make_app, make_probe, spec)
    model = session.showcase.showcase.model
    g = model.gyro
    scale = gyroscope_torque.OMEGA_LENGTH / float(np.max(np.linalg.norm(model.omega, axis=1)))
    samples = sample(session, probe, np.linspace(0.0, g.nutation_period, 65))
    t = np.array([f.t for f, _ in samples])
    w = (
        np.array(
            [
                rotation(n["/space/body"]).inv().apply(arrow_tip(n["/space/gyro_omega"]))
                for _, n in samples
            ]
        )
        / scale
    )
    assert_conserved(w[:, 2], 1e-6, "ω₃")  # float32 arrows
    rows = wait_readouts(probe, spec.readouts)
    center = gyroscope_torque.circle_center(w[:, :2])
    assert center[0] == pytest.approx(
        number_in(rows["nutation centre ω₁* = −M/((J₃−J)ω₃)"][0]), rel=1e-5
    )
    assert abs(center[1]) < 1e-6
    drift = -np.trapezoid(w[:, 0], t) / (t[-1] - t[0])
    assert drift == pytest.approx(number_in(rows["drift rate M/((J₃−J)ω₃)"][0]), rel=2e-3)
    assert number_in(rows["drift rate M/((J₃−J)ω₃)"][1]) == pytest.approx(g.drift_rate, rel=1e-8)
    assert number_in(rows["attitude error estimate now"][1]) < 1e-9
    path = trail_points(samples[-1][1], gyroscope_torque.PATH_NODE)
    assert len(path) and np.allclose(
        np.linalg.norm(path, axis=1), gyroscope_torque.AXIS_LENGTH, rtol=1e-6
    )


def test_long_cylinder_progress_along_the_polhode(make_app, make_probe):
    spec = scene_by_name("long-cylinder")
    _, session, probe = start(make_app, make_probe, spec)
    model = session.showcase.showcase.model
    period = model.arc.circuit_time
    samples = sample(session, probe, np.linspace(0.0, 1.25 * period, 80))
    construction_invariants(samples, model.body.inertia)
    zeros = zero_crossings([f.t for f, _ in samples], [body_frame_omega(n)[1] for _, n in samples])
    rows = wait_readouts(probe, spec.readouts)
    assert 2.0 * float(np.mean(np.diff(zeros))) == pytest.approx(
        number_in(rows["one circuit, 4K/λ"][0]), rel=1e-2
    )
    # Play from 0 at a time lapse of ×30, so that the polhode's trace grows from the start.
    # The speed first (it re-grids the motion from the time shown), then the reset, both on
    # the session's thread in that order (a clock set from here could be re-gridded from a
    # frame shown before it).
    session.set_speed(30.0)
    assert wait_until(lambda: session.clock.speed == 30.0, 10)
    session.reset()
    # The traces restart where the time goes back: drawn at 0 while still paused, they hold
    # the whole way from the start (a first frame drawn only once the clock runs again, late
    # on a busy machine, would start them a few frames on).
    assert wait_until(lambda: session.clock.now() == 0.0 and session.frame.t < 1e-3 * period, 10)
    session.clock.paused = False
    assert wait_until(lambda: session.frame.t > 0.35 * period, 20)
    session.clock.paused = True
    shown = session.clock.now()
    assert wait_until(lambda: session.frame.t == session.scene.shown_time(shown), 30)
    expected = f"{100.0 * float(model.arc.fraction(session.frame.t)[0]):.2f} %"
    assert probe.wait_for(
        lambda p: wait_readouts(p, spec.readouts)["travelled along the polhode"][0] == expected, 10
    )
    _, nodes = sent_at(session, probe, session.frame.t)
    traces = drawn_traces(session, probe)
    trace = traces["/space/body/polhode"]
    full = segments(nodes["/space/body/polhode_full"])
    chord = lambda seg: float(np.sum(np.linalg.norm(seg[:, 1] - seg[:, 0], axis=1)))  # noqa: E731
    travelled = float(np.sum(np.linalg.norm(np.diff(trace, axis=0), axis=1))) / chord(full)
    assert travelled == pytest.approx(number_in(expected) / 100.0, abs=0.01), (
        len(trace),
        trace[:2],
    )
    herpolhode = traces["/space/herpolhode"]
    ratio = np.max(np.hypot(herpolhode[:, 0], herpolhode[:, 1])) / np.max(
        np.hypot(full[:, 0, 1], full[:, 0, 2])
    )
    shown = number_in(wait_readouts(probe, spec.readouts)["herpolhode radius / polhode radius"][1])
    assert ratio == pytest.approx(shown, rel=0.05) and shown < 0.15  # tiny beside the polhode


def test_explorer_keeps_L_and_crosses_the_separatrix_when_stated(make_app, make_probe):
    spec = scene_by_name("explorer-1")
    _, session, probe = start(make_app, make_probe, spec)
    model = session.showcase.showcase.model
    radius = explorer_1.SPHERE_RADIUS
    samples = sample(session, probe, np.linspace(0.0, model.span * 0.95, 24))
    for _, nodes in samples:
        m = np.asarray(nodes["/space/momentum/m"].position)
        assert np.linalg.norm(m) == pytest.approx(radius, rel=1e-6)  # |m| = |L|
        L = rotation(nodes["/space/body"]).apply(m)
        assert np.allclose(L, (0.0, 0.0, radius), atol=1e-6)  # L fixed, vertical
    end = model.span - 0.5 / explorer_1.ROWS_PER_TIME
    sent_at(session, probe, end)
    title = spec.plots[0].title
    whole = len(model.plot("D", end)[0])
    assert probe.wait_for(lambda p: len(plot_data(p, title)[0]) == whole, 10)
    t, law, motion, level = plot_data(probe, title)
    assert np.all(np.diff(law) > 0) and np.all(np.diff(motion) >= -1e-12)
    crossed = t[np.argmax(motion >= level)]
    rows = wait_readouts(probe, spec.readouts)
    theory = number_in(rows["separatrix crossing t*"][0])
    assert crossed == pytest.approx(theory, abs=2 * (t[1] - t[0]) + model.sink.window)
    for when, family in ((0.5 * theory, "minor-axis family"), (1.3 * theory, "major-axis family")):
        sent_at(session, probe, when)
        assert probe.wait_for(
            lambda p, f=family: wait_readouts(p, spec.readouts)["family now"][1] == f, 30
        ), (when, readout_table(probe).get("family now"))
