"""A strobe picture: N copies of the body at equal times over an interval, as textbooks draw a
flip, beside the construction with its traces and labels at the interval's end.

The copies stand in a row below the construction as the camera sees it (spread along the
picture's horizontal, at the depth of the camera's target), each turned to the body's attitude
at its time, the earliest faintest. They are drawn in one colour that nothing else in the scene
has (a chartreuse, between the yellow ω and the green axis 2), so that a copy can be told, and
counted, in the picture. The camera is then moved sideways (not turned) so that the
construction and the row share the picture's centre, and ``poinsot screenshot`` frames both.

The default interval for a body that flips (its intermediate-axis component of ω changes sign)
is one flip: half a flip-to-flip time either side of a flip, so that the row starts with the
body calm, turns it over in the middle and ends calm the other way up. A body that does not flip
gets one period of ω, and one without a period 20 time units.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import viser

from poinsot.app.construction.ellipsoid import ellipsoid_mesh
from poinsot.app.construction.geometry import (
    DISPLAY_RADIUS,
    L_OVERSHOOT,
    PLANE_RADIUS,
    Geometry,
    triple,
)
from poinsot.app.construction.view import View
from poinsot.app.stage.scene_stage import SceneStage
from poinsot.app.stage.served import Stage
from poinsot.physics import FreeRigidBody
from poinsot.physics.models.flip import measure_flips

RGB = tuple[int, int, int]
#: The copies' colour on the dark and on the light theme (hue 81 degrees: no other element of
#: the scene has it).
STROBE_COLOR: dict[bool, RGB] = {True: (170, 230, 60), False: (105, 150, 15)}
#: Opacity of the earliest copy (the last one is opaque).
FAINTEST = 0.3
#: Copies allowed in one picture.
MAX_COPIES = 24
#: A copy's radius is at most this fraction of its slot in the row, and at most this many
#: display units (the ellipsoid's largest semi-axis is 1).
SLOT_FILL = 0.42
MAX_COPY_RADIUS = 0.5
#: The row's centres stand this many copy radii below the construction.
ROW_GAP = 1.6
#: Room kept above L's tip for its label [display units].
LABEL_ROOM = 0.3
#: Without a period, the strobe covers this much time.
DEFAULT_SPAN = 20.0


class StrobeError(ValueError):
    """A strobe that cannot be drawn (one line for the command line and the panel)."""


@dataclasses.dataclass(frozen=True)
class Strobe:
    """``copies`` copies over [t0, t1]; None for either end: the default interval's."""

    copies: int
    t0: float | None = None
    t1: float | None = None

    def __post_init__(self) -> None:
        if not 2 <= self.copies <= MAX_COPIES:
            raise StrobeError(f"a strobe has 2 to {MAX_COPIES} copies, not {self.copies}")
        for t in (self.t0, self.t1):
            if t is not None and not (math.isfinite(t) and t >= 0.0):
                raise StrobeError("the strobe's times must be finite numbers >= 0")
        if self.t0 is not None and self.t1 is not None and not self.t0 < self.t1:
            raise StrobeError(f"--from ({self.t0:g}) must come before --to ({self.t1:g})")

    def interval(self, body: FreeRigidBody | None) -> tuple[float, float]:
        """The interval asked for, its open ends filled from :func:`default_interval`."""
        if self.t0 is not None and self.t1 is not None:
            return self.t0, self.t1
        d0, d1 = default_interval(body)
        if self.t0 is not None:
            return self.t0, self.t0 + (d1 - d0)
        if self.t1 is not None:
            return max(0.0, self.t1 - (d1 - d0)), self.t1
        return d0, d1

    def times(self, body: FreeRigidBody | None) -> np.ndarray:
        """The copies' times (copies,), earliest first."""
        t0, t1 = self.interval(body)
        return np.linspace(t0, t1, self.copies)


def default_interval(body: FreeRigidBody | None) -> tuple[float, float]:
    """One flip of a flipping body (centred on its first flip at least a quarter period in),
    else one period of ω from 0, else (0, DEFAULT_SPAN)."""
    period = float(body.period) if body is not None else math.inf
    if not (math.isfinite(period) and 0 < period):
        return 0.0, DEFAULT_SPAN
    assert body is not None
    flips = measure_flips(body, 2.0 * period)  # ω about the intermediate axis changes sign
    half = period / 4.0  # flips come every half period: half of that either side
    later = flips[flips >= half]
    if later.size:
        return float(later[0] - half), float(later[0] + half)
    return 0.0, period


def body_mesh(geometry: Geometry) -> tuple[np.ndarray, np.ndarray]:
    """The body as drawn (the solid, else the energy ellipsoid): vertices (n, 3) in body
    coordinates and display units, faces (m, 3)."""
    mesh = geometry.solid_mesh
    if mesh is not None:
        return np.asarray(mesh.vertices, float), np.asarray(mesh.faces)
    mesh = ellipsoid_mesh(geometry.semi_axes)
    return np.asarray(mesh.vertices, float), np.asarray(mesh.faces)


def _basis(view: View) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """The camera's forward, right and down directions, and its distance to its target."""
    position, target = np.asarray(view.position, float), np.asarray(view.look_at, float)
    forward = target - position
    distance = float(np.linalg.norm(forward))
    forward /= distance
    right = np.cross(forward, view.up)
    right /= np.linalg.norm(right)
    return forward, right, np.cross(forward, right), distance


