"""Poinsot's construction as a viser scene, built on any scene API (``server.scene`` or a
``client.scene``), so that sessions, exports and tests share one construction.

Node tree (names are paths; a child inherits its parent's pose in the browser)::

    /space                  space frame, L along +z, the fixed point at the origin
    /space/plane            invariable plane, a disc at z = h (its pose is its height)
    /space/L, /space/L_label
    /space/omega            omega, an arrow from the origin to the contact point
    /space/tip              a frame at the contact point (the tip of omega on the plane):
    /space/tip/contact, /space/tip/omega_label      its marker and the omega label
    /space/herpolhode/g*/c*  herpolhode trail (space frame; one layer a clearing)
    /space/body             body frame: its wxyz is the attitude R(t)
    /space/body/ellipsoid   energy ellipsoid: unit icosphere scaled by the semi-axes
    /space/body/axis{1,2,3}, .../label     principal axes and their labels
    /space/body/solid       the solid body (box, disc, rod, T-handle)
    /space/body/polhode_full, /space/body/polhode/g*/c*   polhode (whole curve, live trail)

Sizes are in display units (:mod:`poinsot.app.construction.geometry`); the nodes of each element are
made by :mod:`poinsot.app.construction.nodes`.

Traffic: :meth:`PoinsotScene.load` (once per parameter change) sends meshes, scales and
static curves; :meth:`PoinsotScene.advance` (per frame) sends three messages: the body frame's
``wxyz`` (everything that turns with the body is under ``/space/body``), the tip frame's
position (the contact point's marker and the omega label ride on it) and the omega arrow's
points; and every TRAIL_EVERY frames one message per trace. The labels' own messages come
only when their layout changes an anchor or a push (:mod:`poinsot.app.construction.labels.layout`).
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from contextlib import AbstractContextManager

import numpy as np
import viser

from poinsot.app.construction import palette, updates
from poinsot.app.construction.geometry import L_OVERSHOOT, Geometry
from poinsot.app.construction.labels.layout import (
    Camera,
    Placement,
    Steps,
    finish,
    lay_out_in_steps,
)
from poinsot.app.construction.labels.nodes import Pose
from poinsot.app.construction.nodes import Drawing, OmegaArrow, Trace, draw
from poinsot.app.construction.palette import Look
from poinsot.app.construction.sampled.batch import Frame, FrameBatch
from poinsot.app.construction.sampled.frames import rotation_from_wxyz
from poinsot.app.construction.sampled.motion import Motion
from poinsot.app.construction.sampled.sampling import FIRST_BATCH, MotionSampler
from poinsot.app.construction.trail import Trail
from poinsot.app.model.elements import Element, Solid
from poinsot.physics import FreeRigidBody

#: After a stall of the frame loop, the grid samples missed are drawn from the exact solution
#: (one physics call, however many frames were missed), up to this many; after a longer gap
#: the traces are lifted (a new piece starts, joined to nothing) and this frame draws its last
#: MAX_SAMPLES_PER_FRAME samples. Never a straight chord through the body.
MAX_FILL_SAMPLES = 4096
MAX_SAMPLES_PER_FRAME = 64
#: The traces are sent every TRAIL_EVERY frames (15 Hz at 60 frames per second), one message
#: per trace (the head chunk's points): a quarter of the messages and of the head's resends.
#: The trace's end trails the contact point (its marker covers it) by at most three frames,
#: and is completed as soon as the time stands still (paused).
TRAIL_EVERY = 4

ROOT = "/space"
#: The labels' order of importance: earlier ones choose their place first.
LABEL_ORDER = (Element.L, Element.OMEGA, Element.AXES, Element.POLHODE, Element.HERPOLHODE)
#: The contact point's marker as the labels keep clear of it [CSS px].
MARKER_RADIUS_PX = 9.0
#: ... and of the omega and L arrows' shafts [CSS px].
ARROW_HALF_WIDTH_PX = 3.0


def no_fitting(motion: Motion) -> AbstractContextManager[None]:
    """A scene's :attr:`~PoinsotScene.fitting` by default: nothing bracketed."""
    return contextlib.nullcontext()


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
        self._drawings: dict[Element, Drawing] = {}
        # Per-frame shortcuts into the drawings (kept by _index()).
        self._trails: dict[Element, Trail] = {}
        self._omega_arrow: viser.ArrowsHandle | None = None
        self._body: FreeRigidBody | None = None
        self._geometry: Geometry | None = None
        self._motion: Motion | None = None
        self._k_last: int | None = None
        self._frame: Frame | None = None
        self._batch: FrameBatch | None = None
        # Rows drawn since the last trail flush: (batch, first row, end row, force last row).
        self._pending: list[tuple[FrameBatch, int, int, bool]] = []
        self._frames_since_flush = 0
        self._sent_traces = False  # by the last advance()
        #: False: a frame leaves its three pose messages to another sender (a follower's poses,
        #: encoded once for all the followers of a process: live/classroom/cast.py).
        self.send_pose = True
        self._label_epoch = 0  # a layout begun before a change of it sends nothing
        self._look: Look = palette.DARK
        #: Called with each drawing made (a pointer binds its callbacks to the ellipsoid's).
        self.on_create: Callable[[Element, Drawing], None] | None = None
        #: Brackets the drawings' fit to a new body in :meth:`load`, given its motion (a
        #: follower's new body is handed to the followers that still show the old one:
        #: live/classroom/cast.py).
        self.fitting: Callable[[Motion], AbstractContextManager[None]] = no_fitting
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
            drawing = self._drawings.pop(element, None)
            if drawing is not None:
                drawing.remove()
        added = elements - self._elements
        self._elements = elements
        self._label_epoch += 1
        if self._geometry is not None:
            for element in sorted(added):
                self._create(element).fit(self._geometry)
            if added:
                self._frame = None  # the next advance() draws even if time stands still
        self._index()

    def set_visible(self, element: Element, visible: bool) -> None:
        if visible:
            self._hidden.discard(element)
        else:
            self._hidden.add(element)
        drawing = self._drawings.get(element)
        if drawing is not None:
            drawing.set_visible(visible)

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

    def _create(self, element: Element) -> Drawing:
        drawing = draw(element, self.api, self.root, self._trail_points)
        if self._look is not palette.DARK:  # drawn in the dark theme's colours
            drawing.restyle(self._look)
        if element in self._hidden:
            drawing.set_visible(False)
        self._drawings[element] = drawing
        if self.on_create is not None:
            self.on_create(element, drawing)
        return drawing

    def drawing(self, element: Element) -> Drawing | None:
        """The drawing of ``element``, if it is drawn."""
        return self._drawings.get(element)

    # -- look and labels -------------------------------------------------------------------
    @property
    def look(self) -> Look:
        return self._look

    def restyle(self, look: Look) -> None:
        """Draw in the colours, widths and label sizes of ``look`` (theme, projector)."""
        self._look = look
        self._label_epoch += 1
        for drawing in self._drawings.values():
            drawing.restyle(look)

    def lay_out_labels(self, camera: Camera) -> dict[str, Placement]:
        """Place the labels of the shown elements for ``camera`` (see
        :mod:`poinsot.app.construction.labels.layout`) and send what changed; returns the
        placements."""
        return finish(self.label_steps(camera))

    def label_steps(self, camera: Camera) -> Steps[dict[str, Placement]]:
        """:meth:`lay_out_labels` in five steps, a ``yield`` between two (the labels' points,
        the three of :func:`~poinsot.app.construction.labels.layout.lay_out_in_steps`, the
        messages), so that a caller resuming it once per frame spreads a layout over frames. A
        layout that the scene outdates before its end (a new body, elements or look) sends
        nothing."""
        frame, geometry, epoch = self._frame, self._geometry, self._label_epoch
        if frame is None or geometry is None:
            return {}
        pose = Pose(rotation_from_wxyz(frame.wxyz).as_matrix(), np.asarray(frame.contact), camera)
        shown = [self._drawings[e] for e in LABEL_ORDER if self.is_visible(e)]
        slots = [slot for drawing in shown for slot in drawing.slots(pose)]
        markers = [(pose.contact, MARKER_RADIUS_PX)] if self.is_visible(Element.CONTACT) else []
        arrows = [
            (np.zeros(3), end, ARROW_HALF_WIDTH_PX)
            for element, end in (
                (Element.OMEGA, pose.contact),
                (Element.L, np.array([0.0, 0.0, geometry.plane_height + L_OVERSHOOT])),
            )
            if self.is_visible(element)
        ]
        yield
        placements = yield from lay_out_in_steps(slots, camera, markers, arrows)
        yield
        if epoch != self._label_epoch:
            return {}
        for drawing in shown:
            drawing.place(placements)
        return placements

    def _index(self) -> None:
        drawings = self._drawings
        self._trails = {e: d.trail for e, d in drawings.items() if isinstance(d, Trace)}
        omega = drawings.get(Element.OMEGA)
        self._omega_arrow = omega.arrow if isinstance(omega, OmegaArrow) else None

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
        motion: Motion | None = None,
    ) -> Frame:
        """Show ``body`` (and ``solid``) at time ``t``; ``frame_time`` is the simulation time one
        frame advances (speed / frame rate). ``motion``: theirs, prepared already (shared with
        other views, :class:`~.motion.MotionCache`), else prepared here. Raises ValueError, with
        the previous scene untouched, if physics gives anything non-finite."""
        if motion is None:
            motion = Motion.prepare(body, solid, frame_time, t)
        geometry = motion.geometry
        k = motion.sampler.index(t)
        batch = motion.frames(k, k, FIRST_BATCH)
        with self._atomic():
            self._body, self._geometry = motion.body, geometry
            self._label_epoch += 1
            self._motion, self._batch = motion, batch
            with self.fitting(motion):
                for element in sorted(self._elements):
                    drawing = self._drawings.get(element) or self._create(element)
                    drawing.fit(geometry)
            self._index()
            self._k_last = None
            self._frame = None
            return self._draw(k, k, restart=True)

    def unload(self) -> None:
        """Forget the body (a scene that poses its own body draws no construction): the traces
        are emptied and :meth:`advance` needs a new :meth:`load`."""
        for trail in self._trails.values():
            trail.clear()
        self._pending.clear()
        self._body = self._geometry = self._motion = self._batch = None
        self._k_last, self._frame = None, None
        self._label_epoch += 1

    def set_frame_time(self, frame_time: float) -> None:
        """The clock's speed changed: re-grid the motion from the time now shown."""
        if self._motion is None or self._frame is None:
            return
        self._motion, self._batch = self._motion.regridded(frame_time, self._frame.t), None
        self._k_last = 0

    def share(self, motion: Motion) -> None:
        """Draw the same body from ``motion`` from now on (another grid, shared with other
        views): the traces go on from the time now shown."""
        if self._motion is None or self._frame is None:
            return
        self._motion, self._batch = motion, None
        self._body, self._geometry = motion.body, motion.geometry
        self._k_last = motion.sampler.index(self._frame.t)

    @property
    def motion(self) -> Motion | None:
        return self._motion

    def shown_time(self, t: float) -> float:
        """The grid time drawn for clock time ``t``."""
        sampler = self.sampler
        return sampler.time(sampler.index(t)) if sampler else float(t)

    def pose_nodes(self) -> tuple[str, str, str | None]:
        """The names of the nodes a frame poses: the body frame, the tip, the ω arrow (if
        drawn)."""
        arrow = self._omega_arrow
        return self.body_frame.name, self.tip.name, None if arrow is None else arrow.name

    @property
    def sampler(self) -> MotionSampler | None:
        return None if self._motion is None else self._motion.sampler

    # -- per frame -----------------------------------------------------------------------
    def advance(self, t: float) -> Frame:
        """Pose the body at clock time ``t`` (the grid time just before it) and extend the
        traces with the grid samples since the last frame. Going back in time restarts the
        traces; the same grid time again (paused) costs nothing and sends nothing."""
        sampler = self.sampler
        if sampler is None or self._geometry is None:
            raise RuntimeError("load() a body before advance()")
        k = sampler.index(float(t))
        last = self._k_last
        self._sent_traces = False
        if k == last and self._frame is not None:
            if self._pending:  # the time stands still: complete the traces
                with self._atomic():
                    self.flush_trails()
            return self._frame
        restart = last is None or k < last
        if last is None or k <= last:  # k == last: a redraw (new elements), same time
            k_first = k
        elif k - last <= MAX_FILL_SAMPLES:  # every sample since the last frame
            k_first = last + 1
        else:  # too long a gap to fill: the traces go on from here, apart
            k_first = k - MAX_SAMPLES_PER_FRAME + 1
            self.flush_trails()
            for trail in self._trails.values():
                trail.lift()
        with self._atomic():
            return self._draw(k_first, k, restart)

    def _batch_for(self, k_first: int, k_last: int) -> FrameBatch:
        batch = self._batch
        if batch is None or not (batch.k0 <= k_first and k_last < batch.k0 + len(batch.t)):
            assert self._motion is not None
            batch = self._batch = self._motion.frames(k_first, k_last)  # checked finite once
        return batch

    def _draw(self, k_first: int, k: int, restart: bool) -> Frame:
        """Send the pose at grid index ``k`` and queue the trace rows ``k_first..k``: three
        pose-sized messages, every value precomputed by :class:`FrameBatch`."""
        batch = self._batch_for(k_first, k)
        i, j = k_first - batch.k0, k - batch.k0
        if restart:
            for trail in self._trails.values():
                trail.clear()
            self._pending.clear()
        frame = batch.frame(i, j)
        if self.send_pose:
            updates.set_wxyz(self.body_frame, frame.wxyz)
            updates.set_position(self.tip, frame.contact)
            if self._omega_arrow is not None:
                updates.set_points(self._omega_arrow, batch.arrow[j])
        if self._trails:
            self._pending.append((batch, i, j + 1, restart))
        self._frames_since_flush += 1
        # A frame without the pose is one of a follower's few own frames: its traces go at once.
        if restart or self._frames_since_flush >= TRAIL_EVERY or not self.send_pose:
            self.flush_trails()
        self._k_last = k
        self._frame = frame
        return frame

    @property
    def sent_traces(self) -> bool:
        """Whether the last frame drawn sent the traces (a frame heavier than most: other
        periodic work, the labels' layout, waits for the next one)."""
        return self._sent_traces

    @property
    def traces_complete(self) -> bool:
        """Every trace point drawn so far has been sent (none wait for the next flush)."""
        return not self._pending

    def flush_trails(self) -> None:
        """Send the trace points gathered since the last flush."""
        if self._pending:
            self._sent_traces = True
            for element, trail in self._trails.items():
                parts = [b.trace(element, i, j, last) for b, i, j, last in self._pending]
                points = parts[0] if len(parts) == 1 else np.concatenate(parts)
                if len(points):
                    trail.append(points)
        self._pending.clear()
        self._frames_since_flush = 0
