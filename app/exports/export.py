"""Exports for lectures and students: the run as CSV, Poinsot's construction as a GLB mesh, and
the animation as one standalone HTML page.

Every number comes from :mod:`physics` (``FreeRigidBody.state``, ``contact_point``,
``polhode``); this module only samples, formats and packs.

- **CSV**: t, omega (body frame) and the attitude quaternion, written with 17 significant
  digits so that reading it back gives the same doubles; the header names the quaternion
  convention (:data:`QUATERNION_CONVENTION`) and the body. :func:`read_run_csv` reads it back.
- **GLB**: the energy ellipsoid (posed at the current attitude), the invariable plane, the
  polhode (on the ellipsoid, in the body node) and the herpolhode (on the plane), as named
  trimesh geometries. glTF is y-up: the root node ``space`` turns the app's z-up space frame
  (L vertical) into y-up, so Blender and glTF viewers show L vertical too.
- **HTML**: a :class:`app.stage.Stage` recorded frame by frame with viser's scene serializer
  (``insert_sleep`` between frames, ``as_html``): the viser client and the recording in one
  file that plays from ``file://`` with no server.
"""

from __future__ import annotations

import argparse
import dataclasses
import io
import math
import pathlib
import re
import time

import numpy as np
import trimesh
import trimesh.visual.material
from poinsot.app.exports.stage import Stage
from poinsot.app.parameters import Parameters
from poinsot.app.presets import Element, Preset, Solid, preset_by_key
from poinsot.app.scene import meshes, palette
from poinsot.app.scene.construction import HERPOLHODE_LIFT, PLANE_RADIUS, POLHODE_INFLATE, Geometry
from poinsot.app.scene.frames import wxyz
from poinsot.app.scene.view import DEFAULT_VIEW, View
from poinsot.physics import FreeRigidBody

# -- CSV ------------------------------------------------------------------------------------

#: Written into the CSV header; the one convention of every quaternion this module exports.
QUATERNION_CONVENTION = (
    "q = (qw, qx, qy, qz): unit quaternion, scalar first (Hamilton product), the attitude "
    "body -> space (v_space = q v_body q^-1; columns of its matrix = body axes in space), "
    "space frame with L along +z; sign continuous in time, qw >= 0 at the first row"
)
CSV_COLUMNS = ("t", "omega1", "omega2", "omega3", "qw", "qx", "qy", "qz")
#: Samples per period of omega (and time step where omega has no period).
SAMPLES_PER_PERIOD = 200
APERIODIC_STEP = 0.02
#: Rows at most (a 20 000-row file is about 3 MB).
MAX_ROWS = 20_001
#: A run shorter than this is exported over one period of omega instead (a freshly loaded
#: scene still gives a useful file) [time units].
MIN_RUN = 1e-9
DEFAULT_SPAN = 20.0


@dataclasses.dataclass(frozen=True)
class Run:
    """Samples of one run: ``t`` (N,), ``omega`` (N, 3) body frame, ``quaternion`` (N, 4) in
    :data:`QUATERNION_CONVENTION`, and the header's ``key: value`` pairs."""

    t: np.ndarray
    omega: np.ndarray
    quaternion: np.ndarray
    meta: dict[str, str]


def run_span(body: FreeRigidBody, t_now: float) -> float:
    """The time span an export covers: the run so far, or one period of omega (20 time units
    where omega has none) if the run has not started yet."""
    if math.isfinite(t_now) and t_now > MIN_RUN:
        return float(t_now)
    period = float(body.period)
    return period if math.isfinite(period) and period > 0 else DEFAULT_SPAN


def sample_times(body: FreeRigidBody, t_end: float) -> np.ndarray:
    """0 .. t_end with SAMPLES_PER_PERIOD samples per period of omega, at most MAX_ROWS."""
    period = float(body.period)
    step = period / SAMPLES_PER_PERIOD if math.isfinite(period) and period > 0 else APERIODIC_STEP
    rows = min(MAX_ROWS, max(2, math.ceil(t_end / step) + 1))
    return np.linspace(0.0, float(t_end), rows)


def continuous_quaternions(q: np.ndarray) -> np.ndarray:
    """Flip signs so that consecutive quaternions lie in the same hemisphere (q and -q are
    the same attitude; a continuous series is what students plot)."""
    q = np.array(q, dtype=np.float64, copy=True)
    if len(q) > 1:
        flips = np.einsum("ij,ij->i", q[1:], q[:-1]) < 0.0
        sign = np.concatenate([[1.0], np.where(np.cumsum(flips) % 2 == 1, -1.0, 1.0)])
        q *= sign[:, None]
    return q


