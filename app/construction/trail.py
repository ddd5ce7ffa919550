"""A bounded trace that grows by increments: the polhode and the herpolhode.

Viser resends a node's whole ``points`` array when it changes, so a single growing line would
cost O(trail length) bytes per frame. Instead the trail is a ring of small line-segment nodes
("chunks"): each append only resends the head chunk (at most ``chunk`` segments), in one
message unless the head fills; a full head is frozen and a new one started; the oldest chunks
are dropped once the trail is longer than its length. Bytes per append are bounded by the chunk
size; the length stays within one chunk below ``max_points``.

A dropped chunk is not removed but kept as a spare, shrunk to one point of the trail (hidden
under it), and reused as the next head: a chunk's node is made once, and in the steady state
an append sends only ``points`` updates (making a node costs many times an update in viser).
"""

from __future__ import annotations

import collections

import numpy as np
import viser

#: Segments per chunk: the most a frame resends (24 segments x 2 x 3 float32 = 576 bytes).
CHUNK_SEGMENTS = 24
#: Spare chunks kept for reuse (a shorter trail removes the rest).
MAX_SPARE = 2


class Trail:
    """A polyline under scene node ``name`` (a group frame; its children are the chunks)."""

    def __init__(
        self,
        api: viser.SceneApi,
        name: str,
        color: tuple[int, int, int],
        width_px: float,
        max_points: int,
        *,
        position: tuple[float, float, float] = (0.0, 0.0, 0.0),
        scale: float = 1.0,
        chunk: int = CHUNK_SEGMENTS,
    ) -> None:
        self._api = api
        self._name = name
        self._color = np.asarray(color, dtype=np.uint8)
        self._width = float(width_px)
        self._scale = float(scale)
        self._chunk = int(chunk)
        self._max_points = max(int(max_points), 2 * self._chunk)
        self.group = api.add_frame(name, show_axes=False, position=position)
        self._frozen: collections.deque[tuple[viser.LineSegmentsHandle, int]] = collections.deque()
        self._frozen_segments = 0  # sum of the frozen chunks' segment counts
        self._head: viser.LineSegmentsHandle | None = None
        #: Dropped chunks, shrunk to a point of the trail, for the next heads.
        self._spare: list[viser.LineSegmentsHandle] = []
        # The head chunk's segments live in a preallocated buffer: rows [0, n) are drawn.
        self._buffer = np.empty((self._chunk, 2, 3), dtype=np.float32)
        self._n = 0
        self._last: np.ndarray | None = None
        self._counter = 0

    # -- state ---------------------------------------------------------------------------
    @property
    def segment_count(self) -> int:
        return self._frozen_segments + self._n

    @property
    def max_points(self) -> int:
        return self._max_points

    @max_points.setter
    def max_points(self, n: int) -> None:
        self._max_points = max(int(n), 2 * self._chunk)
        self._trim()

    @property
    def visible(self) -> bool:
        return self.group.visible

    @visible.setter
    def visible(self, visible: bool) -> None:
        self.group.visible = visible

    def segments(self) -> np.ndarray:
        """All segments currently drawn, oldest first, shape (N, 2, 3) (for tests)."""
        parts = [h.points for h, _ in self._frozen]
        parts.append(self._buffer[: self._n])
        return np.concatenate(parts).reshape(-1, 2, 3)

    def points(self) -> np.ndarray:
        """All points currently drawn, oldest first, shape (N, 3) (for tests and exports; a
        lifted trail's gap is not marked)."""
        segments = self.segments()
        if len(segments) == 0:
            return np.zeros((0, 3), dtype=np.float32)
        return np.concatenate([segments[:, 0], segments[-1:, 1]])

    # -- mutation ------------------------------------------------------------------------
    def clear(self) -> None:
        for handle in self._spare:
            handle.remove()
        self._spare.clear()
        for handle, _ in self._frozen:
            handle.remove()
        self._frozen.clear()
        self._frozen_segments = 0
        if self._head is not None:
            self._head.remove()
        self._head = None
        self._n = 0
        self._last = None

    def restyle(self, color: tuple[int, int, int], width_px: float) -> None:
        """New colour and width, for the pieces drawn already and those to come."""
        self._color = np.asarray(color, dtype=np.uint8)
        self._width = float(width_px)
        handles = [h for h, _ in self._frozen] + ([self._head] if self._head is not None else [])
        handles += self._spare
        for handle in handles:
            handle.colors = self._color
            handle.thickness = self._width

    def lift(self) -> None:
        """Lift the pen: the next :meth:`append` starts a new piece of the polyline, joined to
        nothing drawn before (after a gap in time, never a straight chord across it)."""
        self._last = None

    def append(self, points: np.ndarray) -> None:
        """Extend the polyline through ``points`` (N, 3); the first call only sets the start."""
        points = np.asarray(points, dtype=np.float32).reshape(-1, 3)
        if len(points) == 0:
            return
        if self._last is None:
            self._last = points[0]
            points = points[1:]
            if len(points) == 0:
                return
        chain = np.concatenate([self._last[None], points])
        self._last = chain[-1]
        start, total = 0, len(points)
        while start < total:
            room = self._chunk - self._n
            if room == 0:
                self._freeze_head()
                continue
            take = min(room, total - start)
            rows = self._buffer[self._n : self._n + take]
            rows[:, 0] = chain[start : start + take]
            rows[:, 1] = chain[start + 1 : start + take + 1]
            self._n += take
            start += take
            self._send_head()
        self._trim()

    # -- internals -----------------------------------------------------------------------
    def _send_head(self) -> None:
        if self._head is None and self._spare:
            self._head = self._spare.pop()
            self._head.points = self._buffer[: self._n]
        elif self._head is None:
            self._counter += 1
            self._head = self._api.add_line_segments(
                f"{self._name}/c{self._counter}",
                self._buffer[: self._n].copy(),  # the creation message keeps its array
                self._color,
                thickness=self._width,
                thickness_units="screen",
                scale=self._scale,
            )
        else:
            self._head.points = self._buffer[: self._n]  # a points update casts (copies)

    def _freeze_head(self) -> None:
        if self._head is not None:
            self._frozen.append((self._head, self._n))
            self._frozen_segments += self._n
        self._head = None
        self._n = 0

    def _trim(self) -> None:
        while self._frozen and self.segment_count > self._max_points:
            handle, n = self._frozen.popleft()
            self._frozen_segments -= n
            if self._last is None or len(self._spare) >= MAX_SPARE:
                handle.remove()
            else:  # shrunk onto the trail's newest point, under the line: nothing shows of it
                handle.points = np.broadcast_to(self._last, (1, 2, 3))
                self._spare.append(handle)
