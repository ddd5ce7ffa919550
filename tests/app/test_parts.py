"""The app's parts on their own: presets (data and sources), parameters, clock, the one
quaternion conversion, the chunked trail, and the command line."""

from __future__ import annotations

import re
import subprocess
import sys
import time
import urllib.request

import numpy as np
import pytest
from conftest import record_frame_times, session_of, wait_until
from scipy.spatial.transform import Rotation

from poinsot.app.cli import main as cli
from poinsot.app.construction.meshes import solid_mesh
from poinsot.app.construction.sampled.frames import rotation_from_wxyz, wxyz
from poinsot.app.construction.trail import MAX_RETIRED, RETIRE_PER_APPEND, Trail
from poinsot.app.live.panel.clock import SimClock
from poinsot.app.model.elements import ALL_ELEMENTS, Element
from poinsot.app.model.parameters import Parameters
from poinsot.app.model.presets import CUSTOM, PRESETS, preset_by_key, preset_by_label
from poinsot.physics import Regime

EXPECTED_REGIME = {
    "major": Regime.MAJOR_AXIS,
    "minor": Regime.MINOR_AXIS,
    "t_handle": Regime.MAJOR_AXIS,
    "near_separatrix": Regime.MAJOR_AXIS,
    "separatrix": Regime.SEPARATRIX,
    "oblate": Regime.SYMMETRIC,
    "prolate": Regime.SYMMETRIC,
    "sphere": Regime.SPHERE,
}


# -- presets ---------------------------------------------------------------------------
def test_the_presets_are_all_there():
    assert [p.key for p in PRESETS] == list(EXPECTED_REGIME)
    assert len({p.label for p in (*PRESETS, CUSTOM)}) == len(PRESETS) + 1
    assert CUSTOM.elements == ALL_ELEMENTS


@pytest.mark.parametrize("preset", PRESETS, ids=[p.key for p in PRESETS])
def test_each_preset_is_a_real_body_with_a_source(preset):
    assert len(preset.source) > 40 and re.search(r"[A-Z][a-z]+", preset.source)
    params = Parameters.from_preset(preset)
    params.check()  # triangle inequality: a real body
    body = params.build()
    assert body.D == pytest.approx(preset.D, rel=1e-12)
    assert np.linalg.norm(body.omega0) == pytest.approx(preset.omega_norm)
    assert np.allclose(body.plane_normal, (0, 0, 1), atol=1e-12)  # L vertical
    assert body.regime is EXPECTED_REGIME[preset.key], body.regime
    assert params.matches(preset)


WITH_SOLID = [p for p in PRESETS if p.solid is not None]


@pytest.mark.parametrize("preset", WITH_SOLID, ids=[p.key for p in WITH_SOLID])
def test_a_preset_s_solid_has_the_preset_s_moments(preset):
    """The drawn solid is the body: trimesh's mass properties of the exact mesh the app sends
    (centre of mass at the origin, principal axes = body axes) give the preset's moments."""
    mesh = solid_mesh(preset.solid)
    assert mesh.is_watertight
    assert np.allclose(mesh.center_mass, 0.0, atol=2e-4 * mesh.scale)
    tensor = mesh.moment_inertia
    assert np.allclose(tensor - np.diag(np.diag(tensor)), 0.0, atol=1e-9 * np.trace(tensor))
    moments = np.diag(tensor)
    # Ratios (the mass is a free scale); polygonal cylinders differ from circles by ~0.2 %.
    assert np.allclose(
        moments / moments.max(), np.divide(preset.inertia, max(preset.inertia)), rtol=5e-3
    )


