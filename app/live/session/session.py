"""One browser's session: its clock, scene, control panel, body (:mod:`.rebuild`), choice of
preset or scene (:mod:`.choice`) and tools, its queue of actions and the frame thread that runs
them and draws the frames (:mod:`.frames`), composed by :mod:`.builder`. Its tools are given its
front (:mod:`.front`), never the session; its public surface here is for the server, the
benchmarks and the tests.

Threads: viser runs GUI callbacks on its thread pool; they only post small actions to this
session's queue and wake its frame thread, which alone touches the scene and the body. So a
callback never blocks or raises into viser, a slider drag is coalesced into one rebuild per
wake-up, and a slow or departed browser never stalls another (each session has its own thread;
viser gives each client its own send buffer, and :mod:`..hardening.pacing` sends a client a new
frame only once it has taken the ones before, so that buffer never grows).
"""

from __future__ import annotations

from collections.abc import Callable, Hashable

import viser

from poinsot.app.construction.sampled.batch import Frame
from poinsot.app.lessons.support.spec import SceneSpec, Value
from poinsot.app.live.hardening.budget import HOLD_SECONDS
from poinsot.app.live.panel.playback import STEP_SECONDS
from poinsot.app.live.panel.showcase import LiveShowcase
from poinsot.app.live.session.builder import MAX_FPS, SessionOptions, compose
from poinsot.app.live.session.refresh import PLOT_HZ, PLOT_MIN_FRAMES, TIME_HZ
from poinsot.app.model.elements import Element
from poinsot.app.model.parameters import Parameters
from poinsot.app.model.presets import DEFAULT_PRESET, Preset
from poinsot.physics import FreeRigidBody

# The frame loop's and the refresh's rates, named here too: the session's knobs in one place.
__all__ = [
    "HOLD_SECONDS",
    "MAX_FPS",
    "PLOT_HZ",
    "PLOT_MIN_FRAMES",
    "STEP_SECONDS",
    "TIME_HZ",
    "Session",
    "SessionOptions",
]


class Session:
    """Create on client connect (:meth:`start` launches the frame thread), :meth:`close` on
    disconnect."""

    def __init__(
        self,
        client: viser.ClientHandle,
        preset: Preset = DEFAULT_PRESET,
        options: SessionOptions | None = None,
    ) -> None:
        """Show ``preset`` (or ``options.scene``) to ``client``: the parts made and wired by
        :func:`.builder.compose`, the first body built, the frame thread not yet started."""
        core, tools = compose(client, preset, options if options is not None else SessionOptions())
        self.client, self.front, self.pacer, self.stats = client, core.front, core.pacer, core.stats
        self.budget, self.source, self.loop, self.frames = (
            core.budget,
            core.source,
            core.loop,
            core.frames,
        )
        self.max_fps = self.pacer.max_fps
        #: The session's parts (read by the benchmarks and the tests).
        self.clock, self.scene, self.actions = self.front.clock, self.front.scene, self.front.queue
        self.panel, self.playback, self.build, self.choice = (
            core.panel,
            core.playback,
            core.build,
            core.choice,
        )
        self.refresh, self.retirement = core.refresh, core.retirement
        #: A follower's poses, sent by the process's cast (:mod:`..classroom.cast`).
        self.shared = core.frames.shared
        self.ghost, self.uploads, self.follow = tools.ghost, tools.uploads, tools.follow
        self.lecture, self.layout = tools.lecture, tools.layout
        self.pointer, self.sphere_pointer = tools.pointer, tools.sphere_pointer

    # -- lifecycle -----------------------------------------------------------------------
    def start(self) -> Session:
        self.loop.start()
        return self

    def close(self, timeout: float | None = None) -> None:
        """Stop the frame thread (never called from it). Safe to call twice."""
        self.follow.close()
        self.shared.leave()
        self.loop.close(timeout)

    @property
    def running(self) -> bool:
        return self.loop.running

    # -- requests (any thread; never block): the front's -----------------------------------
    def post(self, action: Callable[[], None], key: Hashable | None = None) -> None:
        """Run ``action`` on the frame thread (:meth:`.front.Front.post`)."""
        self.front.post(action, key)

    def report(self, error: BaseException) -> None:
        self.front.report(error)

    def choose_preset(self, preset: Preset) -> None:
        self.front.choose_preset(preset)

    def choose_scene(self, scene: SceneSpec) -> None:
        self.front.choose_scene(scene)

    def configure_scene(self, key: str, value: Value) -> None:
        self.front.configure_scene(key, value)

    def set_part_visible(self, part: str, visible: bool) -> None:
        self.front.set_part_visible(part, visible)

    def edit(self, change: Callable[[Parameters], Parameters]) -> None:
        self.front.edit(change)

    def set_speed(self, speed: float) -> None:
        self.front.set_speed(speed)

    def toggle_pause(self) -> None:
        self.front.toggle_pause()

    def step(self) -> None:
        self.front.step()

    def reset(self) -> None:
        self.front.reset()

    def set_trail(self, points: int) -> None:
        self.front.set_trail(points)

    def set_visible(self, element: Element, visible: bool) -> None:
        self.front.set_visible(element, visible)

    # -- what is shown, and its rebuilds (the frame thread's; read by tests) ---------------
    @property
    def status(self) -> str:
        """The status line's message."""
        return self.front.status.text

    @property
    def preset(self) -> Preset:
        """The preset shown: a named one, Custom, or a chosen scene's identity."""
        return self.front.preset

    @property
    def showcase(self) -> LiveShowcase | None:
        """The scene being shown, if one is chosen instead of a preset."""
        return self.front.showcase

    @property
    def params(self) -> Parameters:
        """The parameters of the body shown (the last valid ones asked for)."""
        return self.front.params

    @property
    def body(self) -> FreeRigidBody | None:
        return self.front.body

    @property
    def frame(self) -> Frame | None:
        return self.front.frame

    def wait_applied(self, generation: int, timeout: float = 5.0) -> int:
        """Block (tests, benchmark) until a rebuild after ``generation`` was applied."""
        return self.build.wait_applied(generation, timeout)

    @property
    def generation(self) -> int:
        return self.build.generation
