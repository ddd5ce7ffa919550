"""The scene elements as viser nodes: one class per :class:`~poinsot.app.model.elements.Element`.

Each :class:`Drawing` creates its nodes once (when the element is declared), sends what
changes with the body in :meth:`Drawing.fit` (sizes, static curves: once per parameter
change), and is shown, hidden or removed as a whole. What changes per frame (the body's pose,
the contact point, the omega arrow, the traces' increments) is sent by
:class:`~poinsot.app.construction.construction.PoinsotScene`, through :attr:`OmegaArrow.arrow` and
:attr:`Trace.trail`. A drawing takes a :class:`~poinsot.app.construction.palette.Look` in
:meth:`Drawing.restyle` (theme, projector), and offers its labels to the layout
(:mod:`poinsot.app.construction.labels.layout`) in :meth:`Drawing.slots` and :meth:`Drawing.place`.

The base class is in :mod:`.drawing`, the ellipsoid in :mod:`.ellipsoid`, the traced curves
in :mod:`.traces`; this module holds the other fixed elements and :func:`draw`.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import viser

from poinsot.app.construction import meshes, palette, updates
from poinsot.app.construction.drawing import (
    BEYOND,
    BODY_CLEARANCE,
    HEAD_CLEARANCE,
    MARKER_CLEARANCE,
    NO_SEGMENT,
    ORIGIN_RADIUS,
    UNIT_ARROW,
    Drawing,
)
from poinsot.app.construction.ellipsoid import Ellipsoid
from poinsot.app.construction.geometry import (
    CONTACT_RADIUS,
    GRID_SPACING,
    L_ARROW,
    L_OVERSHOOT,
    OMEGA_ARROW,
    PLANE_RADIUS,
    POLHODE_INFLATE,
    Geometry,
    triple,
)
from poinsot.app.construction.labels.layout import Placement, Slot
from poinsot.app.construction.labels.nodes import LabelNode, Pose
from poinsot.app.construction.palette import Look
from poinsot.app.construction.traces import Trace, draw_trace
from poinsot.app.model.elements import Element

__all__ = ["Drawing", "Ellipsoid", "Trace", "draw"]


class PrincipalAxes(Drawing):
    """The three principal axes, their labels 1, 2, 3, and the fixed point."""

    def __init__(self, api: viser.SceneApi, root: str) -> None:
        # One node per axis: a uniform colour is taken as sRGB by the browser, whereas
        # per-vertex colours are taken as linear and come out washed out.
        self.lines = [
            api.add_line_segments(
                f"{root}/body/axis{i + 1}",
                NO_SEGMENT,
                palette.AXES[i],
                thickness=palette.AXIS_WIDTH_PX,
                thickness_units="screen",
            )
            for i in range(3)
        ]
        self.labels = [
            api.add_label(
                f"{root}/body/axis{i + 1}/label",
                f"{i + 1}",
                anchor="bottom-left",
                font_screen_scale=1.3,
            )
            for i in range(3)
        ]
        self.nodes = [
            LabelNode(h, f"axis{i + 1}", f"{i + 1}", 1.3) for i, h in enumerate(self.labels)
        ]
        self.origin = api.add_icosphere(
            f"{root}/origin", radius=ORIGIN_RADIUS, color=palette.ORIGIN, cast_shadow=False
        )
        self.ends = np.zeros((3, 3))
        self._attitude: np.ndarray | None = None  # the body's attitude at the last layout
        super().__init__([*self.lines, *self.labels, self.origin])

    def fit(self, geometry: Geometry) -> None:
        self.ends = geometry.axis_ends()
        for line, node, end in zip(self.lines, self.nodes, self.ends, strict=True):
            line.points = np.array([[-end, end]], dtype=np.float32)
            node.position = end * (1.0 + BEYOND)  # beyond the axis's tip, on the axis
            updates.set_position(node.handle, node.position)

    def restyle(self, look: Look) -> None:
        for line, color in zip(self.lines, look.axes, strict=True):
            line.colors = np.array(color, dtype=np.uint8)
            line.thickness = look.axis_width
        for node in self.nodes:
            node.restyle(look.label_scale)
        self.origin.color = look.origin

    def slots(self, pose: Pose) -> list[Slot]:
        self._attitude = pose.attitude
        tips = self.ends @ pose.attitude.T
        return [
            node.slot(
                tip * (1.0 + BEYOND), tip, np.zeros(3), movable=True, clearance=BODY_CLEARANCE
            )
            for node, tip in zip(self.nodes, tips, strict=True)
        ]

    def place(self, placements: dict[str, Placement]) -> None:
        for node, end in zip(self.nodes, self.ends, strict=True):
            node.place(placements.get(node.key), end * (1.0 + BEYOND), self._attitude)


class InvariablePlane(Drawing):
    """The invariable plane: a translucent disc with a grid and a rim, posed at height h."""

    def __init__(self, api: viser.SceneApi, root: str) -> None:
        self.frame = api.add_frame(f"{root}/plane", show_axes=False)
        vertices, faces = meshes.disc_mesh(PLANE_RADIUS)
        disc = api.add_mesh_simple(
            f"{root}/plane/disc",
            vertices,
            faces,
            color=palette.PLANE,
            opacity=palette.PLANE_OPACITY,
            side="double",
            cast_shadow=False,
            receive_shadow=False,
        )
        self.disc = disc
        self.grid = grid = api.add_line_segments(
            f"{root}/plane/grid",
            meshes.disc_grid_segments(PLANE_RADIUS, GRID_SPACING),
            palette.PLANE_GRID,
            thickness=palette.GRID_WIDTH_PX,
            thickness_units="screen",
        )
        self.rim = rim = api.add_line_segments(
            f"{root}/plane/rim",
            meshes.circle_segments(PLANE_RADIUS),
            palette.PLANE_RIM,
            thickness=palette.RIM_WIDTH_PX,
            thickness_units="screen",
        )
        super().__init__([self.frame, disc, grid, rim])

    def fit(self, geometry: Geometry) -> None:
        updates.set_position(self.frame, np.array([0.0, 0.0, geometry.plane_height]))

    def restyle(self, look: Look) -> None:
        self.disc.color, self.disc.opacity = look.plane, look.plane_opacity
        self.grid.colors = np.array(look.plane_grid, dtype=np.uint8)
        self.grid.thickness = look.grid_width
        self.rim.colors = np.array(look.plane_rim, dtype=np.uint8)
        self.rim.thickness = look.rim_width


class ContactPoint(Drawing):
    """A marker at the contact point; it rides on the scene's tip frame (no message of its own)."""

    def __init__(self, api: viser.SceneApi, root: str) -> None:
        self.marker = api.add_icosphere(
            f"{root}/tip/contact", radius=CONTACT_RADIUS, color=palette.CONTACT, cast_shadow=False
        )
        super().__init__([self.marker])

    def restyle(self, look: Look) -> None:
        self.marker.color = look.contact


