"""The followers' frames, encoded once per process: a follower's frame is the lead's frame.

Every follower of a process draws the same motion (the hub's shared
:class:`~poinsot.app.construction.sampled.motion.Motion`) at the same time (the hub's clock,
:meth:`~.follow.FollowHub.now`), so a frame's three pose messages (the body frame's orientation,
the tip's position, the ω arrow's points) are the same for all of them. :class:`FollowCast` (one
per process, one thread) makes them once per frame and group of followers drawing the same
motion on the same nodes, serialises them once as viser's own window
(:class:`poinsot.app.viser_private.OwnedWindow`), and hands each follower's socket its copy
(:func:`~poinsot.app.viser_private.send_each`): the same messages, stamped with the follower's
own id, as viser stamps a message of a client's own scene (its browser applies a pose to the
node of that id only; a copy is the one msgpack with the id spliced in, then compressed).

- A follower that falls behind is sent fewer frames, as a slow session is
  (:mod:`..hardening.pacing`): a follower whose last window is not yet written, or with more than
  ``MAX_UNACKED`` bytes of its own queue not acknowledged, is skipped this frame (counted), and
  never holds the others (each socket's write is a task of its own on viser's loop).
- What differs between followers stays each one's own, drawn by its own session at
  :func:`own_fps`: the traces (its own history of the motion), the labels laid out for its own
  camera, the ω plot and the time readout (widgets of its own page), one follower's at a time
  in the process (:meth:`.shared_frames.SharedFrames.drawing`), as are their rebuilds. The pose
  is then left out of its frames (``PoinsotScene.send_pose``).
- The lead's new body is made once per process too. Every follower rebuilds it, but the first
  of the cast to open it makes it (:meth:`FollowCast.claim_move`: the others wait for it, at
  most :data:`MAKER_WAIT`), and what its drawings' fit queues (the body's sizes and static
  curves: about a dozen node updates) is held back from its own queue and handed, encoded
  once, to it and to every follower whose browser still shows the body it showed
  (:meth:`FollowCast.share_fit`); those are posed from the new motion at once, and their own
  fits to the same body send nothing. The hall sees the lead's move once one follower has
  made it, not once the last has; each follower's own rebuild then sends only what is its own
  (its sliders, traces, readouts). A member's :attr:`Member.geometry` says which body its
  browser was last sent (by the cast or its session), so that a share never takes a follower
  back to an older body; a fit of a lead's state left since its session took it is not sent
  (:meth:`FollowCast.share_fit`); and every fit of a follower's goes through the cast's
  path, in the order handed. Only node updates are shared, to followers drawing the same
  elements on the same nodes; a fit that makes or removes a node is its follower's own, sent
  as ever.
- The lead's new body or scene is a rebuild in every follower: the cast then holds its frames
  (:meth:`FollowCast.hold`) until every follower it poses poses another motion (the maker's
  share took it to the new body, or it rebuilt) or :data:`MOVE_HOLD` has passed, so that the
  rebuilds have the interpreter to themselves and the move reaches the last follower of a hall
  sooner (the poses of the old body would be outdated by then anyway).
- A follower whose frame is not the lead's falls back to its own frames at its own rate at once
  (its session calls :meth:`.shared_frames.SharedFrames.update` with None): the lead shows a
  lecture scene (its frame is the scene's own drawing), the follower's ghost is on, its camera
  rides along with the body, or its rebuild is pending. "Explore from here" leaves the cast the
  same way.
"""

from __future__ import annotations

import dataclasses
import logging
import threading
import time
from collections.abc import Callable, Hashable
from typing import Any

import numpy as np
import viser

from poinsot.app.construction.construction import PoinsotScene
from poinsot.app.construction.sampled.motion import Motion
from poinsot.app.live.hardening.budget import HOLD_SECONDS
from poinsot.app.live.hardening.pacing import MAX_UNACKED, Outbox, next_due
from poinsot.app.model.elements import Element
from poinsot.app.viser_private import (
    OwnedWindow,
    WindowSocket,
    client_owner,
    orientation_message,
    position_message,
    props_message,
    send_each,
)

log = logging.getLogger(__name__)

