"""A session's queue of actions: bounded, and coalescing the ones that supersede each other.

GUI callbacks (viser's thread pool, any number of threads) post actions; the session's frame
thread takes them all at once and runs them in order. Two rules keep the queue small whatever
the clients send:

- an action posted with a ``key`` (the speed, the trail, one element's visibility, one scene
  control) replaces the one with the same key still queued: it is moved to the end, since it
  sets what the earlier one set, after everything posted before it;
- past :data:`MAX_ACTIONS` queued, a new action is refused and counted (:meth:`refused`): the
  session tells the user in its status line. A person dragging sliders posts a few dozen
  between two frames at most.
"""

from __future__ import annotations

import itertools
import threading
from collections.abc import Callable, Hashable

#: Actions a session may have queued; beyond, new ones are refused.
MAX_ACTIONS = 256

Action = Callable[[], None]


class ActionQueue:
    """Bounded and coalescing (see the module's docstring). ``put``: any thread; ``take``:
    the frame thread."""

    def __init__(self, maxsize: int = MAX_ACTIONS) -> None:
        self.maxsize = int(maxsize)
        self._lock = threading.Lock()
        self._queued: dict[Hashable, Action] = {}  # in order; unkeyed actions get a fresh key
        self._fresh = itertools.count()
        self._refused = 0
        #: The most actions ever queued at once, and all ever refused (tests).
        self.most = 0
        self.refused_total = 0

    def __len__(self) -> int:
        return len(self._queued)

    def put(self, action: Action, key: Hashable | None = None) -> bool:
        """Queue ``action`` (replacing the one queued with the same ``key``); False if the
        queue is full and the action was refused."""
        with self._lock:
            if key is not None and self._queued.pop(("keyed", key), None) is not None:
                self._queued[("keyed", key)] = action  # never more than before
                return True
            if len(self._queued) >= self.maxsize:
                self._refused += 1
                self.refused_total += 1
                return False
            self._queued[("keyed", key) if key is not None else next(self._fresh)] = action
            self.most = max(self.most, len(self._queued))
            return True

    def take(self) -> list[Action]:
        """Every action queued, oldest first; the queue is then empty."""
        with self._lock:
            actions = list(self._queued.values())
            self._queued.clear()
            return actions

    def run(self, report: Callable[[Exception], None]) -> int:
        """(Frame thread) Run every action queued, oldest first, then those queued meanwhile;
        one that raises is given to ``report`` and the others still run. Returns how many were
        refused since the last call (:meth:`refused`); 0 at once if none is queued."""
        if not len(self._queued):  # the usual frame
            return 0
        while actions := self.take():
            for action in actions:
                try:
                    action()
                except Exception as exc:
                    report(exc)
        return self.refused()

    def refused(self) -> int:
        """Actions refused since the last call."""
        with self._lock:
            refused, self._refused = self._refused, 0
            return refused
