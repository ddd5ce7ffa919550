"""Follow the lecturer: one lead session's state, shared with every follower of the server.

The hub (one per server process) holds the lecturer code, which session leads, and the lead's
last state (:class:`LeadState`: its link query (:mod:`.links`) without the clock, its time,
play/pause, speed and camera). The lead session publishes its state through the hub when it
changes and a few times a second; the hub hands it to its followers and, with ``poinsot serve
--workers N``, sends it up a pipe to the parent, which passes it on to every other worker
(:mod:`.relay`): a process-level mechanism of the standard library, within one host.

Followers read the lead's time from :meth:`FollowHub.now`, one clock for every follower of
the process, anchored at the last state's monotonic time (the same clock for every process
of a host).

Messages (tuples, pickled by :mod:`multiprocessing`): ``("lead", token)`` a session took the
lead; ``("state", LeadState)``; ``("gone", token, message)`` the lead left or its process
ended. A state or a departure from a lead that is no longer the current one is ignored.
"""

from __future__ import annotations

import dataclasses
import hmac
import secrets
import threading
import time
import uuid
from collections.abc import Callable
from typing import Any

from poinsot.app.construction.sampled.motion import MotionCache
from poinsot.app.live.classroom.cast import FollowCast

#: Wrong codes from one client before its connection is closed.
MAX_WRONG_CODES = 5
#: A lead's time this far from the time its followers extrapolate is a jump [time units].
JUMP = 1e-3
#: The code's alphabet: no 0/O, 1/l/I to misread from a projector.
_ALPHABET = "23456789abcdefghjkmnpqrstuvwxyz"
LEFT = "The lecturer left; you keep the last state (Explore from here to go on yourself)."
ENDED = "The lecturer's server process stopped; you keep the last state."

Message = tuple[Any, ...]


def new_code(length: int = 6) -> str:
    """A random lecturer code (one per server run)."""
    return "".join(secrets.choice(_ALPHABET) for _ in range(length))


@dataclasses.dataclass(frozen=True)
class LeadState:
    """What a follower shows: ``query`` (a link's query without t, speed, paused and view),
    simulation time ``t`` at monotonic time ``at`` [s], ``paused``, ``speed``, the lead's
    camera (position, look-at, up: three 3-tuples) or None, the traces' length, the
    elements hidden and the scene's parts hidden."""

    leader: str
    query: str
    t: float
    at: float
    paused: bool
    speed: float
    camera: tuple[tuple[float, ...], ...] | None = None
    trail: int | None = None  # the traces' length [points]
    hidden: tuple[str, ...] = ()  # the construction's elements the lead hides (their names)
    parts: tuple[str, ...] = ()  # the scene's parts the lead hides (their keys)

    def time(self, now: float) -> float:
        """Simulation time at monotonic time ``now``."""
        return self.t if self.paused else self.t + self.speed * (now - self.at)

    def shown(self) -> tuple[Any, ...]:
        """What a follower shows of this state, its time apart."""
        return (
            self.query,
            self.paused,
            self.speed,
            self.camera,
            self.trail,
            self.hidden,
            self.parts,
        )

    def jumped_from(self, before: LeadState) -> bool:
        """Whether this state's time is not where ``before``'s clock had got to (a jump: a
        time set by hand, a step)."""
        return abs(self.t - before.time(self.at)) > JUMP * max(1.0, abs(self.speed))

    def news(self, before: LeadState | None) -> bool:
        """Whether a follower showing ``before`` has anything to change for this state (another
        lead, something shown, a jump in time): a state published again only re-anchors the
        clock, which every follower of a process reads from the hub (:meth:`FollowHub.now`)."""
        return (
            before is None
            or self.leader != before.leader
            or self.shown() != before.shown()
            or self.jumped_from(before)
        )


class Claim:
    """The answer to "Lead this class": ``ok``, its message, and whether to close the client."""

    def __init__(self, ok: bool, message: str, close: bool = False) -> None:
        self.ok, self.message, self.close = ok, message, close


