"""Point at a start on Landau's momentum sphere: in a scene that draws one (the polhode family),
a click, a tap or a drag on the sphere chooses the body-frame L where the motion starts, at
|L| kept.

As on the energy ellipsoid (:mod:`poinsot.app.live.pointer`): the sphere mesh's ``on_click``
gives the ray, its ``on_drag`` the pointer on a plane facing the camera (the ray runs from the
camera through it). The physics (:mod:`poinsot.physics.models.pointing`) meets the ray with the
sphere ``|L| = G`` of the body on screen; ω = I⁻¹L and D follow from the point. Within
:data:`~poinsot.app.live.pointer.SNAP_PX` pixels of the separatrix the point is snapped onto it
at |L| kept, and the body built from it is the exact separatrix.

While a drag lasts the motion stands still and the polhode through the point is drawn twice:
on the sphere, and its twin on the energy ellipsoid on screen (the polhode of the new start
scaled onto the drawn ellipsoid: D depends on ω's direction only). On release the scene is
rebuilt from the start (its setting :data:`~poinsot.app.scenes.spec.START_KEY`). A ray that
misses the sphere does nothing and says nothing.

viser's callbacks are ``async``: they only post to the session's queue; the work is the
session thread's.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable
from typing import Protocol

import numpy as np
import viser

from poinsot.app.live.clock import SimClock
from poinsot.app.live.pointer import PREVIEW_POINTS, Ray, snap_length
from poinsot.app.live.showcase import LiveShowcase
from poinsot.app.scene.construction import PoinsotScene
from poinsot.app.scene.frames import rotation_from_wxyz
from poinsot.app.scene.geometry import POLHODE_INFLATE
from poinsot.app.scenes import colors
from poinsot.app.scenes.momentum import MomentumPicture
from poinsot.app.scenes.spec import START_KEY, Value, start_setting
from poinsot.physics import FreeRigidBody
from poinsot.physics.models.pointing import (
    body_from_start,
    momentum_from_ray,
    omega_from_momentum,
    snap_momentum_to_separatrix,
)

#: A start on the sphere: body-frame L, and whether it was snapped onto the separatrix.
SphereStart = tuple[tuple[float, float, float], bool]


class SphereSession(Protocol):
    """What the sphere's pointer uses of a session."""

    client: viser.ClientHandle
    scene: PoinsotScene
    body: FreeRigidBody | None
    clock: SimClock
    showcase: LiveShowcase | None

    def post(self, action: Callable[[], None], key: Hashable | None = None) -> None: ...
    def configure_scene(self, key: str, value: Value) -> None: ...


