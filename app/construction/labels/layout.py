"""Where the scene's labels go on screen: each label's box beside its point, beyond the tip of
what it names, clear of the other labels and of the contact point, for the camera of the
browser that shows it.

viser draws a label as a box of constant pixel size (an em of 12 CSS px times its font scale)
whose corner or edge, its *anchor*, sits on the label's point. Labels pile up when their
points meet on screen: seen along L, the tips of L and ω and the end of axis 3 all fall near
the centre. So the server lays them out, a few times a second, from the camera the browser
reports (:class:`Camera`):

- each label has a point (the tip of its arrow or axis, pushed a little beyond it) and a root
  (where its arrow starts): the box goes on the side of the point that faces away from the
  root on screen, "beyond the tip";
- labels are placed in order of importance, each taking the first of its anchors (ordered by
  that outward direction) whose box overlaps no box placed before and no marker (the contact
  point); if none is free, the one that overlaps least;
- a box keeps inside the picture: a label whose point is near an edge takes an anchor on the
  inner side (a box cut by the edge cannot be read); a label whose point is outside the
  picture keeps as much of its box inside as it can;
- a label whose point may move (:attr:`Slot.movable`: L's, ω's, the herpolhode's, which hang
  from frames that only translate) may also be pushed, in the screen plane, in one of eight
  directions (the outward one first), far enough beyond its tip to clear a marker drawn there,
  and farther (up to PUSH_RINGS times) where that is taken.

Only anchors and these offsets change, and only when they do: a label rides on its frame
(the body, the contact point) between two layouts, with no message of its own.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Generator, Sequence
from typing import TypeVar

import numpy as np
from numpy.typing import ArrayLike

T = TypeVar("T")

#: CSS pixels of a label's em at font scale 1 (viser's screen-size labels).
EM_PX = 12.0
#: A label box: the line height and the padding of viser's label, in ems, and the mean
#: advance of a character (a sans-serif font: Latin letters and digits).
LINE_EM = 1.2
PAD_EM = 0.24
CHAR_EM = 0.55
#: Wider glyphs [em]: ω's box measured 18-19 CSS px wide in Chromium at a 16.8 px em (the mean
#: advance gave 13.3, and ω's box touched its neighbour's).
GLYPH_EM = {"ω": 0.9}
#: Gap kept between boxes, and between a box and a marker [CSS px].
GAP_PX = 4.0

#: Anchor -> where the box lies from the label's point, as the fractions (fx, fy) of its width
#: and height by which its top-left corner is offset (screen y points down).
ANCHORS: dict[str, tuple[float, float]] = {
    f"{v}-{h}": (fx, fy)
    for v, fy in (("top", 0.0), ("center", -0.5), ("bottom", -1.0))
    for h, fx in (("left", 0.0), ("center", -0.5), ("right", -1.0))
    if (v, h) != ("center", "center")
}


@dataclasses.dataclass(frozen=True)
class Camera:
    """A perspective camera as the browser reports it: position, look-at point and up
    direction (world), vertical field of view [rad], and the view's size [CSS px]."""

    position: np.ndarray
    look_at: np.ndarray
    up: np.ndarray
    fov: float
    width: float
    height: float

    def axes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The camera's forward, right and up unit vectors (world), computed once (kept in the
        instance without ``functools.cached_property``, whose lock all threads shared)."""
        axes = self.__dict__.get("_axes")
        if axes is None:
            axes = self._compute_axes()
            object.__setattr__(self, "_axes", axes)
        return axes

    def _compute_axes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        forward = np.asarray(self.look_at, float) - np.asarray(self.position, float)
        forward /= math.sqrt(forward @ forward)
        right = _cross(forward, np.asarray(self.up, float))
        norm = math.sqrt(right @ right)
        if norm < 1e-9:  # looking along "up": any right angle will do
            other = (1.0, 0.0, 0.0) if abs(forward[0]) < 0.9 else (0.0, 1.0, 0.0)
            right = _cross(forward, np.array(other))
            norm = math.sqrt(right @ right)
        right /= norm
        return forward, right, _cross(right, forward)

    def project(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Screen positions (N, 2) [CSS px, y down] and depths (N,) of world points (N, 3)."""
        forward, right, up = self.axes()
        d = np.asarray(points, float).reshape(-1, 3) - np.asarray(self.position, float)
        depth = d @ forward
        focal = 0.5 * self.height / math.tan(0.5 * self.fov)
        safe = np.where(depth > 1e-6, depth, 1e-6)
        x = 0.5 * self.width + focal * (d @ right) / safe
        y = 0.5 * self.height - focal * (d @ up) / safe
        return np.stack([x, y], axis=1), depth

    def world_per_px(self, depth: ArrayLike) -> np.ndarray:
        """World length of one CSS pixel at ``depth`` (any shape; in the screen plane)."""
        return 2.0 * np.asarray(depth, float) * math.tan(0.5 * self.fov) / self.height


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b of two 3-vectors (``np.cross`` costs ten times as much on one pair)."""
    (a0, a1, a2), (b0, b1, b2) = a.tolist(), b.tolist()
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


@functools.lru_cache(maxsize=256)
def box_size(text: str, scale: float) -> tuple[float, float]:
    """(width, height) [CSS px] of a one-line label's box at font scale ``scale``."""
    em = EM_PX * scale
    advance = sum(GLYPH_EM.get(char, CHAR_EM) for char in text)
    return (advance + PAD_EM) * em, (LINE_EM + PAD_EM) * em


