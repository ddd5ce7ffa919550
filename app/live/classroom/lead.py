"""A session's "Class" folder: lead the class with the lecturer code, follow the lecturer, or
explore from the lecturer's state (the process's :class:`~.follow.FollowHub` links them).

- Leading: each frame the session's state is compared with the last one published; a change
  (a new body or scene, a control, play/pause, speed, a jump in time, the camera) is published
  at once, and the state again every :data:`REPUBLISH` seconds.
- Following: the session shows the lead's state (its link query, :mod:`.links`, opened as a
  link would be) and takes its time from the hub (the session's motion source asks it); the
  browser's changes to the other widgets are refused and put back
  (:func:`.widgets.hold_input`), said once. "Explore from here" (or unticking "Follow") goes
  on from exactly that state.

Threads: GUI callbacks post to the session's queue; the hub's callback only posts; the frame
thread alone applies a state and publishes one.
"""

from __future__ import annotations

import functools
import math
import time
import urllib.parse
from collections.abc import Callable
from typing import Any, Protocol

import numpy as np
import viser

from poinsot.app.lessons.support.spec import SceneSpec
from poinsot.app.live.classroom import links
from poinsot.app.live.classroom.follow import FollowHub, LeadState
from poinsot.app.live.hardening.backlog import close_connection
from poinsot.app.live.panel.playback import clamp_trail
from poinsot.app.live.panel.widgets import Sent, hold_input, on_user, set_value
from poinsot.app.model.elements import Element
from poinsot.app.model.parameters import Parameters
from poinsot.app.model.presets import PRESETS, Preset

#: Order of the folder in the main panel (before the ghost's).
FOLDER_ORDER = 44.0
#: Seconds between two publications of an unchanged lead state.
REPUBLISH = 0.25
#: The link parameters a state carries on their own.
_CLOCK_KEYS = ("t", "speed", "paused", "view")
HELD = (
    "You follow the lecturer: your controls show the lecturer's values. "
    "Press Explore from here to go on yourself."
)


#: A lead's query parsed once per process, not once per follower (it builds the body to check it).
_parsed = functools.lru_cache(maxsize=16)(links.parse)


def motion_query(query: str) -> str:
    """A link's query without its clock and view: the body or scene and its controls."""
    pairs = urllib.parse.parse_qsl(query, keep_blank_values=True)
    return urllib.parse.urlencode([(k, v) for k, v in pairs if k not in _CLOCK_KEYS], safe=",")


def _camera(client: viser.ClientHandle) -> tuple[tuple[float, ...], ...]:
    cam = client.camera
    return tuple(
        tuple(round(float(x), 4) for x in v) for v in (cam.position, cam.look_at, cam.up_direction)
    )


class LeadSession(links.LinkState, Protocol):
    """What leading and following use of a session's front: what a link reads, its client,
    clock and construction, and the requests that open the lead's body or scene."""

    client: viser.ClientHandle
    clock: Any
    scene: Any

    def report(self, error: BaseException) -> None: ...
    def post(self, action: Callable[[], None], key: object = None) -> None: ...
    def edit(self, change: Callable[[Parameters], Parameters]) -> None: ...
    def choose_scene(self, scene: SceneSpec) -> None: ...
    def choose_preset(self, preset: Preset) -> None: ...


class Mirror(Protocol):
    """What a follower changes on its frame thread to show the lead's state: its playback's
    speed range and trail, the panel's playback and show/hide rows, the motion's grid; and
    :meth:`moving` before it opens the lead's new body or scene, the state's query (the first
    follower of the process makes it, the others wait for it: :mod:`.cast`)."""

    @property
    def speed_range(self) -> tuple[float, float]: ...
    def set_trail(self, points: int) -> None: ...
    def show_playback(self, speed: float, paused: bool, trail: int) -> None: ...
    def show_visibility(self, visible: Callable[[Element], bool]) -> None: ...
    def moving(self, query: str) -> None: ...
    def regrid(self) -> None: ...