def test_a_body_without_a_preset_solid_is_drawn_as_the_physics_box(make_app, make_probe):
    """The separatrix preset (exact data, no solid of its own) and any hand-edited body show
    the homogeneous box with the same moments, from physics.box_dimensions."""
    from poinsot.physics import box_dimensions

    preset = preset_by_key("separatrix")
    assert preset.solid is None and len(WITH_SOLID) == len(PRESETS) - 1
    app = make_app(preset)
    probe = make_probe(app)
    assert probe.wait_for(lambda p: "/space/body/solid" in p.nodes, 15)
    session = app.wait_for_sessions(1)[0]
    sides = np.asarray(probe.snapshot()[0]["/space/body/solid"].props["scale"])
    expected = box_dimensions(preset.inertia)
    assert np.allclose(sides / sides.max(), expected / expected.max())
    assert session.body.regime is Regime.SEPARATRIX


def test_presets_are_found_by_key_and_label():
    assert preset_by_key("t_handle").label == "Dzhanibekov flip (T-handle)"
    assert preset_by_label(CUSTOM.label) is CUSTOM
    with pytest.raises(KeyError, match="no preset named"):
        preset_by_key("nope")


# -- parameters ------------------------------------------------------------------------
def test_an_impossible_body_is_named_in_the_message():
    bad = Parameters((1.0, 1.0, 2.5), 1.5)
    with pytest.raises(ValueError, match=r"no real body .* I3 = 2\.5 is larger than I1 \+ I2 = 2"):
        bad.check()
    with pytest.raises(ValueError, match="no real body"):
        bad.build()
    Parameters((1.0, 1.0, 2.0), 1.5).check()  # a flat lamina is a real body


def test_editing_a_moment_keeps_D_in_range_and_sides_mirror():
    p = Parameters((1.0, 2.0, 2.6), 2.45)
    q = p.with_inertia(2, 2.2)
    assert q.D == 2.2 and q.inertia == (1.0, 2.0, 2.2)
    assert p.side() == "major"
    m = p.mirrored("minor")
    assert m.side() == "minor" and 1.0 <= m.D < 2.0
    assert m.mirrored("major").D == pytest.approx(p.D)
    assert p.mirrored("major") == p


# -- clock -----------------------------------------------------------------------------
class FakeTime:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def test_clock_speed_pause_step_reset():
    wall = FakeTime()
    clock = SimClock(speed=2.0, monotonic=wall)
    wall.now += 1.5
    assert clock.now() == pytest.approx(3.0)
    clock.speed = 0.5  # continuous across the change
    assert clock.now() == pytest.approx(3.0)
    wall.now += 2.0
    assert clock.now() == pytest.approx(4.0)
    clock.paused = True
    wall.now += 10.0
    assert clock.now() == pytest.approx(4.0)
    clock.step(0.25)
    assert clock.now() == pytest.approx(4.25)
    clock.paused = False
    wall.now += 1.0
    assert clock.now() == pytest.approx(4.75)
    clock.reset()
    assert clock.now() == 0.0


# -- the one quaternion conversion -----------------------------------------------------
def test_wxyz_is_scalar_first_and_round_trips():
    rotations = Rotation.random(50, random_state=3)
    q = wxyz(rotations)
    assert q.shape == (50, 4) and np.all(q[:, 0] >= 0)
    assert np.allclose(np.abs(q[:, 0]), np.abs(rotations.as_quat()[:, 3]))
    for r, qi in zip(rotations, q, strict=True):
        assert (rotation_from_wxyz(qi) * r.inv()).magnitude() < 1e-12
    single = wxyz(Rotation.from_rotvec([0.0, 0.0, np.pi / 2]))
    assert np.allclose(single, [np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)])


# -- trail -----------------------------------------------------------------------------
class FakeHandle:
    def __init__(self, api, name, points) -> None:
        # Kept by reference, as viser's add_line_segments keeps a float32 array it is given.
        self.api, self.name, self._points = api, name, np.asarray(points)
        self.visible = True
        api.sent_bytes += self._points.nbytes

    @property
    def points(self):
        return self._points

    @points.setter
    def points(self, value) -> None:
        self._points = np.array(value)
        self.api.sent_bytes += self._points.nbytes

    def remove(self) -> None:
        self.api.removed += 1
        self.api.live.discard(self.name)
        self.api.live -= {n for n in self.api.live if n.startswith(self.name + "/")}


