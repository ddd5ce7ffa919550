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
drawn and plays (unless it was paused before). A click is a drag's release at once. The Scene
folder says that the ellipsoid can be clicked (:data:`~poinsot.app.live.panel.panel.POINTING_HINT`);
a click that misses it (beside the body, or on the rim where the drawn mesh and the exact
ellipsoid part) is told so there, in one short line (the panel does not move); a click on a
challenge's body is told that its start is fixed. A click while a scene of its own (which draws
no construction of a free body) is shown does nothing.

:class:`StartPointer` is the drag and the release of any pointable surface (this ellipsoid, and
Landau's sphere: :mod:`.sphere_pointer`): a drag update only meets the ray, evaluates the one
polhode and updates its line nodes (no rebuild: the body and its sampler are rebuilt once, on
release); updates queued behind a busy session thread are coalesced to the newest.

viser's callbacks are ``async``: they run in order on its event loop and only post to the
session's queue; the work is the session thread's.
"""

from __future__ import annotations

import collections
import math
import time
from collections.abc import Callable, Hashable
from typing import Generic, Protocol, TypeVar

import numpy as np
import viser
from numpy.typing import ArrayLike

from poinsot.app.construction.construction import PoinsotScene
from poinsot.app.construction.nodes import Drawing, Ellipsoid
from poinsot.app.construction.sampled.batch import Frame
from poinsot.app.construction.sampled.frames import rotation_from_wxyz
from poinsot.app.live.panel.clock import SimClock
from poinsot.app.live.panel.panel import POINTING_HINT
from poinsot.app.live.panel.widgets import refuse_held
from poinsot.app.model.elements import Element
from poinsot.app.model.parameters import Parameters, Vector
from poinsot.app.model.presets import Preset
from poinsot.physics import FreeRigidBody
from poinsot.physics.models.pointing import snap_to_separatrix, start_from_ray

#: The pointer snaps onto the separatrix within this many pixels of it (on screen).
SNAP_PX = 6.0
#: Points of the polhode drawn while dragging.
PREVIEW_POINTS = 240
#: The canvas height assumed before the browser has reported its own [px].
DEFAULT_HEIGHT_PX = 800.0
#: Drag updates whose server time is kept (:attr:`StartPointer.server_seconds`).
KEPT_TIMES = 2000
#: What the Scene folder says after a click that missed the ellipsoid (``verb``: click, tap),
#: and after one on a challenge's body: one short line each, as the hint.
MISSED = "**Missed the ellipsoid:** {verb} on its surface."
FIXED = "**A challenge's body: its start is fixed.**"

Ray = tuple[tuple[float, float, float], tuple[float, float, float]]
Start = tuple[Vector, bool]  # (a point: ω0 or L, snapped onto the separatrix)
Look = tuple[str, tuple[int, int, int], float]  # a line's node, colour, thickness [px]
S = TypeVar("S", bound="BaseSession")


class BaseSession(Protocol):
    """What every pointer uses of a session."""

    client: viser.ClientHandle
    scene: PoinsotScene
    clock: SimClock

    @property
    def body(self) -> FreeRigidBody | None: ...

    def post(self, action: Callable[[], None], key: Hashable | None = None) -> None: ...


class PointerSession(BaseSession, Protocol):
    """What the ellipsoid's pointer uses of a session."""

    @property
    def frame(self) -> Frame | None: ...
    @property
    def showcase(self) -> object | None: ...
    @property
    def preset(self) -> Preset: ...

    def edit(self, change: Callable[[Parameters], Parameters]) -> None: ...
    def set_pointing_verb(self, verb: str) -> None: ...
    def show_pointing(self, text: str) -> None: ...


class StartPointer(Generic[S]):
    """A drag and a release on one pointable surface of a session (the module's docstring).

    A surface says where a ray meets it (:meth:`start_of`), which polhode lines a start draws
    (:meth:`lines`), where and how they are drawn (:meth:`looks`), and what a release sets
    (:meth:`commit`)."""

    def __init__(self, session: S, drag: bool = True) -> None:
        """``drag``: a drag on the surface draws the start's polhode (else a drag on it turns
        the camera, as on a touch screen, where viser's drag binding on a node costs the
        browser a console error and one finger turns the camera everywhere)."""
        self.session = session
        self.dragging = drag
        self.previews_drawn: list[viser.LineSegmentsHandle] = []
        self.last: Start | None = None  # the start drawn last while dragging
        self._paused_before: bool | None = None  # the clock's state when a drag began
        #: Starts set, and polhodes drawn while dragging (tests, benchmark).
        self.starts = self.previews = 0
        #: Per polhode drawn: seconds from the drag update's arrival (viser's event loop) to
        #: its line sent (the benchmark's server share).
        self.server_seconds: collections.deque[float] = collections.deque(maxlen=KEPT_TIMES)

    # -- to be given by a surface ----------------------------------------------------------
    def start_of(self, ray: Ray) -> Start | None:
        raise NotImplementedError

    def lines(self, start: Start) -> list[np.ndarray] | None:
        raise NotImplementedError

    def looks(self) -> list[Look]:
        """(node name, colour, thickness in screen pixels) of each line of :meth:`lines`."""
        raise NotImplementedError

    def commit(self, start: Start) -> None:
        raise NotImplementedError

    # -- viser's event loop: post only ------------------------------------------------------
    def listen(self, node: viser.MeshHandle) -> None:
        """Take the clicks (and drags, if :attr:`dragging`) on ``node``."""
        if self.dragging:
            node.on_drag(self._on_drag)
        node.on_click(self._on_click)

    async def _on_click(self, event: viser.SceneNodePointerEvent) -> None:
        if refuse_held(event.client):  # a follower's: refused, and told once
            return
        ray: Ray = (event.ray_origin, event.ray_direction)
        self.session.post(lambda: self.release(ray))

    async def _on_drag(self, event: viser.SceneNodeDragEvent) -> None:
        if refuse_held(event.client):
            return
        arrived = time.perf_counter()
        x, y, z = (float(v) for v in event.client.camera.position)
        end = event.end_position
        ray: Ray = ((x, y, z), (end[0] - x, end[1] - y, end[2] - z))
        if event.phase == "end":
            self.session.post(lambda: self.release(ray))
        else:  # keyed: only the newest update waits in the queue
            self.session.post(lambda: self.drag(ray, arrived), (type(self), "drag"))

    # -- the session's thread ------------------------------------------------------------------
    def drag(self, ray: Ray, arrived: float | None = None) -> None:
        """Draw the polhode through the start under the pointer; the motion stands still."""
        start = self.start_of(ray)
        if start is None:
            return
        clock = self.session.clock
        if self._paused_before is None:
            self._paused_before = clock.paused
            clock.paused = True
        self.last = start
        lines = self.lines(start)
        if lines is None or not all(np.all(np.isfinite(line)) for line in lines):
            return
        self._send(lines)
        self.previews += 1
        if arrived is not None:
            self.server_seconds.append(time.perf_counter() - arrived)

    def release(self, ray: Ray) -> None:
        """Start the motion from the start under the pointer (or, off the surface, the one
        drawn last while dragging)."""
        self._release(ray)

    def _release(self, ray: Ray) -> bool:
        """:meth:`release`; False if there was no start."""
        start = self.start_of(ray) or self.last
        for handle in self.previews_drawn:
            handle.visible = False
        self.cancel()
        if start is None:
            return False
        self.starts += 1
        self.commit(start)
        return True

    def cancel(self) -> None:
        """End a drag without a start: the clock as it was before it."""
        if self._paused_before is not None:
            self.session.clock.paused = self._paused_before
        self._paused_before, self.last = None, None

    def _send(self, lines: list[np.ndarray]) -> None:
        """The lines out at once: an update sets the points alone (one message a line)."""
        client = self.session.client
        if not self.previews_drawn:
            with client.atomic():
                self.previews_drawn = [
                    client.scene.add_line_segments(
                        name, line, colors=color, thickness=thickness, thickness_units="screen"
                    )
                    for line, (name, color, thickness) in zip(lines, self.looks(), strict=True)
                ]
        else:  # no atomic window: its end would wake viser's loop once more than the flush
            for handle, line in zip(self.previews_drawn, lines, strict=True):
                handle.points = line
                if not handle.visible:
                    handle.visible = True
        client.flush()  # out now, not at viser's next 1/60 s window


class Pointer(StartPointer[PointerSession]):
    """The ellipsoid's pointer of one session (see the module's docstring)."""

    def __init__(self, session: PointerSession, drag: bool = True) -> None:
        super().__init__(session, drag)
        #: Clicks that missed the ellipsoid, and were told so (tests).
        self.misses = 0
        self._on_node = False  # the click being dispatched met the ellipsoid's mesh
        self.verb = "Click" if drag else "Tap"
        session.set_pointing_verb(self.verb)  # the hint in the verb of this screen
        session.scene.on_create = self._bind
        drawing = session.scene.drawing(Element.ELLIPSOID)
        if drawing is not None:
            self._bind(Element.ELLIPSOID, drawing)
        # viser awaits a coroutine callback (its types name only plain ones)
        session.client.scene.on_click()(self._on_scene_click)  # type: ignore[arg-type]

    async def _on_click(self, event: viser.SceneNodePointerEvent) -> None:
        self._on_node = True  # the scene-wide click of the same gesture follows
        await super()._on_click(event)

    async def _on_scene_click(self, event: viser.SceneClickEvent) -> None:
        """A click anywhere (after the mesh's own, if it met the mesh): one beside the body
        is told that it missed."""
        on_node, self._on_node = self._on_node, False
        if on_node or refuse_held(event.client):
            return
        ray: Ray = (event.ray_origin, event.ray_direction)
        self.session.post(lambda: self.beside(ray))

    def beside(self, ray: Ray) -> None:
        """A click that did not meet the ellipsoid's mesh (session thread): said, unless the
        exact ellipsoid is under it after all, or a scene of its own is shown."""
        s = self.session
        if s.showcase is not None or Element.ELLIPSOID not in s.preset.elements:
            return
        if s.preset.challenge:
            self._say(FIXED)
        elif self.start_of(ray) is None:
            self._missed()

    def release(self, ray: Ray) -> None:
        """As :meth:`StartPointer.release`; the Scene folder says what came of it."""
        if self.session.preset.challenge:  # a challenge's body: its start is the question's
            self.cancel()
            for handle in self.previews_drawn:
                handle.visible = False
            self._say(FIXED)
        elif self._release(ray):
            self._say(POINTING_HINT.format(verb=self.verb))
        elif self.session.showcase is None:
            self._missed()

    def _missed(self) -> None:
        self.misses += 1
        self._say(MISSED.format(verb=self.verb.lower()))

    def _say(self, text: str) -> None:
        self.session.show_pointing(text)

    @property
    def preview(self) -> viser.LineSegmentsHandle | None:
        """The polhode drawn while dragging, once there is one."""
        return self.previews_drawn[0] if self.previews_drawn else None

    def _bind(self, element: Element, drawing: Drawing) -> None:
        if element is Element.ELLIPSOID and isinstance(drawing, Ellipsoid):
            self.listen(drawing.mesh)

    def start_of(self, ray: Ray) -> Start | None:
        """The start where ``ray`` (space frame, display units) meets the ellipsoid as drawn
        now, snapped onto a separatrix within :data:`SNAP_PX`; None if it misses."""
        s = self.session
        body, geometry, frame = s.body, s.scene.geometry, s.frame
        if s.showcase is not None or body is None or geometry is None or frame is None:
            return None
        if s.preset.challenge:  # a challenge's body: its start is the question's
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

    def lines(self, start: Start) -> list[np.ndarray] | None:
        """The polhode through ``start`` on the ellipsoid as drawn (body frame)."""
        geometry, body = self.session.scene.geometry, self.session.body
        if geometry is None or body is None:
            return None
        omega0, separatrix = start
        curve = polhode_through(body.inertia, omega0, separatrix)
        return [segments(curve * geometry.scale, separatrix)]

    def looks(self) -> list[Look]:
        scene = self.session.scene
        return [(f"{scene.root}/body/pointed_polhode", scene.look.polhode, 4.0)]

    def commit(self, start: Start) -> None:
        omega0, separatrix = start
        self.session.edit(lambda p: p.with_start(omega0, separatrix))


def polhode_through(inertia: ArrayLike, omega0: ArrayLike, separatrix: bool) -> np.ndarray:
    """(PREVIEW_POINTS, 3) the polhode through ``omega0`` (body frame): the body's attitude
    does not enter it, so none is computed (a drag update's time is the class's)."""
    body = FreeRigidBody(inertia, omega0, on_separatrix=separatrix)
    return body.polhode(PREVIEW_POINTS)


def segments(points: np.ndarray, separatrix: bool) -> np.ndarray:
    """(n, 2, 3) float32 segments along ``points`` (n, 3), closed unless it is a separatrix
    arc (from pole to pole)."""
    p = points.astype(np.float32)
    if not separatrix:
        p = np.concatenate([p, p[:1]])
    return np.stack([p[:-1], p[1:]], axis=1)


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
