"""Poinsot's construction as a viser scene, built on any scene API (``server.scene`` or a
``client.scene``), so that sessions, exports and tests share one construction.

Node tree (names are paths; a child inherits its parent's pose in the browser)::

    /space                  space frame, L along +z, the fixed point at the origin
    /space/plane            invariable plane, a disc at z = h (its pose is its height)
    /space/L, /space/L/label
    /space/omega            omega, an arrow from the origin to the contact point
    /space/tip              a frame at the contact point (the tip of omega on the plane):
    /space/tip/contact, /space/tip/omega_label      its marker and the omega label
    /space/herpolhode/c*    herpolhode trail (space frame)
    /space/body             body frame: its wxyz is the attitude R(t)
    /space/body/ellipsoid   energy ellipsoid: unit icosphere scaled by the semi-axes
    /space/body/axis{1,2,3}, .../label     principal axes and their labels
    /space/body/solid       the solid body (box, disc, rod, T-handle)
    /space/body/polhode_full, /space/body/polhode/c*   polhode (whole curve, live trail)

Sizes: everything is drawn in *display units*, the physical lengths times one factor
``scale = DISPLAY_RADIUS / max(semi_axes)`` so that the picture is the same size for any
|omega0| and any inertia scale. Scaling the whole construction by one factor keeps every
incidence (the ellipsoid touches the plane at the tip of omega).

Traffic: :meth:`PoinsotScene.load` (once per parameter change) sends meshes, scales and
static curves; :meth:`PoinsotScene.advance` (per frame) sends the body pose, the contact point,
the omega arrow's tip, and trail increments only.
"""

from __future__ import annotations

import contextlib
import dataclasses
from collections.abc import Callable
from contextlib import AbstractContextManager

import numpy as np
import trimesh
import viser
from poinsot.app.presets import Element, Solid
from poinsot.app.scene import meshes, palette
from poinsot.app.scene.frames import wxyz_from_xyzw
from poinsot.app.scene.sampling import FIRST_BATCH, MotionSampler, Samples, trace_speed
from poinsot.app.scene.trail import Trail
from poinsot.physics import FreeRigidBody, Regime

#: Largest semi-axis of the ellipsoid on screen [display units].
DISPLAY_RADIUS = 1.0
#: Radius of the plane disc and spacing of its grid [display units].
PLANE_RADIUS = 1.75
GRID_SPACING = 0.25
#: The L arrow reaches this far above the plane [display units].
L_OVERSHOOT = 0.65
#: Principal axes extend past the ellipsoid by this factor.
AXES_OVERSHOOT = 1.22
#: Trace points are at most this far apart [display units] (see app/motion.py).
MAX_CHORD = 0.02
#: At most this many grid samples per frame (after a long stall the trace takes a chord).
MAX_SAMPLES_PER_FRAME = 64
#: The traces are sent every TRAIL_EVERY frames (30 Hz at 60 frames per second): half the
#: messages, and the trace's end trails the contact point by at most one frame.
TRAIL_EVERY = 2
#: Lift of the herpolhode above the plane and growth of the polhode off the ellipsoid,
#: against z-fighting with the surfaces they lie on (drawing only; the contact point and
#: the omega arrow are exact).
HERPOLHODE_LIFT = 0.004
POLHODE_INFLATE = 1.004
#: Points of the whole closed polhode.
POLHODE_FULL_POINTS = 384

ROOT = "/space"


class SceneDataError(ValueError):
    """Physics returned something the scene must not draw (NaN or infinity)."""


def _finite(name: str, value) -> np.ndarray:
    arr = np.asarray(value, dtype=np.float64)
    if not np.all(np.isfinite(arr)):
        raise SceneDataError(f"{name} is not finite; the scene keeps the last valid state")
    return arr


