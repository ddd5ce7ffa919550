"""One session's body and its rebuild: the parameters asked for and those shown, the body built
for them, its drawn solid and its last frame.

A preset or a hand edit changes the parameters asked for (:attr:`BodyBuild.desired`) and marks
the build dirty; the session's frame thread then calls :meth:`BodyBuild.rebuild` once, however
many changes came, which loads the chosen scene or the desired body in one atomic window, keeps
the last valid one on a ValueError, and counts the rebuilds (:meth:`BodyBuild.wait_applied`).
Frame thread only, except :attr:`~BodyBuild.generation` and :meth:`~BodyBuild.wait_applied`.
"""

from __future__ import annotations

import contextlib
import threading
import time
from collections.abc import Callable

import viser

from poinsot.app.construction.construction import PoinsotScene
from poinsot.app.construction.sampled.batch import Frame
from poinsot.app.construction.sampled.motion import Motion
from poinsot.app.live.hardening.budget import RebuildGate
from poinsot.app.live.hardening.pacing import SessionStats
from poinsot.app.live.panel import readouts
from poinsot.app.live.panel.ghost_controls import GhostControls
from poinsot.app.live.panel.panel import ControlPanel
from poinsot.app.live.panel.playback import Playback
from poinsot.app.live.panel.showcase import LiveShowcase
from poinsot.app.live.session.source import MotionSource
from poinsot.app.model.elements import Solid
from poinsot.app.model.parameters import Parameters, drawn_solid
from poinsot.app.model.presets import Preset
from poinsot.physics import FreeRigidBody

#: The readouts of a challenge's body, until the answer is in.
WITHHELD = "_The readouts are hidden until you answer the challenge._"