class FakeApi:
    """Records what a Trail sends, in place of a viser SceneApi: the chunks alive, the frames
    by name, the bytes of points and the removals."""

    def __init__(self) -> None:
        self.live: set[str] = set()
        self.frames: dict[str, FakeHandle] = {}
        self.sent_bytes = 0
        self.removed = 0
        self.made = 0

    def add_frame(self, name, **kwargs):
        self.frames[name] = FakeHandle(self, name, np.zeros((0, 3)))
        return self.frames[name]

    def add_line_segments(self, name, points, color, **kwargs):
        self.live.add(name)
        self.made += 1
        return FakeHandle(self, name, points)

    def shown(self) -> set[str]:
        """The chunks alive whose frames (every prefix of their name) are all visible."""
        return {
            c
            for c in self.live
            if all(f.visible for name, f in self.frames.items() if c.startswith(name + "/"))
        }


def test_trail_is_bounded_and_sends_increments_only():
    api = FakeApi()
    trail = Trail(api, "/t", (255, 0, 0), 2.0, max_points=200, chunk=16)
    points = np.cumsum(np.ones((1000, 3)), axis=0).astype(np.float32)
    worst = 0
    for p in points:
        before = api.sent_bytes
        trail.append(p[None])
        worst = max(worst, api.sent_bytes - before)
    assert worst <= 16 * 2 * 3 * 4  # at most one chunk per frame
    assert 200 - 16 <= trail.segment_count <= 200
    drawn = trail.points()
    assert np.array_equal(drawn, points[-len(drawn) :])  # contiguous, oldest first
    assert len(api.live) <= 200 // 16 + 1
    trail.max_points = 50
    assert trail.segment_count <= 50
    trail.clear()
    assert trail.segment_count == 0 and api.live and api.shown() == set()
    trail.append(points[:5])
    assert np.array_equal(trail.points(), points[:5])