@dataclasses.dataclass(frozen=True)
class Geometry:
    """Everything :meth:`PoinsotScene.load` sends, in display units, computed (and checked
    finite) before anything is sent, so that a failure leaves the previous scene intact."""

    scale: float
    semi_axes: np.ndarray  # (3,) display units
    plane_height: float  # h in display units
    polhode: np.ndarray  # (n, 3) body frame, display units
    polhode_closed: bool  # False on the separatrix: an open arc between the two poles
    solid_key: tuple | None  # equal keys share the mesh already sent
    solid_base: trimesh.Trimesh | None  # the mesh sent for the solid (a unit cube for boxes)
    solid_scale: np.ndarray | None  # node scale (3,) that makes solid_base the displayed solid
    trace_speed: float  # fastest trace point [display units per time unit]

    @classmethod
    def from_body(cls, body: FreeRigidBody, solid: Solid | None) -> Geometry:
        semi = _finite("the semi-axes", body.semi_axes)
        if not np.all(semi > 0.0):
            raise SceneDataError("the body is at rest: there is no ellipsoid to draw")
        scale = DISPLAY_RADIUS / float(np.max(semi))
        h = float(_finite("the plane distance", body.plane_distance))
        normal = _finite("the plane normal", body.plane_normal)
        if not np.allclose(normal, (0.0, 0.0, 1.0), atol=1e-9):
            raise SceneDataError(f"L is not vertical (plane normal {normal}); use attitude0")
        polhode = _finite("the polhode", body.polhode(POLHODE_FULL_POINTS)) * scale
        key = mesh = solid_scale = None
        if solid is not None:
            key, mesh, shape_scale = meshes.solid_shape(solid)
            vertices = np.asarray(mesh.vertices) * shape_scale
            solid_scale = shape_scale * meshes.fit_scale(vertices, semi * scale)
        closed = body.regime is not Regime.SEPARATRIX
        speed = _finite("the trace speed", trace_speed(body, scale))
        return cls(
            scale, semi * scale, h * scale, polhode, closed, key, mesh, solid_scale, float(speed)
        )

    @property
    def solid_mesh(self) -> trimesh.Trimesh | None:
        """The solid as displayed, in body coordinates and display units (for exports)."""
        if self.solid_base is None or self.solid_scale is None:
            return None
        mesh = self.solid_base.copy()
        mesh.apply_scale(self.solid_scale)
        return mesh


@dataclasses.dataclass(frozen=True)
class Frame:
    """What one call of :meth:`PoinsotScene.advance` drew (for readouts, plots, tests)."""

    t: float
    omega: np.ndarray  # (3,) body frame, physical units
    wxyz: np.ndarray  # (4,) attitude as sent
    contact: np.ndarray  # (3,) space frame, display units, as sent
    samples: int  # trace samples evaluated for this frame


@dataclasses.dataclass(frozen=True)
class _Batch:
    """One physics batch (:meth:`MotionSampler.batch`) converted, once and vectorised, into
    what frames send: a frame then only picks rows (no numpy work, no allocation per frame).
    Row ``i`` is grid index ``k0 + i``; the arrays are read-only."""

    source: Samples  # the sampler's batch this was converted from
    k0: int
    t: np.ndarray  # (N,) simulation time
    omega: np.ndarray  # (N, 3) body frame, physical units
    wxyz: np.ndarray  # (N, 4) attitude as viser takes it
    tip: np.ndarray  # (N, 3) contact point, space frame, display units (float64)
    arrow: np.ndarray  # (N, 1, 2, 3) float32: the omega arrow, origin to contact point
    polhode: np.ndarray  # (N, 3) float32 trace points, body frame, display units
    herpolhode: np.ndarray  # (N, 3) float32 trace points, space frame, display units
    keep: np.ndarray  # (N,) bool: grid samples the traces take (every stride-th)

    @classmethod
    def convert(cls, samples: Samples, scale: float, stride: int) -> _Batch:
        tip = samples.contact * scale
        arrow = np.zeros((len(tip), 1, 2, 3), np.float32)
        arrow[:, 0, 1] = tip
        batch = cls(
            samples,
            int(samples.k[0]),
            samples.t,
            samples.omega,
            wxyz_from_xyzw(samples.quat_xyzw),
            tip,
            arrow,
            (samples.omega * scale).astype(np.float32),
            tip.astype(np.float32),
            samples.k % stride == 0,
        )
        for field in dataclasses.fields(cls)[2:]:
            getattr(batch, field.name).flags.writeable = False
        return batch

    def trace(self, element: Element, i: int, j: int, last: bool) -> np.ndarray:
        """Trace points of rows ``i..j-1`` (the last row too if ``last``)."""
        points = self.polhode if element is Element.POLHODE else self.herpolhode
        keep = self.keep[i:j]
        if last and not keep[-1]:
            keep = keep.copy()
            keep[-1] = True
        return points[i:j][keep]


