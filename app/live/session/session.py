"""One browser's session: the composition of its clock, scene, control panel, body
(:mod:`.rebuild`), choice of preset or scene (:mod:`.choice`) and tools, its queue of actions
and the frame thread that runs them and draws the frames.

Threads: viser runs GUI callbacks on its thread pool; they only post small actions to this
session's queue and wake its frame thread, which alone touches the scene and the body. So a
callback never blocks or raises into viser, a slider drag is coalesced into one rebuild per
wake-up, and a slow or departed browser never stalls another (each session has its own thread;
viser gives each client its own send buffer, and :mod:`..hardening.pacing` sends a client a new
frame only once it has taken the ones before, so that buffer never grows).
"""

from __future__ import annotations

import functools
import logging
import time
from collections.abc import Callable

import viser

from poinsot.app.construction.construction import PoinsotScene
from poinsot.app.construction.sampled.batch import Frame
from poinsot.app.construction.view import DEFAULT_VIEW, View, apply_theme
from poinsot.app.lessons.support.spec import SceneSpec, Value
from poinsot.app.live.classroom.follow import FollowHub
from poinsot.app.live.classroom.lead import LeadControls
from poinsot.app.live.hardening.budget import RebuildGate
from poinsot.app.live.hardening.pacing import Outbox, Pacer, SessionStats
from poinsot.app.live.lecture.layout import Layout
from poinsot.app.live.lecture.lecture import add_lecture_controls
from poinsot.app.live.panel.clock import SimClock
from poinsot.app.live.panel.ghost_controls import add_ghost_controls
from poinsot.app.live.panel.panel import ControlPanel
from poinsot.app.live.panel.playback import STEP_SECONDS, Playback, clamp_trail
from poinsot.app.live.panel.showcase import LiveShowcase
from poinsot.app.live.panel.uploads import UploadControls
from poinsot.app.live.panel.widgets import Retirement
from poinsot.app.live.pointing.pointer import Pointer
from poinsot.app.live.pointing.sphere_pointer import SpherePointer
from poinsot.app.live.session.actions import MAX_ACTIONS, ActionQueue
from poinsot.app.live.session.choice import Choice
from poinsot.app.live.session.frame_loop import HOLD_SECONDS, FrameLoop
from poinsot.app.live.session.rebuild import BodyBuild
from poinsot.app.live.session.refresh import PLOT_HZ, PLOT_MIN_FRAMES, TIME_HZ, Refresh
from poinsot.app.model.elements import Element
from poinsot.app.model.parameters import Parameters
from poinsot.app.model.presets import DEFAULT_PRESET, Preset
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
        self.status = ""
        self.actions = ActionQueue(max_actions)
        self.loop = self._frame_loop()
        self.sphere_pointer: SpherePointer | None = None  # mounted with the pointer below
        self.layout: Layout | None = None  # mounted with the tools, after the first body

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
        self.build, self.choice = self._compose(preset)
        self.choice.apply_preset(preset) if scene is None else self._apply_scene(scene)
        self._rebuild()
        self._mount_tools(user_agent)

    def _compose(self, preset: Preset) -> tuple[BodyBuild, Choice]:
        """The body and its rebuild (:mod:`.rebuild`), the preset or scene shown (:mod:`.choice`):
        what the preset, scene and edit actions change."""
        build = BodyBuild(
            preset,
            client=self.client,
            scene=self.scene,
            playback=self.playback,
            panel=self.panel,
            ghost=self.ghost,
            follow=self.follow,
            budget=self.budget,
            stats=self.stats,
            say=self._set_status,
            post=self.post,
        )
        choice = Choice(
            preset,
            build,
            client=self.client,
            scene=self.scene,
            panel=self.panel,
            playback=self.playback,
            retirement=self.retirement,
            actions=self,
            resolve=lambda preset: self.uploads.resolve(preset),
        )
        return build, choice

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
        self.post(lambda: self.choice.configure(key, value), ("configure", key))

    def set_part_visible(self, part: str, visible: bool) -> None:
        self.post(lambda: self.choice.set_part_visible(part, visible), ("part", part))

    def edit(self, change: Callable[[Parameters], Parameters]) -> None:
        count = self.panel.menu.count
        self.post(lambda: self.choice.edit(change, count))

    def set_speed(self, speed: float) -> None:
        speed = self.playback.clamp_speed(speed)
        self.post(lambda: self.playback.set_speed(speed), "speed")

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

    # -- what is shown, and its rebuilds (the frame thread's; read by the tools and tests) --
    @property
    def preset(self) -> Preset:
        """The preset shown: a named one, Custom, or a chosen scene's identity."""
        return self.choice.preset

    @property
    def showcase(self) -> LiveShowcase | None:
        """The scene being shown, if one is chosen instead of a preset."""
        return self.choice.showcase

    @property
    def params(self) -> Parameters:
        """The parameters of the body shown (the last valid ones asked for)."""
        return self.build.params

    @property
    def body(self) -> FreeRigidBody | None:
        return self.build.body

    @property
    def frame(self) -> Frame | None:
        return self.build.frame

    def wait_applied(self, generation: int, timeout: float = 5.0) -> int:
        """Block (tests, benchmark) until a rebuild after ``generation`` was applied."""
        return self.build.wait_applied(generation, timeout)

    @property
    def generation(self) -> int:
        return self.build.generation

    # -- frame thread --------------------------------------------------------------------
    def _work(self) -> None:
        """Before each frame: the queued actions, then a rebuild if they asked for one (none
        once the client has left: what they would send goes to nobody)."""
        outbox = self.pacer.outbox
        if outbox.closed():
            return
        with outbox.quiet_if_left():
            self._drain()
            if self.build.dirty:
                self._rebuild()

    def _frame_if_taken(self, now: float) -> bool:
        """Draw a frame, unless the browser has not yet taken the one before (:class:`Pacer`:
        skipped, the rate lowered). A frame's messages go out at once, in one atomic window."""
        if not self.pacer.may_draw():
            return False
        with self.pacer.outbox.quiet_if_left(), self.client.atomic():
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
        if self.layout is not None and self.frame is not None:  # a phone's sheet: t, regime
            self.layout.show_header(now, self.frame.t)
        if self.showcase is not None and self.frame is not None:
            self.showcase.refresh(now, self.frame.t)  # its readouts and plots, at their rates

    def _drain(self) -> None:
        refused = self.actions.run(self._report)
        if refused:  # said after the rebuild they ask for (which clears the status line)
            if self.build.dirty:
                self._rebuild()
            self._set_status(f"Too many changes at once: {refused} were ignored; please redo them.")

    def _advance(self) -> None:
        showcase = self.showcase
        if (self.body is None) if showcase is None else not showcase.loaded:
            return
        start = time.perf_counter()
        t = self.follow.now(self.clock)  # the lecturer's time while following
        frame = self.scene.advance(t) if showcase is None else showcase.advance(t)
        self.build.frame = frame
        self.lecture.on_frame(frame)
        self.ghost.on_frame(frame)
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
        self.choice.apply_preset(preset, menu_count)
        if self.layout is not None:  # a phone's view framed for its aspect
            self.layout.reframe()

    def _apply_scene(self, scene: SceneSpec, menu_count: int | None = None) -> None:
        self.choice.apply_scene(scene, menu_count)
        if self.sphere_pointer is not None:
            self.sphere_pointer.bind()
        if self.layout is not None:
            self.layout.reframe()

    def _rebuild(self) -> None:
        self.build.rebuild(self.showcase)

    def regrid(self) -> None:
        """The clock's speed changed (frame thread): the motion on the new grid (a follower's:
        the process's shared one)."""
        self.build.regrid(self.showcase)

    def _reset(self) -> None:
        self.clock.reset(0.0)
        self.panel.motion.clear_plot()
