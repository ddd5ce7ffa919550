"""Outgoing frame rate per client: as many frames as the client takes, never a backlog.

Each browser has its own send queue in viser (the client's message buffer, drained by a task
on viser's event loop that hands windows of messages to the websocket). A frame's messages are
*taken* when that task has drained them from the queue; it stops draining while the socket's
write buffer is full (websockets waits for the socket to drain), that is while the browser, or
the network to it, does not keep up. Past the queue, the bytes wait in the websocket's write
buffer and then in the kernel's socket buffer until the client's side acknowledges them (TCP);
the kernel lets that buffer grow to megabytes, thousands of stale frames for a client that
reads nothing. :class:`Outbox` reads, for one client (through the adapter
:mod:`poinsot.app.viser_private.transport`), the id of the last message the frame put in the
queue, how far the draining task has got, and the bytes written but not yet acknowledged by the
client (the transport's buffer plus the socket's ``SIOCOUTQ``).

:class:`Pacer` is the session's frame-rate controller. After each frame it records the frame's
last message id (:meth:`Pacer.sent`); before the next it asks how many frames are still
queued (:meth:`Pacer.may_draw`): with more than MAX_IN_FLIGHT, or more than MAX_UNACKED bytes
not acknowledged, the frame is skipped (the time
shown jumps forward at the next one; the traces are filled from the exact solution) and the
client's rate is halved (retrying a quarter of a frame later instead, without halving, kept
the event loop of a crowded process busier: ten browsers' slider-to-redraw p95 rose by half);
a frame taken on time lets the rate climb back to ``max_fps``. A
client that reads nothing gets no new frames, so its queue holds at most MAX_IN_FLIGHT + 1 frames
however long it stalls, while the other sessions (each its own thread and queue) go on.

One process's browsers share its frames (:func:`frame_share`): each may have up to ``max_fps``
while few are connected, fewer as more share the process, never fewer than SHARED_MIN_FPS. A
process drawing all the frames its browsers would take has no time left to answer a slider at
once: on this 2-core machine, 15 browsers per process at 44 fps each answered a slider in
104 ms (p95), at 35 fps each in 45 ms.
"""

from __future__ import annotations

import collections
import contextlib
import dataclasses
import fcntl
import struct
import termios
from typing import Any

import viser

from poinsot.app import viser_private as private

#: Frames a client may have queued, not yet taken, before the next frame is skipped. 0: a
#: frame is drawn only once the one before was taken; with 1, under a busy event loop, a
#: third of the frames drawn were never seen (two frames taken together, the older pose
#: replaced by the newer in viser's queue), work for nothing.
MAX_IN_FLIGHT = 0
#: Bytes written to a client but not yet acknowledged by it before the next frame is skipped
#: (a few frames' worth; a client that keeps up has about one frame's bytes in flight).
MAX_UNACKED = 32 * 1024
#: The slowest rate a stalled client is polled at [frames per second]: it costs one check.
MIN_FPS = 2.0
#: A frame taken on time raises the rate by this factor (a skip halves it).
RAISE = 1.25
#: Frames a second one process shares among its browsers [frames/s], and the least each gets:
#: a smooth 30 with room for the frames a slider move costs (a class of 30 followers per
#: process lose two to three each per move of the lecturer's, while every follower's body is
#: rebuilt; with a slider moved every second, the slowest of 60 followers got 27.7 to 29.9
#: frames a second at 34 in four runs in a row, 30.3 to 31.7 at 36 in five). 36 is also the
#: share of 15 browsers (540 / 15): a classroom of 30 sessions on two workers is not changed.
PROCESS_FRAMES = 540.0
SHARED_MIN_FPS = 36.0


def frame_share(max_fps: float, browsers: int) -> float:
    """The frame rate cap of each of ``browsers`` sharing one process [frames/s]."""
    return min(max_fps, max(SHARED_MIN_FPS, PROCESS_FRAMES / max(browsers, 1)))


class Outbox:
    """How far one client's send queue has been taken (viser's per-client message buffer)."""

    def __init__(self, client: viser.ClientHandle) -> None:
        self.client = client
        self.client_id = client.client_id
        self._buffer: Any = private.message_buffer(client)
        self._transport: Any = _transport(client)

    @property
    def available(self) -> bool:
        return self._buffer is not None

    def last_queued(self) -> int:
        """The id of the last message put in the client's queue (-1: none)."""
        return private.last_queued(self._buffer) if self._buffer is not None else -1

    def last_taken(self) -> int:
        """The id of the last message the client's sender has taken from the queue (every
        message after it is still queued)."""
        taken = None if self._buffer is None else private.last_taken(self._buffer, self.client_id)
        return self.last_queued() if taken is None else taken  # no sender yet: nothing due

    def closed(self) -> bool:
        """True once the client has left (what is queued then is never sent)."""
        return self._buffer is not None and private.closed(self._buffer)

    def quiet_if_left(self) -> contextlib.AbstractContextManager[None]:
        """A frame's or an action's messages within this block, if the client leaves while it
        runs, are dropped without viser's warning (the session is closing: the next pass of
        its frame thread sees :meth:`closed`)."""
        return private.quiet_if_closed(self._buffer)

    def pending(self) -> int:
        """Messages in the client's queue now (after viser's coalescing of updates)."""
        return private.pending(self._buffer) if self._buffer is not None else 0

    def unacknowledged(self) -> int:
        """Bytes written to the client and not yet acknowledged by it: the websocket
        transport's buffer and the kernel's send queue (0 if unknown)."""
        transport = self._transport
        if transport is None:
            return 0
        try:
            queued = int(transport.get_write_buffer_size())
            sock = transport.get_extra_info("socket")
            if sock is None:
                return queued
            raw = fcntl.ioctl(sock.fileno(), termios.TIOCOUTQ, b"\0\0\0\0")  # SIOCOUTQ
            return queued + struct.unpack("i", raw)[0]
        except (OSError, ValueError, AttributeError):  # closed meanwhile
            return 0


