"""Exports without a browser: the CSV round-trips to the very doubles physics gives, the GLB
loads back with trimesh with Poinsot's incidences intact, the HTML page carries the whole
recording and nothing from the network, and the pieces of the screenshot pipeline (sizes, file
names, camera orientation, framing, compositing) do what they say."""

from __future__ import annotations

import base64
import io
import math
import os
import re
import subprocess
import sys

import msgspec
import numpy as np
import pytest
import trimesh
import zstandard
from PIL import Image

from poinsot.app.cli import main as cli
from poinsot.app.construction.cameras import BODY_VIEW, ride_along, space_view
from poinsot.app.construction.geometry import HERPOLHODE_LIFT, POLHODE_INFLATE, Geometry
from poinsot.app.construction.sampled.frames import wxyz, xyzw_from_wxyz
from poinsot.app.construction.view import VIEWS
from poinsot.app.exports import chromium, glb, run_csv, screenshot
from poinsot.app.exports import html as html_export
from poinsot.app.model.parameters import Parameters
from poinsot.app.model.presets import PRESETS, preset_by_key
from poinsot.physics.core import rotations

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
#: Relative agreement of independently computed quantities (double rounding only).
CLOSE = 1e-12
#: glTF stores vertices as float32: positions of size ~1 round to ~6e-8.
FLOAT32 = 1e-6
#: The ellipsoid mesh is an icosphere with chord error ~2e-3 of the radius
# (app/construction/meshes.py).
MESH_CHORD = 3e-3


def body_of(key: str):
    return Parameters.from_preset(preset_by_key(key)).build()


def turned(q_wxyz: np.ndarray, v: np.ndarray) -> np.ndarray:
    """q v q^-1 for scalar-first unit quaternions (N, 4) and vectors (N, 3), by the project's
    one quaternion algebra (physics.core.rotations, independent of scipy)."""
    return rotations.rotate(xyzw_from_wxyz(q_wxyz), v)


# -- CSV -------------------------------------------------------------------------------------
@pytest.mark.parametrize("key", ["major", "t_handle", "separatrix", "sphere"])
def test_csv_round_trips_to_the_same_doubles(key):
    body = body_of(key)
    text = run_csv.run_csv(body, 25.0, name=key, source=preset_by_key(key).source)
    run = run_csv.read_run_csv(text)
    assert run.t[0] == 0.0 and run.t[-1] == 25.0
    assert np.all(np.diff(run.t) > 0)
    omega, rotation = body.state(run.t)
    # Written with the shortest exact representation: reading back gives identical doubles.
    assert np.array_equal(run.omega, omega)
    assert np.array_equal(np.abs(run.quaternion), np.abs(wxyz(rotation)))
    assert run.meta["scene"] == key
    assert run.meta["regime"] == body.regime.name
    assert run.meta["quaternion"] == run_csv.QUATERNION_CONVENTION
    inertia = [float(x) for x in run.meta["inertia I1, I2, I3"].split(",")]
    assert inertia == list(body.inertia)


def test_csv_quaternion_follows_the_convention_in_its_header():
    """The header says scalar first, body -> space, continuous sign: check each claim against
    physics' contact point R(t) omega(t), computed by physics, not from the quaternion."""
    body = body_of("t_handle")
    run = run_csv.read_run_csv(run_csv.run_csv(body, 40.0))
    assert "scalar first" in run.meta["quaternion"] and "body -> space" in run.meta["quaternion"]
    assert np.allclose(np.linalg.norm(run.quaternion, axis=1), 1.0, atol=CLOSE)
    assert run.quaternion[0, 0] >= 0.0
    assert np.all(np.einsum("ij,ij->i", run.quaternion[1:], run.quaternion[:-1]) > 0.0)
    rotated = turned(run.quaternion, run.omega)
    assert np.allclose(rotated, body.contact_point(run.t), rtol=0, atol=1e-12)
    # L = R (I omega) is constant and along +z in the space frame.
    L = turned(run.quaternion, run.omega * np.asarray(body.inertia))
    assert np.allclose(L, body.angular_momentum, atol=1e-12)
    assert np.allclose(L[:, :2], 0.0, atol=1e-12)


def test_csv_covers_the_run_or_one_period():
    body = body_of("major")
    assert run_csv.run_span(body, 0.0) == pytest.approx(body.period)
    assert run_csv.run_span(body, 12.5) == 12.5
    assert run_csv.run_span(body_of("sphere"), 0.0) == run_csv.DEFAULT_SPAN
    t = run_csv.sample_times(body, 1e6)
    assert len(t) == run_csv.MAX_ROWS


