"""The traced curves as scene elements: the polhode (on the body) and the herpolhode (on the
invariable plane), each a :class:`~poinsot.app.construction.trail.Trail` and its label.

:class:`~poinsot.app.construction.construction.PoinsotScene` sends their increments each
frame through :attr:`Trace.trail`; this module fits their labels to the body and lays them
out.
"""

from __future__ import annotations

import numpy as np
import viser

from poinsot.app.construction import palette, updates
from poinsot.app.construction.drawing import BEYOND, BODY_CLEARANCE, HEAD_CLEARANCE, Drawing
from poinsot.app.construction.geometry import HERPOLHODE_LIFT, POLHODE_INFLATE, Geometry
from poinsot.app.construction.labels.layout import Placement, Slot
from poinsot.app.construction.labels.nodes import LabelNode, Pose, screen_right_in_plane
from poinsot.app.construction.palette import Look
from poinsot.app.construction.trail import Trail
from poinsot.app.model.elements import Element

#: Font scale of the curves' labels.
LABEL_SCALE = 1.1


class Trace(Drawing):
    """A live trace (polhode or herpolhode): a :class:`Trail` the scene extends per frame, and
    the label that names it."""

    def __init__(self, trail: Trail, label: viser.LabelHandle, element: Element) -> None:
        super().__init__([label])
        self.trail, self.element = trail, element
        self.node = LabelNode(label, element.value, label.text, LABEL_SCALE)
        self.point = np.zeros(3)  # the named point: on the polhode (body), on the ring (space)
        self.ring = (0.0, 0.0)  # herpolhode: the radius of its ring and the plane's height
        self._base = np.zeros(3)  # herpolhode: the label's point before the layout's push
        self._attitude: np.ndarray | None = None  # polhode: the body's attitude at the layout

    def fit(self, geometry: Geometry) -> None:
        if self.element is Element.POLHODE:  # a point of the curve, on the body
            self.point = geometry.polhode[int(np.argmax(geometry.polhode[:, 0]))]
            radius = float(np.linalg.norm(self.point))
            outward = self.point / radius if radius > 0 else np.zeros(3)
            self.node.position = self.point * POLHODE_INFLATE + BEYOND * outward
            updates.set_position(self.node.handle, self.node.position)
        else:  # the ring's near side in the default view, until the layout turns it
            self.ring = (geometry.herpolhode_radius, geometry.plane_height)
            self.node.position = self._on_ring(np.array([0.93, 0.37]), BEYOND)
            updates.set_position(self.node.handle, self.node.position)

    def _on_ring(self, direction: np.ndarray, beyond: float = 0.0) -> np.ndarray:
        radius, height = self.ring
        return np.array([*((radius + beyond) * direction), height + HERPOLHODE_LIFT])

    def restyle(self, look: Look) -> None:
        polhode = self.element is Element.POLHODE
        self.trail.restyle(look.polhode if polhode else look.herpolhode, look.trace_width)
        self.node.restyle(look.label_scale)

    def slots(self, pose: Pose) -> list[Slot]:
        if self.element is Element.POLHODE:
            self._attitude = pose.attitude
            tip = pose.attitude @ self.point
            radius = float(np.linalg.norm(tip))
            point = tip * (1.0 + BEYOND / radius) if radius > 0 else tip
            return [self.node.slot(point, tip, np.zeros(3), movable=True, clearance=BODY_CLEARANCE)]
        toward = screen_right_in_plane(pose)
        tip, centre = self._on_ring(toward), np.array([0.0, 0.0, self.ring[1]])
        self._base = self._on_ring(toward, BEYOND)
        return [self.node.slot(self._base, tip, centre, movable=True, clearance=HEAD_CLEARANCE)]

    def place(self, placements: dict[str, Placement]) -> None:
        placement = placements.get(self.node.key)
        if self.element is Element.POLHODE:
            radius = float(np.linalg.norm(self.point))
            base = self.point * (POLHODE_INFLATE + BEYOND / radius) if radius > 0 else self.point
            self.node.place(placement, base, self._attitude)
        else:
            self.node.place(placement, self._base)

    def set_visible(self, visible: bool) -> None:
        super().set_visible(visible)
        self.trail.visible = visible

    def remove(self) -> None:
        super().remove()
        self.trail.remove()


def draw_trace(element: Element, api: viser.SceneApi, root: str, trail_points: int) -> Trace:
    """The polhode's or the herpolhode's trail and label under the scene root ``root``."""
    if element is Element.POLHODE:
        trail = Trail(
            api,
            f"{root}/body/polhode",
            palette.POLHODE,
            palette.TRACE_WIDTH_PX,
            trail_points,
            scale=POLHODE_INFLATE,
        )
        label = api.add_label(
            f"{root}/body/polhode_label",
            "polhode",
            anchor="top-left",
            font_screen_scale=LABEL_SCALE,
        )
        return Trace(trail, label, element)
    if element is not Element.HERPOLHODE:
        raise ValueError(f"{element} is not a traced curve")
    trail = Trail(
        api,
        f"{root}/herpolhode",
        palette.HERPOLHODE,
        palette.TRACE_WIDTH_PX,
        trail_points,
        position=(0.0, 0.0, HERPOLHODE_LIFT),
    )
    label = api.add_label(
        f"{root}/herpolhode_label",
        "herpolhode",
        anchor="center-left",
        font_screen_scale=LABEL_SCALE,
    )
    return Trace(trail, label, element)