class OmegaArrow(Drawing):
    """omega, from the origin to the contact point: the scene moves :attr:`arrow` per frame."""

    def __init__(self, api: viser.SceneApi, root: str) -> None:
        self.arrow = api.add_arrows(
            f"{root}/omega",
            UNIT_ARROW,
            palette.OMEGA,
            shaft_radius=OMEGA_ARROW.shaft_radius,
            head_radius=OMEGA_ARROW.head_radius,
            head_length=OMEGA_ARROW.head_length,
        )
        # The label rides on the tip frame, posed at the contact point: its own messages only
        # when the layout moves it (beyond the tip, clear of the contact point's marker).
        label = api.add_label(
            f"{root}/tip/omega_label",
            "ω",
            anchor="bottom-left",
            font_screen_scale=1.4,
            position=(0.0, 0.0, BEYOND),
        )
        self.node = LabelNode(label, "omega", "ω", 1.4)
        self._beyond = np.array([0.0, 0.0, BEYOND])
        super().__init__([self.arrow, label])

    def restyle(self, look: Look) -> None:
        self.arrow.colors = np.array(look.omega, dtype=np.uint8)
        self.node.restyle(look.label_scale)

    def slots(self, pose: Pose) -> list[Slot]:
        tip = np.asarray(pose.contact, float)
        norm = float(np.linalg.norm(tip))
        self._beyond = BEYOND * tip / norm if norm > 0 else np.array([0.0, 0.0, BEYOND])
        slot = self.node.slot(
            tip + self._beyond, tip, np.zeros(3), movable=True, clearance=MARKER_CLEARANCE
        )
        return [slot]

    def place(self, placements: dict[str, Placement]) -> None:
        self.node.place(placements.get("omega"), self._beyond)