@dataclasses.dataclass
class Slot:
    """A label to lay out: its ``point`` (world), beyond the ``tip`` of the arrow or axis it
    names, which starts at ``root``. ``movable``: the point may be pushed in the screen plane,
    to at least ``clearance`` CSS px beyond the tip (clear of a marker drawn there)."""

    key: str
    text: str
    scale: float
    point: np.ndarray
    tip: np.ndarray
    root: np.ndarray
    movable: bool = False
    clearance: float = 0.0
    anchor: str = "bottom-left"


@dataclasses.dataclass(frozen=True)
class Placement:
    """Where a label goes: its anchor, its world offset (movable labels; zero otherwise) and
    its box on screen [x0, y0, x1, y1] (CSS px)."""

    anchor: str
    offset: np.ndarray
    box: tuple[float, float, float, float]
    overlap: float


def _overlap_costs(boxes: np.ndarray, placed: np.ndarray) -> np.ndarray:
    """The overlap of each candidate box (K, 4) with the boxes placed (M, 4), each grown by
    GAP_PX, times LABEL_WEIGHT."""
    w = np.minimum(boxes[:, None, 2], placed[None, :, 2])
    w = w - np.maximum(boxes[:, None, 0], placed[None, :, 0]) + GAP_PX
    h = np.minimum(boxes[:, None, 3], placed[None, :, 3])
    h = h - np.maximum(boxes[:, None, 1], placed[None, :, 1]) + GAP_PX
    return LABEL_WEIGHT * np.sum(np.maximum(w, 0.0) * np.maximum(h, 0.0), axis=1)


def _outside_costs(boxes: np.ndarray, width: float, height: float) -> np.ndarray:
    """The area of each candidate box (K, 4) outside the view [0, width] x [0, height] (CSS
    px), times OUTSIDE_WEIGHT: zero for a box wholly inside (a box may touch the edge)."""
    x0, y0, x1, y1 = boxes.T
    inside_w = np.maximum(np.minimum(x1, width) - np.maximum(x0, 0.0), 0.0)
    inside_h = np.maximum(np.minimum(y1, height) - np.maximum(y0, 0.0), 0.0)
    outside = (x1 - x0) * (y1 - y0) - inside_w * inside_h
    return OUTSIDE_WEIGHT * np.maximum(outside, 0.0)


def _disc_costs(
    boxes: np.ndarray, centres: np.ndarray, radii: np.ndarray, weights: np.ndarray
) -> np.ndarray:
    """The weighted reach of each candidate box (K, 4) into the discs (D): the sum over the
    discs of weight x (radius + GAP_PX - distance from box to centre)^2 where positive. It
    does not depend on the other labels, so every label's candidates are costed in one pass;
    the root is taken only for the (few) pairs that touch."""
    cost = np.zeros(len(boxes))
    cx, cy = centres[:, 0], centres[:, 1]
    dx = np.maximum(np.maximum(boxes[:, 0:1] - cx, cx - boxes[:, 2:3]), 0.0)
    dy = np.maximum(np.maximum(boxes[:, 1:2] - cy, cy - boxes[:, 3:4]), 0.0)
    limit = radii + GAP_PX
    squared = dx * dx + dy * dy
    rows, cols = np.nonzero(squared < limit * limit)
    reach = limit[cols] - np.sqrt(squared[rows, cols])
    np.add.at(cost, rows, weights[cols] * reach * reach)
    return cost