def test_csv_reader_rejects_other_files():
    with pytest.raises(ValueError, match="column header"):
        run_csv.read_run_csv("# a comment\na,b,c\n1,2,3\n")
    with pytest.raises(ValueError, match="no column header"):
        run_csv.read_run_csv("# only comments\n")


# -- GLB -------------------------------------------------------------------------------------
def load_glb(data: bytes) -> trimesh.Scene:
    return trimesh.load(io.BytesIO(data), file_type="glb", force="scene")


def world_vertices(scene: trimesh.Scene, node: str) -> np.ndarray:
    """A node's vertices in the file's (glTF, y-up) world."""
    transform, geometry = scene.graph.get(node)
    return trimesh.transform_points(scene.geometry[geometry].vertices, transform)


def space_vertices(scene: trimesh.Scene, node: str) -> np.ndarray:
    """A node's vertices in the app's z-up space frame (undoing the glTF y-up root)."""
    return trimesh.transform_points(world_vertices(scene, node), np.linalg.inv(glb.Z_UP_TO_Y_UP))


@pytest.mark.parametrize("key,t", [("major", 3.7), ("t_handle", 11.0), ("oblate", 2.0)])
def test_glb_loads_back_with_the_named_geometries_and_the_incidences(key, t):
    preset = preset_by_key(key)
    body = Parameters.from_preset(preset).build()
    geometry = Geometry.from_body(body, preset.solid)
    scene = load_glb(glb.scene_glb(body, t, geometry=geometry))
    assert set(glb.GLB_NAMES) <= set(scene.geometry)
    assert "solid" in scene.geometry
    s, h = geometry.scale, geometry.plane_height
    R = body.attitude(t).as_matrix()
    # The ellipsoid, carried by the body node, is the energy ellipsoid at the attitude R(t) ...
    ellipsoid = space_vertices(scene, "ellipsoid")
    in_body = ellipsoid @ R  # R^T x for each row
    radius = np.sqrt(np.sum((in_body / geometry.semi_axes) ** 2, axis=1))
    assert np.allclose(radius, 1.0, rtol=0, atol=FLOAT32)
    # ... under the invariable plane, touching it (to the mesh's chord error).
    assert ellipsoid[:, 2].max() <= h + FLOAT32
    assert ellipsoid[:, 2].max() >= h - MESH_CHORD
    # The contact marker sits at physics' contact point, on the plane.
    contact = space_vertices(scene, "contact").mean(axis=0)
    assert np.allclose(contact, body.contact_point(t) * s, rtol=0, atol=FLOAT32)
    assert contact[2] == pytest.approx(h, abs=FLOAT32)
    plane = space_vertices(scene, "plane")
    assert np.allclose(plane[:, 2], h, rtol=0, atol=FLOAT32)
    # The herpolhode tube runs on the plane (its centre line is lifted against z-fighting).
    herpolhode = space_vertices(scene, "herpolhode")
    assert np.all(np.abs(herpolhode[:, 2] - h - HERPOLHODE_LIFT) <= glb.TUBE_RADIUS + FLOAT32)
    # The polhode tube lies on the (drawn, slightly inflated) ellipsoid in the body frame.
    polhode = space_vertices(scene, "polhode") @ R
    r = np.sqrt(np.sum((polhode / (geometry.semi_axes * POLHODE_INFLATE)) ** 2, axis=1))
    assert np.all(np.abs(r - 1.0) <= 1.05 * glb.TUBE_RADIUS / geometry.semi_axes.min())
    # glTF is y-up: L, vertical in the app, points along +y of the file's world.
    arrow = world_vertices(scene, "L")
    assert arrow[:, 1].max() == pytest.approx(h + 0.65, abs=FLOAT32)
    assert np.abs(arrow[:, [0, 2]]).max() < 0.06  # the head's radius


def test_tube_follows_its_polyline_without_twisting():
    angles = np.linspace(0, 2 * np.pi, 200)
    helix = np.stack([np.cos(angles), np.sin(angles), 0.1 * angles], 1)
    mesh = glb.tube(helix, radius=0.05, sides=8)
    ring = mesh.vertices.reshape(len(helix), 8, 3)
    distance = np.linalg.norm(ring - helix[:, None, :], axis=2)
    assert np.allclose(distance, 0.05, atol=1e-12)
    # Neighbouring rings keep their orientation (no twist): vertex k moves little.
    step = np.linalg.norm(np.diff(ring, axis=0), axis=2)
    assert step.max() < 3 * np.linalg.norm(np.diff(helix, axis=0), axis=1).max()
    with pytest.raises(ValueError):
        glb.tube(np.zeros((5, 3)))


