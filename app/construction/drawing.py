"""What every scene element's nodes share: :class:`Drawing` (create once, :meth:`Drawing.fit`
to a body, restyle, offer labels to the layout, show, hide, remove) and the distances its
labels keep."""

from __future__ import annotations

import numpy as np
import viser

from poinsot.app.construction.geometry import Geometry
from poinsot.app.construction.labels.layout import Placement, Slot
from poinsot.app.construction.labels.nodes import Pose
from poinsot.app.construction.palette import Look

#: Radius of the marker at the fixed point (the origin) [display units].
ORIGIN_RADIUS = 0.03
#: How far a label's point lies beyond the tip it names [display units].
BEYOND = 0.05
#: Screen distance [CSS px] a label keeps from the contact point's marker and from L's head.
MARKER_CLEARANCE = 14.0
HEAD_CLEARANCE = 6.0
#: How far the labels on the body (axes, polhode) may be pushed beyond their tips [CSS px]:
#: far enough to step round the contact point's marker where the tips crowd together.
BODY_CLEARANCE = 10.0
#: An arrow's points before its first fit: along +z, unit length.
UNIT_ARROW = np.array([[[0.0, 0.0, 0.0], [0.0, 0.0, 1.0]]], np.float32)
#: A line-segments node's points before its first fit: one degenerate segment.
NO_SEGMENT = np.zeros((1, 2, 3), np.float32)


class Drawing:
    """The nodes of one element."""

    def __init__(self, handles: list[viser.SceneNodeHandle] | None = None) -> None:
        self.handles: list[viser.SceneNodeHandle] = handles or []
        self.visible = True

    def fit(self, geometry: Geometry) -> None:
        """Send what changes with the body (sizes, static curves); nothing by default."""

    def restyle(self, look: Look) -> None:
        """Take the colours, widths and label size of ``look``; nothing by default."""

    def slots(self, pose: Pose) -> list[Slot]:
        """The drawing's labels for the layout (world points at ``pose``); none by default."""
        return []

    def place(self, placements: dict[str, Placement]) -> None:
        """Send what the layout chose for the drawing's labels; nothing by default."""

    def set_visible(self, visible: bool) -> None:
        self.visible = visible
        for handle in self.handles:
            handle.visible = visible

    def remove(self) -> None:
        """Remove the nodes that are under none of the others: viser removes the nodes under
        them (an axis's label, the plane's grid) and warns if one is removed again."""
        names = [handle.name for handle in self.handles]
        for handle in self.handles:
            if not any(handle.name.startswith(name + "/") for name in names):
                handle.remove()
        self.handles = []
