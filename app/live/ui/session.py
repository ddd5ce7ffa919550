"""One browser's session: its parameters, clock, scene, control panel and frame thread.

Threads: viser runs GUI callbacks on its thread pool; they only post small actions to this
session's queue and wake its frame thread, which alone touches the scene and the body. So a
callback never blocks or raises into viser, a slider drag is coalesced into one rebuild per
wake-up, and a slow or departed browser never stalls another (each session has its own thread;
viser gives each client its own send buffer, and :mod:`..hardening.pacing` sends a client a new
frame only once it has taken the ones before, so that buffer never grows).
"""

from __future__ import annotations

import contextlib
import functools
import logging
import threading
import time
from collections.abc import Callable

import viser

from poinsot.app.elements import ALL_ELEMENTS, Control, Element, Plot, Solid
from poinsot.app.live.hardening.budget import RebuildGate
from poinsot.app.live.hardening.pacing import Outbox, Pacer, SessionStats
from poinsot.app.live.ui import readouts
from poinsot.app.live.ui.actions import MAX_ACTIONS, ActionQueue
from poinsot.app.live.ui.clock import SimClock
from poinsot.app.live.ui.follow import FollowHub
from poinsot.app.live.ui.frame_loop import HOLD_SECONDS, FrameLoop
from poinsot.app.live.ui.ghost_controls import add_ghost_controls
from poinsot.app.live.ui.layout import Layout
from poinsot.app.live.ui.lead import LeadControls
from poinsot.app.live.ui.lecture import add_lecture_controls
from poinsot.app.live.ui.panel import ControlPanel
from poinsot.app.live.ui.playback import STEP_SECONDS, Playback, clamp_trail
from poinsot.app.live.ui.pointer import Pointer
from poinsot.app.live.ui.refresh import PLOT_HZ, PLOT_MIN_FRAMES, TIME_HZ, Refresh
from poinsot.app.live.ui.showcase import LiveShowcase
from poinsot.app.live.ui.sphere_pointer import SpherePointer
from poinsot.app.live.ui.uploads import UploadControls
from poinsot.app.live.ui.widgets import Retirement
from poinsot.app.parameters import SPEED_RANGE, Parameters, drawn_solid
from poinsot.app.presets import CUSTOM, DEFAULT_PRESET, Preset
from poinsot.app.scene.batch import Frame
from poinsot.app.scene.construction import PoinsotScene
from poinsot.app.scene.motion import Motion
from poinsot.app.scene.view import DEFAULT_VIEW, View, apply_theme
from poinsot.app.scenes.spec import SceneSpec, Value
from poinsot.physics import FreeRigidBody

log = logging.getLogger(__name__)

# The frame loop's and the refresh's rates, named here too: the session's knobs in one place.
__all__ = [
    "HOLD_SECONDS",
    "MAX_FPS",
    "PLOT_HZ",
    "PLOT_MIN_FRAMES",
    "STEP_SECONDS",
    "TIME_HZ",
    "Session",
]

#: The animation rate cap per client [frames per second].
MAX_FPS = 60.0