# -- HTML ------------------------------------------------------------------------------------
def embedded_recording(html: str) -> dict:
    """Decode the scene recording viser's as_html embeds (base64 of the serializer's bytes:
    8-byte size, zstd of [8-byte msgpack size, msgpack, binary buffers])."""
    data = re.search(r'window\.__VISER_EMBED_DATA__="([A-Za-z0-9+/=]*)"', html)
    assert data, "no embedded recording"
    raw = base64.b64decode(data.group(1))
    size = int.from_bytes(raw[:8], "little")
    inner = zstandard.ZstdDecompressor().decompress(raw[8:], max_output_size=size)
    length = int.from_bytes(inner[:8], "little")
    return msgspec.msgpack.decode(inner[8 : 8 + length])


def test_html_is_self_contained_and_records_every_frame():
    preset = preset_by_key("t_handle")
    html = html_export.preset_html(preset, 2.0, fps=15)
    assert html.startswith("<!doctype html>")
    assert f"<title>Poinsot: {preset.label}</title>" in html
    # Nothing is fetched: no external scripts, styles or URLs besides the SVG namespace.
    assert not re.search(r"<(script|link|img)[^>]+(src|href)=\"(?!data:)", html)
    urls = set(re.findall(r"https?://[^\s\"')]+", html))
    assert all(u.startswith("http://www.w3.org/") for u in urls), urls
    recording = embedded_recording(html)
    assert recording["durationSeconds"] == pytest.approx(2.0)
    messages = recording["messages"]
    names = {m.get("name") for _, m in messages}
    assert {"/space/body/ellipsoid", "/space/plane/disc", "/space/L"} <= names
    times = [
        t
        for t, m in messages
        if m.get("type") == "SetOrientationMessage" and m.get("name") == "/space/body"
    ]
    assert len(times) == 30 + 1  # the snapshot at t = 0 and one pose per frame
    assert np.allclose(np.diff(times), 1 / 15)
    assert any(m.get("type") == "SetCameraFovMessage" for _, m in messages)


def test_html_of_a_20_second_clip_is_small():
    html = html_export.preset_html(preset_by_key("major"), 20.0)
    size = len(html.encode("utf-8"))
    # ~0.82 MB is viser's client itself; the 600 recorded frames add ~0.12 MB.
    assert size < 1.1e6, size
    recording = embedded_recording(html)
    assert recording["durationSeconds"] == pytest.approx(20.0)


def test_html_rejects_bad_lengths():
    preset = preset_by_key("major")
    with pytest.raises(ValueError):
        html_export.preset_html(preset, 0.0)
    with pytest.raises(ValueError):
        html_export.preset_html(preset, 5.0, fps=500)


# -- screenshot pieces -----------------------------------------------------------------------
def test_sizes_and_file_names():
    assert screenshot.parse_size("1920x1080") == (1920, 1080)
    assert screenshot.parse_size(" 3840×2160 ") == (3840, 2160)
    for bad in ("1920", "0x10", "99999x10", "axb"):
        with pytest.raises(ValueError):
            screenshot.parse_size(bad)
    assert screenshot.filename("t_handle", 12.345) == "poinsot_t_handle_t12.35.png"
    assert screenshot.filename("a b/c", 0.0, "csv") == "poinsot_a-b-c_t0.00.csv"