class PoinsotScene:
    """The scene nodes of one view. Create with the elements to draw; then :meth:`load` a body
    and call :meth:`advance` every frame. Not thread-safe: one thread drives a scene."""

    def __init__(
        self,
        api: viser.SceneApi,
        elements: frozenset[Element],
        trail_points: int = 1200,
        root: str = ROOT,
        atomic: Callable[[], AbstractContextManager[None]] = contextlib.nullcontext,
    ) -> None:
        """``atomic``: the owner's ``atomic`` (``client.atomic`` or ``server.atomic``), so
        that one frame's messages reach the browser together."""
        self.api = api
        self._atomic = atomic
        self.root = root
        self._trail_points = int(trail_points)
        self._elements: frozenset[Element] = frozenset()
        self._hidden: set[Element] = set()
        self._nodes: dict[Element, list[viser.SceneNodeHandle]] = {}
        self._trails: dict[Element, Trail] = {}
        self._body: FreeRigidBody | None = None
        self._solid: Solid | None = None
        self._geometry: Geometry | None = None
        self._sampler: MotionSampler | None = None
        self._solid_key: tuple | None = None
        self._k_last: int | None = None
        self._frame: Frame | None = None
        self._batch: _Batch | None = None
        self._omega_arrow: viser.SceneNodeHandle | None = None
        # Rows drawn since the last trail flush: (batch, first row, end row, force last row).
        self._pending: list[tuple[_Batch, int, int, bool]] = []
        self._frames_since_flush = 0
        self.space = api.add_frame(root, show_axes=False)
        self.body_frame = api.add_frame(f"{root}/body", show_axes=False)
        self.tip = api.add_frame(f"{root}/tip", show_axes=False)
        self.declare(elements)

    # -- declaration ---------------------------------------------------------------------
    @property
    def elements(self) -> frozenset[Element]:
        return self._elements

    def declare(self, elements: frozenset[Element]) -> None:
        """Draw exactly ``elements``: remove the nodes of the others, build the new ones."""
        elements = frozenset(elements)
        for element in self._elements - elements:
            self._destroy(element)
        added = elements - self._elements
        self._elements = elements
        if self._geometry is not None:
            for element in sorted(added):
                self._build(element)
                self._apply_geometry(element)
            if added:
                self._frame = None  # the next advance() draws even if time stands still

    def set_visible(self, element: Element, visible: bool) -> None:
        if visible:
            self._hidden.discard(element)
        else:
            self._hidden.add(element)
        for handle in self._nodes.get(element, ()):
            handle.visible = visible
        if element in self._trails:
            self._trails[element].visible = visible

    def is_visible(self, element: Element) -> bool:
        return element in self._elements and element not in self._hidden

    @property
    def trail_points(self) -> int:
        return self._trail_points

    @trail_points.setter
    def trail_points(self, n: int) -> None:
        self._trail_points = int(n)
        for trail in self._trails.values():
            trail.max_points = self._trail_points

    def trail(self, element: Element) -> Trail | None:
        return self._trails.get(element)

    # -- per parameter change ------------------------------------------------------------
    @property
    def geometry(self) -> Geometry | None:
        return self._geometry

    @property
    def body(self) -> FreeRigidBody | None:
        return self._body

    def load(
        self,
        body: FreeRigidBody,
        solid: Solid | None,
        t: float = 0.0,
        frame_time: float = 1.0 / 60.0,
    ) -> Frame:
        """Show ``body`` (and ``solid``) at time ``t``; ``frame_time`` is the simulation time one
        frame advances (speed / frame rate). Raises ValueError, with the previous scene
        untouched, if physics gives anything non-finite."""
        geometry = Geometry.from_body(body, solid)
        sampler = MotionSampler.for_body(body, geometry.trace_speed, frame_time, MAX_CHORD, t)
        k = sampler.index(t)
        source = sampler.batch(k, k, FIRST_BATCH)  # checked finite by the sampler
        batch = _Batch.convert(source, geometry.scale, sampler.stride)
        with self._atomic():
            self._body, self._solid, self._geometry = body, solid, geometry
            self._sampler = sampler
            self._batch = batch
            for element in sorted(self._elements):
                if not self._nodes.get(element) and element not in self._trails:
                    self._build(element)
                self._apply_geometry(element)
            self._k_last = None
            self._frame = None
            return self._draw(k, k, restart=True)

    def set_frame_time(self, frame_time: float) -> None:
        """The clock's speed changed: re-grid the motion from the time now shown."""
        if self._body is None or self._geometry is None or self._frame is None:
            return
        self._sampler = MotionSampler.for_body(
            self._body, self._geometry.trace_speed, frame_time, MAX_CHORD, self._frame.t
        )
        self._k_last = 0

    def shown_time(self, t: float) -> float:
        """The grid time drawn for clock time ``t``."""
        return self._sampler.time(self._sampler.index(t)) if self._sampler else float(t)

    @property
    def sampler(self) -> MotionSampler | None:
        return self._sampler

    # -- per frame -----------------------------------------------------------------------
    def advance(self, t: float) -> Frame:
        """Pose the body at clock time ``t`` (the grid time just before it) and extend the
        traces with the grid samples since the last frame. Going back in time restarts the
        traces; the same grid time again (paused) costs nothing and sends nothing."""
        sampler = self._sampler
        if sampler is None or self._geometry is None:
            raise RuntimeError("load() a body before advance()")
        k = sampler.index(float(t))
        if k == self._k_last and self._frame is not None:
            return self._frame
        restart = self._k_last is None or k < self._k_last
        if restart or k == self._k_last:  # k == k_last: a redraw (new elements), same time
            k_first = k
        else:
            k_first = max(self._k_last + 1, k - MAX_SAMPLES_PER_FRAME + 1)
        with self._atomic():
            return self._draw(k_first, k, restart)

    def _batch_for(self, k_first: int, k_last: int) -> _Batch:
        sampler, geometry = self._sampler, self._geometry
        assert sampler is not None and geometry is not None
        source = sampler.batch(k_first, k_last)  # checked finite once per batch
        if self._batch is None or self._batch.source is not source:
            self._batch = _Batch.convert(source, geometry.scale, sampler.stride)
        return self._batch

    def _draw(self, k_first: int, k: int, restart: bool) -> Frame:
        """Send the pose at grid index ``k`` and queue the trace rows ``k_first..k``: three
        pose-sized messages, every value precomputed by :class:`_Batch`."""
        batch = self._batch_for(k_first, k)
        i, j = k_first - batch.k0, k - batch.k0
        if restart:
            for trail in self._trails.values():
                trail.clear()
            self._pending.clear()
        wxyz, tip = batch.wxyz[j], batch.tip[j]
        self.body_frame.wxyz = wxyz
        self.tip.position = tip
        if self._omega_arrow is not None:
            self._omega_arrow.points = batch.arrow[j]
        if self._trails:
            self._pending.append((batch, i, j + 1, restart))
        self._frames_since_flush += 1
        if restart or self._frames_since_flush >= TRAIL_EVERY:
            self.flush_trails()
        self._k_last = k
        self._frame = Frame(float(batch.t[j]), batch.omega[j], wxyz, tip, j - i + 1)
        return self._frame

    def flush_trails(self) -> None:
        """Send the trace points gathered since the last flush."""
        if self._pending:
            for element, trail in self._trails.items():
                parts = [b.trace(element, i, j, last) for b, i, j, last in self._pending]
                points = parts[0] if len(parts) == 1 else np.concatenate(parts)
                if len(points):
                    trail.append(points)
        self._pending.clear()
        self._frames_since_flush = 0

    # -- element construction ------------------------------------------------------------
    def _destroy(self, element: Element) -> None:
        for handle in self._nodes.pop(element, []):
            handle.remove()
        if element is Element.SOLID:
            self._solid_key = None
        trail = self._trails.pop(element, None)
        if trail is not None:
            trail.clear()
            trail.group.remove()
        if element is Element.OMEGA:
            self._omega_arrow = None

    def _build(self, element: Element) -> None:
        api, r = self.api, self.root
        nodes: list[viser.SceneNodeHandle] = []
        if element is Element.ELLIPSOID:
            # Sent as a plain mesh (the browser computes smooth normals; a GLB with normals
            # and a non-uniform node scale did not render in viser 1.1).
            sphere = meshes.ellipsoid_unit_mesh()
            nodes.append(
                api.add_mesh_simple(
                    f"{r}/body/ellipsoid",
                    sphere.vertices,
                    sphere.faces,
                    color=palette.ELLIPSOID,
                    opacity=palette.ELLIPSOID_OPACITY,
                    material="standard",
                    side="front",
                    cast_shadow=False,
                    receive_shadow=False,
                )
            )
        elif element is Element.AXES:
            # One node per axis: a uniform colour is taken as sRGB by the browser, whereas
            # per-vertex colours are taken as linear and come out washed out.
            for i in range(3):
                nodes.append(
                    api.add_line_segments(
                        f"{r}/body/axis{i + 1}",
                        np.zeros((1, 2, 3), np.float32),
                        palette.AXES[i],
                        thickness=palette.AXIS_WIDTH_PX,
                        thickness_units="screen",
                    )
                )
            for i in range(3):
                nodes.append(
                    api.add_label(
                        f"{r}/body/axis{i + 1}/label",
                        f"{i + 1}",
                        anchor="center-center",
                        font_screen_scale=1.3,
                    )
                )
            nodes.append(
                api.add_icosphere(
                    f"{r}/origin", radius=0.03, color=palette.ORIGIN, cast_shadow=False
                )
            )
        elif element is Element.PLANE:
            plane = api.add_frame(f"{r}/plane", show_axes=False)
            vertices, faces = meshes.disc_mesh(PLANE_RADIUS)
            nodes += [
                plane,
                api.add_mesh_simple(
                    f"{r}/plane/disc",
                    vertices,
                    faces,
                    color=palette.PLANE,
                    opacity=palette.PLANE_OPACITY,
                    side="double",
                    cast_shadow=False,
                    receive_shadow=False,
                ),
                api.add_line_segments(
                    f"{r}/plane/grid",
                    meshes.disc_grid_segments(PLANE_RADIUS, GRID_SPACING),
                    palette.PLANE_GRID,
                    thickness=palette.GRID_WIDTH_PX,
                    thickness_units="screen",
                ),
                api.add_line_segments(
                    f"{r}/plane/rim",
                    meshes.circle_segments(PLANE_RADIUS),
                    palette.PLANE_RIM,
                    thickness=2.0,
                    thickness_units="screen",
                ),
            ]
        elif element is Element.CONTACT:
            nodes.append(
                api.add_icosphere(
                    f"{r}/tip/contact", radius=0.035, color=palette.CONTACT, cast_shadow=False
                )
            )
        elif element is Element.OMEGA:
            # The label rides on /space/tip, posed at the contact point: no message of its own.
            self._omega_arrow = api.add_arrows(
                f"{r}/omega",
                np.array([[[0, 0, 0], [0, 0, 1]]], np.float32),
                palette.OMEGA,
                shaft_radius=0.014,
                head_radius=0.04,
                head_length=0.11,
            )
            nodes += [
                self._omega_arrow,
                api.add_label(
                    f"{r}/tip/omega_label",
                    "ω",
                    anchor="bottom-right",
                    font_screen_scale=1.4,
                    position=(-0.03, 0.0, -0.04),
                ),
            ]
        elif element is Element.L:
            nodes += [
                api.add_arrows(
                    f"{r}/L",
                    np.array([[[0, 0, 0], [0, 0, 1]]], np.float32),
                    palette.ANGULAR_MOMENTUM,
                    shaft_radius=0.016,
                    head_radius=0.05,
                    head_length=0.14,
                ),
                api.add_label(f"{r}/L_label", "L", anchor="bottom-left", font_screen_scale=1.4),
            ]
        elif element is Element.POLHODE_FULL:
            nodes.append(
                api.add_line_segments(
                    f"{r}/body/polhode_full",
                    np.zeros((1, 2, 3), np.float32),
                    palette.POLHODE_FULL,
                    thickness=palette.FULL_POLHODE_WIDTH_PX,
                    thickness_units="screen",
                    scale=POLHODE_INFLATE,
                )
            )
        elif element is Element.POLHODE:
            self._trails[element] = Trail(
                api,
                f"{r}/body/polhode",
                palette.POLHODE,
                palette.TRACE_WIDTH_PX,
                self._trail_points,
                scale=POLHODE_INFLATE,
            )
        elif element is Element.HERPOLHODE:
            self._trails[element] = Trail(
                api,
                f"{r}/herpolhode",
                palette.HERPOLHODE,
                palette.TRACE_WIDTH_PX,
                self._trail_points,
                position=(0.0, 0.0, HERPOLHODE_LIFT),
            )
        elif element is Element.SOLID:
            pass  # built in _apply_geometry: the mesh itself changes with the body
        self._nodes[element] = nodes
        if element in self._hidden:
            self.set_visible(element, False)

    def _apply_geometry(self, element: Element) -> None:
        """Send the per-parameter-change state of one element (sizes, static curves)."""
        g = self._geometry
        assert g is not None
        nodes = self._nodes.get(element, [])
        if element is Element.ELLIPSOID:
            nodes[0].scale = tuple(float(a) for a in g.semi_axes)
        elif element is Element.AXES:
            ends = np.diag(g.semi_axes * AXES_OVERSHOOT)
            for i in range(3):
                nodes[i].points = np.array([[-ends[i], ends[i]]], dtype=np.float32)
                nodes[3 + i].position = ends[i] * 1.08
        elif element is Element.PLANE:
            nodes[0].position = (0.0, 0.0, g.plane_height)
        elif element is Element.L:
            top = g.plane_height + L_OVERSHOOT
            nodes[0].points = np.array([[[0.0, 0.0, 0.0], [0.0, 0.0, top]]], np.float32)
            nodes[1].position = (0.04, 0.0, top - 0.05)
        elif element is Element.POLHODE_FULL:
            curve = g.polhode
            if g.polhode_closed:
                curve = np.concatenate([curve, curve[:1]])
            curve = curve.astype(np.float32)
            nodes[0].points = np.stack([curve[:-1], curve[1:]], axis=1)
        elif element is Element.SOLID:
            if g.solid_base is None or g.solid_key != self._solid_key:
                for handle in nodes:
                    handle.remove()
                nodes.clear()
                self._solid_key = None
            if g.solid_base is not None:
                if not nodes:
                    nodes.append(
                        self.api.add_mesh_simple(
                            f"{self.root}/body/solid",
                            g.solid_base.vertices,
                            g.solid_base.faces,
                            color=palette.SOLID,
                            material="standard",
                            flat_shading=True,
                            cast_shadow=False,
                            receive_shadow=False,
                            visible=element not in self._hidden,
                        )
                    )
                    self._solid_key = g.solid_key
                nodes[0].scale = tuple(float(x) for x in g.solid_scale)
            self._nodes[element] = nodes