class FollowHub:
    """One per server process. ``uplink``: sends a message to the other workers (None: this
    process is the whole server). Callbacks given to :meth:`watch` run on the thread that
    delivers a message: they must only post to their session."""

    def __init__(self, code: str | None = None, uplink: Callable[[Message], None] | None = None):
        self.code = code or new_code()
        self._uplinks = [] if uplink is None else [uplink]
        self._lock = threading.Lock()
        self._lead: Any = None  # this process's lead (a session's controls), if it has it
        self._lead_token = ""
        self.token = ""  # the current lead's, wherever it is
        self.state: LeadState | None = None
        self.gone = ""  # why there is no lead any more (followers keep the last state)
        self._watchers: dict[int, Callable[[], None]] = {}
        self._wrong: dict[int, int] = {}
        #: States delivered to this process, and those of them that woke no follower (the
        #: same state again, its clock re-anchored) (tests, load test).
        self.delivered = 0
        self.quiet = 0
        #: The lead's bodies, built once for the lead and the followers of this process.
        self.motions = MotionCache()
        #: The lead's scenes (their models and motions), built once for this process's followers.
        self.scenes = MotionCache()
        #: The followers' poses, encoded once for all of them (:mod:`.cast`).
        self.cast = FollowCast(self.now)

    # -- the lead ------------------------------------------------------------------------
    def claim(self, lead: Any, code: str, client_key: int) -> Claim:
        """``lead`` asks to lead with ``code``; a wrong one counts against ``client_key``."""
        if not hmac.compare_digest(code.strip().lower().encode(), self.code.encode()):
            with self._lock:
                wrong = self._wrong[client_key] = self._wrong.get(client_key, 0) + 1
            if wrong >= MAX_WRONG_CODES:
                return Claim(False, "Too many wrong codes: this page is closed.", close=True)
            left = MAX_WRONG_CODES - wrong
            return Claim(False, f"Wrong lecturer code ({left} tries left).")
        token = uuid.uuid4().hex
        with self._lock:
            self._wrong.pop(client_key, None)
            before, self._lead, self._lead_token = self._lead, lead, token
        if before is not None and before is not lead:  # this process's lead, taken over
            before.deposed()
        self._send(("lead", token))
        return Claim(True, "You lead this class: every follower sees what you show.")

    def publish(self, lead: Any, state: LeadState) -> bool:
        """The lead's new state (False, not sent, if ``lead`` no longer leads)."""
        with self._lock:
            if lead is not self._lead or state.leader != self._lead_token:
                return False
        self._send(("state", state))
        return True

    def leave(self, lead: Any, message: str = LEFT) -> None:
        """``lead`` stops leading (its browser left, or it follows now)."""
        with self._lock:
            if lead is not self._lead:
                return
            token, self._lead, self._lead_token = self._lead_token, None, ""
        self._send(("gone", token, message))

    def forget(self, client_key: int) -> None:
        """A client left: its count of wrong codes goes with it."""
        with self._lock:
            self._wrong.pop(client_key, None)

    def lead_token(self, lead: Any) -> str:
        with self._lock:
            return self._lead_token if lead is self._lead else ""

    def add_uplink(self, uplink: Callable[[Message], None]) -> None:
        """Send this process's messages there too (another host's link, :mod:`..broker`)."""
        self._uplinks.append(uplink)

    def leads_here(self) -> bool:
        """Whether the lead is a session of this process."""
        with self._lock:
            return self._lead is not None

    def _send(self, message: Message) -> None:
        self.deliver(message)
        for uplink in self._uplinks:
            uplink(message)

    # -- every message -------------------------------------------------------------------
    def deliver(self, message: Message) -> None:
        """A message from this process's lead or from another worker's."""
        deposed = None
        with self._lock:
            kind, token = message[0], message[1]
            if kind == "lead":
                self.token, self.gone = token, ""
                if self._lead is not None and self._lead_token != token:
                    deposed, self._lead, self._lead_token = self._lead, None, ""
            elif kind == "state" and token.leader == self.token:
                news = token.news(self.state)
                if self.state is None or token.query != self.state.query:
                    self.cast.hold(token.query)  # every follower rebuilds (:mod:`.cast`)
                self.state, self.gone = token, ""
                self.delivered += 1
                if not news:  # the same state again: the followers' clock is the hub's
                    self.quiet += 1
                    return
            elif kind == "gone" and token == self.token:
                self.token, self.gone = "", message[2]
            else:
                return
            watchers = list(self._watchers.values())
        if deposed is not None:
            deposed.deposed()
        for watcher in watchers:
            watcher()

    # -- followers -----------------------------------------------------------------------
    def watch(self, key: int, callback: Callable[[], None]) -> None:
        with self._lock:
            self._watchers[key] = callback

    def unwatch(self, key: int) -> None:
        with self._lock:
            self._watchers.pop(key, None)

    @property
    def followers(self) -> int:
        with self._lock:
            return len(self._watchers)

    def now(self) -> float | None:
        """The lead's simulation time now (None before its first state)."""
        state = self.state
        return None if state is None else state.time(time.monotonic())