class SpherePointer:
    """The sphere's pointer of one session (see the module's docstring)."""

    def __init__(self, session: SphereSession, drag: bool = True) -> None:
        """``drag``: as :class:`~poinsot.app.live.pointer.Pointer`'s (off on a touch screen)."""
        self.session = session
        self.dragging = drag
        self.previews_drawn: list[viser.LineSegmentsHandle] = []  # sphere, ellipsoid
        self.last: SphereStart | None = None
        self._paused_before: bool | None = None
        self._bound: MomentumPicture | None = None
        #: Starts set, and polhodes drawn while dragging (tests, benchmark).
        self.starts = self.previews = 0

    def picture(self) -> MomentumPicture | None:
        """The scene's pointable momentum sphere, if the scene on screen draws one."""
        showcase = self.session.showcase
        if showcase is None:
            return None
        picture = getattr(showcase.showcase.drawing, "pointable", None)
        return picture if isinstance(picture, MomentumPicture) else None

    def bind(self) -> None:
        """Listen to the sphere of the scene just shown (session thread)."""
        picture = self.picture()
        if picture is self._bound:
            return
        if self.previews_drawn:  # the last scene's: the sphere's went with its group
            self.previews_drawn[1].remove()
        if self._paused_before is not None:  # a drag cut short by the change of scene
            self.session.clock.paused = self._paused_before
        self.previews_drawn, self.last, self._bound = [], None, picture
        self._paused_before = None
        if picture is not None:
            if self.dragging:
                picture.sphere.on_drag(self._on_drag)
            picture.sphere.on_click(self._on_click)

    # -- viser's event loop: post only ------------------------------------------------------
    async def _on_click(self, event: viser.SceneNodePointerEvent) -> None:
        ray: Ray = (event.ray_origin, event.ray_direction)
        self.session.post(lambda: self.release(ray))

    async def _on_drag(self, event: viser.SceneNodeDragEvent) -> None:
        x, y, z = (float(v) for v in event.client.camera.position)
        end = event.end_position
        ray: Ray = ((x, y, z), (end[0] - x, end[1] - y, end[2] - z))
        if event.phase == "end":
            self.session.post(lambda: self.release(ray))
        else:
            self.session.post(lambda: self.drag(ray), "sphere-pointer-drag")

    # -- the session's thread ------------------------------------------------------------------
    def start_of(self, ray: Ray) -> SphereStart | None:
        """The L where ``ray`` (space frame, display units) meets the sphere as drawn, at the
        body's |L|, snapped onto the separatrix within SNAP_PX; None if it misses."""
        picture, body = self.picture(), self.session.body
        if picture is None or body is None or picture is not self._bound:
            return None
        pose = rotation_from_wxyz(np.asarray(picture.wxyz)).inv()
        origin = pose.apply(np.asarray(ray[0], dtype=float) - np.asarray(picture.offset))
        direction = pose.apply(np.asarray(ray[1], dtype=float))
        G = float(np.linalg.norm(body.angular_momentum))
        momentum = momentum_from_ray(G, origin, direction, scale=picture.scale)
        if not np.all(np.isfinite(momentum)):
            return None
        distance = float(np.linalg.norm(momentum * picture.scale - origin))
        tolerance = snap_length(self.session.client.camera, distance) / picture.scale
        snapped, near = snap_momentum_to_separatrix(body.inertia, momentum, tolerance)
        x, y, z = (float(v) for v in snapped)
        return (x, y, z), bool(near)

    def drag(self, ray: Ray) -> None:
        """Draw the polhode through the point under the pointer; the motion stands still."""
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
        """Start the motion from the point under the pointer (or, off the sphere, the one drawn
        last while dragging)."""
        start = self.start_of(ray) or self.last
        for handle in self.previews_drawn:
            handle.visible = False
        if self._paused_before is not None:
            self.session.clock.paused = self._paused_before
        self._paused_before, self.last = None, None
        if start is None:
            return
        self.starts += 1
        self.session.configure_scene(START_KEY, start_setting(*start))

    def _draw_polhode(self, start: SphereStart) -> None:
        s, picture = self.session, self._bound
        geometry, body = s.scene.geometry, s.body
        if picture is None or geometry is None or body is None:
            return
        momentum, separatrix = start
        omega0 = omega_from_momentum(body.inertia, momentum)
        new = body_from_start(body.inertia, omega0, separatrix=separatrix)
        curve = new.polhode(PREVIEW_POINTS)  # ω(t) over a period, body frame
        on_drawn = np.sqrt(body.energy / new.energy)  # onto the ellipsoid on screen
        ellipsoid = curve * (on_drawn * geometry.scale * POLHODE_INFLATE)
        sphere = curve * np.asarray(body.inertia) * picture.scale  # L = Iω, as drawn
        lines = [_segments(sphere, separatrix), _segments(ellipsoid, separatrix)]
        if not all(np.all(np.isfinite(line)) for line in lines):
            return
        with s.client.atomic():
            self._send(picture, lines)
        s.client.flush()  # out now, not at viser's next 1/60 s window
        self.previews += 1

    def _send(self, picture: MomentumPicture, lines: list[np.ndarray]) -> None:
        if self.previews_drawn:
            for handle, segments in zip(self.previews_drawn, lines, strict=True):
                handle.points = segments
                handle.visible = True
            return
        s = self.session
        names = (f"{picture.root}/pointed_polhode", f"{s.scene.root}/body/sphere_pointed_polhode")
        self.previews_drawn = [
            s.client.scene.add_line_segments(
                name,
                segments,
                colors=colors.POINTED,
                thickness=5.0,
                thickness_units="screen",
            )
            for name, segments in zip(names, lines, strict=True)
        ]


def _segments(points: np.ndarray, separatrix: bool) -> np.ndarray:
    """(n, 2, 3) float32 segments along ``points``, closed unless it is a separatrix arc."""
    p = points.astype(np.float32)
    if not separatrix:
        p = np.concatenate([p, p[:1]])
    return np.stack([p[:-1], p[1:]], axis=1)