#: The followers' shared frames a second (above a classroom's 30, with room to skip a few);
#: never more than the server's own cap (:attr:`FollowCast.fps`).
CAST_FPS = 40.0
#: A shared follower's own frames a second (its traces, labels, plot and time readout), at most,
#: and at least; a process's followers share OWN_PROCESS_FRAMES of them a second between them
#: (:func:`own_fps`): each own frame costs about a session's frame, so their sum must not grow
#: with the hall, up to 240 followers a process (OWN_MIN_FPS: a follower's traces and clock
#: then move every 2 s; its body, posed by the cast, still turns at the cast's rate). At 6 a
#: second, a worker's own frames were most of its followers' cost in a class of 30 on two
#: workers (0.17 to 0.19 ms of the server's CPU per follower-frame, 3.2 to 3.5 times below a
#: session-frame); at 3, 0.14 to 0.15 ms, 4.1 to 4.4 times below (four runs).
OWN_FPS = 3.0
OWN_MIN_FPS = 0.5
OWN_PROCESS_FRAMES = 120.0
#: A follower's unacknowledged bytes are read every this many of the cast's frames.
CHECK_TICKS = 8
#: The longest the cast holds its frames after the lead's new body or scene [s]
#: (:meth:`FollowCast.hold`).
MOVE_HOLD = 1.0
#: The messages a follower's fit to a new body may hand to the others (node updates).
FIT_MESSAGES = frozenset({"SceneNodeUpdateMessage", "SetPositionMessage", "SetOrientationMessage"})
#: The longest a follower's own fit waits for the windows already handed to its socket [s].
FIT_WAIT = 0.5
#: The longest a follower waits for another to make the new body it is about to fit [s].
MAKER_WAIT = 0.25


def updates_only(messages: list[Any]) -> bool:
    """Whether ``messages`` only update existing nodes (no node made or removed)."""
    return all(type(m).__name__ in FIT_MESSAGES for m in messages)


def own_fps(members: int) -> float:
    """Each shared follower's own frame rate when ``members`` share its process's cast."""
    return min(OWN_FPS, max(OWN_MIN_FPS, OWN_PROCESS_FRAMES / max(members, 1)))


@dataclasses.dataclass(frozen=True)
class Source:
    """What a follower's frame is drawn from: ``motion``, posing the nodes ``body``, ``tip``
    and ``arrow`` (None: no ω arrow drawn), in a scene that draws ``elements``."""

    motion: Motion
    body: str
    tip: str
    arrow: str | None
    elements: frozenset[Element] = frozenset()

    @classmethod
    def of(cls, scene: PoinsotScene) -> Source | None:
        """The motion ``scene`` shows and the nodes it poses (None: no body loaded)."""
        motion = scene.motion
        if motion is None:
            return None
        body, tip, arrow = scene.pose_nodes()
        return cls(motion, body, tip, arrow, scene.elements)

    @property
    def layout(self) -> Hashable:
        """Followers with the same layout fit a body to the same nodes."""
        return (self.body, self.tip, self.arrow, self.elements)

    @property
    def key(self) -> Hashable:
        """Followers with the same key are sent one window (each its copy)."""
        return (id(self.motion), self.body, self.tip, self.arrow)

    def messages(self, k: int) -> list[Any]:
        """The frame at grid index ``k``: the messages the session's own frame would send
        (``PoinsotScene.advance`` through ``construction/updates.py``), in the same order."""
        batch = self.motion.frames(k, k)
        j = k - batch.k0
        q, p = batch.wxyz[j], batch.tip[j]
        messages = [
            orientation_message(self.body, (float(q[0]), float(q[1]), float(q[2]), float(q[3]))),
            position_message(self.tip, (float(p[0]), float(p[1]), float(p[2]))),
        ]
        if self.arrow is not None:
            points = np.array(batch.arrow[j], dtype=np.float32)
            messages.append(props_message(self.arrow, {"points": points}))
        return messages


class Member:
    """One follower in the cast: its socket, how far its client has taken its own queue, what
    it shows (``source``, set by its session's thread) and the frame it was last sent."""

    def __init__(self, client: viser.ClientHandle) -> None:
        self.socket = WindowSocket(client)
        self.owner = client_owner(client)  # the scope of its nodes, stamped on its copy
        self.outbox = Outbox(client)
        self.source: Source | None = None
        self.shown: tuple[Hashable, int] | None = None
        #: The body (its motion's geometry) its browser was last sent, by its session or the
        #: cast (None: not known; it is then sent no other follower's).
        self.geometry: Any = None
        self.skipped = 0
        self._behind, self._looked = False, -CHECK_TICKS  # its socket's backlog, as last read

    def ready(self, tick: int) -> bool:
        """Whether it may be sent a frame at the cast's ``tick`` (else it is skipped: the slow
        client's rule). Its socket's backlog is read every :data:`CHECK_TICKS` ticks (a system
        call, which lets every other thread of the process take the interpreter)."""
        if self.socket.busy or self.outbox.closed():
            return False
        if tick - self._looked >= CHECK_TICKS:
            self._behind, self._looked = self.outbox.unacknowledged() > MAX_UNACKED, tick
        return not self._behind


