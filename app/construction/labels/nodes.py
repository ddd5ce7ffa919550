"""The scene's side of the labels' layout (:mod:`poinsot.app.construction.labels.layout`): a label
node that offers its point to the layout (:meth:`LabelNode.slot`) and sends what the layout chose
for it (:meth:`LabelNode.place`), only when it changed; and the pose the labels' points are
computed at (:class:`Pose`)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import viser

from poinsot.app.construction import updates
from poinsot.app.construction.labels.layout import Camera, Placement, Slot

#: A movable label's position is resent only when it moved by more than this [display units].
POSITION_TOLERANCE = 2e-3


@dataclasses.dataclass(frozen=True)
class Pose:
    """What the labels' points depend on at a layout: the body's attitude (its rotation
    matrix, body -> space), the contact point (world) and the camera."""

    attitude: np.ndarray
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
        attitude: np.ndarray | None = None,
    ) -> None:
        """Send the placement's anchor and, given the label's ``base`` position in its frame,
        that position plus the placement's offset (turned into the frame by ``attitude``, the
        frame's rotation matrix at the layout, for a label on the body), if they changed."""
        if placement is None:
            return
        if placement.anchor != self.anchor:
            self.anchor = placement.anchor
            self.handle.anchor = placement.anchor  # type: ignore[assignment]
        if base is not None:
            offset = placement.offset
            if attitude is not None:  # a world offset, into the body's coordinates
                offset = offset @ attitude
            position = np.asarray(base, float) + offset
            if np.max(np.abs(position - self.position)) > POSITION_TOLERANCE:
                self.position = position
                updates.set_position(self.handle, position)


def screen_right_in_plane(pose: Pose) -> np.ndarray:
    """The direction in the plane (x, y) that points right on the screen (the herpolhode's
    label goes on that side of its ring: below it on screen runs ω's arrow)."""
    _, right, _ = pose.camera.axes()
    norm = math.hypot(right[0], right[1])
    return right[:2] / norm if norm > 1e-6 else np.array([1.0, 0.0])