_ANCHOR_NAMES = tuple(ANCHORS)
_ANCHOR_INDEX = {name: i for i, name in enumerate(_ANCHOR_NAMES)}
#: Each anchor's (fx, fy), in the order of _ANCHOR_NAMES.
_FRACTIONS = np.array(list(ANCHORS.values()), dtype=np.float64)
#: The unit direction (screen, y down) in which each anchor's box lies from its point.
_ANCHOR_DIRECTIONS = np.array([[fx + 0.5, fy + 0.5] for fx, fy in ANCHORS.values()])
_ANCHOR_DIRECTIONS /= np.linalg.norm(_ANCHOR_DIRECTIONS, axis=1)[:, None]


def _ranked(direction: np.ndarray, current: Sequence[str]) -> np.ndarray:
    """Per label, the anchors (N, 8; indices into _ANCHOR_NAMES), the one whose box lies most
    along its ``direction`` (N, 2; screen) first; the ``current`` anchor wins ties, so that a
    label does not flicker between equals."""
    score = -(direction @ _ANCHOR_DIRECTIONS.T)
    rows = [i for i, anchor in enumerate(current) if anchor in _ANCHOR_INDEX]
    score[rows, [_ANCHOR_INDEX[current[i]] for i in rows]] -= 1e-3
    return np.argsort(score, axis=1, kind="stable")


#: A label's outward direction when its arrow is seen end-on: up-right (screen, y down).
_UP_RIGHT = np.array([math.sqrt(0.5), -math.sqrt(0.5)])