def test_png_is_opaque_on_the_theme_or_transparent():
    rgba = np.zeros((6, 8, 4), np.uint8)
    rgba[2:4, 2:4] = (255, 179, 71, 255)
    rgba[0, 0] = (255, 255, 255, 128)
    opaque = Image.open(io.BytesIO(screenshot.png_bytes(rgba, (20, 20, 20))))
    assert opaque.mode == "RGB" and opaque.size == (8, 6)
    pixels = np.asarray(opaque)
    assert tuple(pixels[5, 7]) == (20, 20, 20) and tuple(pixels[2, 2]) == (255, 179, 71)
    assert abs(int(pixels[0, 0, 0]) - (255 * 128 + 20 * 127) // 255) <= 1
    clear = Image.open(io.BytesIO(screenshot.png_bytes(rgba, None)))
    assert clear.mode == "RGBA" and np.array_equal(np.asarray(clear), rgba)


def test_camera_orientation_looks_at_its_target():
    for view in (*VIEWS.values(), space_view("body", np.array([0.9, 0.1, -0.3, 0.3]) / 1.0)):
        q = screenshot.camera_wxyz(view)
        R = np.asarray(trimesh.transformations.quaternion_matrix(q))[:3, :3]
        forward = np.subtract(view.look_at, view.position)
        forward /= np.linalg.norm(forward)
        assert np.allclose(R[:, 2], forward, atol=1e-12)  # camera +z looks at the target
        up = np.asarray(view.up) - forward * np.dot(view.up, forward)
        assert np.dot(-R[:, 1], up) > 0  # camera -y is the view's up


def test_framing_scales_about_the_centre():
    rgba = np.zeros((100, 200, 4), np.uint8)
    rgba[40:60, 80:130, 3] = 255  # reaches 30 px right of centre: 0.3 of the half-width
    assert screenshot.content_extent(rgba) == pytest.approx(0.3)
    fov = math.radians(45)
    fitted = screenshot.fitted_fov(fov, 0.3, fill=0.9)
    assert math.tan(fov / 2) / math.tan(fitted / 2) * 0.3 == pytest.approx(0.9)
    assert screenshot.fitted_fov(fov, 0.0) == fov


def test_ride_along_view_turns_with_the_body():
    q = np.array([math.cos(0.4), 0.0, 0.0, math.sin(0.4)])  # 0.8 rad about z
    view = ride_along(BODY_VIEW, q)
    c, s_ = math.cos(0.8), math.sin(0.8)
    x, y, z = BODY_VIEW.position
    assert np.allclose(view.position, (c * x - s_ * y, s_ * x + c * y, z))
    assert np.allclose(view.up, BODY_VIEW.up)
    with pytest.raises(ValueError):
        space_view("body")
    with pytest.raises(ValueError):
        space_view("nowhere")


def test_every_preset_stages_and_seeks():
    """Each preset's stage loads and seeks (what the CLI does before it opens a browser)."""
    from poinsot.app.stage.served import Stage

    for preset in PRESETS:
        with Stage.from_preset(preset) as stage:
            frame = stage.seek(3.0)
            assert frame.t == 3.0
            assert np.all(np.isfinite(frame.wxyz))
            back = stage.seek(1.0)  # going back restarts the traces
            assert back.t == 1.0


def run_cli(*args: str, env: dict[str, str] | None = None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "poinsot.app", *args],
        cwd=ROOT,
        env={**os.environ, **(env or {})},
        capture_output=True,
        text=True,
        timeout=120,
    )


@pytest.mark.server  # it starts a process of its own
def test_cli_screenshot_without_chromium_says_how_to_install_it(tmp_path):
    out = tmp_path / "x.png"
    done = run_cli(
        "screenshot",
        "--out",
        str(out),
        env={chromium.CHROMIUM_ENV: str(tmp_path / "no-chromium")},
    )
    assert done.returncode == chromium.EXIT_NO_BROWSER != 0
    assert "sudo apt-get install chromium" in done.stderr
    assert not out.exists()


def test_cli_screenshot_rejects_bad_arguments(tmp_path, capsys):
    """Through ``main`` in this process (the test above runs the command as a process)."""
    for args, message in (
        (["--scene", "no such scene"], "no preset named"),
        (["--size", "big"], "size must look like"),
    ):
        with pytest.raises(SystemExit) as exit_:
            cli.main(["screenshot", *args, "--out", str(tmp_path / "x.png")])
        assert exit_.value.code == 2 and message in capsys.readouterr().err
    assert screenshot.resolve_scene("Sphere (a cube)").key == "sphere"
    assert screenshot.resolve_scene("T_HANDLE").key == "t_handle"


@pytest.mark.slow
def test_cli_export_html_writes_the_page(tmp_path):
    out = tmp_path / "clip.html"
    done = run_cli("export-html", "--preset", "oblate", "--seconds", "1.5", "--out", str(out))
    assert done.returncode == 0, done.stderr
    assert re.search(
        r"wrote .*clip\.html \(0\.\d\d MB, 1\.5 s at 30 fps, preset oblate\)", done.stdout
    ), done.stdout
    recording = embedded_recording(out.read_text(encoding="utf-8"))
    assert recording["durationSeconds"] == pytest.approx(1.5)
