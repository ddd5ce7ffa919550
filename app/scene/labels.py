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
- a label whose point may move (:attr:`Slot.movable`: L's, ω's, the herpolhode's, which hang
  from frames that only translate) may also be pushed, in the screen plane, in one of eight
  directions (the outward one first), far enough beyond its tip to clear a marker drawn there,
  and farther (up to PUSH_RINGS times) where that is taken.

Only anchors and these offsets change, and only when they do: a label rides on its frame
(the body, the contact point) between two layouts, with no message of its own.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np
import viser
from scipy.spatial.transform import Rotation

from poinsot.app.scene import updates

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
        forward /= np.linalg.norm(forward)
        right = np.cross(forward, self.up)
        norm = np.linalg.norm(right)
        if norm < 1e-9:  # looking along "up": any right angle will do
            right = np.cross(forward, (1.0, 0.0, 0.0) if abs(forward[0]) < 0.9 else (0, 1.0, 0))
            norm = np.linalg.norm(right)
        right /= norm
        return forward, right, np.cross(right, forward)

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

    def world_per_px(self, depth: float) -> float:
        """World length of one CSS pixel at ``depth`` (in the screen plane)."""
        return 2.0 * depth * math.tan(0.5 * self.fov) / self.height


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


def _disc_costs(
    boxes: np.ndarray, centres: np.ndarray, radii: np.ndarray, weights: np.ndarray
) -> np.ndarray:
    """The weighted reach of each candidate box (K, 4) into the discs (D): it does not depend
    on the other labels, so every label's candidates are costed in one pass. A box farther
    than a disc's radius from it along x or y cannot reach it (cost 0): only the boxes near
    some disc get the exact sum."""
    cost = np.zeros(len(boxes))
    if not len(centres):
        return cost
    cx, cy, limit = centres[None, :, 0], centres[None, :, 1], (radii + GAP_PX)[None, :]
    near_x = (boxes[:, None, 0] - cx < limit) & (cx - boxes[:, None, 2] < limit)
    near_y = (boxes[:, None, 1] - cy < limit) & (cy - boxes[:, None, 3] < limit)
    rows = np.flatnonzero(np.any(near_x & near_y, axis=1))
    if not len(rows):
        return cost
    near = boxes[rows]
    nearest = np.minimum(np.maximum(centres[None], near[:, None, :2]), near[:, None, 2:])
    gap = nearest - centres[None]
    reach = radii[None, :] + GAP_PX - np.hypot(gap[..., 0], gap[..., 1])
    cost[rows] = np.sum(weights[None, :] * np.maximum(reach, 0.0) ** 2, axis=1)
    return cost


_ANCHOR_NAMES = tuple(ANCHORS)
_ANCHOR_INDEX = {name: i for i, name in enumerate(_ANCHOR_NAMES)}
#: Each anchor's (fx, fy), in the order of _ANCHOR_NAMES.
_FRACTIONS = np.array(list(ANCHORS.values()), dtype=np.float64)
#: The unit direction (screen, y down) in which each anchor's box lies from its point.
_ANCHOR_DIRECTIONS = np.array([[fx + 0.5, fy + 0.5] for fx, fy in ANCHORS.values()])
_ANCHOR_DIRECTIONS /= np.linalg.norm(_ANCHOR_DIRECTIONS, axis=1)[:, None]


def _ranked(direction: np.ndarray, current: str) -> list[str]:
    """Anchors, the one whose box lies most along ``direction`` (screen) first; the current
    anchor wins ties, so that a label does not flicker between equals."""
    score = (-(_ANCHOR_DIRECTIONS @ direction)).tolist()
    if current in _ANCHOR_INDEX:
        score[_ANCHOR_INDEX[current]] -= 1e-3
    # A stable sort of a few floats: Python's is much cheaper than numpy's on 8 elements.
    return [_ANCHOR_NAMES[i] for i in sorted(range(len(score)), key=score.__getitem__)]


def _outward(*candidates: np.ndarray) -> np.ndarray:
    """The first screen direction (unit) longer than 2 px; up-right if there is none (an arrow
    seen end-on)."""
    for vector in candidates:
        length = math.hypot(float(vector[0]), float(vector[1]))
        if length > 2.0:
            return vector / length
    return np.array([math.sqrt(0.5), -math.sqrt(0.5)])


