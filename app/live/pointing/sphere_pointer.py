"""Point at a start on Landau's momentum sphere: in a scene that draws one (the polhode family),
a click, a tap or a drag on the sphere chooses the body-frame L where the motion starts, at
|L| kept.

As on the energy ellipsoid (:mod:`poinsot.app.live.pointing.pointer`, whose
:class:`~poinsot.app.live.pointing.pointer.StartPointer` drags and releases here too): the sphere
mesh's ``on_click`` gives the ray, its ``on_drag`` the pointer on a plane facing the camera (the ray
runs from the camera through it). The physics (:mod:`poinsot.physics.models.pointing`) meets the ray
with the sphere ``|L| = G`` of the body on screen; ω = I⁻¹L and D follow from the point. Within
:data:`~poinsot.app.live.pointing.pointer.SNAP_PX` pixels of the separatrix the point is snapped
onto it at |L| kept, and the body built from it is the exact separatrix.

While a drag lasts the motion stands still and the polhode through the point is drawn twice:
on the sphere, and its twin on the energy ellipsoid on screen (the polhode of the new start
scaled onto the drawn ellipsoid: D depends on ω's direction only). On release the scene is
rebuilt from the start (its setting :data:`~poinsot.app.lessons.support.spec.START_KEY`). A ray that
misses the sphere does nothing and says nothing.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable
from typing import Protocol

import numpy as np

from poinsot.app.construction.geometry import POLHODE_INFLATE
from poinsot.app.construction.sampled.frames import rotation_from_wxyz
from poinsot.app.lessons.momentum import MomentumPicture
from poinsot.app.lessons.support import colors
from poinsot.app.lessons.support.spec import START_KEY, Value, start_setting
from poinsot.app.live.panel.showcase import LiveShowcase
from poinsot.app.live.pointing.pointer import (
    BaseSession,
    Look,
    Ray,
    Start,
    StartPointer,
    polhode_through,
    segments,
    snap_length,
)
from poinsot.physics.models.pointing import (
    momentum_from_ray,
    omega_from_momentum,
    snap_momentum_to_separatrix,
)


class SphereSession(BaseSession, Protocol):
    """What the sphere's pointer uses of a session."""

    @property
    def showcase(self) -> LiveShowcase | None: ...

    def post(self, action: Callable[[], None], key: Hashable | None = None) -> None: ...
    def configure_scene(self, key: str, value: Value) -> None: ...


class SpherePointer(StartPointer[SphereSession]):
    """The sphere's pointer of one session (see the module's docstring)."""

    def __init__(self, session: SphereSession, drag: bool = True) -> None:
        """``drag``: as :class:`~poinsot.app.live.pointing.pointer.Pointer`'s (off on a touch
        screen)."""
        super().__init__(session, drag)
        self._bound: MomentumPicture | None = None

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
        self.cancel()  # a drag cut short by the change of scene
        self.previews_drawn, self._bound = [], picture
        if picture is not None:
            self.listen(picture.sphere)

    def start_of(self, ray: Ray) -> Start | None:
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

    def lines(self, start: Start) -> list[np.ndarray] | None:
        """The polhode through the point on the sphere, and its twin on the ellipsoid drawn."""
        s, picture = self.session, self._bound
        geometry, body = s.scene.geometry, s.body
        if picture is None or geometry is None or body is None:
            return None
        momentum, separatrix = start
        omega0 = omega_from_momentum(body.inertia, momentum)
        curve = polhode_through(body.inertia, omega0, separatrix)  # ω over a period, body frame
        two_T = float(omega0 @ (np.asarray(body.inertia) * omega0))
        on_drawn = np.sqrt(2.0 * body.energy / two_T)  # onto the ellipsoid on screen
        ellipsoid = curve * (on_drawn * geometry.scale * POLHODE_INFLATE)
        sphere = curve * np.asarray(body.inertia) * picture.scale  # L = Iω, as drawn
        return [segments(sphere, separatrix), segments(ellipsoid, separatrix)]

    def looks(self) -> list[Look]:
        picture = self._bound
        assert picture is not None  # lines() drew on it
        return [
            (f"{picture.root}/pointed_polhode", colors.POINTED, 5.0),
            (f"{self.session.scene.root}/body/sphere_pointed_polhode", colors.POINTED, 5.0),
        ]

    def commit(self, start: Start) -> None:
        self.session.configure_scene(START_KEY, start_setting(*start))