class MomentumArrow(Drawing):
    """L, vertical, from the origin through the plane."""

    def __init__(self, api: viser.SceneApi, root: str) -> None:
        self.arrow = api.add_arrows(
            f"{root}/L",
            UNIT_ARROW,
            palette.ANGULAR_MOMENTUM,
            shaft_radius=L_ARROW.shaft_radius,
            head_radius=L_ARROW.head_radius,
            head_length=L_ARROW.head_length,
        )
        self.label = api.add_label(
            f"{root}/L_label", "L", anchor="bottom-center", font_screen_scale=1.4
        )
        self.node = LabelNode(self.label, "L", "L", 1.4)
        self.top = 1.0
        super().__init__([self.arrow, self.label])

    def fit(self, geometry: Geometry) -> None:
        self.top = top = geometry.plane_height + L_OVERSHOOT
        updates.set_points(self.arrow, np.array([[[0.0, 0.0, 0.0], [0.0, 0.0, top]]]))
        self.node.position = np.array([0.0, 0.0, top + BEYOND])
        updates.set_position(self.label, self.node.position)  # beyond the tip, on the axis

    def restyle(self, look: Look) -> None:
        self.arrow.colors = np.array(look.angular_momentum, dtype=np.uint8)
        self.node.restyle(look.label_scale)

    def slots(self, pose: Pose) -> list[Slot]:
        tip = np.array([0.0, 0.0, self.top])
        point = tip + (0.0, 0.0, BEYOND)
        return [self.node.slot(point, tip, np.zeros(3), movable=True, clearance=HEAD_CLEARANCE)]

    def place(self, placements: dict[str, Placement]) -> None:
        self.node.place(placements.get("L"), np.array([0.0, 0.0, self.top + BEYOND]))


class FullPolhode(Drawing):
    """The whole polhode on the ellipsoid (an open arc on the separatrix)."""

    def __init__(self, api: viser.SceneApi, root: str) -> None:
        self.curve = api.add_line_segments(
            f"{root}/body/polhode_full",
            NO_SEGMENT,
            palette.POLHODE_FULL,
            thickness=palette.FULL_POLHODE_WIDTH_PX,
            thickness_units="screen",
            scale=POLHODE_INFLATE,
        )
        super().__init__([self.curve])

    def fit(self, geometry: Geometry) -> None:
        self.curve.points = geometry.polhode_segments()

    def restyle(self, look: Look) -> None:
        self.curve.colors = np.array(look.polhode_full, dtype=np.uint8)
        self.curve.thickness = look.full_polhode_width


class SolidBody(Drawing):
    """The solid inside the ellipsoid. Its mesh changes with the body, so it is made in
    :meth:`fit`; a box whose sides change keeps its mesh and only changes its scale."""

    def __init__(self, api: viser.SceneApi, root: str) -> None:
        super().__init__()
        self._api, self._name = api, f"{root}/body/solid"
        self._key: tuple | None = None
        self._color = palette.SOLID
        self.mesh: viser.MeshHandle | None = None

    def restyle(self, look: Look) -> None:
        self._color = look.solid
        if self.mesh is not None:
            self.mesh.color = look.solid

    def fit(self, geometry: Geometry) -> None:
        if self.mesh is not None and (
            geometry.solid_base is None or geometry.solid_key != self._key
        ):
            self.remove()
        if geometry.solid_base is None or geometry.solid_scale is None:
            return
        if self.mesh is None:
            self.mesh = self._api.add_mesh_simple(
                self._name,
                geometry.solid_base.vertices,
                geometry.solid_base.faces,
                color=self._color,
                material="standard",
                flat_shading=True,
                cast_shadow=False,
                receive_shadow=False,
                visible=self.visible,
            )
            self.handles = [self.mesh]
            self._key = geometry.solid_key
        self.mesh.scale = triple(geometry.solid_scale)

    def remove(self) -> None:
        super().remove()
        self.mesh, self._key = None, None


def draw(element: Element, api: viser.SceneApi, root: str, trail_points: int) -> Drawing:
    """Create the nodes of ``element`` under the scene root ``root``."""
    if element in (Element.POLHODE, Element.HERPOLHODE):
        return draw_trace(element, api, root, trail_points)
    return _DRAWINGS[element](api, root)


_DRAWINGS: dict[Element, Callable[[viser.SceneApi, str], Drawing]] = {
    Element.ELLIPSOID: Ellipsoid,
    Element.AXES: PrincipalAxes,
    Element.PLANE: InvariablePlane,
    Element.CONTACT: ContactPoint,
    Element.OMEGA: OmegaArrow,
    Element.L: MomentumArrow,
    Element.POLHODE_FULL: FullPolhode,
    Element.SOLID: SolidBody,
}
