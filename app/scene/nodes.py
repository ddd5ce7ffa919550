"""The scene elements as viser nodes: one class per :class:`~poinsot.app.elements.Element`.

Each :class:`Drawing` creates its nodes once (when the element is declared), sends what
changes with the body in :meth:`Drawing.fit` (sizes, static curves: once per parameter
change), and is shown, hidden or removed as a whole. What changes per frame (the body's pose,
the contact point, the omega arrow, the traces' increments) is sent by
:class:`~poinsot.app.scene.construction.PoinsotScene`, through :attr:`OmegaArrow.arrow` and
:attr:`Trace.trail`. A drawing takes a :class:`~poinsot.app.scene.palette.Look` in
:meth:`Drawing.restyle` (theme, projector), and offers its labels to the layout
(:mod:`poinsot.app.scene.labels`) in :meth:`Drawing.slots` and :meth:`Drawing.place`.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import viser

from poinsot.app.elements import Element
from poinsot.app.scene import meshes, palette, updates
from poinsot.app.scene.geometry import (
    CONTACT_RADIUS,
    GRID_SPACING,
    HERPOLHODE_LIFT,
    L_ARROW,
    L_OVERSHOOT,
    OMEGA_ARROW,
    PLANE_RADIUS,
    POLHODE_INFLATE,
    Geometry,
    triple,
)
from poinsot.app.scene.label_nodes import LabelNode, Pose, screen_right_in_plane
from poinsot.app.scene.labels import Placement, Slot
from poinsot.app.scene.palette import Look
from poinsot.app.scene.trail import Trail

#: Radius of the marker at the fixed point (the origin) [display units].
ORIGIN_RADIUS = 0.03
#: How far a label's point lies beyond the tip it names [display units].
BEYOND = 0.05
#: Screen distance [CSS px] a label keeps from the contact point's marker and from L's head.
MARKER_CLEARANCE = 14.0
HEAD_CLEARANCE = 6.0
#: How far the labels on the body (axes, polhode) may be pushed beyond their tips [CSS px]:
#: far enough to step round the contact point's marker where the tips crowd together.
BODY_CLEARANCE = 10.0
#: An arrow's points before its first fit: along +z, unit length.
_UNIT_ARROW = np.array([[[0.0, 0.0, 0.0], [0.0, 0.0, 1.0]]], np.float32)
#: A line-segments node's points before its first fit: one degenerate segment.
_NO_SEGMENT = np.zeros((1, 2, 3), np.float32)


class Drawing:
    """The nodes of one element."""

    def __init__(self, handles: list[viser.SceneNodeHandle] | None = None) -> None:
        self.handles: list[viser.SceneNodeHandle] = handles or []
        self.visible = True

    def fit(self, geometry: Geometry) -> None:
        """Send what changes with the body (sizes, static curves); nothing by default."""

    def restyle(self, look: Look) -> None:
        """Take the colours, widths and label size of ``look``; nothing by default."""

    def slots(self, pose: Pose) -> list[Slot]:
        """The drawing's labels for the layout (world points at ``pose``); none by default."""
        return []

    def place(self, placements: dict[str, Placement]) -> None:
        """Send what the layout chose for the drawing's labels; nothing by default."""

    def set_visible(self, visible: bool) -> None:
        self.visible = visible
        for handle in self.handles:
            handle.visible = visible

    def remove(self) -> None:
        """Remove the nodes that are under none of the others: viser removes the nodes under
        them (an axis's label, the plane's grid) and warns if one is removed again."""
        names = [handle.name for handle in self.handles]
        for handle in self.handles:
            if not any(handle.name.startswith(name + "/") for name in names):
                handle.remove()
        self.handles = []


class Ellipsoid(Drawing):
    """The energy ellipsoid: the unit icosphere, scaled by the semi-axes."""

    def __init__(self, api: viser.SceneApi, root: str) -> None:
        # Sent as a plain mesh (the browser computes smooth normals; a GLB with normals
        # and a non-uniform node scale did not render in viser 1.1).
        sphere = meshes.ellipsoid_unit_mesh()
        self.mesh = api.add_mesh_simple(
            f"{root}/body/ellipsoid",
            sphere.vertices,
            sphere.faces,
            color=palette.ELLIPSOID,
            opacity=palette.ELLIPSOID_OPACITY,
            material="standard",
            side="front",
            cast_shadow=False,
            receive_shadow=False,
        )
        super().__init__([self.mesh])

    def fit(self, geometry: Geometry) -> None:
        self.mesh.scale = triple(geometry.semi_axes)

    def restyle(self, look: Look) -> None:
        self.mesh.color, self.mesh.opacity = look.ellipsoid, look.ellipsoid_opacity


