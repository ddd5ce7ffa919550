"""The scene elements as viser nodes: one class per :class:`~poinsot.app.elements.Element`.

Each :class:`Drawing` creates its nodes once (when the element is declared), sends what
changes with the body in :meth:`Drawing.fit` (sizes, static curves: once per parameter
change), and is shown, hidden or removed as a whole. What changes per frame (the body's pose,
the contact point, the omega arrow, the traces' increments) is sent by
:class:`~poinsot.app.scene.construction.PoinsotScene`, through :attr:`OmegaArrow.arrow` and
:attr:`Trace.trail`.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import viser

from poinsot.app.elements import Element
from poinsot.app.scene import meshes, palette
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
from poinsot.app.scene.trail import Trail

#: Radius of the marker at the fixed point (the origin) [display units].
ORIGIN_RADIUS = 0.03
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

    def set_visible(self, visible: bool) -> None:
        self.visible = visible
        for handle in self.handles:
            handle.visible = visible

    def remove(self) -> None:
        for handle in self.handles:
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
                anchor="center-center",
                font_screen_scale=1.3,
            )
            for i in range(3)
        ]
        origin = api.add_icosphere(
            f"{root}/origin", radius=ORIGIN_RADIUS, color=palette.ORIGIN, cast_shadow=False
        )
        super().__init__([*self.lines, *self.labels, origin])

    def fit(self, geometry: Geometry) -> None:
        ends = geometry.axis_ends()
        for line, label, end in zip(self.lines, self.labels, ends, strict=True):
            line.points = np.array([[-end, end]], dtype=np.float32)
            label.position = end * 1.08


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
        grid = api.add_line_segments(
            f"{root}/plane/grid",
            meshes.disc_grid_segments(PLANE_RADIUS, GRID_SPACING),
            palette.PLANE_GRID,
            thickness=palette.GRID_WIDTH_PX,
            thickness_units="screen",
        )
        rim = api.add_line_segments(
            f"{root}/plane/rim",
            meshes.circle_segments(PLANE_RADIUS),
            palette.PLANE_RIM,
            thickness=palette.RIM_WIDTH_PX,
            thickness_units="screen",
        )
        super().__init__([self.frame, disc, grid, rim])

    def fit(self, geometry: Geometry) -> None:
        self.frame.position = (0.0, 0.0, geometry.plane_height)


class ContactPoint(Drawing):
    """A marker at the contact point; it rides on the scene's tip frame (no message of its own)."""

    def __init__(self, api: viser.SceneApi, root: str) -> None:
        marker = api.add_icosphere(
            f"{root}/tip/contact", radius=CONTACT_RADIUS, color=palette.CONTACT, cast_shadow=False
        )
        super().__init__([marker])


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
        # The label rides on the tip frame, posed at the contact point: no message of its own.
        label = api.add_label(
            f"{root}/tip/omega_label",
            "ω",
            anchor="bottom-right",
            font_screen_scale=1.4,
            position=(-0.03, 0.0, -0.04),
        )
        super().__init__([self.arrow, label])


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
            f"{root}/L_label", "L", anchor="bottom-left", font_screen_scale=1.4
        )
        super().__init__([self.arrow, self.label])

    def fit(self, geometry: Geometry) -> None:
        top = geometry.plane_height + L_OVERSHOOT
        self.arrow.points = np.array([[[0.0, 0.0, 0.0], [0.0, 0.0, top]]], np.float32)
        self.label.position = (0.04, 0.0, top - 0.05)


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


class SolidBody(Drawing):
    """The solid inside the ellipsoid. Its mesh changes with the body, so it is made in
    :meth:`fit`; a box whose sides change keeps its mesh and only changes its scale."""

    def __init__(self, api: viser.SceneApi, root: str) -> None:
        super().__init__()
        self._api, self._name = api, f"{root}/body/solid"
        self._key: tuple | None = None
        self.mesh: viser.MeshHandle | None = None

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
                color=palette.SOLID,
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
    """A live trace (polhode or herpolhode): a :class:`Trail` the scene extends per frame."""

    def __init__(self, trail: Trail) -> None:
        super().__init__()
        self.trail = trail

    def set_visible(self, visible: bool) -> None:
        self.visible = visible
        self.trail.visible = visible

    def remove(self) -> None:
        self.trail.clear()
        self.trail.group.remove()


def draw(element: Element, api: viser.SceneApi, root: str, trail_points: int) -> Drawing:
    """Create the nodes of ``element`` under the scene root ``root``."""
    if element is Element.POLHODE:
        return Trace(
            Trail(
                api,
                f"{root}/body/polhode",
                palette.POLHODE,
                palette.TRACE_WIDTH_PX,
                trail_points,
                scale=POLHODE_INFLATE,
            )
        )
    if element is Element.HERPOLHODE:
        return Trace(
            Trail(
                api,
                f"{root}/herpolhode",
                palette.HERPOLHODE,
                palette.TRACE_WIDTH_PX,
                trail_points,
                position=(0.0, 0.0, HERPOLHODE_LIFT),
            )
        )
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
