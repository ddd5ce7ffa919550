"""What keeps a long-running server level through storms of connections: a fixed set of worker
threads, and memory handed back once sessions are gone.

- :func:`fixed_pool`: the threads that build sessions and run the widgets' worker-thread
  callbacks, all started at once. A ``ThreadPoolExecutor`` starts threads as work comes and
  never stops them, so a burst of 40 browsers connecting at once left the process with more
  threads than before it, for good. Started up front, their number never changes.
- :class:`MemoryTrim`: after sessions end, once things are quiet for :data:`QUIET_SECONDS`,
  collect reference cycles and hand the heap's free pages back to the system (glibc's
  ``malloc_trim``). Without it, a storm of 200 visits left the server 17 % larger, in freed
  but kept memory, long after the last visitor left.
- A hall's heap, *settled*: in a serving process that holds :data:`SETTLE_SESSIONS` sessions or
  more, the same quiet moment also comes after sessions arrive, and what is alive then is
  frozen out of the collector's later scans (``gc.freeze``), to be unfrozen and scanned again
  at the next such moment. With a hall of followers (75 sessions a worker, the load test's
  follow phase) each of Python's whole-heap collections scanned every session's objects: 0.13
  to 0.23 s of a worker's interpreter, every session's frames held meanwhile, and a lead's
  move that met one reached the followers 0.2 s later than the others. Settled, a session's
  long-lived objects are scanned once per arrival or departure, not at Python's whim; what
  dies among them meanwhile is freed by its reference count, and a cycle among them waits for
  the next quiet moment, so what it can keep is bounded by what was alive at the last one.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import gc
import threading
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from typing import Any

#: Threads that build sessions (a build is 30-300 ms of CPU: more threads than cores buy
#: nothing) and run the widgets' worker-thread callbacks.
POOL_THREADS = 4
#: Seconds without a departure before memory is trimmed (a storm is trimmed once, after it).
QUIET_SECONDS = 2.0
#: Sessions in a serving process from which its heap is settled: a whole-heap collection
#: costs the interpreter about 3 ms a session (0.13 to 0.23 s with 75 followers), so a few
#: sessions gain little, and a storm of visits beside a few steady ones is trimmed as ever
#: (settled, its server kept 3 to 4 % more memory after it: the collector's whole-heap
#: scans, measured against the survivors of the last full one, came rarer during the storm).
SETTLE_SESSIONS = 20


def fixed_pool(threads: int = POOL_THREADS, name: str = "poinsot-pool") -> ThreadPoolExecutor:
    """A thread pool whose ``threads`` threads are all running when it is returned."""
    pool = ThreadPoolExecutor(max_workers=threads, thread_name_prefix=name)
    barrier = threading.Barrier(threads + 1)
    for _ in range(threads):  # each task holds its thread until all have started
        pool.submit(barrier.wait)
    barrier.wait()
    return pool


def _malloc_trim() -> Any:
    name = ctypes.util.find_library("c")
    try:
        return ctypes.CDLL(name).malloc_trim if name else None
    except (OSError, AttributeError):  # not glibc: collecting cycles is all there is
        return None


class MemoryTrim:
    """Call :meth:`departed` when a session ends and :meth:`arrived` when one starts; the trim
    runs QUIET_SECONDS after the last of either. ``sessions``: how many sessions the process
    serves now, given by a serving process only (``poinsot serve``: never a test's or a
    notebook's, whose heap is not the server's alone); with :data:`SETTLE_SESSIONS` or more,
    arrivals count too and the trim settles the heap."""

    def __init__(
        self, quiet_seconds: float = QUIET_SECONDS, *, sessions: Callable[[], int] | None = None
    ) -> None:
        self.quiet_seconds = float(quiet_seconds)
        self.trims = 0  # how many times memory was trimmed (tests)
        self._sessions = sessions
        self._trim = _malloc_trim()
        self._lock = threading.Lock()
        self._work = threading.Lock()  # a trim's own (its collection can take 0.2 s: the
        # sessions that arrive or leave meanwhile only wait for the GIL, not for this)
        self._timer: threading.Timer | None = None
        self._stopped = False
        self._frozen = False

    def departed(self) -> None:
        self._later()

    def arrived(self) -> None:
        """A session started (only a hall's arrivals wait for a trim, to settle its heap)."""
        if self._hall():
            self._later()

    def _hall(self) -> bool:
        """Whether this is a serving process that holds a hall (:data:`SETTLE_SESSIONS`)."""
        return self._sessions is not None and self._sessions() >= SETTLE_SESSIONS

    def _later(self) -> None:
        with self._lock:
            if self._stopped:
                return
            if self._timer is not None:
                self._timer.cancel()
            self._timer = threading.Timer(self.quiet_seconds, self._run)
            self._timer.daemon = True
            self._timer.start()

    def _run(self) -> None:
        with self._work:
            if self._stopped:
                return
            self._thaw()  # the last settled heap is scanned again, once
            gc.collect()
            if self._trim is not None:
                self._trim(0)
            if self._hall():
                gc.freeze()
                self._frozen = True
            with self._lock:
                self.trims += 1

    @property
    def settled(self) -> bool:
        """Whether the heap is settled now (tests)."""
        return self._frozen

    def _thaw(self) -> None:
        if self._frozen:
            gc.unfreeze()
            self._frozen = False

    def stop(self) -> None:
        """No trim after this; a settled heap is scanned by the collector again."""
        with self._lock:
            self._stopped = True
            if self._timer is not None:
                self._timer.cancel()
        with self._work:
            self._thaw()