class Session:
    """Create on client connect (:meth:`start` launches the frame thread), :meth:`close` on
    disconnect."""

    def __init__(
        self,
        client: viser.ClientHandle,
        preset: Preset = DEFAULT_PRESET,
        *,
        max_fps: float = MAX_FPS,
        view: View = DEFAULT_VIEW,
        budget: RebuildGate | None = None,
        scene: SceneSpec | None = None,
        max_actions: int = MAX_ACTIONS,
        user_agent: str = "",
        follow: FollowHub | None = None,
    ) -> None:
        """``budget``: the server's rebuild gate (its own if None); ``scene``: start with it,
        not ``preset``. Frames: as many as taken, up to ``max_fps`` (:attr:`pacer`). Others:
        ``max_actions`` :mod:`.actions`, ``user_agent`` :mod:`.layout`, ``follow`` :mod:`.lead`."""
        self.client = client
        self.max_fps = float(max_fps)
        self.budget = budget if budget is not None else RebuildGate()
        self.pacer = Pacer(Outbox(client), max_fps=self.max_fps)
        self.stats = SessionStats()
        self.clock = SimClock(speed=preset.speed)
        self.preset = preset
        self._base = preset  # the last named preset: it supplies the solid
        self.params = self._desired = Parameters.from_preset(preset)
        self._base_inertia = self.params.inertia
        self._dirty = True
        self.body: FreeRigidBody | None = None
        self._solid: Solid | None = None  # the body's drawn solid
        self.frame: Frame | None = None
        self.status = ""
        self.actions = ActionQueue(max_actions)
        self._applied = threading.Condition()
        self._generation = 0  # bumped after each rebuild (tests wait on it)
        self.loop = self._frame_loop()
        #: The scene being shown, if one is chosen instead of a preset (frame thread).
        self.showcase: LiveShowcase | None = None
        self.sphere_pointer: SpherePointer | None = None  # mounted with the pointer below

        apply_theme(client)
        view.apply(client.camera)
        elements = preset.elements if scene is None else frozenset()
        self.scene = PoinsotScene(client.scene, elements, preset.trail_points, atomic=client.atomic)
        #: Widgets removed from the panel, deleted a moment later (frame thread).
        self.retirement = Retirement()
        self.panel = ControlPanel(
            client.gui, self, preset if scene is None else scene.identity(), self.retirement
        )
        self.refresh = Refresh(self.panel.motion, self.retirement)
        self.playback = Playback(self.clock, self.scene, self.panel.show_playback, self.max_fps)
        # The ghost's controls; the ghost itself when switched on (fitted after each rebuild).
        self.ghost = add_ghost_controls(client, self.scene, self.retirement)
        self.follow = LeadControls(self, follow if follow is not None else FollowHub())
        self._apply_preset(preset) if scene is None else self._apply_scene(scene)
        self._rebuild()
        self._mount_tools(user_agent)

    def _frame_loop(self) -> FrameLoop:
        return FrameLoop(
            f"poinsot-session-{self.client.client_id}",
            pacer=self.pacer,
            budget=self.budget,
            stats=self.stats,
            max_fps=self.max_fps,
            work=self._work,
            draw=lambda now: self._frame_if_taken(now),  # looked up late: tests wrap it
            report=self._report,
        )

    def _mount_tools(self, user_agent: str) -> None:
        """What works on the first body: the lecture's tools, the page's layout, pointing."""
        self.lecture = add_lecture_controls(self)  # exports, views, theme, hotkeys
        self.layout = Layout(self, self.panel.motion, user_agent)  # a phone's, a tablet's page
        self.pointer = Pointer(self, drag=not self.layout.touch)  # a start pointed at
        self.sphere_pointer = SpherePointer(self, drag=not self.layout.touch)
        self.sphere_pointer.bind()  # on Landau's sphere, in a scene that draws one

    # -- lifecycle -----------------------------------------------------------------------
    def start(self) -> Session:
        self.loop.start()
        return self

    def close(self, timeout: float | None = None) -> None:
        """Stop the frame thread (never called from it). Safe to call twice."""
        self.follow.close()
        self.loop.close(timeout)

    @property
    def running(self) -> bool:
        return self.loop.running

    # -- actions (any thread; never block) -----------------------------------------------
    def post(self, action: Callable[[], None], key: object = None) -> None:
        """Run ``action`` on the frame thread (from any thread; never blocks). One with a
        ``key`` replaces the one queued with the same key (it sets the same thing). Refused if
        the queue is full (:meth:`_drain` says so)."""
        self.actions.put(action, key)
        self.loop.wake()

    def choose_preset(self, preset: Preset) -> None:
        count = self.panel.menu.count  # the menu's choices so far (Panel.show_preset)
        self.post(lambda: self._apply_preset(preset, count))

    @functools.cached_property
    def uploads(self) -> UploadControls:
        """The toss and mesh folders (made before the panel's first declaration)."""
        return UploadControls(self)

    def choose_scene(self, scene: SceneSpec) -> None:
        count = self.panel.menu.count
        self.post(lambda: self._apply_scene(scene, count))

    def configure_scene(self, key: str, value: Value) -> None:
        """A control of the current scene moved."""

        def action() -> None:
            if self.showcase is not None and self.showcase.configure(key, value):
                self._dirty = True

        self.post(action, ("configure", key))

    def set_part_visible(self, part: str, visible: bool) -> None:
        def action() -> None:
            if self.showcase is not None:
                self.showcase.set_visible(part, visible)

        self.post(action, ("part", part))

    def edit(self, change: Callable[[Parameters], Parameters]) -> None:
        count = self.panel.menu.count
        self.post(lambda: self._edit(change, count))

    def set_speed(self, speed: float) -> None:
        speed = self.playback.clamp_speed(speed)
        self.post(lambda: self.playback.set_speed(speed), "speed")

    @property
    def frame_time(self) -> float:
        """Simulation time one frame advances at full frame rate."""
        return self.playback.frame_time

    def toggle_pause(self) -> None:
        self.post(self.playback.toggle_pause)

    def step(self) -> None:
        self.post(self.playback.step)

    def reset(self) -> None:
        self.post(self._reset)

    def set_trail(self, points: int) -> None:
        points = clamp_trail(points)
        self.post(lambda: self.playback.set_trail(points), "trail")

    def set_visible(self, element: Element, visible: bool) -> None:
        self.post(lambda: self.scene.set_visible(element, visible), ("element", element))

    def report(self, error: BaseException) -> None:
        """Show an error raised outside the frame thread (a GUI callback)."""
        self.post(lambda: self._report(error))

    def wait_applied(self, generation: int, timeout: float = 5.0) -> int:
        """Block (tests, benchmark) until a rebuild after ``generation`` was applied."""
        with self._applied:
            self._applied.wait_for(lambda: self._generation > generation, timeout)
            return self._generation

    @property
    def generation(self) -> int:
        return self._generation

    # -- frame thread --------------------------------------------------------------------
    def _work(self) -> None:
        """Before each frame: the queued actions, then a rebuild if they asked for one (none
        once the client has left: what they would send goes to nobody)."""
        if self.pacer.outbox.closed():
            return
        self._drain()
        if self._dirty:
            self._rebuild()

    def _frame_if_taken(self, now: float) -> bool:
        """Draw a frame, unless the browser has not yet taken the one before (:class:`Pacer`:
        skipped, the rate lowered). A frame's messages go out at once, in one atomic window."""
        if not self.pacer.may_draw():
            return False
        with self.client.atomic():
            self._advance()
            self._refresh(now)
        self.client.flush()  # out now, not at viser's next 1/60 s window
        self.pacer.sent()
        return True

    def _refresh(self, now: float) -> None:
        """After a frame: the plot, the time readout and retired widgets at their rates
        (:class:`~.refresh.Refresh`), and the scene's own readouts and plots."""
        self.follow.on_frame(now)  # a lead publishes its state
        busy = self.scene.sent_traces or self.lecture.display.laid_out_now  # a layout step
        self.refresh.after_frame(now, self.frame, self.clock.paused, busy)
        if self.showcase is not None and self.frame is not None:
            self.showcase.refresh(now, self.frame.t)  # its readouts and plots, at their rates

    def _drain(self) -> None:
        if not len(self.actions):  # the usual frame
            return
        while actions := self.actions.take():
            for action in actions:
                try:
                    action()
                except Exception as exc:
                    self._report(exc)
        refused = self.actions.refused()
        if refused:  # said after the rebuild they ask for (which clears the status line)
            if self._dirty:
                self._rebuild()
            self._set_status(f"Too many changes at once: {refused} were ignored; please redo them.")

    def _advance(self) -> None:
        showcase = self.showcase
        if (self.body is None) if showcase is None else not showcase.loaded:
            return
        start = time.perf_counter()
        t = self.follow.now(self.clock)  # the lecturer's time while following
        self.frame = self.scene.advance(t) if showcase is None else showcase.advance(t)
        self.lecture.on_frame(self.frame)
        self.ghost.on_frame(self.frame)
        self.stats.frame_seconds.append(time.perf_counter() - start)
        self.stats.frames += 1

    def _report(self, exc: BaseException) -> None:
        self.stats.errors += 1
        message = f"{type(exc).__name__}: {exc}"
        if message != self.stats.last_error:
            log.exception("session %s: %s", self.client.client_id, message, exc_info=exc)
            self.stats.last_error = message
        try:
            self._set_status(f"Internal error ({message}); the last valid scene is kept.")
        except Exception:  # the GUI itself may be gone (client left)
            pass

    # -- state changes (frame thread only) -----------------------------------------------
    def _set_status(self, message: str) -> None:
        self.status = message
        self.panel.show_status(message)

    def _apply_preset(self, preset: Preset, menu_count: int | None = None) -> None:
        # The menu's "Fitted toss" and "Body from a mesh": this session's own, if it has one.
        preset = self.uploads.resolve(preset)
        self._leave_scene()
        self.preset = preset
        if preset is not CUSTOM:
            self._base = preset
            self._base_inertia = Parameters.from_preset(preset).inertia
            self._desired = Parameters.from_preset(preset)
            self.playback.take(preset.speed, preset.trail_points)
            self._dirty = True
        self.scene.declare(preset.elements)
        self._declare(preset.controls, preset.plots, preset.elements, self._desired)
        self.panel.show_preset(preset, menu_count)
        self.playback.show()

    def _apply_scene(self, scene: SceneSpec, menu_count: int | None = None) -> None:
        """Show ``scene``: the construction's elements it declares, the panel's groups it shares
        (speed, playback, trail, show/hide), and its own controls, parts, readouts and plots."""
        self._leave_scene()
        self.preset = scene.identity()
        self.playback.take(scene.initial_speed(), scene.trail_points, scene.speed_range)
        self.showcase = LiveShowcase(
            scene, self.client, self.scene, self.panel.motion, self, self.retirement
        )
        self._declare(scene.shared, frozenset(), scene.elements, self._desired)
        self.panel.show_preset(self.preset, menu_count)
        self.playback.show()
        scene.view.apply(self.client.camera)
        if self.sphere_pointer is not None:
            self.sphere_pointer.bind()
        self._dirty = True

    def _declare(
        self,
        controls: frozenset[Control],
        plots: frozenset[Plot],
        elements: frozenset[Element],
        params: Parameters,
    ) -> None:
        """Show exactly these groups in the panel, with the session's playback settings."""
        speed, trail = self.clock.speed, self.scene.trail_points
        self.panel.declare(controls, plots, elements, params, speed, trail, self.scene.is_visible)

    def _leave_scene(self) -> None:
        """Remove the current scene (if any); the next preset rebuilds its body."""
        if self.showcase is not None:
            self.showcase.remove()
            self.showcase = None
            self.playback.speed_range = SPEED_RANGE
            self.body = None
            self._dirty = True
            DEFAULT_VIEW.apply(self.client.camera)

    def _edit(
        self, change: Callable[[Parameters], Parameters], menu_count: int | None = None
    ) -> None:
        new = change(self._desired)
        if new == self._desired:
            return
        self._desired = new
        self._dirty = True
        if self.preset is not CUSTOM and not new.matches(self.preset):
            # Edited by hand: the scene becomes "Custom", which declares everything. Only
            # additions happen here, so the slider being dragged stays in place.
            self.preset = CUSTOM
            self.scene.declare(ALL_ELEMENTS)
            self._declare(CUSTOM.controls, CUSTOM.plots, CUSTOM.elements, new)
            self.panel.show_preset(CUSTOM, menu_count)

    def _rebuild(self) -> None:
        """Build the body for the desired parameters and load it; on a ValueError keep the
        last valid scene and say why. A session's own rebuild holds the other sessions'
        frames (:class:`RebuildGate`: the student who moved a slider sees the new body at once);
        a follower's does not: it mirrors the lead's move, whose rebuild took precedence where
        the lead is, and a class of followers rebuilding one after the other would hold each
        other's frames for the whole round."""
        own = self.follow.mode != "follow"
        with self.budget.rebuild() if own else contextlib.nullcontext():
            start = time.perf_counter()
            desired = self._desired
            self._dirty = False
            with self.client.atomic():  # one window: the browser shows the new body at once
                try:
                    if self.showcase is not None:
                        self._load_scene(self.showcase)
                    else:
                        self._load_body(desired)
                except ValueError as exc:
                    reason = str(exc)
                    self._set_status(
                        f"{reason[:1].upper()}{reason[1:]}. Showing the last valid body."
                    )
                self.ghost.fit(exact_body=self.body is not None)
            self.client.flush()  # out now, not at viser's next 1/60 s window
            self.stats.rebuild_seconds.append(time.perf_counter() - start)
            self.stats.rebuilds += 1
        with self._applied:
            self._generation += 1
            self._applied.notify_all()

    def _load_scene(self, showcase: LiveShowcase) -> None:
        """Load the scene's desired settings at t = 0 (ValueError: the last scene is kept)."""
        self.clock.reset(0.0)
        follow = self.follow  # a follower's scene: the process's one model and motion
        shared = follow.hub.scenes if follow.mode == "follow" else None
        self.frame = showcase.load(self.frame_time, shared)
        self.body = showcase.body
        self.panel.motion.clear_plot()
        self._set_status("")

    def _load_body(self, params: Parameters) -> None:
        """Build the body of ``params`` (a ValueError keeps the last one), load it at t = 0 and
        mirror it into the panel and the "Motion" window."""
        solid = drawn_solid(params.inertia, self._base, self._base_inertia)
        shared = self._shared_motion(params, solid)
        body = params.build() if shared is None else shared.body
        self.clock.reset(0.0)
        frame = self.scene.load(body, solid, frame_time=self.frame_time, motion=shared)
        self.body, self.params, self.frame, self._solid = body, params, frame, solid
        self.panel.show_parameters(params)
        motion = self.panel.motion
        motion.set_body(body)
        motion.clear_plot()
        motion.record_plot(0.0, frame.omega, frame.wxyz)
        self._set_status("")
        # The readouts' table just after the new body has gone out (Montgomery's phase is
        # measured over a period: half a millisecond that the redraw need not wait for).
        self.post(lambda: self._show_readouts(body, shared), "readouts")

    def _show_readouts(self, body: FreeRigidBody, shared: Motion | None) -> None:
        if body is not self.body:  # a newer body came meanwhile: its own readouts follow
            return
        if shared is None:
            text = readouts.markdown(body)
        else:  # a follower's: made once for the followers of the process
            text = shared.memo("readouts", lambda: readouts.markdown(body))
        self.panel.motion.show_readouts(text)

    def _shared_motion(self, params: Parameters, solid: Solid | None) -> Motion | None:
        """While following: the process's one motion of this body, on the grid of this frame
        time from t = 0 (the first follower to ask builds it); else None."""
        follow = self.follow
        if follow.mode != "follow":
            return None
        frame_time = self.frame_time
        return follow.hub.motions.get(
            (params, solid, frame_time), lambda: Motion.prepare(params.build(), solid, frame_time)
        )

    def regrid(self) -> None:
        """The clock's speed changed (frame thread): the motion on the new grid (a follower's:
        the process's shared one)."""
        shared = None
        if self.showcase is None and self.body is not None:
            shared = self._shared_motion(self.params, self._solid)
        if shared is None:
            self.scene.set_frame_time(self.frame_time)
        else:
            self.scene.share(shared)

    def _reset(self) -> None:
        self.clock.reset(0.0)
        self.panel.motion.clear_plot()
