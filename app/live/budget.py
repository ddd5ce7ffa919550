"""Frame-rate governor: keeps the server responsive however many browsers are connected.

All sessions share one Python process (one GIL). Each drives its browser at up to 60 frames
per second; with many browsers the frames alone would take every CPU cycle, and a slider move
would then wait behind them. The budget measures what a client-frame really costs (process CPU
time per frame: physics, scene updates, viser's serialisation, the sends) and gives each session
a frame rate such that all frames together use at most ``share`` of one CPU, never more than
``max_fps`` and never less than ``min_fps``.

It also gives a slider move precedence: while any session rebuilds its scene (:meth:`rebuild`),
the other sessions hold their next frame (:attr:`rebuilding`), so the rebuild has the
interpreter to itself and the student who moved the slider sees the new body at once; the
others lose at most a frame or two.

:class:`MessageBudget` is the other direction: how many messages one client may send.
"""

from __future__ import annotations

import contextlib
import math
import threading
import time
from collections.abc import Iterator


class FrameBudget:
    def __init__(
        self,
        max_fps: float = 60.0,
        min_fps: float = 12.0,
        share: float = 0.6,
        recalibrate_seconds: float = 0.5,
    ) -> None:
        self.max_fps, self.min_fps, self.share = float(max_fps), float(min_fps), float(share)
        self._every = float(recalibrate_seconds)
        self._lock = threading.Lock()
        self._frames = 0
        self._sessions = 1
        self._fps = float(max_fps)
        self._cost = 0.0  # CPU seconds per client-frame, smoothed
        self._t0 = time.monotonic()
        self._cpu0 = time.process_time()
        self._rebuilding = 0

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

    @property
    def rebuilding(self) -> bool:
        """True while some session rebuilds: hold frames (never the rebuilds themselves)."""
        return self._rebuilding > 0

    def set_sessions(self, count: int) -> None:
        with self._lock:
            self._sessions = max(1, int(count))
            self._update_locked(force=True)

    def frame_done(self) -> None:
        with self._lock:
            self._frames += 1
            self._update_locked()

    @property
    def fps(self) -> float:
        """Frames per second each session may draw now."""
        return self._fps

    @property
    def cost(self) -> float:
        """Measured CPU seconds per client-frame (0 until measured)."""
        return self._cost

    def _update_locked(self, force: bool = False) -> None:
        now = time.monotonic()
        elapsed = now - self._t0
        if elapsed < self._every and not force:
            return
        if self._frames >= 10 and elapsed > 0:
            cost = (time.process_time() - self._cpu0) / self._frames
            self._cost = cost if self._cost == 0.0 else 0.5 * (self._cost + cost)
        if self._cost > 0.0:
            allowed = self.share / (self._cost * self._sessions)
            self._fps = max(self.min_fps, min(self.max_fps, allowed))
        else:
            self._fps = self.max_fps
        self._t0, self._cpu0, self._frames = now, time.process_time(), 0


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