def construction_points(geometry: Geometry) -> np.ndarray:
    """Points that bound the construction (the plane's rim, L's tip and room for its label
    above it, the ellipsoid's reach)."""
    angle = np.linspace(0.0, 2.0 * np.pi, 72, endpoint=False)
    h = geometry.plane_height
    rim = np.column_stack([PLANE_RADIUS * np.cos(angle), PLANE_RADIUS * np.sin(angle)])
    rim = np.column_stack([rim, np.full(angle.size, h)])
    reach = DISPLAY_RADIUS * np.vstack([np.eye(3), -np.eye(3)])
    return np.vstack([rim, reach, [(0.0, 0.0, h + L_OVERSHOOT + LABEL_ROOM)]])


@dataclasses.dataclass(frozen=True)
class Row:
    """Where the copies go: centres (n, 3), the scale of the body's mesh, and the camera moved
    sideways so that construction and row share the picture's centre."""

    centres: np.ndarray
    scale: float
    camera: View
    radius: float  # a copy's reach from its centre [display units]

    def bounds(self) -> np.ndarray:
        """Points around every copy (the corners of a cube of side 2 radius about each)."""
        signs = np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).reshape(3, -1).T
        return (self.centres[:, None, :] + self.radius * signs[None]).reshape(-1, 3)


def row_below(view: View, points: np.ndarray, copies: int, mesh_radius: float) -> Row:
    """A row of ``copies`` slots below ``points`` as ``view`` sees them."""
    forward, right, down, distance = _basis(view)
    rel = points - np.asarray(view.position, float)
    depth = rel @ forward
    if np.any(depth <= 0.0):
        raise StrobeError("the camera is inside the construction: no room for a strobe row")
    x, y = (rel @ right) / depth, (rel @ down) / depth  # tangent-plane coordinates
    x0, x1, y0, y1 = float(x.min()), float(x.max()), float(y.min()), float(y.max())
    slot = distance * (x1 - x0) / copies
    radius = min(SLOT_FILL * slot, MAX_COPY_RADIUS)
    offsets = (np.arange(copies) - (copies - 1) / 2.0) * slot + distance * (x0 + x1) / 2.0
    row_y = distance * y1 + ROW_GAP * radius
    base = np.asarray(view.position, float) + distance * forward + row_y * down
    centres = base + offsets[:, None] * right
    bottom = (row_y + radius) / distance
    shift = distance * ((y0 + bottom) / 2.0 * down + (x0 + x1) / 2.0 * right)
    camera = dataclasses.replace(
        view,
        position=triple(np.asarray(view.position) + shift),
        look_at=triple(np.asarray(view.look_at) + shift),
    )
    return Row(centres, radius / mesh_radius, camera, radius)


def geometry_of(stage: Stage | SceneStage) -> Geometry:
    construction = stage.scene if isinstance(stage, Stage) else stage.poinsot
    geometry = construction.geometry
    if geometry is None:
        raise StrobeError("this scene draws no rigid body to strobe")
    return geometry


def body_of(stage: Stage | SceneStage) -> FreeRigidBody | None:
    return stage.body if isinstance(stage, Stage) else stage.poinsot.body


def add_copies(
    api: viser.SceneApi,
    geometry: Geometry,
    attitudes: list[np.ndarray],
    view: View,
    dark_mode: bool,
    prefix: str = "/strobe",
) -> tuple[Row, list[viser.MeshHandle]]:
    """The copies of the body at ``attitudes`` (wxyz, earliest first) in a row below the
    construction as ``view`` sees it; the row and the copies' handles."""
    vertices, faces = body_mesh(geometry)
    radius = float(np.linalg.norm(vertices, axis=1).max())
    row = row_below(view, construction_points(geometry), len(attitudes), radius)
    opacity = np.linspace(FAINTEST, 1.0, len(attitudes))
    handles = [
        api.add_mesh_simple(
            f"{prefix}/copy{k}",
            (vertices * row.scale).astype(np.float32),
            faces.astype(np.uint32),
            color=STROBE_COLOR[dark_mode],
            opacity=float(opacity[k]) if opacity[k] < 1.0 else None,
            wxyz=np.asarray(wxyz, float),
            position=centre,
            cast_shadow=False,
            receive_shadow=False,
        )
        for k, (wxyz, centre) in enumerate(zip(attitudes, row.centres, strict=True))
    ]
    return row, handles


def framing_fov(view: View, points: np.ndarray, aspect: float, fill: float = 0.9) -> float:
    """The vertical field of view [degrees] in which ``points`` fill ``fill`` of a picture of
    ``aspect`` (width / height) seen from ``view`` (its direction kept)."""
    forward, right, down, _ = _basis(view)
    rel = points - np.asarray(view.position, float)
    depth = rel @ forward
    if np.any(depth <= 0.0):
        raise StrobeError("the camera is inside the construction: no room for a strobe row")
    x, y = np.abs(rel @ right / depth).max(), np.abs(rel @ down / depth).max()
    return math.degrees(2.0 * math.atan(max(y, x / aspect) / fill))


def add_strobe(
    stage: Stage | SceneStage, strobe: Strobe, view: View, dark_mode: bool, aspect: float
) -> View:
    """Pose ``stage`` at the interval's end (traces drawn up to it) with the row of copies, and
    return the camera that holds both in a picture of ``aspect`` (``view`` moved sideways, its
    field of view widened or narrowed to frame them)."""
    times = strobe.times(body_of(stage))
    attitudes = [stage.seek(float(t)).wxyz for t in times]  # forward in time: traces grow
    construction = stage.scene if isinstance(stage, Stage) else stage.poinsot
    geometry = geometry_of(stage)
    with stage.atomic():
        row, _ = add_copies(construction.api, geometry, attitudes, view, dark_mode)
    points = np.vstack([construction_points(geometry), row.bounds()])
    return dataclasses.replace(row.camera, fov_degrees=framing_fov(row.camera, points, aspect))