class FollowCast:
    """One per process (the hub's): :meth:`join` and :meth:`leave` from the sessions' threads;
    its own thread draws, encodes and sends at ``fps`` while it has members."""

    def __init__(self, now: Callable[[], float | None], fps: float = CAST_FPS) -> None:
        self._now, self.fps = now, float(fps)
        self._lock = threading.Lock()
        self._members: dict[int, Member] = {}
        self._wake, self._stop = threading.Event(), threading.Event()
        self._thread: threading.Thread | None = None
        #: Windows encoded, handed to sockets, and followers skipped (tests, load test).
        self.encoded = 0
        self.handed = 0
        self.skipped = 0
        #: The thread's CPU time [s] (load test).
        self.cpu_seconds = 0.0
        self.ticks = 0
        #: Frames not sent while a move was held (:meth:`hold`) or another session rebuilt.
        self.held = 0
        #: True while a session of the process rebuilds its own body (the server's
        #: :class:`~..hardening.budget.RebuildGate`): no frame then, for at most
        #: :data:`~..hardening.budget.HOLD_SECONDS`, as a session's own frame is held. A lead's
        #: rebuild in a worker of 150 followers took up to 46 ms for its 3 to 5 ms of CPU
        #: beside the cast's ticks, each followed by 150 writes on viser's loop; all of the
        #: hall waits for it (its followers are posed from the old body meanwhile).
        self.yield_to: Callable[[], bool] = lambda: False
        self._yielding_since: float | None = None  # the rebuild it yields to, since
        #: New bodies handed from one follower to others, and the copies handed.
        self.fits = 0
        self.fit_copies = 0
        #: The query of the lead's state last moved to (:meth:`hold`).
        self.query: str | None = None
        #: The lead's last move: set once its maker has rebuilt, and its maker.
        self._move: tuple[threading.Event, Member | None] = (threading.Event(), None)
        self._move[0].set()
        self._hold: tuple[float, list[Motion]] | None = None  # until when, the old motions
        self._error = ""
        #: The members' own frames and rebuilds, one at a time in the process
        #: (:meth:`.shared_frames.SharedFrames.drawing`).
        self.draw_gate = threading.Lock()

    def join(self, key: int, client: viser.ClientHandle) -> Member | None:
        """``client`` is sent the shared frames from now on (None if its socket cannot be
        reached: it keeps its own)."""
        member = Member(client)
        if not member.socket.usable:
            return None
        with self._lock:
            self._members[key] = member
            if self._thread is None:
                self._thread = threading.Thread(target=self._run, name="poinsot-cast", daemon=True)
                self._thread.start()
        self._wake.set()
        return member

    def leave(self, key: int) -> None:
        with self._lock:
            self._members.pop(key, None)

    @property
    def members(self) -> int:
        with self._lock:
            return len(self._members)

    def close(self) -> None:
        self._stop.set()
        self._wake.set()

    def hold(self, query: str) -> None:
        """The lead's state opens another body or scene, or is its first (any thread), of
        ``query``: no frame until no member poses a motion it poses now (a share took it to
        the new body, it rebuilt, or it left), or :data:`MOVE_HOLD` has passed; and a new move
        begins, whose maker is the first member to open it (:meth:`claim_move`)."""
        with self._lock:
            self.query = query
            old = {id(m.source.motion): m.source.motion for m in self._members.values() if m.source}
            self._move = (threading.Event(), None)  # its maker: the first member to rebuild
        if old:
            self._hold = (time.monotonic() + MOVE_HOLD, list(old.values()))

    def _holding(self, members: list[Member]) -> bool:
        hold = self._hold
        if hold is None:
            return False
        until, old = hold
        if time.monotonic() < until and any(
            m.source is not None and any(m.source.motion is o for o in old) for m in members
        ):
            self.held += 1
            return True
        self._hold = None
        return False

    def tick(self) -> int:
        """One frame for every member: returns the windows encoded (one per group)."""
        t = self._now()
        if t is None:
            return 0
        self.ticks += 1
        with self._lock:  # a follower whose client left is dropped here, whatever its session did
            for gone in [k for k, m in self._members.items() if m.outbox.closed()]:
                del self._members[gone]
            members = list(self._members.values())
        if self._holding(members):
            return 0
        if self._yielding():
            self.held += 1
            return 0
        groups: dict[Hashable, tuple[Source, list[Member]]] = {}
        for member in members:
            source = member.source
            if source is not None:
                groups.setdefault(source.key, (source, []))[1].append(member)
        encoded = 0
        for key, (source, group) in groups.items():
            k = source.motion.sampler.index(t)
            ready = [m for m in group if m.shown != (key, k) and self._ready(m)]
            if ready:
                window = OwnedWindow(source.messages(k))
                encoded += 1
                sends = [(m.socket, window.bytes_for(m.owner)) for m in ready]
                with self._lock:  # a socket's windows are counted as a fit waits for them
                    self.handed += send_each(sends)
                for member in ready:
                    member.shown = (key, k)
        self.encoded += encoded
        return encoded

    def _yielding(self) -> bool:
        """Whether this tick waits for a session's rebuild (:attr:`yield_to`), at most
        :data:`HOLD_SECONDS` from the first tick it held."""
        if not self.yield_to():
            self._yielding_since = None
            return False
        now = time.monotonic()
        if self._yielding_since is None:
            self._yielding_since = now
        return now - self._yielding_since < HOLD_SECONDS

    # -- a new body, handed from the first follower to fit it ------------------------------
    def claim_move(self, member: Member) -> Callable[[], None] | None:
        """``member``'s session is about to open the lead's new body or scene (its thread).
        The first member to do so after the lead's move (:meth:`hold`) *makes* it: the others
        wait for it here (at most :data:`MAKER_WAIT`), so that it has the interpreter to
        itself and the new body it hands them (:meth:`share_fit`) reaches them before they
        make their own. Returns what its maker calls once its work is over (None: another
        member makes it)."""
        with self._lock:
            made, maker = self._move
            if maker is None:
                self._move = (made, member)
                return made.set
        if maker is not member:
            made.wait(MAKER_WAIT)
        return None

    def fitting(self, member: Member, geometry: Any) -> Any:
        """``member``'s session begins to fit its drawings to ``geometry`` (its thread):
        returns the body its browser was sent before (None: not known)."""
        with self._lock:
            before, member.geometry = member.geometry, geometry
        return before

    def forget_geometry(self, member: Member) -> None:
        """Its fit failed half-way: which body its browser shows is not known."""
        with self._lock:
            member.geometry = None

    def share_fit(
        self, sender: Member, before: Any, motion: Motion, messages: list[Any], query: str | None
    ) -> bool:
        """``sender`` fitted its drawings to ``motion``'s body, holding back ``messages``: hand
        them as one window, encoded once, each its copy, to ``sender`` and to every other
        member whose browser was last sent ``before`` too (the same updates take it to the
        same body) on the same nodes, and pose all of them from ``motion`` from now on (their
        sessions' rebuilds follow; a move's hold, :meth:`hold`, ends once the maker's share
        has taken every member to the new body, not once its own rebuild is over). One path
        for all of them: every window a socket is handed is written in the order handed.
        False (nothing handed) if ``messages`` are not all node updates.

        Nothing is handed, not even to ``sender``, if its fit is of a lead's state (``query``)
        left since its session took it (then waited for the move's maker and the interpreter):
        its browser keeps ``before`` (or a share's body) and its next rebuild follows. Handed
        round, such a fit took every browser back a move (a lead going back and forth brings
        the same geometry back: the process keeps its motions), each of their fits then all
        the others forth again."""
        source = sender.source
        if source is None or not messages or not updates_only(messages):
            return False
        geometry, layout = motion.geometry, source.layout
        with self._lock:  # handed in the order the members' geometries change
            if query != self.query:  # left behind: sent to nobody
                if sender.geometry is geometry:  # no share took it elsewhere meanwhile
                    sender.geometry = before
                return True
            behind = before is not None and before is not geometry  # else only the sender's
            targets = [
                m
                for m in self._members.values()
                if behind
                and m is not sender
                and m.geometry is before
                and m.source is not None
                and m.source.layout == layout
            ]
            for member in targets:
                member.geometry = geometry
            members = [sender, *targets]
            for member in members:  # the sender too: its rebuild's own part may take a while
                if member.source is not None:
                    member.source = dataclasses.replace(member.source, motion=motion)
            window = OwnedWindow(messages)
            send_each([(m.socket, window.bytes_for(m.owner)) for m in members])
            self.fits += 1
            self.fit_copies += len(targets)
        return True

    def _ready(self, member: Member) -> bool:
        if member.ready(self.ticks):
            return True
        member.skipped += 1
        self.skipped += 1
        return False

    def _run(self) -> None:
        due = time.monotonic()
        while not self._stop.is_set():
            with self._lock:
                idle = not self._members
            if idle:
                self._wake.wait()
                self._wake.clear()
                due = time.monotonic()
                continue
            delay = due - time.monotonic()
            if delay > 0:
                self._stop.wait(delay)
            cpu = time.thread_time()
            try:
                self.tick()
            except Exception as exc:  # the thread must survive; said once per new error
                message = f"{type(exc).__name__}: {exc}"
                if message != self._error:
                    self._error = message
                    log.exception("followers' shared frames: %s", message)
            self.cpu_seconds += time.thread_time() - cpu
            due = next_due(due, time.monotonic(), 1.0 / self.fps)
