"""A bounded trace that grows by increments: the polhode and the herpolhode.

Viser resends a node's whole ``points`` array when it changes, so a single growing line would
cost O(trail length) bytes per frame. Instead the trail is a ring of small line-segment nodes
("chunks"): each append only resends the head chunk (at most ``chunk`` segments), in one
message unless the head fills; a full head is frozen and a new one started; the oldest chunks
are dropped once the trail is longer than its length. Bytes per append are bounded by the chunk
size, or by the append's own size when it brings more than a chunk: what overflows the head is
then sent as one chunk of its own, frozen at once (a follower of a lecture draws its traces a
few times a second, a hundred points an append: one node, not four). The length stays within
one chunk (or one such append) below ``max_points``.

A dropped chunk is not removed but kept as a spare, shrunk to one point of the trail (hidden
under it), and reused as the next head: a chunk's node is made once, and in the steady state
an append sends only ``points`` updates (making a node costs many times an update in viser).

A cleared trail (a new body, a jump in time) is not removed at once either: its chunks hang
from a frame of their own (a *layer*, ``name/g<n>``), which is hidden in one message, and its
chunks are removed :data:`RETIRE_PER_APPEND` at a time with the appends that follow. A trail
a minute long is some seventy chunks: removed at once they were most of a new body's rebuild
(about 1 ms of the interpreter, and seventy messages, for each follower of a lecture).
"""

from __future__ import annotations

import collections

import numpy as np
import viser

#: Segments per chunk: the most a frame resends (24 segments x 2 x 3 float32 = 576 bytes).
CHUNK_SEGMENTS = 24
#: Spare chunks kept for reuse (a shorter trail removes the rest).
MAX_SPARE = 2
#: A cleared layer's chunks removed with each append that follows.
RETIRE_PER_APPEND = 4
#: Cleared layers kept hidden at most: clearing another removes the oldest whole (a trail
#: cleared again and again with no append between, as a slider dragged over a paused scene).
MAX_RETIRED = 2


class Trail:
    """A polyline under scene node ``name`` (a group frame; its children are the layers, whose
    children are the chunks: the newest layer drawn, the cleared ones hidden)."""

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
        self._layers = 0
        self._layer: viser.FrameHandle | None = None  # made with its first chunk
        #: Cleared layers, oldest first, with the chunks still to remove.
        self._retired: collections.deque[tuple[viser.FrameHandle, list[viser.SceneNodeHandle]]]
        self._retired = collections.deque()

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
        """Empty the trail: its layer hidden at once, its chunks removed with the next appends
        (:data:`RETIRE_PER_APPEND` each)."""
        chunks: list[viser.SceneNodeHandle] = [*self._spare, *(h for h, _ in self._frozen)]
        if self._head is not None:
            chunks.append(self._head)
        if self._layer is not None and chunks:
            self._layer.visible = False
            self._retired.append((self._layer, chunks))
            self._layer = None
            while len(self._retired) > MAX_RETIRED:
                self._retired.popleft()[0].remove()  # its chunks with it
        self._spare.clear()
        self._frozen.clear()
        self._frozen_segments = 0
        self._head = None
        self._n = 0
        self._last = None

    def remove(self) -> None:
        """Remove the trail's nodes, its group included (the trail is not used again)."""
        self.group.remove()  # its layers and their chunks with it
        self._retired.clear()
        self._spare.clear()
        self._frozen.clear()
        self._frozen_segments, self._head, self._layer, self._n, self._last = 0, None, None, 0, None

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
            if self._n == 0 and total - start > self._chunk:  # more than a chunk: one node
                self._add_frozen(np.stack([chain[start:total], chain[start + 1 :]], axis=1))
                break
            take = min(room, total - start)
            rows = self._buffer[self._n : self._n + take]
            rows[:, 0] = chain[start : start + take]
            rows[:, 1] = chain[start + 1 : start + take + 1]
            self._n += take
            start += take
            self._send_head()
        self._trim()
        self._retire(RETIRE_PER_APPEND)

    # -- internals -----------------------------------------------------------------------
    def _send_head(self) -> None:
        if self._head is None:  # the creation message keeps its array: a copy
            self._head = self._chunk_showing(self._buffer[: self._n].copy())
        else:
            self._head.points = self._buffer[: self._n]  # a points update casts (copies)

    def _add_frozen(self, segments: np.ndarray) -> None:
        """A chunk of ``segments`` (K, 2, 3), K above the chunk size, sent and frozen at once."""
        self._frozen.append((self._chunk_showing(segments), len(segments)))
        self._frozen_segments += len(segments)

    def _chunk_showing(self, segments: np.ndarray) -> viser.LineSegmentsHandle:
        """A chunk's node drawing ``segments``: a spare's points updated if there is one (a
        node is made once), else a node made."""
        if self._spare:
            handle = self._spare.pop()
            handle.points = segments
            return handle
        self._counter += 1
        return self._api.add_line_segments(
            f"{self._current_layer().name}/c{self._counter}",
            segments,
            self._color,
            thickness=self._width,
            thickness_units="screen",
            scale=self._scale,
        )

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

    def _current_layer(self) -> viser.FrameHandle:
        if self._layer is None:
            self._layers += 1
            self._layer = self._api.add_frame(f"{self._name}/g{self._layers}", show_axes=False)
        return self._layer

    def _retire(self, count: int) -> None:
        """Remove up to ``count`` chunks of the cleared layers, then each emptied layer."""
        while self._retired and count > 0:
            layer, chunks = self._retired[0]
            while chunks and count > 0:
                chunks.pop().remove()
                count -= 1
            if not chunks:
                layer.remove()
                self._retired.popleft()