#: Points along an arrow that the boxes keep clear of.
ARROW_SAMPLES = 12
#: Where no place is free, what is worst to cover: another label, then a marker, then an
#: arrow's shaft (weights of the overlaps).
LABEL_WEIGHT = 10.0
MARKER_WEIGHT = 5.0
#: A movable label is pushed up to this many times its clearance before it settles for the
#: least overlap.
PUSH_RINGS = 3


@dataclasses.dataclass(frozen=True)
class _Candidates:
    """A label's places to try, best first: anchors, screen shifts (K, 2), boxes (K, 4)."""

    slot: Slot
    depth: float
    anchors: list[str]
    shifts: np.ndarray
    boxes: np.ndarray


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
    reach into the markers and arrows; the first candidate of cost 0 wins, else the cheapest.
    The second part is the same whatever the order, so it is computed for all labels at once
    and only the first is computed per label (a layout is a few numpy calls per label)."""
    placed: dict[str, Placement] = {}
    if not slots:
        return placed
    _, right, up = camera.axes()
    points = np.array([[slot.point, slot.tip, slot.root] for slot in slots], float)
    screen, depths = camera.project(points.reshape(-1, 3))
    screen, depths = screen.reshape(-1, 3, 2), depths.reshape(-1, 3)
    candidates = [
        _candidates(slot, point, tip, root, float(depth))
        for slot, (point, tip, root), depth in zip(slots, screen, depths[:, 0], strict=True)
        if depth > 0
    ]
    if not candidates:
        return placed
    reach = _disc_costs(
        np.concatenate([c.boxes for c in candidates]), *_discs(camera, markers, arrows)
    )
    placed_boxes: list[np.ndarray] = []
    start = 0
    for c in candidates:
        cost = reach[start : start + len(c.boxes)]
        start += len(c.boxes)
        if placed_boxes:
            cost = _overlap_costs(c.boxes, np.array(placed_boxes)) + cost
        free = np.flatnonzero(cost == 0.0)
        k = int(free[0]) if len(free) else int(np.argmin(cost))
        shift = c.shifts[k] * camera.world_per_px(c.depth)
        offset = shift[0] * right - shift[1] * up
        box = c.boxes[k]
        placed[c.slot.key] = Placement(
            c.anchors[k],
            offset,
            (float(box[0]), float(box[1]), float(box[2]), float(box[3])),
            float(cost[k]),
        )
        placed_boxes.append(box)
    return placed


def _candidates(
    slot: Slot, point: np.ndarray, tip: np.ndarray, root: np.ndarray, depth: float
) -> _Candidates:
    """The places to try for ``slot``, its point, tip and root on screen (see :func:`_options`)."""
    direction = _outward(tip - root, point - tip)
    anchors, shifts = _options(slot, point, tip, direction)
    width, height = box_size(slot.text, slot.scale)
    corner = point + shifts + _FRACTIONS[[_ANCHOR_INDEX[a] for a in anchors]] * (width, height)
    boxes = np.concatenate([corner, corner + (width, height)], axis=1)
    return _Candidates(slot, depth, anchors, shifts, boxes)


def _discs(
    camera: Camera,
    markers: Sequence[tuple[np.ndarray, float]],
    arrows: Sequence[tuple[np.ndarray, np.ndarray, float]],
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Screen centres (D, 2), radii and weights of the discs the boxes keep clear of: the
    markers, and ARROW_SAMPLES points along each arrow (those in front of the camera)."""
    points = [np.asarray(p, float) for p, _ in markers]
    radii = [float(r) for _, r in markers]
    weights = [MARKER_WEIGHT] * len(markers)
    f = np.linspace(0.0, 1.0, ARROW_SAMPLES)[:, None]
    for start, end, radius in arrows:
        points.extend((1.0 - f) * np.asarray(start, float) + f * np.asarray(end, float))
        radii += [float(radius)] * ARROW_SAMPLES
        weights += [1.0] * ARROW_SAMPLES
    if not points:
        return np.zeros((0, 2)), np.zeros(0), np.zeros(0)
    screen, depth = camera.project(np.array(points))
    front = depth > 0
    return screen[front], np.array(radii)[front], np.array(weights)[front]


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


_DIRECTION_ANCHORS = [_anchor_towards(d) for d in _DIRECTIONS]
_RINGS = np.arange(1, PUSH_RINGS + 1, dtype=np.float64)