def test_a_cleared_trail_is_hidden_at_once_and_removed_a_few_chunks_an_append():
    """A long trail cleared (a new body) is hidden in one message, not removed chunk by
    chunk; its chunks go RETIRE_PER_APPEND with each append after; a trail cleared again and
    again with no append keeps at most MAX_RETIRED hidden layers."""
    api = FakeApi()
    trail = Trail(api, "/t", (255, 0, 0), 2.0, max_points=10_000, chunk=8)
    points = np.cumsum(np.ones((801, 3)), axis=0).astype(np.float32)
    trail.append(points[:1])
    for k in range(100):  # a chunk an append, as a live session's frames draw it
        trail.append(points[1 + 8 * k : 9 + 8 * k])
    chunks = len(api.live)
    assert chunks == 100 and api.shown() == api.live
    removed = api.removed
    trail.clear()
    assert api.removed == removed and api.shown() == set() and len(api.live) == chunks
    trail.append(points[:2])  # a first point, then a segment: one new chunk, shown
    new = api.shown()
    assert len(new) == 1 and len(api.live) == 1 + chunks - RETIRE_PER_APPEND
    appends = 0
    while len(api.live) > len(api.shown()):
        trail.append(points[2 + appends][None])
        appends += 1
    assert appends == -(-(chunks - RETIRE_PER_APPEND) // RETIRE_PER_APPEND)
    assert np.array_equal(trail.points(), points[: 2 + appends])
    assert api.removed == removed + chunks + 1  # each chunk, then its emptied layer
    for _ in range(MAX_RETIRED + 2):  # cleared again and again, each time with a chunk
        trail.append(points[:2])
        trail.clear()
    hidden = {n.rsplit("/", 1)[0] for n in api.live}
    assert len(hidden) <= MAX_RETIRED and api.shown() == set()
    trail.remove()
    assert api.live == set()


def test_a_follower_s_long_appends_make_one_node_each_then_none():
    """A follower's few own frames a second append a hundred points each: what overflows the
    head is one chunk (one node, not one per chunk size), and once the trail is full the
    chunks it drops are reused: no node made, and the length within an append of its bound."""
    api = FakeApi()
    trail = Trail(api, "/t", (255, 0, 0), 2.0, max_points=1200, chunk=24)
    points = np.cumsum(np.ones((1 + 90 * 60, 3)), axis=0).astype(np.float32)
    trail.append(points[:1])
    made = []
    for k in range(60):
        before = api.made
        trail.append(points[1 + 90 * k : 91 + 90 * k])
        made.append(api.made - before)
        assert 1200 - 90 - 24 <= trail.segment_count <= 1200 or k < 14
    assert max(made) == 1 and sum(made[30:]) == 0, made
    assert api.removed == 0
    drawn = trail.points()
    assert np.array_equal(drawn, points[-len(drawn) :])  # contiguous, oldest first
    segments = np.concatenate([h.points for h, _ in trail._frozen])
    assert np.array_equal(segments[1:, 0], segments[:-1, 1])  # chunks join end to end


def test_trail_appends_of_any_size_draw_one_unbroken_polyline():
    """Batches that straddle chunks (as a frame after a stall does) keep every point once,
    in order, and a chunk already sent is never rewritten by later appends."""
    api = FakeApi()
    trail = Trail(api, "/t", (0, 0, 255), 2.0, max_points=10_000, chunk=8)
    rng = np.random.default_rng(7)
    points = rng.normal(size=(400, 3)).astype(np.float32)
    start = 0
    for size in rng.integers(1, 30, size=200):
        if start >= len(points):
            break
        trail.append(points[start : start + size])
        start += size
    assert np.array_equal(trail.points(), points)
    segments = np.concatenate([h.points for h, _ in trail._frozen])
    assert np.array_equal(segments[1:, 0], segments[:-1, 1])  # chunks join end to end


# -- command line ----------------------------------------------------------------------
def test_cli_serve_forms_parse_alike():
    parser = cli.build_parser()
    bare = parser.parse_args([])
    assert (bare.host, bare.port, bare.func) == ("127.0.0.1", 8080, cli.serve)
    flags = parser.parse_args(["--host", "0.0.0.0", "--port", "9000"])
    assert (flags.host, flags.port, flags.func) == ("0.0.0.0", 9000, cli.serve)
    sub = parser.parse_args(["serve", "--host", "0.0.0.0", "--port", "9001", "--preset", "sphere"])
    assert (sub.command, sub.host, sub.port, sub.preset) == ("serve", "0.0.0.0", 9001, "sphere")


@pytest.mark.server  # a `poinsot serve` child process
@pytest.mark.parametrize("argv", [["-m", "poinsot.app", "serve"], ["-m", "poinsot.app"]])
def test_cli_serves_the_page_and_prints_the_url(argv):
    proc = subprocess.Popen(
        [sys.executable, *argv, "--port", "0", "--preset", "minor"],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    try:
        url = None
        deadline = time.monotonic() + 30
        while url is None and time.monotonic() < deadline:
            line = proc.stdout.readline()
            match = re.search(r"Poinsot is running at (http://\S+)", line)
            url = match.group(1) if match else None
        assert url, "no URL printed"
        with urllib.request.urlopen(url, timeout=10) as response:
            assert response.status == 200 and b"<html" in response.read().lower()
    finally:
        proc.terminate()
        proc.wait(10)
    assert wait_until(lambda: proc.poll() is not None, 30)


@pytest.mark.server  # it starts a process of its own
@pytest.mark.parametrize(
    "command", [[sys.prefix + "/bin/poinsot"], [sys.executable, "-m", "poinsot.app"]]
)
def test_console_script_and_module_forms_answer(command):
    out = subprocess.run([*command, "serve", "--help"], capture_output=True, text=True, timeout=180)
    assert out.returncode == 0 and "--host" in out.stdout and "--port" in out.stdout


def test_element_enum_matches_labels():
    from poinsot.app.live.panel.panel import ELEMENT_LABELS

    assert set(ELEMENT_LABELS) == set(Element)


# -- motion sampling and the frame budget ------------------------------------------------
def test_motion_sampler_gives_the_exact_solution_at_grid_times_in_batches():
    from poinsot.app.construction.sampled.sampling import BATCH, MotionSampler

    body = Parameters.from_preset(preset_by_key("t_handle")).build()
    sampler = MotionSampler(body, step=0.01, stride=2, t0=0.5)
    assert sampler.index(0.5) == 0 and sampler.index(0.5 + 0.0349) == 3
    assert sampler.time(3) == pytest.approx(0.53)
    first = sampler.samples(0, 0)
    later = sampler.samples(5, 40)
    assert sampler.evaluations == 1  # one physics call for a whole batch of frames
    omega, rotation, contact = body.sample(later.t)
    assert np.array_equal(later.omega, omega) and np.array_equal(later.contact, contact)
    assert np.array_equal(later.quat_xyzw, rotation.as_quat())  # exact values, no interpolation
    assert np.allclose(first.t, [0.5])
    sampler.samples(BATCH + 3, BATCH + 10)
    assert sampler.evaluations == 2


def test_grid_step_keeps_trace_chords_short():
    from poinsot.app.construction.sampled.sampling import (
        STEPS_PER_FRAME,
        MotionSampler,
        trace_speed,
    )

    body = Parameters.from_preset(preset_by_key("major")).build()
    scale = 1.0 / float(np.max(body.semi_axes))
    speed = trace_speed(body, scale)
    for frame_time in (1 / 60, 4 / 60):
        sampler = MotionSampler.for_body(body, speed, frame_time, 0.02)
        assert sampler.step <= frame_time / STEPS_PER_FRAME
        s = sampler.samples(0, 400)
        kept = s.contact[s.k % sampler.stride == 0] * scale
        chords = np.linalg.norm(np.diff(kept, axis=0), axis=1)
        assert chords.max() <= 0.02 * 1.01


def test_a_rebuild_holds_the_other_sessions_frames_for_a_bounded_time(probe, poinsot_app):
    """While some session rebuilds (a slider moved), the others hold their frames so that the
    rebuild runs alone; a rebuild that never ends holds them at most HOLD_SECONDS each."""
    from poinsot.app.live.session.session import HOLD_SECONDS

    session = session_of(poinsot_app)
    budget = poinsot_app.budget
    assert not budget.rebuilding
    assert wait_until(lambda: session.stats.frames > 5, 30)
    drawn_at = record_frame_times(session)  # by the frame thread's own clock
    with budget.rebuild():
        assert budget.rebuilding
        first = len(drawn_at)  # a frame already in progress may still be drawn unheld
        assert wait_until(lambda: len(drawn_at) >= first + 4, 30)  # held, not stopped
        held = np.diff(drawn_at[first + 1 :])
    assert not budget.rebuilding
    # Held: one frame per hold, after its period (at 60 fps a frame would come every 1/60 s).
    assert held.min() >= HOLD_SECONDS, held
    first = len(drawn_at)
    assert wait_until(lambda: len(drawn_at) >= first + 30, 30)
    assert np.diff(drawn_at[first:]).min() < HOLD_SECONDS  # free again


def test_a_held_frame_is_woken_when_the_last_rebuild_ends():
    """A session holding its frame sleeps on its own wake, which the gate sets when no rebuild
    is left (not before); with no rebuild on, nothing is held."""
    import threading

    from poinsot.app.live.hardening.budget import RebuildGate

    gate, wake = RebuildGate(), threading.Event()
    assert not gate.hold(wake)
    first, second = gate.rebuild(), gate.rebuild()
    first.__enter__()
    second.__enter__()
    assert gate.hold(wake) and not wake.is_set()
    first.__exit__(None, None, None)
    assert not wake.is_set()  # the other rebuild still runs
    second.__exit__(None, None, None)
    assert wake.is_set()
    wake.clear()
    with gate.rebuild():
        pass
    assert not wake.is_set()  # woken once: a later rebuild does not wake a frame not held
