"""Simulation clock: monotonic wall time scaled by a speed, with pause, step and reset."""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable


class SimClock:
    """``now()`` = simulation time. Pausing freezes it; changing the speed re-anchors so that
    the time is continuous. Thread-safe (GUI callbacks and the frame loop both use it)."""

    def __init__(self, speed: float = 1.0, monotonic: Callable[[], float] = time.monotonic):
        self._monotonic = monotonic
        self._lock = threading.Lock()
        self._speed = float(speed)
        self._paused = False
        self._t_anchor = 0.0
        self._wall_anchor = monotonic()

    def now(self) -> float:
        with self._lock:
            return self._now_locked()

    def at(self, wall: float) -> float:
        """Simulation time at monotonic time ``wall`` (the clock's own monotonic clock)."""
        with self._lock:
            return self._at_locked(wall)

    def _now_locked(self) -> float:
        return self._at_locked(self._monotonic())

    def _at_locked(self, wall: float) -> float:
        if self._paused:
            return self._t_anchor
        return self._t_anchor + self._speed * (wall - self._wall_anchor)

    def _reanchor_locked(self) -> None:
        self._t_anchor = self._now_locked()
        self._wall_anchor = self._monotonic()

    @property
    def speed(self) -> float:
        return self._speed

    @speed.setter
    def speed(self, speed: float) -> None:
        if not math.isfinite(speed):  # the clock would read NaN from now on, every frame
            raise ValueError(f"the speed must be a finite number, not {speed!r}")
        with self._lock:
            self._reanchor_locked()
            self._speed = float(speed)

    @property
    def paused(self) -> bool:
        return self._paused

    @paused.setter
    def paused(self, paused: bool) -> None:
        with self._lock:
            self._reanchor_locked()
            self._paused = bool(paused)

    def step(self, dt: float) -> None:
        """Advance by ``dt`` simulation seconds (used while paused)."""
        if not math.isfinite(dt):
            raise ValueError(f"a step must be a finite time, not {dt!r}")
        with self._lock:
            self._reanchor_locked()
            self._t_anchor += float(dt)

    def reset(self, t: float = 0.0) -> None:
        with self._lock:
            self._t_anchor = float(t)
            self._wall_anchor = self._monotonic()