def _options(
    slot: Slot, point: np.ndarray, tip: np.ndarray, direction: np.ndarray
) -> tuple[list[str], np.ndarray]:
    """The anchors and screen shifts of the point (K, 2) to try, best first. A fixed label
    tries its anchors round its point, those along ``direction`` first; a movable one is first
    pushed, at least ``clearance`` beyond its tip, in each of eight directions, the outward one
    first (and up to PUSH_RINGS times as far)."""
    ranked = _ranked(direction, slot.anchor)
    if not slot.movable:
        return ranked, np.zeros((len(ranked), 2))
    reach = max(math.hypot(*(point - tip)), slot.clearance, 1.0)
    score = (-(_DIRECTIONS @ direction)).tolist()
    order = sorted(range(len(score)), key=score.__getitem__)  # stable, as np.argsort's
    pushes = _RINGS[:, None, None] * reach * _DIRECTIONS[order][None, :, :]
    pushes = pushes.reshape(-1, 2) + (tip - point)
    anchors = [_DIRECTION_ANCHORS[i] for i in order] * PUSH_RINGS
    return anchors + ranked, np.vstack([pushes, np.zeros((len(ranked), 2))])


def overlapping(boxes: Sequence[tuple[float, float, float, float]]) -> list[tuple[int, int]]:
    """Pairs of boxes that overlap (for tests): indices (i, j), i < j."""
    pairs = []
    for i, a in enumerate(boxes):
        for j in range(i + 1, len(boxes)):
            b = boxes[j]
            if min(a[2], b[2]) > max(a[0], b[0]) and min(a[3], b[3]) > max(a[1], b[1]):
                pairs.append((i, j))
    return pairs


#: A movable label's position is resent only when it moved by more than this [display units].
POSITION_TOLERANCE = 2e-3


@dataclasses.dataclass(frozen=True)
class Pose:
    """What the labels' points depend on at a layout: the body's attitude (body -> space), the
    contact point (world) and the camera."""

    rotation: Rotation
    contact: np.ndarray
    camera: Camera


class LabelNode:
    """A label node of the scene, its own font scale, and the anchor and position the layout
    last sent it (so that only changes are sent)."""

    def __init__(self, handle: viser.LabelHandle, key: str, text: str, scale: float) -> None:
        self.handle, self.key, self.text, self.scale = handle, key, text, float(scale)
        self.look_scale = 1.0
        self.anchor: str = handle.anchor
        self.position = np.asarray(handle.position, dtype=np.float64)

    def restyle(self, look_scale: float) -> None:
        if look_scale != self.look_scale:
            self.look_scale = look_scale
            self.handle.font_screen_scale = self.scale * look_scale

    def slot(
        self,
        point: np.ndarray,
        tip: np.ndarray,
        root: np.ndarray,
        *,
        movable: bool = False,
        clearance: float = 0.0,
    ) -> Slot:
        """The layout's view of this label, its points in world coordinates."""
        return Slot(
            self.key,
            self.text,
            self.scale * self.look_scale,
            np.asarray(point, float),
            np.asarray(tip, float),
            np.asarray(root, float),
            movable,
            clearance,
            self.anchor,
        )

    def place(
        self,
        placement: Placement | None,
        base: np.ndarray | None = None,
        rotation: Rotation | None = None,
    ) -> None:
        """Send the placement's anchor and, given the label's ``base`` position in its frame,
        that position plus the placement's offset (turned into the frame by ``rotation``, the
        frame's attitude at the layout, for a label on the body), if they changed."""
        if placement is None:
            return
        if placement.anchor != self.anchor:
            self.anchor = placement.anchor
            self.handle.anchor = placement.anchor  # type: ignore[assignment]
        if base is not None:
            offset = placement.offset
            if rotation is not None:  # a world offset, into the body's coordinates
                offset = rotation.apply(offset, inverse=True)
            position = np.asarray(base, float) + offset
            if np.max(np.abs(position - self.position)) > POSITION_TOLERANCE:
                self.position = position
                updates.set_position(self.handle, position)


def screen_right_in_plane(pose: Pose) -> np.ndarray:
    """The direction in the plane (x, y) that points right on the screen (the herpolhode's
    label goes on that side of its ring: below it on screen runs ω's arrow)."""
    _, right, _ = pose.camera.axes()
    norm = float(np.linalg.norm(right[:2]))
    return right[:2] / norm if norm > 1e-6 else np.array([1.0, 0.0])
