"""Shapes the scenes draw beside Poinsot's construction: curves as line segments, translucent
surfaces, cones, arrows and markers, kept by part (:class:`Parts`) so that a part is shown,
hidden and removed as a whole.

Geometry only: every point comes from a scene's model (:mod:`poinsot.physics`), scaled to display
units by the scene. A line's colour is one uniform colour per node (the browser takes it as
sRGB, so a picture shows exactly that colour).
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import TypeVar

import numpy as np
import viser
from numpy.typing import ArrayLike

from poinsot.app.construction import meshes
from poinsot.app.construction.geometry import ArrowShape, finite, triple
from poinsot.app.construction.trail import Trail

RGB = tuple[int, int, int]
Node = TypeVar("Node", bound=viser.SceneNodeHandle)

#: A line node's points before its first fit: one degenerate segment.
NO_SEGMENT = np.zeros((1, 2, 3), np.float32)
#: An arrow's points before its first fit.
NO_ARROW = np.array([[[0.0, 0.0, 0.0], [0.0, 0.0, 1e-3]]], np.float32)
#: Thin arrows of the scenes (display units).
THIN_ARROW = ArrowShape(shaft_radius=0.012, head_radius=0.035, head_length=0.09)
#: Marker radius (display units).
MARKER_RADIUS = 0.035


def segments(curve: ArrayLike, closed: bool) -> np.ndarray:
    """A polyline (n, 3) as line segments (m, 2, 3) float32 (closed: back to the first point)."""
    points = finite("a curve", curve).reshape(-1, 3)
    if closed:
        points = np.concatenate([points, points[:1]])
    if len(points) < 2:
        return NO_SEGMENT.copy()
    points = points.astype(np.float32)
    return np.stack([points[:-1], points[1:]], axis=1)


def many_segments(curves: Iterable[tuple[ArrayLike, bool]]) -> np.ndarray:
    """Several polylines (each with its ``closed``) in one line-segments array."""
    parts = [segments(curve, closed) for curve, closed in curves]
    return np.concatenate(parts) if parts else NO_SEGMENT.copy()


def arrow_points(start: ArrayLike, end: ArrayLike) -> np.ndarray:
    """One arrow from ``start`` to ``end`` as viser takes it, (1, 2, 3) float32."""
    return np.stack([finite("an arrow", start), finite("an arrow", end)])[None].astype(np.float32)


def cone_mesh(rim: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """A cone with its apex at the origin through the closed ``rim`` (n, 3): a triangle fan,
    as (vertices, faces)."""
    points = finite("a cone's rim", rim).reshape(-1, 3)
    n = len(points)
    vertices = np.vstack([np.zeros((1, 3)), points])
    i = np.arange(n)
    faces = np.stack([np.zeros(n, dtype=np.int64), 1 + i, 1 + (i + 1) % n], axis=1)
    return vertices, faces


def unit_sphere() -> tuple[np.ndarray, np.ndarray]:
    """The unit icosphere the app's ellipsoids are made of, as (vertices, faces)."""
    vertices, faces = meshes.unit_sphere_vertices_faces()
    return vertices.copy(), faces.copy()


class Parts:
    """The scene nodes and trails of a scene's parts, by part key."""

    def __init__(self, api: viser.SceneApi) -> None:
        self.api = api
        self._nodes: dict[str, list[viser.SceneNodeHandle]] = {}
        self._trails: dict[str, list[Trail]] = {}
        self._hidden: set[str] = set()

    def keep(self, part: str, handle: Node) -> Node:
        """Keep ``handle`` as a node of ``part`` (hidden if the part is) and return it."""
        self._nodes.setdefault(part, []).append(handle)
        if part in self._hidden:
            handle.visible = False
        return handle

    def lines(self, part: str, name: str, color: RGB, width: float) -> viser.LineSegmentsHandle:
        return self.keep(
            part,
            self.api.add_line_segments(
                name, NO_SEGMENT, color, thickness=width, thickness_units="screen"
            ),
        )

    def surface(
        self,
        part: str,
        name: str,
        mesh: tuple[np.ndarray, np.ndarray],
        color: RGB,
        opacity: float | None = None,
    ) -> viser.MeshHandle:
        """A mesh; translucent and seen from both sides when ``opacity`` is given, else lit and
        flat-shaded like the presets' solids."""
        vertices, faces = mesh
        return self.keep(
            part,
            self.api.add_mesh_simple(
                name,
                vertices,
                faces,
                color=color,
                opacity=opacity,
                material="standard",
                flat_shading=opacity is None,
                side="double" if opacity is not None else "front",
                cast_shadow=False,
                receive_shadow=False,
            ),
        )

    def arrow(self, part: str, name: str, color: RGB, shape: ArrowShape) -> viser.ArrowsHandle:
        return self.keep(
            part,
            self.api.add_arrows(
                name,
                NO_ARROW,
                color,
                shaft_radius=shape.shaft_radius,
                head_radius=shape.head_radius,
                head_length=shape.head_length,
            ),
        )

    def marker(self, part: str, name: str, color: RGB) -> viser.IcosphereHandle:
        return self.keep(
            part,
            self.api.add_icosphere(name, radius=MARKER_RADIUS, color=color, cast_shadow=False),
        )

    def label(
        self, part: str, name: str, text: str, position: ArrayLike, *, centred: bool = False
    ) -> viser.LabelHandle:
        """A label whose lower left corner is at ``position`` (its lower middle if ``centred``:
        a title over a picture, as wide on either side)."""
        return self.keep(
            part,
            self.api.add_label(
                name,
                text,
                anchor="bottom-center" if centred else "bottom-left",
                font_screen_scale=1.2,
                position=triple(position),
            ),
        )

    def frame(
        self,
        part: str,
        name: str,
        position: ArrayLike = (0.0, 0.0, 0.0),
        wxyz: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0),
    ) -> viser.FrameHandle:
        return self.keep(
            part,
            self.api.add_frame(name, show_axes=False, position=triple(position), wxyz=wxyz),
        )

    def trail(self, part: str, name: str, color: RGB, width: float, points: int) -> Trail:
        trail = Trail(self.api, name, color, width, points)
        self._trails.setdefault(part, []).append(trail)
        if part in self._hidden:
            trail.visible = False
        return trail

    def set_visible(self, part: str, visible: bool) -> None:
        if visible:
            self._hidden.discard(part)
        else:
            self._hidden.add(part)
        for handle in self._nodes.get(part, []):
            handle.visible = visible
        for trail in self._trails.get(part, []):
            trail.visible = visible

    def is_visible(self, part: str) -> bool:
        return part not in self._hidden

    def remove(self) -> None:
        for trails in self._trails.values():
            for trail in trails:
                trail.remove()
        # Children before their parents: a parent's removal takes its children with it.
        handles = [h for hs in self._nodes.values() for h in hs]
        for handle in sorted(handles, key=lambda h: -h.name.count("/")):
            handle.remove()
        self._nodes.clear()
        self._trails.clear()