class BodyBuild:
    """The body a session shows, rebuilt by :meth:`rebuild` when :attr:`dirty`. ``say`` sets the
    session's status line; ``defer`` queues an action for its frame thread's next frame (the
    readouts); ``source`` says where the motion comes from (:mod:`.source`: the session's own
    or the lead's)."""

    def __init__(
        self,
        preset: Preset,
        *,
        client: viser.ClientHandle,
        scene: PoinsotScene,
        playback: Playback,
        panel: ControlPanel,
        ghost: GhostControls,
        source: MotionSource,
        budget: RebuildGate,
        stats: SessionStats,
        say: Callable[[str], None],
        defer: Callable[[Callable[[], None], object], None],
    ) -> None:
        self.client, self.scene, self.playback, self.panel = client, scene, playback, panel
        self.ghost, self.source, self.budget, self.stats = ghost, source, budget, stats
        self._say, self._defer = say, defer
        self.base = preset  # the last named preset: it supplies the solid
        self.params = self.desired = Parameters.from_preset(preset)
        self.base_inertia = self.params.inertia
        self.dirty = True
        self.body: FreeRigidBody | None = None
        self.solid: Solid | None = None  # the body's drawn solid
        self.frame: Frame | None = None  # the last loaded or drawn
        self._applied = threading.Condition()
        self._generation = 0  # bumped after each rebuild (tests wait on it)

    # -- what is asked for -----------------------------------------------------------------
    def take(self, preset: Preset) -> None:
        """A named preset was chosen: its parameters are asked for, its solid drawn."""
        self.base = preset
        self.base_inertia = Parameters.from_preset(preset).inertia
        self.desired = Parameters.from_preset(preset)
        self.dirty = True

    def want(self, params: Parameters) -> bool:
        """Ask for ``params``; False (nothing to rebuild) if they are asked for already."""
        if params == self.desired:
            return False
        self.desired = params
        self.dirty = True
        return True

    def unload(self) -> None:
        """The scene shown went: the next rebuild builds the desired body anew."""
        self.body = None
        self.dirty = True

    # -- the rebuild -----------------------------------------------------------------------
    def rebuild(self, showcase: LiveShowcase | None) -> None:
        """Load ``showcase`` (the chosen scene) if any, else build the body of the desired
        parameters; on a ValueError keep the last valid scene and say why. The rebuild holds
        the other sessions' frames (:class:`RebuildGate`) if the source says so
        (:attr:`~.source.MotionSource.holds_others`: a session's own, not a follower's)."""
        gated = self.source.holds_others
        with self.budget.rebuild() if gated else contextlib.nullcontext():
            start = time.perf_counter()
            desired = self.desired
            self.dirty = False
            with self.client.atomic():  # one window: the browser shows the new body at once
                try:
                    if showcase is not None:
                        self._load_scene(showcase)
                    else:
                        self._load_body(desired)
                except ValueError as exc:
                    reason = str(exc)
                    self._say(f"{reason[:1].upper()}{reason[1:]}. Showing the last valid body.")
                self.ghost.fit(exact_body=self.body is not None)
            self.client.flush()  # out now, not at viser's next 1/60 s window
            self.stats.rebuild_seconds.append(time.perf_counter() - start)
            self.stats.rebuilds += 1
        with self._applied:
            self._generation += 1
            self._applied.notify_all()

    def wait_applied(self, generation: int, timeout: float = 5.0) -> int:
        """Block (tests, benchmark) until a rebuild after ``generation`` was applied."""
        with self._applied:
            self._applied.wait_for(lambda: self._generation > generation, timeout)
            return self._generation

    @property
    def generation(self) -> int:
        return self._generation

    def _load_scene(self, showcase: LiveShowcase) -> None:
        """Load the scene's desired settings at t = 0 (ValueError: the last scene is kept)."""
        self.playback.clock.reset(0.0)
        # A follower's scene: the process's one model and motion (None: its own).
        self.frame = showcase.load(self.playback.frame_time, self.source.scenes)
        self.body = showcase.body
        self.panel.motion.clear_plot()
        self._say("")

    def _load_body(self, params: Parameters) -> None:
        """Build the body of ``params`` (a ValueError keeps the last one), load it at t = 0 and
        mirror it into the panel and the "Motion" window."""
        solid = drawn_solid(params.inertia, self.base, self.base_inertia)
        shared = self.shared_motion(params, solid)
        body = params.build() if shared is None else shared.body
        self.playback.clock.reset(0.0)
        frame = self.scene.load(body, solid, frame_time=self.playback.frame_time, motion=shared)
        self.body, self.params, self.frame, self.solid = body, params, frame, solid
        self.panel.show_parameters(params)
        motion = self.panel.motion
        motion.set_body(body)
        motion.restart_plot(0.0, frame.omega, frame.wxyz)  # the old curve goes with its motion
        self._say("")
        if self.base.withheld:  # a challenge's body: hidden at once, with the body itself
            motion.show_readouts(WITHHELD)  # (the last body's readouts would tell the answer)
            return
        # The readouts' table before the next frame, once the new body has gone out: made now,
        # its 2 ms (Montgomery's phase is measured over a period) would hold that window's
        # sending, which needs the interpreter (``defer`` holds it: :meth:`.front.Front.defer`).
        self._defer(lambda: self._show_readouts(body, shared), "readouts")

    def _show_readouts(self, body: FreeRigidBody, shared: Motion | None) -> None:
        if body is not self.body or self.base.withheld:  # a newer body came meanwhile
            return  # (its own readouts follow, or it is a challenge's: hidden already)
        if shared is None:
            text = readouts.markdown(body)
        else:  # a follower's: made once for the followers of the process
            text = shared.memo("readouts", lambda: readouts.markdown(body))
        self.panel.motion.show_readouts(text)

    # -- the motion's grid -----------------------------------------------------------------
    def shared_motion(self, params: Parameters, solid: Solid | None) -> Motion | None:
        """While following: the process's one motion of this body, on the grid of this frame
        time from t = 0 (the first follower to ask builds it); else None."""
        motions = self.source.motions
        if motions is None:
            return None
        frame_time = self.playback.frame_time
        return motions.get(
            (params, solid, frame_time), lambda: Motion.prepare(params.build(), solid, frame_time)
        )

    def regrid(self, showcase: LiveShowcase | None) -> None:
        """The clock's speed changed: the motion on the new grid (a follower's: the process's
        shared one; ``showcase``: the scene shown, if any)."""
        shared = None
        if showcase is None and self.body is not None:
            shared = self.shared_motion(self.params, self.solid)
        if shared is None:
            self.scene.set_frame_time(self.playback.frame_time)
        else:
            self.scene.share(shared)