def _transport(client: viser.ClientHandle) -> Any:
    """The asyncio transport of the client's websocket, or None."""
    transport = getattr(private.connection_of(client)[0], "transport", None)
    return transport if hasattr(transport, "get_write_buffer_size") else None


@dataclasses.dataclass
class PacerStats:
    drawn: int = 0
    skipped: int = 0
    #: The most frames ever found queued before a frame (bounded by MAX_IN_FLIGHT + 1).
    max_in_flight: int = 0


def next_due(due: float, now: float, step: float) -> float:
    """When the frame after one due at ``due`` and drawn at ``now`` is due, ``step`` [s]
    apart: on the cadence (a frame drawn a little late, after a rebuild or a wait for the
    interpreter, is followed by one a little early, so the rate holds), but never sooner than
    half a step after it, and from ``now`` if it was a whole step late (never a burst of
    frames to catch up). Always at least ``step`` after ``due``."""
    if now - due >= step:
        return now + step
    return max(due + step, now + 0.5 * step)


class Pacer:
    """A client's frame rate (see the module's docstring). Frame thread only."""

    def __init__(
        self,
        outbox: Outbox,
        max_fps: float = 60.0,
        min_fps: float = MIN_FPS,
        max_in_flight: int = MAX_IN_FLIGHT,
        max_unacked: int = MAX_UNACKED,
    ) -> None:
        self.outbox = outbox
        self.max_fps = float(max_fps)
        self.min_fps = min(float(min_fps), self.max_fps)
        self.max_in_flight = int(max_in_flight)
        self.max_unacked = int(max_unacked)
        self.fps = self.max_fps
        #: A lower cap on the frame rate, whatever ``max_fps`` is (None: none): a follower
        #: whose poses the process's cast sends draws its own frames at this rate
        #: (:mod:`..classroom.cast`).
        self.cap: float | None = None
        self.stats = PacerStats()
        self._marks: collections.deque[int] = collections.deque()

    @property
    def interval(self) -> float:
        """Seconds to the next frame at the client's current rate."""
        cap = self.cap
        return 1.0 / (self.fps if cap is None else min(self.fps, cap))

    def in_flight(self) -> int:
        """Frames drawn whose messages the client has not all taken yet."""
        taken = self.outbox.last_taken()
        marks = self._marks
        while marks and marks[0] <= taken:
            marks.popleft()
        return len(marks)

    def may_draw(self) -> bool:
        """Before a frame: False (and a lower rate) while the client has too many frames
        queued; otherwise True (and a higher rate if the client keeps up). False once the
        client has left: between viser's closing its queue and the session's close, a frame
        would be queued for nobody (and viser would warn in the server's terminal)."""
        if self.outbox.closed():  # the client left; its session is closing
            return False
        queued = self.in_flight()
        self.stats.max_in_flight = max(self.stats.max_in_flight, queued)
        if queued > self.max_in_flight or self.outbox.unacknowledged() > self.max_unacked:
            self.fps = max(self.min_fps, 0.5 * self.fps)
            self.stats.skipped += 1
            return False
        if queued <= 1:
            self.fps = min(self.max_fps, RAISE * self.fps)
        return True

    def sent(self) -> None:
        """After a frame: remember its last message, to know when the client has taken it."""
        self.stats.drawn += 1
        last = self.outbox.last_queued()
        if not self._marks or last > self._marks[-1]:
            self._marks.append(last)


@dataclasses.dataclass
class SessionStats:
    """Timings for the benchmark and the tests (seconds)."""

    frame_seconds: collections.deque = dataclasses.field(
        default_factory=lambda: collections.deque(maxlen=2000)
    )
    #: CPU time of the session thread per loop pass that drew a frame: everything Poinsot
    #: does for one client-frame (actions, physics, scene updates, plot and time readout, and
    #: viser's setters that queue the messages), but not viser's transport thread.
    frame_cpu_seconds: collections.deque = dataclasses.field(
        default_factory=lambda: collections.deque(maxlen=2000)
    )
    rebuild_seconds: collections.deque = dataclasses.field(
        default_factory=lambda: collections.deque(maxlen=500)
    )
    #: Frames drawn (those the browser was not ready for are the pacer's ``stats.skipped``).
    frames: int = 0
    rebuilds: int = 0
    errors: int = 0
    last_error: str = ""
