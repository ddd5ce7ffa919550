"""One body's motion prepared for drawing, built once and drawn by any number of views.

:class:`Motion` is what :meth:`~poinsot.app.construction.construction.PoinsotScene.load` computes
before it sends anything: the geometry (:class:`~.geometry.Geometry`: the traces' survey, the
whole polhode, the solid's mesh) and the grid the motion is sampled on
(:class:`~.sampling.MotionSampler`), with the batches evaluated and converted for the frames
(:class:`~.batch.FrameBatch`). It changes only by adding batches, under a lock: any number of
threads may draw from one motion, and each batch is evaluated and converted once, by the first
thread that needs it. Views that draw the same grid times (the followers of a lecturer, on the
lecturer's clock) thus share one physics call per batch.

:class:`MotionCache` (one per server process) gives every session that asks for the same key
(the body's parameters, its solid and the grid's frame time) the same motion, built by the
first that asks while the others wait for it: one build per process, not one per session. A
scene's model (:meth:`~poinsot.app.lessons.support.runtime.Showcase.load`) is shared the same way.
"""

from __future__ import annotations

import collections
import threading
from collections.abc import Callable, Hashable
from typing import Any, Generic, TypeVar

from poinsot.app.construction.geometry import Geometry
from poinsot.app.construction.sampled.batch import FrameBatch
from poinsot.app.construction.sampled.sampling import BATCH, FIRST_BATCH, MotionSampler
from poinsot.app.model.elements import Solid
from poinsot.physics import FreeRigidBody

#: Trace points are at most this far apart [display units] (see scene/sampling.py).
MAX_CHORD = 0.02
#: Converted batches a motion keeps: a view a few frames behind the others still finds its own.
KEPT_BATCHES = 4
#: Motions a cache keeps (the newest used): a lead's drag of a slider builds one per value.
KEPT_MOTIONS = 8

T = TypeVar("T")


class Motion:
    """``body`` (and ``solid``) on ``sampler``'s grid, with its ``geometry``. Build with
    :meth:`prepare`; :meth:`frames` gives the batch of any grid range (thread-safe)."""

    def __init__(
        self, body: FreeRigidBody, solid: Solid | None, geometry: Geometry, sampler: MotionSampler
    ) -> None:
        self.body, self.solid, self.geometry, self.sampler = body, solid, geometry, sampler
        self._lock = threading.Lock()
        self._kept: collections.deque[FrameBatch] = collections.deque(maxlen=KEPT_BATCHES)
        self._memo: dict[str, Any] = {}

    @classmethod
    def prepare(
        cls, body: FreeRigidBody, solid: Solid | None, frame_time: float, t: float = 0.0
    ) -> Motion:
        """The motion of ``body`` on the grid for ``frame_time`` (the simulation time a frame
        advances) through ``t``, its first frames evaluated. Raises ValueError if physics gives
        anything non-finite."""
        geometry = Geometry.from_body(body, solid)
        motion = cls(body, solid, geometry, _grid(body, geometry, frame_time, t))
        k = motion.sampler.index(t)
        motion.frames(k, k, FIRST_BATCH)  # checked finite by the sampler
        return motion

    def regridded(self, frame_time: float, t: float) -> Motion:
        """The same body and geometry on the grid for ``frame_time`` through ``t`` (nothing
        evaluated yet)."""
        return Motion(
            self.body, self.solid, self.geometry, _grid(self.body, self.geometry, frame_time, t)
        )

    def frames(self, k_first: int, k_last: int, size: int = BATCH) -> FrameBatch:
        """The converted batch holding grid indices ``k_first..k_last``: a kept one, or a new
        one of ``size`` (or more) grid times from ``k_first`` (:meth:`MotionSampler.batch`)."""
        with self._lock:
            for batch in reversed(self._kept):
                if batch.k0 <= k_first and k_last < batch.k0 + len(batch.t):
                    return batch
            source = self.sampler.batch(k_first, k_last, size)
            batch = FrameBatch.convert(source, self.geometry.scale, self.sampler.stride)
            self._kept.append(batch)
            return batch

    def memo(self, name: str, make: Callable[[], Any]) -> Any:
        """``make()``, computed once per motion (text shown beside it, say)."""
        with self._lock:
            if name not in self._memo:
                self._memo[name] = make()
            return self._memo[name]


def _grid(body: FreeRigidBody, geometry: Geometry, frame_time: float, t: float) -> MotionSampler:
    return MotionSampler.for_body(body, geometry.trace_speed, frame_time, MAX_CHORD, t)


class _Pending(Generic[T]):
    def __init__(self) -> None:
        self.done = threading.Event()
        self.value: T | None = None
        self.error: BaseException | None = None


class MotionCache:
    """Motions (or scenes' models) by key, each built once (see the module). Thread-safe."""

    def __init__(self, keep: int = KEPT_MOTIONS) -> None:
        self.keep = int(keep)
        self._lock = threading.Lock()
        self._entries: collections.OrderedDict[Hashable, _Pending[Any]] = collections.OrderedDict()
        #: Builds so far (tests, load test): one per key, however many sessions ask.
        self.builds = 0

    def get(self, key: Hashable, build: Callable[[], T]) -> T:
        """What ``key`` names: ``build()`` by the first caller, waited for by the others. A
        ValueError (no such body) is raised to every caller with its message."""
        with self._lock:
            pending = self._entries.get(key)
            mine = pending is None
            if pending is None:
                pending = self._entries[key] = _Pending[Any]()
                self.builds += 1
                while len(self._entries) > self.keep:
                    self._entries.popitem(last=False)
            else:
                self._entries.move_to_end(key)
        if mine:
            try:
                pending.value = build()
            except BaseException as exc:
                pending.error = exc
                if not isinstance(exc, ValueError):  # not the body's fault: the next one tries
                    with self._lock:
                        self._entries.pop(key, None)
                raise
            finally:
                pending.done.set()
        pending.done.wait()
        if pending.value is None:
            error = pending.error
            if isinstance(error, ValueError):
                raise ValueError(str(error))
            raise RuntimeError(f"the shared build failed ({type(error).__name__}: {error})")
        return pending.value