def _outward(first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """Per row (N, 2): the first of the two screen directions longer than 2 px, as a unit
    vector; up-right where neither is (an arrow seen end-on)."""
    out = np.tile(_UP_RIGHT, (len(first), 1))
    for vector in (second, first):  # the first wins: written last
        length = np.hypot(vector[:, 0], vector[:, 1])
        long = length > 2.0
        out[long] = vector[long] / length[long, None]
    return out


#: Points along an arrow that the boxes keep clear of.
ARROW_SAMPLES = 12
#: Where no place is free, what is worst: to cover another label or to lie outside the
#: picture (unread either way), then to cover a marker, then an arrow's shaft (weights of the
#: overlaps).
LABEL_WEIGHT = 10.0
OUTSIDE_WEIGHT = 10.0
MARKER_WEIGHT = 5.0
#: A movable label is pushed up to this many times its clearance before it settles for the
#: least overlap.
PUSH_RINGS = 3


@dataclasses.dataclass(frozen=True)
class _Candidates:
    """Every label's places to try, best first, K per label (N labels): the anchors (N, K;
    indices into _ANCHOR_NAMES), the screen shifts of the label's point (N, K, 2), the boxes
    (N, K, 4), and ``barred`` (N, K): +inf for the pushes of a label that may not move."""

    anchors: np.ndarray
    shifts: np.ndarray
    boxes: np.ndarray
    barred: np.ndarray

    @classmethod
    def of(cls, slots: Sequence[Slot], screen: np.ndarray) -> _Candidates:
        """The candidates of ``slots``, their point, tip and root on screen (N, 3, 2). Each
        label is first pushed (:func:`_pushes`), then tries its anchors round its point,
        those along its outward direction first (away from its arrow's root)."""
        point, tip, root = screen[:, 0], screen[:, 1], screen[:, 2]
        direction = _outward(tip - root, point - tip)
        ranked = _ranked(direction, [slot.anchor for slot in slots])
        pushes, push_anchors = _pushes(slots, point, tip, direction)
        anchors = np.concatenate([push_anchors, ranked], axis=1)
        shifts = np.concatenate([pushes, np.zeros((*ranked.shape, 2))], axis=1)
        size = np.array([box_size(slot.text, slot.scale) for slot in slots])[:, None]
        corner = point[:, None] + shifts + _FRACTIONS[anchors] * size
        boxes = np.concatenate([corner, corner + size], axis=2)
        barred = np.zeros(anchors.shape)
        barred[[not slot.movable for slot in slots], : pushes.shape[1]] = np.inf
        return cls(anchors, shifts, boxes, barred)


def lay_out(
    slots: Sequence[Slot],
    camera: Camera,
    markers: Sequence[tuple[np.ndarray, float]] = (),
    arrows: Sequence[tuple[np.ndarray, np.ndarray, float]] = (),
) -> dict[str, Placement]:
    """Place ``slots`` in their order (most important first); ``markers``: (world point,
    radius [CSS px]) that no box may cover; ``arrows``: (start, end, half-width [CSS px]) that
    the boxes avoid crossing. Labels behind the camera keep their anchor.

    A candidate's cost is its overlap with the labels placed before it (LABEL_WEIGHT) plus its
    area outside the camera's view (OUTSIDE_WEIGHT) and its reach into the markers and arrows;
    the first candidate of cost 0 wins, else the cheapest.
    Every label's candidates are made, and their reach costed, in one pass of array
    operations (:class:`_Candidates`); only the overlap with the labels placed before is a
    step per label (:func:`_choose`)."""
    return finish(lay_out_in_steps(slots, camera, markers, arrows))


Steps = Generator[None, None, T]


def lay_out_in_steps(
    slots: Sequence[Slot],
    camera: Camera,
    markers: Sequence[tuple[np.ndarray, float]] = (),
    arrows: Sequence[tuple[np.ndarray, np.ndarray, float]] = (),
) -> Steps[dict[str, Placement]]:
    """:func:`lay_out` in three steps, a ``yield`` between two: the candidates, their reach
    into the markers and arrows and out of the picture, the choice. A caller that resumes it
    once per frame spreads a layout over frames (:func:`finish` runs it at once)."""
    if not slots:
        return {}
    points = np.array([[slot.point, slot.tip, slot.root] for slot in slots], float)
    screen, depths = camera.project(points.reshape(-1, 3))
    front = np.flatnonzero(depths[::3] > 0)
    if not len(front):
        return {}
    shown = [slots[i] for i in front.tolist()]
    c = _Candidates.of(shown, screen.reshape(-1, 3, 2)[front])
    yield
    boxes = c.boxes.reshape(-1, 4)
    cost = _disc_costs(boxes, *_discs(camera, markers, arrows))
    cost += _outside_costs(boxes, camera.width, camera.height)
    cost = cost.reshape(c.boxes.shape[:2]) + c.barred
    yield
    chosen, costs = _choose(c.boxes, cost)
    return _placements(shown, c, chosen, costs, camera, depths[::3][front])


def finish(steps: Steps[T]) -> T:
    """Run ``steps`` to their end; their result."""
    while True:
        try:
            next(steps)
        except StopIteration as stop:
            return stop.value


def _choose(boxes: np.ndarray, reach: np.ndarray) -> tuple[list[int], list[float]]:
    """Label by label, in order: the first candidate whose cost is 0, else the cheapest, a
    candidate's cost being its ``reach`` (N, K) plus its overlap with the boxes (N, K, 4)
    chosen before. Returns each label's chosen candidate and its cost.

    A candidate of no reach is checked against the chosen boxes in plain floats, in order:
    the usual label, free at its first or second try, costs no array operation. Only a label
    with no free candidate costs them all (:func:`_overlap_costs`), to take the cheapest."""
    box_rows, reach_rows = boxes.tolist(), reach.tolist()
    chosen: list[int] = []
    costs: list[float] = []
    placed: list[list[float]] = []
    for i, (row_boxes, row_reach) in enumerate(zip(box_rows, reach_rows, strict=True)):
        free = (k for k, r in enumerate(row_reach) if r == 0.0 and _clear(row_boxes[k], placed))
        k = next(free, -1)
        cost = 0.0
        if k < 0:
            row = reach[i] + _overlap_costs(boxes[i], np.array(placed)) if placed else reach[i]
            k = int(np.argmin(row))
            cost = float(row[k])
        chosen.append(k)
        costs.append(cost)
        placed.append(row_boxes[k])
    return chosen, costs


def _clear(box: list[float], placed: list[list[float]]) -> bool:
    """Whether ``box`` overlaps none of the ``placed`` boxes, each grown by GAP_PX (as
    :func:`_overlap_costs` would find it: a zero overlap; NaN is not clear)."""
    x0, y0, x1, y1 = box
    for p0, q0, p1, q1 in placed:
        w = min(x1, p1) - max(x0, p0) + GAP_PX
        h = min(y1, q1) - max(y0, q0) + GAP_PX
        if not (w <= 0.0 or h <= 0.0 or w * h == 0.0):
            return False
    return True


def _placements(
    slots: Sequence[Slot],
    c: _Candidates,
    chosen: list[int],
    costs: list[float],
    camera: Camera,
    depths: np.ndarray,
) -> dict[str, Placement]:
    """Each slot's chosen candidate as a :class:`Placement`: its screen shift turned into a
    world offset in the screen plane at the label's depth."""
    rows = np.arange(len(slots))
    _, right, up = camera.axes()
    shift = c.shifts[rows, chosen] * camera.world_per_px(depths)[:, None]
    offsets = shift[:, :1] * right - shift[:, 1:] * up
    boxes = c.boxes[rows, chosen].tolist()
    anchors = c.anchors[rows, chosen].tolist()
    return {
        slot.key: Placement(_ANCHOR_NAMES[a], offset, tuple(box), cost)
        for slot, a, offset, box, cost in zip(slots, anchors, offsets, boxes, costs, strict=True)
    }


def _discs(
    camera: Camera,
    markers: Sequence[tuple[np.ndarray, float]],
    arrows: Sequence[tuple[np.ndarray, np.ndarray, float]],
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Screen centres (D, 2), radii and weights of the discs the boxes keep clear of: the
    markers, and ARROW_SAMPLES points along each arrow (those in front of the camera)."""
    points = np.zeros((len(markers) + ARROW_SAMPLES * len(arrows), 3))
    radii = np.empty(len(points))
    weights = np.ones(len(points))
    for i, (point, radius) in enumerate(markers):
        points[i], radii[i], weights[i] = point, radius, MARKER_WEIGHT
    if arrows:
        ends = np.array([(start, end) for start, end, _ in arrows], float)
        samples = (1.0 - _ALONG) * ends[:, None, 0] + _ALONG * ends[:, None, 1]
        points[len(markers) :] = samples.reshape(-1, 3)
        radii[len(markers) :] = np.repeat([radius for _, _, radius in arrows], ARROW_SAMPLES)
    screen, depth = camera.project(points)
    front = depth > 0
    return screen[front], radii[front], weights[front]


#: Where along an arrow its samples lie (fractions of its length, (ARROW_SAMPLES, 1)).
_ALONG = np.linspace(0.0, 1.0, ARROW_SAMPLES)[:, None]


#: The eight screen directions a movable label may be pushed in (y down).
_DIRECTIONS = np.array(
    [[math.cos(a), math.sin(a)] for a in np.arange(8) * math.pi / 4.0], dtype=np.float64
)


def _anchor_towards(direction: np.ndarray) -> str:
    """The anchor whose box lies from its point in ``direction`` (screen, y down)."""
    dx, dy = direction
    horizontal = "left" if dx > 0.38 else "right" if dx < -0.38 else "center"
    vertical = "bottom" if dy < -0.38 else "top" if dy > 0.38 else "center"
    return f"{vertical}-{horizontal}"


#: The anchor of a push in each of those directions (indices into _ANCHOR_NAMES).
_DIRECTION_ANCHORS = np.array([_ANCHOR_INDEX[_anchor_towards(d)] for d in _DIRECTIONS])
_RINGS = np.arange(1, PUSH_RINGS + 1, dtype=np.float64)


def _pushes(
    slots: Sequence[Slot], point: np.ndarray, tip: np.ndarray, direction: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The shifts (N, PUSH_RINGS * 8, 2) of each label's point (N, 2) that push it at least
    its clearance beyond its ``tip``, in each of eight directions, the one nearest its
    outward ``direction`` first, and up to PUSH_RINGS times as far; and their anchors (N,
    PUSH_RINGS * 8), each box lying on the far side of its push."""
    gap = point - tip
    clearance = np.array([slot.clearance for slot in slots])
    reach = np.maximum(np.maximum(np.hypot(gap[:, 0], gap[:, 1]), clearance), 1.0)
    order = np.argsort(-(direction @ _DIRECTIONS.T), axis=1, kind="stable")
    pushes = _RINGS[None, :, None, None] * reach[:, None, None, None] * _DIRECTIONS[order][:, None]
    pushes = pushes.reshape(len(slots), -1, 2) - gap[:, None]
    return pushes, np.tile(_DIRECTION_ANCHORS[order], (1, PUSH_RINGS))


def overlapping(boxes: Sequence[tuple[float, float, float, float]]) -> list[tuple[int, int]]:
    """Pairs of boxes that overlap (for tests): indices (i, j), i < j."""
    pairs = []
    for i, a in enumerate(boxes):
        for j in range(i + 1, len(boxes)):
            b = boxes[j]
            if min(a[2], b[2]) > max(a[0], b[0]) and min(a[3], b[3]) > max(a[1], b[1]):
                pairs.append((i, j))
    return pairs