def sample_run(body: FreeRigidBody, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """omega (N, 3) and the attitude quaternions (N, 4) at times ``t``, from physics."""
    omega, rotation = body.state(np.asarray(t, dtype=np.float64))
    return np.asarray(omega), continuous_quaternions(wxyz(rotation))


def _fmt(values) -> str:
    """Shortest text that reads back as the same doubles (Python's float repr)."""
    return ", ".join(repr(float(v)) for v in np.ravel(values))


def run_csv(body: FreeRigidBody, t_end: float, *, name: str = "", source: str = "") -> str:
    """The run 0 <= t <= t_end as CSV text (header comments start with ``#``)."""
    t = sample_times(body, t_end)
    omega, q = sample_run(body, t)
    header = {
        "poinsot run": "torque-free rigid body, exact closed-form solution (physics.FreeRigidBody)",
        "scene": name,
        "source": source,
        "inertia I1, I2, I3": _fmt(body.inertia),
        "omega0 (body frame)": _fmt(body.omega0),
        "angular momentum L (space frame)": _fmt(body.angular_momentum),
        "energy T": _fmt([body.energy]),
        "D = |L|^2/2T": _fmt([body.D]),
        "regime": body.regime.name,
        "period of omega": _fmt([body.period]),
        "omega": "angular velocity in the body frame, principal axes 1, 2, 3 as the inertia",
        "quaternion": QUATERNION_CONVENTION,
        "rows": f"{len(t)}, t from 0 to {_fmt([t[-1]])}",
    }
    out = io.StringIO()
    for key, value in header.items():
        if value:
            out.write(f"# {key}: {value}\n")
    out.write(",".join(CSV_COLUMNS) + "\n")
    data = np.column_stack([t, omega, q])
    out.write("\n".join(",".join(map(repr, row)) for row in data.tolist()))
    out.write("\n")
    return out.getvalue()


def read_run_csv(text: str) -> Run:
    """Parse :func:`run_csv` output (or any file with the same columns)."""
    meta: dict[str, str] = {}
    lines = text.splitlines()
    body_start = 0
    for i, line in enumerate(lines):
        if line.startswith("#"):
            key, _, value = line[1:].partition(":")
            meta[key.strip()] = value.strip()
            continue
        if tuple(c.strip() for c in line.split(",")) != CSV_COLUMNS:
            raise ValueError(f"expected the column header {','.join(CSV_COLUMNS)!r}, got {line!r}")
        body_start = i + 1
        break
    else:
        raise ValueError("no column header found")
    data = np.loadtxt(io.StringIO("\n".join(lines[body_start:])), delimiter=",", ndmin=2)
    if data.shape[1] != len(CSV_COLUMNS):
        raise ValueError(f"expected {len(CSV_COLUMNS)} columns, got {data.shape[1]}")
    return Run(data[:, 0], data[:, 1:4], data[:, 4:8], meta)


# -- GLB ------------------------------------------------------------------------------------

#: Tube radius of the exported polhode and herpolhode, and its number of sides [display units].
TUBE_RADIUS = 0.008
TUBE_SIDES = 10
#: Points of the exported herpolhode (one period of omega before the current time).
HERPOLHODE_POINTS = 1200
#: Names of the geometries in the GLB (tests and users look for them).
GLB_NAMES = ("ellipsoid", "plane", "polhode", "herpolhode", "contact", "omega", "L")
#: glTF is y-up; the app's space frame is z-up (L vertical): x -> x, z -> y, y -> -z.
Z_UP_TO_Y_UP = np.array(
    [[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, -1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
)


def _pbr(rgb: palette.RGB, opacity: float = 1.0) -> trimesh.visual.material.PBRMaterial:
    return trimesh.visual.material.PBRMaterial(
        baseColorFactor=[*(c / 255.0 for c in rgb), opacity],
        metallicFactor=0.0,
        roughnessFactor=0.5,
        alphaMode="BLEND" if opacity < 1.0 else "OPAQUE",
        doubleSided=opacity < 1.0,
    )


def _painted(mesh: trimesh.Trimesh, rgb: palette.RGB, opacity: float = 1.0) -> trimesh.Trimesh:
    mesh.visual = trimesh.visual.TextureVisuals(material=_pbr(rgb, opacity))
    return mesh


def tube(
    points: np.ndarray, radius: float = TUBE_RADIUS, sides: int = TUBE_SIDES
) -> trimesh.Trimesh:
    """A tube of ``radius`` around the polyline ``points`` (N, 3), with rotation-minimising
    frames (each normal is the previous one with its tangential part removed), so that it
    does not twist."""
    pts = np.asarray(points, dtype=np.float64)
    keep = np.concatenate([[True], np.linalg.norm(np.diff(pts, axis=0), axis=1) > 1e-12])
    pts = pts[keep]
    if len(pts) < 2:
        raise ValueError("a tube needs at least two distinct points")
    tangents = np.gradient(pts, axis=0)
    tangents /= np.linalg.norm(tangents, axis=1, keepdims=True)
    normals = np.empty_like(pts)
    seed = np.eye(3)[int(np.argmin(np.abs(tangents[0])))]
    n = seed - tangents[0] * (seed @ tangents[0])
    # Sequential by nature (each frame comes from the previous one); a loop over the polyline's
    # vertices, a few thousand at most, run once per export.
    for i, tangent in enumerate(tangents):
        n = n - tangent * (n @ tangent)
        norm = np.linalg.norm(n)
        if norm < 1e-9:  # the tangent turned onto the old normal: take any perpendicular
            seed = np.eye(3)[int(np.argmin(np.abs(tangent)))]
            n = seed - tangent * (seed @ tangent)
            norm = np.linalg.norm(n)
        n = n / norm
        normals[i] = n
    binormals = np.cross(tangents, normals)
    angles = np.linspace(0.0, 2.0 * np.pi, sides, endpoint=False)
    ring = (
        np.cos(angles)[None, :, None] * normals[:, None]
        + np.sin(angles)[None, :, None] * binormals[:, None]
    )
    vertices = (pts[:, None, :] + radius * ring).reshape(-1, 3)
    i = np.arange(len(pts) - 1)[:, None]
    j = np.arange(sides)[None, :]
    a, b = i * sides + j, i * sides + (j + 1) % sides
    c, d = a + sides, b + sides
    faces = np.concatenate([np.stack([a, b, d], -1), np.stack([a, d, c], -1)]).reshape(-1, 3)
    return trimesh.Trimesh(vertices=vertices, faces=faces, process=False)


def _arrow(tip: np.ndarray, shaft: float, head: float, head_length: float) -> trimesh.Trimesh:
    """An arrow from the origin to ``tip``."""
    tip = np.asarray(tip, dtype=np.float64)
    length = float(np.linalg.norm(tip))
    direction = tip / length
    cylinder = trimesh.creation.cylinder(
        radius=shaft, segment=[np.zeros(3), direction * (length - head_length)], sections=24
    )
    cone = trimesh.creation.cone(radius=head, height=head_length, sections=24)
    align = trimesh.geometry.align_vectors([0.0, 0.0, 1.0], direction)
    align[:3, 3] = direction * (length - head_length)
    cone.apply_transform(align)
    return trimesh.util.concatenate([cylinder, cone])


def scene_glb(
    body: FreeRigidBody,
    t: float,
    geometry: Geometry | None = None,
    solid: Solid | None = None,
) -> bytes:
    """Poinsot's construction at time ``t`` as GLB bytes, in the app's display units.

    ``geometry``: what the app's scene already computed for ``body`` (sizes, polhode, solid
    mesh); computed here from ``body`` and ``solid`` if omitted.
    """
    g = geometry if geometry is not None else Geometry.from_body(body, solid)
    s = g.scale
    t = float(t)
    _, rotation = body.state(np.array([t]))
    attitude = np.eye(4)
    attitude[:3, :3] = rotation.as_matrix()[0]
    contact = np.asarray(body.contact_point(np.array([t])))[0] * s
    period = float(body.period)
    span = period if math.isfinite(period) and period > 0 else DEFAULT_SPAN
    herpolhode = (
        np.asarray(
            body.contact_point(np.linspace(t - span, t, HERPOLHODE_POINTS)), dtype=np.float64
        )
        * s
    )

    scene = trimesh.Scene(base_frame="world")
    scene.graph.update(frame_from="world", frame_to="space", matrix=Z_UP_TO_Y_UP)
    scene.graph.update(frame_from="space", frame_to="body", matrix=attitude)

    def add(name: str, mesh: trimesh.Trimesh, parent: str) -> None:
        scene.add_geometry(mesh, geom_name=name, node_name=name, parent_node_name=parent)

    ellipsoid = meshes.ellipsoid_unit_mesh()
    ellipsoid.apply_transform(np.diag([*g.semi_axes, 1.0]))
    _painted(ellipsoid, palette.ELLIPSOID, palette.ELLIPSOID_OPACITY)
    add("ellipsoid", ellipsoid, "body")

    polhode = g.polhode * POLHODE_INFLATE
    if g.polhode_closed:
        polhode = np.concatenate([polhode, polhode[:1]])
    add("polhode", _painted(tube(polhode), palette.POLHODE), "body")
    if g.solid_mesh is not None:
        add("solid", g.solid_mesh.copy(), "body")

    vertices, faces = meshes.disc_mesh(PLANE_RADIUS)
    plane = trimesh.Trimesh(
        vertices=vertices + [0.0, 0.0, g.plane_height], faces=faces, process=False
    )
    add("plane", _painted(plane, palette.PLANE, 0.35), "space")
    lifted = herpolhode + [0.0, 0.0, HERPOLHODE_LIFT]
    add("herpolhode", _painted(tube(lifted), palette.HERPOLHODE), "space")
    add(
        "contact",
        _painted(
            trimesh.creation.icosphere(2, radius=0.035).apply_translation(contact), palette.CONTACT
        ),
        "space",
    )
    add("omega", _painted(_arrow(contact, 0.014, 0.04, 0.11), palette.OMEGA), "space")
    top = np.array([0.0, 0.0, g.plane_height + 0.65])
    add("L", _painted(_arrow(top, 0.016, 0.05, 0.14), palette.ANGULAR_MOMENTUM), "space")
    return scene.export(file_type="glb")


# -- HTML -----------------------------------------------------------------------------------

#: Frames per second of the recorded animation: smooth, and half the bytes of 60.
HTML_FPS = 30.0
#: Longest clip [s]. The page is viser's client (0.82 MB) plus the recording: a 20 s clip at
#: 30 fps adds ~0.12 MB (0.94 MB in all), about 6 kB per second.
HTML_MAX_SECONDS = 600.0


def animation_html(
    params: Parameters,
    solid: Solid | None,
    elements: frozenset[Element],
    *,
    seconds: float,
    speed: float = 1.0,
    fps: float = HTML_FPS,
    trail_points: int = 1200,
    view: View = DEFAULT_VIEW,
    dark_mode: bool = True,
    title: str = "Poinsot",
) -> str:
    """A standalone HTML page that plays ``seconds`` of the motion (``speed`` simulation time
    units per second), looping, in any browser, from a file."""
    if not (math.isfinite(seconds) and 0 < seconds <= HTML_MAX_SECONDS):
        raise ValueError(f"the clip length must be in (0, {HTML_MAX_SECONDS:g}] seconds")
    if not (math.isfinite(fps) and 1 <= fps <= 60):
        raise ValueError("the frame rate must be between 1 and 60 per second")
    with Stage(params, solid, elements, trail_points=trail_points, dark_mode=dark_mode) as stage:
        stage.set_initial_camera(view)
        serializer = stage.server.get_scene_serializer()  # snapshot: the scene at t = 0
        frames = round(seconds * fps)
        for i in range(1, frames + 1):
            serializer.insert_sleep(1.0 / fps)
            stage.advance(i / fps * speed)
        html = serializer.as_html(dark_mode=dark_mode)
    safe_title = re.sub(r"[<>&\"]", "", title)
    return html.replace("<title>Viser</title>", f"<title>{safe_title}</title>", 1)


def preset_html(preset: Preset, seconds: float, **kwargs) -> str:
    kwargs.setdefault("speed", preset.speed)
    kwargs.setdefault("trail_points", preset.trail_points)
    kwargs.setdefault("title", f"Poinsot: {preset.label}")
    return animation_html(
        Parameters.from_preset(preset), preset.solid, preset.elements, seconds=seconds, **kwargs
    )


def export_html_command(args: argparse.Namespace) -> int:
    """``poinsot export-html``: write the clip, print where and how big."""
    from poinsot.app.scene.cameras import space_view

    preset = preset_by_key(args.preset)
    start = time.perf_counter()
    html = preset_html(
        preset, args.seconds, fps=args.fps, view=space_view(args.view), dark_mode=not args.light
    )
    out = pathlib.Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(html, encoding="utf-8")
    size = out.stat().st_size
    print(
        f"wrote {out} ({size / 1e6:.2f} MB, {args.seconds:g} s at {args.fps:g} fps, "
        f"preset {preset.key}) in {time.perf_counter() - start:.1f} s"
    )
    return 0


def add_export_html_arguments(parser: argparse.ArgumentParser, presets: list[str]) -> None:
    parser.add_argument("--preset", default=presets[0], choices=presets, help="scene to record")
    parser.add_argument("--seconds", type=float, default=20.0, help="clip length (wall seconds)")
    parser.add_argument("--fps", type=float, default=HTML_FPS, help="recorded frames per second")
    parser.add_argument(
        "--view",
        default="default",
        choices=("default", "top", "side"),
        help="initial camera (the viewer can still orbit)",
    )
    parser.add_argument("--light", action="store_true", help="light theme (default: dark)")
    parser.add_argument("--out", required=True, help="output .html file")
