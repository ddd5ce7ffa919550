"""What one session may take from the others, and what one client may send.

All sessions share one Python process (one GIL). How many frames each draws is its own
client's business (:mod:`~poinsot.app.live.hardening.pacing`: as many as that browser takes). What
is shared is precedence: while any session rebuilds its scene (:meth:`RebuildGate.rebuild`, a
slider moved), the other sessions hold their next frame (:meth:`RebuildGate.hold`), so the
rebuild has the interpreter to itself and the student who moved the slider sees the new body
at once; the others lose at most a frame or two. A held session sleeps until the rebuild ends
(the gate wakes it): it does not poll, which under load took the interpreter from the rebuild
it was waiting for.

:class:`MessageBudget` is the other direction: how many messages one client may send.
"""

from __future__ import annotations

import contextlib
import math
import threading
import time
from collections.abc import Iterator

#: While a session rebuilds, another's due frame is held until the rebuild ends, for at most
#: HOLD_SECONDS [s] (the sessions' frame loops, and the followers' shared frames).
HOLD_SECONDS = 0.05


class RebuildGate:
    """Gives a slider move precedence over the other sessions' frames (see the module)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._rebuilding = 0
        self._held: set[threading.Event] = set()  # the wakes of the sessions holding a frame

    @contextlib.contextmanager
    def rebuild(self) -> Iterator[None]:
        """Scope of one session's rebuild: the other sessions' frames wait until it ends."""
        with self._lock:
            self._rebuilding += 1
        try:
            yield
        finally:
            with self._lock:
                self._rebuilding -= 1
                held = self._held if self._rebuilding == 0 else set()
                if held:
                    self._held = set()
            for wake in held:
                wake.set()

    def hold(self, wake: threading.Event) -> bool:
        """Before a frame: True if some session rebuilds (hold the frame); ``wake`` is then set
        when the last rebuild ends. False: draw."""
        with self._lock:
            if self._rebuilding == 0:
                return False
            self._held.add(wake)
            return True

    @property
    def rebuilding(self) -> bool:
        """True while some session rebuilds: hold frames (never the rebuilds themselves)."""
        return self._rebuilding > 0


class MessageBudget:
    """What one client may send: ``rate`` messages a second, in bursts of up to ``burst`` (a
    token bucket). A message beyond it is refused (:meth:`admit` is False) and counted; a client
    that keeps exceeding it for ``excess_seconds`` is :meth:`sustained` (the guard then closes
    its connection). A browser sends at most a few dozen messages a second (camera moves, a
    slider dragged, parts of an upload): it never meets the limit."""

    def __init__(self, rate: float, burst: float, excess_seconds: float) -> None:
        self.rate, self.burst = float(rate), float(burst)
        self.excess_seconds = float(excess_seconds)
        self._tokens = self.burst
        self._last = time.monotonic()
        self._excess_since: float | None = None
        self._last_refusal = -math.inf
        self.admitted = 0
        self.dropped = 0

    def admit(self, now: float) -> bool:
        """Take one message arriving at ``now`` (time.monotonic()): True if within budget."""
        self._tokens = min(self.burst, self._tokens + max(0.0, now - self._last) * self.rate)
        self._last = max(self._last, now)
        if self._tokens >= 1.0:
            self._tokens -= 1.0
            self.admitted += 1
            return True
        self.dropped += 1
        if now - self._last_refusal > 1.0:  # a second within budget ends a streak of excess
            self._excess_since = now
        self._last_refusal = now
        return False

    def sustained(self, now: float) -> bool:
        """True once the client has been over its budget for ``excess_seconds`` without a
        second's pause."""
        if self._excess_since is None or now - self._last_refusal > 1.0:
            return False
        return now - self._excess_since >= self.excess_seconds