class LeadControls:
    """Mounted by the session after its panel; :meth:`on_frame` each frame, :meth:`close`
    when the browser leaves (the frame's time while following: the session's motion source,
    :mod:`..session.source`). ``mirror``: what a follower changes to show the lead's state."""

    def __init__(
        self, session: LeadSession, hub: FollowHub, mirror: Mirror, order: float = FOLDER_ORDER
    ) -> None:
        self.session, self.hub, self.client = session, hub, session.client
        self.mirror = mirror
        self.mode = "own"  # "lead", "follow" or "own"
        self._published: LeadState | None = None
        self._applied_query: str | None = None
        self._applied_camera: tuple[tuple[float, ...], ...] | None = None
        self._told = False  # the follower was told its controls are held
        gui = self.client.gui
        with gui.add_folder("Class: lead or follow", order=order, expand_by_default=False):
            self.code = gui.add_text("Lecturer code", "", hint="Printed by poinsot serve.")
            self.lead_button = gui.add_button("Lead this class", icon=viser.Icon.SCHOOL)
            self.follow = gui.add_checkbox(
                "Follow the lecturer", False, hint="Show what the lecturer shows, live."
            )
            self.camera = gui.add_checkbox(
                "Lecturer's camera", False, hint="While following: the lecturer's view too."
            )
            self.explore = gui.add_button("Explore from here", icon=viser.Icon.ROUTE)
            self.message = gui.add_markdown("")
        report = session.report
        on_user(self.lead_button, lambda _: self._claim(), report, inline=True, free=True)
        on_user(self.follow, self._on_follow, report, inline=True, free=True)
        on_user(self.explore, lambda _: session.post(self._detach, "follow"), report, free=True)
        on_user(self.code, lambda _: None, report, inline=True, free=True)
        on_user(self.camera, lambda _: None, report, inline=True, free=True)

    # -- browser (viser's loop: post only) -------------------------------------------------
    def _claim(self) -> None:
        claim = self.hub.claim(self, str(self.code.value), id(self.client))
        if claim.close:
            close_connection(self.client, "too many wrong lecturer codes")
            return
        if claim.ok:
            self.session.post(self._lead, "follow")
        self.session.post(lambda: self.say(claim.message), "follow-message")

    def _on_follow(self, sent: Sent) -> None:
        self.session.post(self._start_following if sent.value else self._detach, "follow")

    def start_following(self) -> None:
        """Follow the lecturer (a link with ``follow=1``, or the checkbox)."""
        self.session.post(self._start_following, "follow")

    def deposed(self) -> None:
        """Another lecturer took the lead (any thread)."""
        self.session.post(self._deposed, "follow")

    # -- frame thread ----------------------------------------------------------------------
    def say(self, message: str) -> None:
        self.message.content = message

    def _lead(self) -> None:
        if self.mode == "follow":
            self._stop_following()
        self.mode, self._published = "lead", None

    def _deposed(self) -> None:
        if self.mode == "lead":
            self.mode = "own"
            self.say("Another lecturer took over the lead; your session is your own again.")

    def _start_following(self) -> None:
        if self.mode == "lead":
            self.hub.leave(self)
        self.mode, self._applied_query, self._told = "follow", None, False
        set_value(self.follow, True)
        hold_input(self.client, self._refused)
        self.hub.watch(id(self), self._notified)
        self._sync()

    def _stop_following(self) -> None:
        hold_input(self.client, None)
        self.hub.unwatch(id(self))
        set_value(self.follow, False)

    def _detach(self) -> None:
        """Explore from here: the session's own clock goes on from the lead's time, in the
        lead's state now (a state taken just before the lead moved may still be on its way)."""
        if self.mode != "follow":
            return
        self._sync()
        lead = self.hub.now()  # the lead's time (None before its first state)
        t = float(self.session.clock.now()) if lead is None else lead
        self._stop_following()
        self.mode = "own"
        self.session.clock.reset(t)
        self.say(f"Exploring on your own from the lecturer's state at t = {t:.3g}.")

    def _refused(self, widget: bool) -> None:  # viser's loop
        self.session.post(
            self._tell_held if widget else self._tell_pointer,
            "follow-held" if widget else "pointer",
        )

    def _tell_held(self) -> None:
        self._applied_query = None  # shown again, in case a change got through
        self._sync()
        self._tell_pointer()

    def _tell_pointer(self) -> None:
        """A refused pointer changed nothing: the follower is only told (once)."""
        if not self._told:
            self._told = True
            self.say(HELD)

    def _notified(self) -> None:  # the hub's thread
        self.session.post(self._sync, "follow-sync")

    def _sync(self) -> None:
        """Show the lead's last state (frame thread)."""
        if self.mode != "follow":
            return
        state, session = self.hub.state, self.session
        if self.hub.gone:
            self.say(self.hub.gone)
        elif state is None:
            self.say("Waiting for the lecturer to lead this class.")
        elif not self._told:
            self.say("Following the lecturer.")
        if state is None:
            return
        if state.query != self._applied_query:
            self._applied_query = state.query
            self.mirror.moving(state.query)
            self._open(state.query)
        clock = session.clock
        if clock.paused != state.paused:
            clock.paused = state.paused
        lo, hi = self.mirror.speed_range
        if not math.isclose(clock.speed, state.speed) and lo <= state.speed <= hi:
            clock.speed = state.speed
            self.mirror.regrid()  # the worker's shared motion on the new grid
        clock.reset(state.time(time.monotonic()))
        self._mirror_shown(state)
        self.mirror.show_playback(clock.speed, clock.paused, session.scene.trail_points)
        if self.camera.value and state.camera and state.camera != self._applied_camera:
            self._applied_camera = state.camera
            position, look_at, up = (np.asarray(v, float) for v in state.camera)
            with self.client.atomic():  # the position moves look_at along: look_at after it
                self.client.camera.up_direction = up
                self.client.camera.position = position
                self.client.camera.look_at = look_at

    def _mirror_shown(self, state: LeadState) -> None:
        """The lead's trail length, the elements it hides and the scene's parts it hides."""
        session = self.session
        scene = session.scene
        if state.trail is not None and state.trail != scene.trail_points:
            self.mirror.set_trail(clamp_trail(state.trail))
        changed = False
        for element in Element:
            visible = element.name not in state.hidden
            if element not in scene.elements:
                scene.set_visible(element, visible)  # for when it is drawn (no message)
            elif scene.is_visible(element) != visible:
                scene.set_visible(element, visible)
                changed = True
        if changed:
            self.mirror.show_visibility(scene.is_visible)
        if session.showcase is not None:
            session.showcase.show_parts(state.parts)

    def _open(self, query: str) -> None:
        try:
            link = _parsed(query)
        except links.LinkError as exc:  # a lead on another version: keep the last state
            self.say(f"The lecturer's state could not be shown ({exc}).")
            return
        session = self.session
        if link.scene is not None:
            session.choose_scene(link.scene)
        elif link.preset in PRESETS or session.showcase is not None:
            session.choose_preset(link.preset)
        else:  # a body of the lead's own: as a slider move would (no panel redeclared)
            params = Parameters.from_preset(link.preset)
            session.edit(lambda _: params)

    def on_frame(self, now: float) -> None:
        """Each frame: a lead publishes its state if it changed, or if it is due again."""
        if self.mode != "lead":
            return
        token = self.hub.lead_token(self)
        if not token:
            return
        state = self._state(token, now)
        last = self._published
        if last is None or now - last.at >= REPUBLISH or state.news(last):
            self._published = state
            self.hub.publish(self, state)

    def _state(self, token: str, now: float) -> LeadState:
        session = self.session
        clock, frame, scene = session.clock, session.frame, session.scene
        # Paused: the time of the frame on screen, which the followers then show exactly.
        # Playing: the time at ``now``, the state's own instant (read a little later, the
        # clock's time would look like a jump of the lead's and be published again at once).
        t = frame.t if clock.paused and frame is not None else clock.at(now)
        return LeadState(
            leader=token,
            query=motion_query(links.query_of(session)),
            t=t,
            at=now,
            paused=clock.paused,
            speed=clock.speed,
            camera=_camera(self.client),
            trail=scene.trail_points,
            hidden=tuple(e.name for e in sorted(scene.elements) if not scene.is_visible(e)),
            parts=() if session.showcase is None else session.showcase.hidden_parts(),
        )

    def close(self) -> None:
        """The browser left."""
        hold_input(self.client, None)
        self.hub.unwatch(id(self))
        self.hub.forget(id(self.client))
        self.hub.leave(self)