class PrincipalAxes(Drawing):
    """The three principal axes, their labels 1, 2, 3, and the fixed point."""

    def __init__(self, api: viser.SceneApi, root: str) -> None:
        # One node per axis: a uniform colour is taken as sRGB by the browser, whereas
        # per-vertex colours are taken as linear and come out washed out.
        self.lines = [
            api.add_line_segments(
                f"{root}/body/axis{i + 1}",
                _NO_SEGMENT,
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
            _UNIT_ARROW,
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
            _UNIT_ARROW,
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
            _NO_SEGMENT,
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


class Trace(Drawing):
    """A live trace (polhode or herpolhode): a :class:`Trail` the scene extends per frame, and
    the label that names it."""

    def __init__(self, trail: Trail, label: viser.LabelHandle, element: Element) -> None:
        super().__init__([label])
        self.trail, self.element = trail, element
        self.node = LabelNode(label, element.value, label.text, LABEL_SCALE)
        self.point = np.zeros(3)  # the named point: on the polhode (body), on the ring (space)
        self.ring = (0.0, 0.0)  # herpolhode: the radius of its ring and the plane's height
        self._base = np.zeros(3)  # herpolhode: the label's point before the layout's push
        self._attitude: np.ndarray | None = None  # polhode: the body's attitude at the layout

    def fit(self, geometry: Geometry) -> None:
        if self.element is Element.POLHODE:  # a point of the curve, on the body
            self.point = geometry.polhode[int(np.argmax(geometry.polhode[:, 0]))]
            radius = float(np.linalg.norm(self.point))
            outward = self.point / radius if radius > 0 else np.zeros(3)
            self.node.position = self.point * POLHODE_INFLATE + BEYOND * outward
            updates.set_position(self.node.handle, self.node.position)
        else:  # the ring's near side in the default view, until the layout turns it
            self.ring = (geometry.herpolhode_radius, geometry.plane_height)
            self.node.position = self._on_ring(np.array([0.93, 0.37]), BEYOND)
            updates.set_position(self.node.handle, self.node.position)

    def _on_ring(self, direction: np.ndarray, beyond: float = 0.0) -> np.ndarray:
        radius, height = self.ring
        return np.array([*((radius + beyond) * direction), height + HERPOLHODE_LIFT])

    def restyle(self, look: Look) -> None:
        polhode = self.element is Element.POLHODE
        self.trail.restyle(look.polhode if polhode else look.herpolhode, look.trace_width)
        self.node.restyle(look.label_scale)

    def slots(self, pose: Pose) -> list[Slot]:
        if self.element is Element.POLHODE:
            self._attitude = pose.attitude
            tip = pose.attitude @ self.point
            radius = float(np.linalg.norm(tip))
            point = tip * (1.0 + BEYOND / radius) if radius > 0 else tip
            return [self.node.slot(point, tip, np.zeros(3), movable=True, clearance=BODY_CLEARANCE)]
        toward = screen_right_in_plane(pose)
        tip, centre = self._on_ring(toward), np.array([0.0, 0.0, self.ring[1]])
        self._base = self._on_ring(toward, BEYOND)
        return [self.node.slot(self._base, tip, centre, movable=True, clearance=HEAD_CLEARANCE)]

    def place(self, placements: dict[str, Placement]) -> None:
        placement = placements.get(self.node.key)
        if self.element is Element.POLHODE:
            radius = float(np.linalg.norm(self.point))
            base = self.point * (POLHODE_INFLATE + BEYOND / radius) if radius > 0 else self.point
            self.node.place(placement, base, self._attitude)
        else:
            self.node.place(placement, self._base)

    def set_visible(self, visible: bool) -> None:
        super().set_visible(visible)
        self.trail.visible = visible

    def remove(self) -> None:
        super().remove()
        self.trail.clear()
        self.trail.group.remove()


#: Font scale of the curves' labels.
LABEL_SCALE = 1.1


def draw(element: Element, api: viser.SceneApi, root: str, trail_points: int) -> Drawing:
    """Create the nodes of ``element`` under the scene root ``root``."""
    if element is Element.POLHODE:
        trail = Trail(
            api,
            f"{root}/body/polhode",
            palette.POLHODE,
            palette.TRACE_WIDTH_PX,
            trail_points,
            scale=POLHODE_INFLATE,
        )
        label = api.add_label(
            f"{root}/body/polhode_label",
            "polhode",
            anchor="top-left",
            font_screen_scale=LABEL_SCALE,
        )
        return Trace(trail, label, element)
    if element is Element.HERPOLHODE:
        trail = Trail(
            api,
            f"{root}/herpolhode",
            palette.HERPOLHODE,
            palette.TRACE_WIDTH_PX,
            trail_points,
            position=(0.0, 0.0, HERPOLHODE_LIFT),
        )
        label = api.add_label(
            f"{root}/herpolhode_label",
            "herpolhode",
            anchor="center-left",
            font_screen_scale=LABEL_SCALE,
        )
        return Trace(trail, label, element)
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
