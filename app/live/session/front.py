"""What a session's tools see of it, and what they may ask of it: its :class:`Front`.

The panel, the uploads, the lecture tools, the "Class" folder and the pointers are given the
front, never the session: its client, clock and construction; what it shows, read-only (the
preset, the scene, the parameters, the body, the last frame, the camera view chosen); and its
requests, each of which only queues an action on the session's frame thread and wakes it. Each
tool's own Protocol names the few of these it uses. What the session runs (its frame loop,
queue, rebuild, choice of preset or scene, statistics) is not on the front.

:class:`Status` is the session's status line and the errors it shows there;
:class:`FollowerMirror` what a follower changes to mirror the lead's state.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Hashable

import viser

from poinsot.app.construction.construction import PoinsotScene
from poinsot.app.construction.sampled.batch import Frame
from poinsot.app.lessons.support.spec import SceneSpec, Value
from poinsot.app.live.hardening.pacing import SessionStats
from poinsot.app.live.panel.clock import SimClock
from poinsot.app.live.panel.panel import ControlPanel
from poinsot.app.live.panel.playback import Playback, clamp_trail
from poinsot.app.live.panel.showcase import LiveShowcase
from poinsot.app.live.session.actions import Action, ActionQueue
from poinsot.app.live.session.choice import Choice
from poinsot.app.model.elements import Element
from poinsot.app.model.parameters import Parameters
from poinsot.app.model.presets import Preset
from poinsot.physics import FreeRigidBody

#: The session's log (its errors, once each).
log = logging.getLogger("poinsot.app.live.session.session")


class Status:
    """The session's status line (frame thread): :meth:`say` a message, :meth:`report` an
    error (counted, logged once, shown). ``show`` writes the line into the panel."""

    def __init__(self, stats: SessionStats, name: str) -> None:
        self.stats, self.name = stats, name
        self.text = ""
        self.show: Callable[[str], None] = lambda _message: None  # the panel's, once it exists

    def say(self, message: str) -> None:
        self.text = message
        self.show(message)

    def report(self, exc: BaseException) -> None:
        self.stats.errors += 1
        message = f"{type(exc).__name__}: {exc}"
        if message != self.stats.last_error:
            log.exception("session %s: %s", self.name, message, exc_info=exc)
            self.stats.last_error = message
        try:
            self.say(f"Internal error ({message}); the last valid scene is kept.")
        except Exception:  # the GUI itself may be gone (client left)
            pass


class Front:
    """A session's front (see the module's docstring). Made before the panel, which takes its
    requests; :meth:`attach` gives it what it shows and changes once they exist."""

    def __init__(
        self,
        client: viser.ClientHandle,
        clock: SimClock,
        scene: PoinsotScene,
        queue: ActionQueue,
        status: Status,
    ) -> None:
        self.client, self.clock, self.scene = client, clock, scene
        self.status = status
        self.queue = queue
        #: Wakes the frame thread (set once the session's frame loop exists).
        self.wake: Callable[[], None] = lambda: None
        #: A follower is about to open the lead's new body or scene, the state of this query
        #: (set by the builder: :meth:`~..classroom.shared_frames.SharedFrames.moving`).
        self.moving: Callable[[str], None] = lambda query: None
        #: The camera view chosen (the lecture tools', once mounted).
        self.camera_of: Callable[[], str] = lambda: "default"
        #: Run on the frame thread after a preset, or a scene, is shown (the layout reframes
        #: the view, the sphere's pointer listens to the new sphere).
        self.after_preset: list[Callable[[], None]] = []
        self.after_scene: list[Callable[[], None]] = []
        self._choice: Choice | None = None
        self._panel: ControlPanel | None = None
        self._playback: Playback | None = None

    def attach(self, choice: Choice, panel: ControlPanel, playback: Playback) -> None:
        self._choice, self._panel, self._playback = choice, panel, playback

    def _parts(self) -> tuple[Choice, ControlPanel, Playback]:
        choice, panel, playback = self._choice, self._panel, self._playback
        assert choice and panel and playback, "the front is attached before its first use"
        return choice, panel, playback

    # -- what is shown (read-only; the frame thread's) -----------------------------------
    @property
    def preset(self) -> Preset:
        """The preset shown: a named one, Custom, or a chosen scene's identity."""
        return self._parts()[0].preset

    @property
    def showcase(self) -> LiveShowcase | None:
        """The scene being shown, if one is chosen instead of a preset."""
        return self._parts()[0].showcase

    @property
    def params(self) -> Parameters:
        """The parameters of the body shown (the last valid ones asked for)."""
        return self._parts()[0].build.params

    @property
    def body(self) -> FreeRigidBody | None:
        return self._parts()[0].build.body

    @property
    def frame(self) -> Frame | None:
        return self._parts()[0].build.frame

    @property
    def camera(self) -> str:
        """The camera view chosen ("default", or a name of :data:`~.cameras.CAMERA_NAMES`)."""
        return self.camera_of()

    # -- requests (any thread; never block) ----------------------------------------------
    def post(self, action: Action, key: Hashable | None = None) -> None:
        """Run ``action`` on the frame thread (never blocks). One with a ``key`` replaces the
        one queued with the same key (it sets the same thing); refused if the queue is full
        (the frame thread says so)."""
        self.queue.put(action, key)
        self.wake()

    def defer(self, action: Action, key: Hashable | None = None) -> None:
        """Run ``action`` on the frame thread before its next frame, without waking it now
        (what may follow the window just sent: it would compete with that window's sending
        for the interpreter). Otherwise as :meth:`post`."""
        self.queue.put(action, key)

    def report(self, error: BaseException) -> None:
        """Show an error raised outside the frame thread (a GUI callback)."""
        self.post(lambda: self.status.report(error))

    def choose_preset(self, preset: Preset) -> None:
        count = self._parts()[1].menu.count  # the menu's choices so far (Panel.show_preset)
        self.post(lambda: self.apply_preset(preset, count))

    def choose_scene(self, scene: SceneSpec) -> None:
        count = self._parts()[1].menu.count
        self.post(lambda: self.apply_scene(scene, count))

    def configure_scene(self, key: str, value: Value) -> None:
        """A control of the current scene moved."""
        choice = self._parts()[0]
        self.post(lambda: choice.configure(key, value), ("configure", key))

    def set_part_visible(self, part: str, visible: bool) -> None:
        choice = self._parts()[0]
        self.post(lambda: choice.set_part_visible(part, visible), ("part", part))

    def edit(self, change: Callable[[Parameters], Parameters]) -> None:
        count = self._parts()[1].menu.count
        self.post(lambda: self._parts()[0].edit(change, count))

    def set_speed(self, speed: float) -> None:
        playback = self._parts()[2]
        speed = playback.clamp_speed(speed)
        self.post(lambda: playback.set_speed(speed), "speed")

    def toggle_pause(self) -> None:
        self.post(lambda: self._unless_withheld(self._parts()[2].toggle_pause))

    def step(self) -> None:
        self.post(lambda: self._unless_withheld(self._parts()[2].step))

    def _unless_withheld(self, action: Action) -> None:
        """Run ``action`` (play, step) unless a challenge's body waits for its answer."""
        if self.preset.withheld:
            self.status.say("Answer the challenge first: its motion plays with the answer.")
            self._parts()[2].show()  # the button as the clock is: paused
            return
        action()

    # -- the panel's entries and lines that tools write --------------------------------------
    def add_menu_entry(self, group: str, label: str, choose: Callable[[], None]) -> None:
        """A menu entry of another module's (the challenges'): ``choose()`` runs on viser's
        event loop when the browser picks it (it must only post)."""
        self._parts()[1].add_entry(group, label, choose)

    def show_playback(self) -> None:
        """Show the playback widgets as the clock is (frame thread)."""
        self._parts()[2].show()

    def set_pointing_verb(self, verb: str) -> None:
        """How this screen points ("Click", "Tap"), and the hint said in it."""
        panel = self._parts()[1]
        panel.pointing_verb = verb
        panel.show_hint(self.preset)

    def show_pointing(self, text: str) -> None:
        """The line saying what a click on the ellipsoid does, or what the last one did."""
        self._parts()[1].show_pointing(text)

    def reset(self) -> None:
        self.post(self._reset)

    def set_trail(self, points: int) -> None:
        points = clamp_trail(points)
        playback = self._parts()[2]
        self.post(lambda: playback.set_trail(points), "trail")

    def set_visible(self, element: Element, visible: bool) -> None:
        self.post(lambda: self.scene.set_visible(element, visible), ("element", element))

    # -- frame thread --------------------------------------------------------------------
    def apply_preset(self, preset: Preset, menu_count: int | None = None) -> None:
        self._parts()[0].apply_preset(preset, menu_count)
        for then in self.after_preset:
            then()

    def apply_scene(self, scene: SceneSpec, menu_count: int | None = None) -> None:
        self._parts()[0].apply_scene(scene, menu_count)
        for then in self.after_scene:
            then()

    def _reset(self) -> None:
        self.clock.reset(0.0)
        self._parts()[1].motion.clear_plot()


class FollowerMirror:
    """What a follower changes on its frame thread to show the lead's state
    (:class:`~..classroom.lead.Mirror`): its playback's speed range and trail, the panel's
    playback and show/hide rows, and the motion's grid (a follower's: the process's one)."""

    def __init__(self, front: Front) -> None:
        self._front = front

    @property
    def speed_range(self) -> tuple[float, float]:
        return self._front._parts()[2].speed_range

    def set_trail(self, points: int) -> None:
        self._front._parts()[2].set_trail(points)

    def show_playback(self, speed: float, paused: bool, trail: int) -> None:
        self._front._parts()[1].show_playback(speed, paused, trail)

    def show_visibility(self, visible: Callable[[Element], bool]) -> None:
        self._front._parts()[1].show_visibility(visible)

    def moving(self, query: str) -> None:
        """The lead's new body or scene (its state of ``query``) is about to be opened."""
        self._front.moving(query)

    def regrid(self) -> None:
        """The clock's speed changed: the motion on the new grid."""
        choice = self._front._parts()[0]
        choice.build.regrid(choice.showcase)
