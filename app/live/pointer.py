"""Point at a start: a click, a tap or a drag on the energy ellipsoid chooses where ω starts.

The browser reports a click or a tap on the ellipsoid with its ray (the mesh's ``on_click``;
viser's scene-wide ``on_click`` hears no tap: its camera holds a touch pointer), and a drag on
it (the mesh's ``on_drag``) with the pointer on a plane facing the camera, so the ray runs from
the camera through that point. The physics
(:mod:`poinsot.physics.models.pointing`) meets the ray with the ellipsoid of the body as it is
turned in the frame on screen, and gives the ω of the energy kept there; D follows from it. Within
:data:`SNAP_PX` pixels of the separatrix the start is snapped onto it, and the body built from
it is the exact separatrix (as the D slider's I₂ mark gives).

While a drag lasts the motion stands still and the polhode through the pointed start is drawn
(body frame, so it lies on the ellipsoid); on release the body is rebuilt from the last start
drawn and plays (unless it was paused before). A click is a drag's release at once. A ray that
misses the ellipsoid does nothing and says nothing; so does one while a scene of its own (which
draws no construction of a free body) is shown.

viser's callbacks are ``async``: they run in order on its event loop and only post to the
session's queue; the work is the session thread's.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Hashable
from typing import Protocol

import numpy as np
import viser

from poinsot.app.elements import Element
from poinsot.app.live.clock import SimClock
from poinsot.app.parameters import Parameters, Vector
from poinsot.app.scene.batch import Frame
from poinsot.app.scene.construction import PoinsotScene
from poinsot.app.scene.frames import rotation_from_wxyz
from poinsot.app.scene.nodes import Drawing, Ellipsoid
from poinsot.physics import FreeRigidBody
from poinsot.physics.models.pointing import body_from_start, snap_to_separatrix, start_from_ray

#: The pointer snaps onto the separatrix within this many pixels of it (on screen).
SNAP_PX = 6.0
#: Points of the polhode drawn while dragging.
PREVIEW_POINTS = 240
#: The canvas height assumed before the browser has reported its own [px].
DEFAULT_HEIGHT_PX = 800.0

Ray = tuple[tuple[float, float, float], tuple[float, float, float]]
Start = tuple[Vector, bool]  # (ω0, snapped onto the separatrix)


class PointerSession(Protocol):
    """What the pointer uses of a session."""

    client: viser.ClientHandle
    scene: PoinsotScene
    body: FreeRigidBody | None
    frame: Frame | None
    clock: SimClock

    @property
    def showcase(self) -> object | None: ...

    def post(self, action: Callable[[], None], key: Hashable | None = None) -> None: ...
    def edit(self, change: Callable[[Parameters], Parameters]) -> None: ...


class Pointer:
    """The pointer of one session (see the module's docstring)."""

    def __init__(self, session: PointerSession, drag: bool = True) -> None:
        """``drag``: a drag on the ellipsoid draws the start's polhode (else a drag on it turns
        the camera, as on a touch screen, where viser's drag binding on a node costs the
        browser a console error and one finger turns the camera everywhere)."""
        self.session = session
        self.dragging = drag
        self.preview: viser.LineSegmentsHandle | None = None
        self.last: Start | None = None  # the start drawn last while dragging
        self._paused_before: bool | None = None  # the clock's state when a drag began
        #: Starts set, and polhodes drawn while dragging (tests, benchmark).
        self.starts = self.previews = 0
        session.scene.on_create = self._bind
        drawing = session.scene.drawing(Element.ELLIPSOID)
        if drawing is not None:
            self._bind(Element.ELLIPSOID, drawing)

    # -- viser's event loop: post only ------------------------------------------------------
    def _bind(self, element: Element, drawing: Drawing) -> None:
        if element is Element.ELLIPSOID and isinstance(drawing, Ellipsoid):
            if self.dragging:
                drawing.mesh.on_drag(self._on_drag)
            drawing.mesh.on_click(self._on_click)

    async def _on_click(self, event: viser.SceneNodePointerEvent) -> None:
        ray: Ray = (event.ray_origin, event.ray_direction)
        self.session.post(lambda: self.release(ray))

    async def _on_drag(self, event: viser.SceneNodeDragEvent) -> None:
        eye = tuple(float(v) for v in event.client.camera.position)
        end = event.end_position
        x, y, z = eye
        ray: Ray = ((x, y, z), (end[0] - x, end[1] - y, end[2] - z))
        if event.phase == "end":
            self.session.post(lambda: self.release(ray))
        else:
            self.session.post(lambda: self.drag(ray), "pointer-drag")

    # -- the session's thread ------------------------------------------------------------------
    def start_of(self, ray: Ray) -> Start | None:
        """The start where ``ray`` (space frame, display units) meets the ellipsoid as drawn
        now, snapped onto a separatrix within :data:`SNAP_PX`; None if it misses."""
        s = self.session
        body, geometry, frame = s.body, s.scene.geometry, s.frame
        if s.showcase is not None or body is None or geometry is None or frame is None:
            return None
        attitude = rotation_from_wxyz(frame.wxyz)
        origin, direction = ray
        omega = start_from_ray(
            body.inertia, 2.0 * body.energy, attitude, origin, direction, scale=geometry.scale
        )
        if not np.all(np.isfinite(omega)):
            return None
        hit = attitude.apply(omega * geometry.scale)
        tolerance = self.snap_world(float(np.linalg.norm(hit - np.asarray(origin))))
        snapped, near = snap_to_separatrix(body.inertia, omega, tolerance / geometry.scale)
        x, y, z = (float(v) for v in snapped)
        return (x, y, z), bool(near)

    def snap_world(self, distance: float) -> float:
        """:data:`SNAP_PX` pixels as a length at ``distance`` from the camera (display units)."""
        return snap_length(self.session.client.camera, distance)

    def drag(self, ray: Ray) -> None:
        """Draw the polhode through the start under the pointer; the motion stands still."""
        start = self.start_of(ray)
        if start is None:
            return
        clock = self.session.clock
        if self._paused_before is None:
            self._paused_before = clock.paused
            clock.paused = True
        self.last = start
        self._draw_polhode(start)

    def release(self, ray: Ray) -> None:
        """Start the motion from the start under the pointer (or, off the ellipsoid, the one
        drawn last while dragging)."""
        start = self.start_of(ray) or self.last
        if self.preview is not None:
            self.preview.visible = False
        if self._paused_before is not None:
            self.session.clock.paused = self._paused_before
        self._paused_before, self.last = None, None
        if start is None:
            return
        omega0, separatrix = start
        self.starts += 1
        self.session.edit(lambda p: p.with_start(omega0, separatrix))

    def _draw_polhode(self, start: Start) -> None:
        s = self.session
        geometry, body = s.scene.geometry, s.body
        assert geometry is not None and body is not None  # start_of() checked
        omega0, separatrix = start
        curve = body_from_start(body.inertia, omega0, separatrix=separatrix).polhode(PREVIEW_POINTS)
        points = (curve * geometry.scale).astype(np.float32)
        if not separatrix:
            points = np.concatenate([points, points[:1]])
        segments = np.stack([points[:-1], points[1:]], axis=1)
        if not np.all(np.isfinite(segments)):
            return
        with s.client.atomic():
            self._send_polhode(segments)
        s.client.flush()  # out now, not at viser's next 1/60 s window
        self.previews += 1

    def _send_polhode(self, segments: np.ndarray) -> None:
        s = self.session
        if self.preview is None:
            self.preview = s.client.scene.add_line_segments(
                f"{s.scene.root}/body/pointed_polhode",
                segments,
                colors=s.scene.look.polhode,
                thickness=4.0,
                thickness_units="screen",
            )
        else:
            self.preview.points = segments
            self.preview.visible = True


def snap_length(camera: viser.CameraHandle, distance: float) -> float:
    """:data:`SNAP_PX` pixels as a length at ``distance`` from ``camera`` (display units)."""
    try:
        height = float(camera.image_height) or DEFAULT_HEIGHT_PX
    except AssertionError:  # the browser has not reported its canvas yet
        height = DEFAULT_HEIGHT_PX
    return SNAP_PX * distance * pixel_angle(float(camera.fov), height)


def pixel_angle(fov: float, height_px: float) -> float:
    """The angle one pixel subtends at the centre of a view ``fov`` radians high."""
    return 2.0 * math.atan(math.tan(0.5 * fov) / max(height_px, 1.0))
