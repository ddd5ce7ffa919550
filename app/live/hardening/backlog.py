"""The hard cap on what a client may leave untaken: past it, for longer than a grace period,
the server closes that client's connection.

:mod:`~poinsot.app.live.hardening.pacing` keeps a session's frames from piling up for a browser that
does not take them. Other messages a session queues (the replies to the client's own actions:
a rebuilt panel, readouts, status) are not paced, and a client that goes on sending while it
reads nothing could make its queue grow until websockets' keepalive gives up on it (tens of
seconds). :class:`BacklogWatch` is one thread per server that looks at every session's
:class:`~poinsot.app.live.hardening.pacing.Outbox` a few times a second: a client with more than
:attr:`BacklogLimit.max_pending` messages in viser's queue, or more than
:attr:`BacklogLimit.max_unacked` bytes written to it and not acknowledged, for longer than
:attr:`BacklogLimit.grace`, has its websocket closed (one log line). viser then runs the
server's disconnect handler, which closes the session as for any browser that leaves.

A client that keeps up never comes near the bounds: its queue holds about one frame (a few
messages, :data:`~poinsot.app.live.hardening.pacing.MAX_IN_FLIGHT`), a rebuild adds a few dozen, and
its unacknowledged bytes stay near one frame's
(:data:`~poinsot.app.live.hardening.pacing.MAX_UNACKED`).
"""

from __future__ import annotations

import dataclasses
import logging
import threading
import time
from collections.abc import Callable, Mapping
from typing import Any, Protocol

import viser

from poinsot.app.live.hardening.pacing import Outbox
from poinsot.app.viser_private import connection_of

log = logging.getLogger(__name__)

#: Messages a client may leave in viser's queue (after viser's coalescing of updates) beyond
#: the grace period. A frame is 3-10 messages, a preset's whole panel a few hundred at once.
MAX_PENDING = 400
#: Bytes written to a client and not acknowledged by it beyond the grace period: about a
#: hundred frames of the heaviest scene, far above what a client that reads ever has.
MAX_UNACKED = 4 * 1024 * 1024
#: How long a client may stay over a bound before its connection is closed [s]: longer than
#: a browser's stall on a new scene's shaders, shorter than websockets' keepalive (40 s).
GRACE_SECONDS = 10.0
#: How often the watch looks at every client [s] (a length and an ioctl per client).
POLL_SECONDS = 0.25
#: The close frame sent (policy violation), and how long the closing handshake may take
#: before the socket is dropped [s]: a client that reads nothing never answers it.
CLOSE_CODE = 1008
ABORT_SECONDS = 2.0


@dataclasses.dataclass(frozen=True)
class BacklogLimit:
    """The bounds (see the module's constants) a server applies to each of its clients."""

    max_pending: int = MAX_PENDING
    max_unacked: int = MAX_UNACKED
    grace: float = GRACE_SECONDS
    poll: float = POLL_SECONDS

    def over(self, pending: int, unacked: int) -> bool:
        return pending > self.max_pending or unacked > self.max_unacked


class Watched(Protocol):
    """A session, as far as the watch goes."""

    @property
    def pacer(self) -> Any: ...


@dataclasses.dataclass
class BacklogStats:
    """Events for the tests and the load test."""

    checks: int = 0
    #: Clients whose connection the watch closed.
    closed: int = 0
    #: The most messages, and bytes, seen queued for one client (per client id).
    most_pending: dict[int, int] = dataclasses.field(default_factory=dict)
    most_unacked: dict[int, int] = dataclasses.field(default_factory=dict)


class BacklogWatch:
    """Close the connection of any client over ``limit`` for longer than its grace. ``sessions``
    returns the live sessions by client id (called from the watch's thread); ``close`` closes a
    client's connection (:func:`close_connection` if None)."""

    def __init__(
        self,
        sessions: Callable[[], Mapping[int, Watched]],
        limit: BacklogLimit | None = None,
        close: Callable[[viser.ClientHandle], bool] | None = None,
    ) -> None:
        self.limit = limit if limit is not None else BacklogLimit()
        self.stats = BacklogStats()
        self._sessions = sessions
        self._close = close if close is not None else close_connection
        self._since: dict[int, float] = {}  # client id -> when it went over
        self._closing: set[int] = set()
        self._stop = threading.Event()
        self._checked = threading.Condition()
        self._thread = threading.Thread(target=self._loop, name="poinsot-backlog", daemon=True)

    def start(self) -> BacklogWatch:
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        if self._thread.is_alive() and self._thread is not threading.current_thread():
            self._thread.join(5.0)

    def wait_checks(self, count: int, timeout: float = 30.0) -> bool:
        """Block (tests) until ``count`` more rounds of checks have run."""
        with self._checked:
            target = self.stats.checks + count
            return self._checked.wait_for(lambda: self.stats.checks >= target, timeout)

    def _loop(self) -> None:
        while not self._stop.wait(self.limit.poll):
            try:
                self.check(time.monotonic())
            except Exception:  # the watch must outlive any one client's oddity
                log.exception("backlog watch")

    def check(self, now: float) -> list[int]:
        """One round: note who is over, close who has been over for longer than the grace.
        Returns the ids of the clients closed in this round."""
        sessions = self._sessions()
        closed = []
        for client_id, session in sessions.items():
            outbox: Outbox = session.pacer.outbox
            pending, unacked = outbox.pending(), outbox.unacknowledged()
            stats = self.stats
            stats.most_pending[client_id] = max(stats.most_pending.get(client_id, 0), pending)
            stats.most_unacked[client_id] = max(stats.most_unacked.get(client_id, 0), unacked)
            if not self.limit.over(pending, unacked):
                self._since.pop(client_id, None)
                continue
            since = self._since.setdefault(client_id, now)
            if now - since >= self.limit.grace and client_id not in self._closing:
                self._closing.add(client_id)
                log.warning(
                    "client %s closed: %d messages queued, %d bytes unacknowledged, "
                    "for %.1f s (bounds %d messages, %d bytes)",
                    client_id,
                    pending,
                    unacked,
                    now - since,
                    self.limit.max_pending,
                    self.limit.max_unacked,
                )
                self._close(outbox.client)
                stats.closed += 1
                closed.append(client_id)
        for gone in set(self._since) - set(sessions):
            del self._since[gone]
        self._closing &= set(sessions)
        with self._checked:
            self.stats.checks += 1
            self._checked.notify_all()
        return closed


def close_connection(client: viser.ClientHandle, reason: str = "too far behind") -> bool:
    """Close ``client``'s websocket from any thread: a close frame, and the socket dropped
    ABORT_SECONDS later if the handshake has not ended. False if viser's internals (1.1: the
    live connections and the event loop on its websocket server) are not found."""
    connection, loop = connection_of(client)
    if loop is None or connection is None:
        return False

    def close() -> None:
        loop.create_task(connection.close(CLOSE_CODE, reason))
        loop.call_later(ABORT_SECONDS, connection.transport.abort)

    try:
        loop.call_soon_threadsafe(close)
    except RuntimeError:  # the loop is closed: the server stopped meanwhile
        return False
    return True
