"""A twin: a second copy of a scene's body, started a little off the first, drawn overlaid in a
colour of its own (:class:`TwinDrawing`), exact like the first.

The twin is opaque, like the first body: a translucent mesh inside the translucent energy
ellipsoid is hidden by it in the browser (the two are sorted by their common centre, and the
ellipsoid, drawn first, writes the depth), so a translucent twin showed nothing.

The twin's attitude is read from a :class:`~poinsot.app.construction.sampled.sampling.MotionSampler`
of its own body (a batch of 512 grid times per physics call, converted to viser's quaternions once
per batch), at the grid time the construction shows for the first body: a frame sends one more
pose, nothing else.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import trimesh

from poinsot.app.construction import meshes, updates
from poinsot.app.construction.geometry import Geometry, triple
from poinsot.app.construction.sampled.batch import Frame
from poinsot.app.construction.sampled.frames import wxyz_from_xyzw
from poinsot.app.construction.sampled.sampling import MotionSampler, Samples
from poinsot.app.lessons.support.base import RidingMesh
from poinsot.app.lessons.support.spec import Canvas, Drawing, Model, Part
from poinsot.physics import FreeRigidBody

#: The twin's grid step [time units]: a frame shows the twin at most this much behind the
#: first body's grid time (a few hundredths of a turn at the scenes' spins).
TWIN_STEP = 1.0 / 256.0


class TwinDrawing(RidingMesh):
    """The first body's mesh (``part``), and the same mesh in ``twin`` (a frame of its own,
    beside the body frame under the construction's root, and the mesh in it, in ``color``)."""

    def __init__(
        self, canvas: Canvas, part: Part, twin: Part, mesh: trimesh.Trimesh, color: tuple[int, ...]
    ) -> None:
        super().__init__(canvas, part, mesh)
        frame_node, mesh_node = twin.nodes
        self.twin_key = twin.key
        self.twin_frame = self.parts.frame(twin.key, frame_node)
        faces = np.asarray(mesh.faces)
        rgb = (int(color[0]), int(color[1]), int(color[2]))
        self.twin_mesh = self.parts.surface(twin.key, mesh_node, (self.vertices, faces), rgb)
        self._sampler: MotionSampler | None = None
        self._source: Samples | None = None
        self._wxyz = np.zeros((0, 4))

    def fit(self, model: Model, geometry: Geometry | None) -> None:
        super().fit(model, geometry)
        # a model with a twin has its exact motion as ``twin`` (None: none at these settings)
        twin: FreeRigidBody | None = getattr(model, "twin", None)
        semi_axes = self.geometry(geometry).semi_axes
        self.twin_mesh.scale = triple(np.full(3, meshes.fit_scale(self.vertices, semi_axes)))
        if twin is not None:  # the first batch now, so that a bad one raises here
            sampler = MotionSampler(twin, TWIN_STEP, 1)
            self._convert(sampler.batch(0, 0))
        self._sampler = None if twin is None else sampler
        self._show_twin()

    def _convert(self, source: Samples) -> None:
        self._source, self._wxyz = source, wxyz_from_xyzw(source.quat_xyzw)

    def _show_twin(self) -> None:
        shown = self._sampler is not None and self.parts.is_visible(self.twin_key)
        self.twin_frame.visible = shown

    def set_visible(self, part: str, visible: bool) -> None:
        super().set_visible(part, visible)
        if part == self.twin_key:
            self._show_twin()

    def advance(self, t: float, frame: Frame | None) -> Frame:
        frame = super().advance(t, frame)
        sampler = self._sampler
        if sampler is not None:
            k = max(0, sampler.index(frame.t))
            source = sampler.batch(k, k)
            if source is not self._source:
                self._convert(source)
            updates.set_wxyz(self.twin_frame, self._wxyz[k - int(source.k[0])])
        return frame


def twin_drawing(
    part: Part, twin: Part, mesh: Callable[[], trimesh.Trimesh], color: tuple[int, ...]
) -> Callable[[Canvas], Drawing]:
    """A scene's ``draw``: ``mesh()`` as ``part`` riding in the construction, and its twin."""
    return lambda canvas: TwinDrawing(canvas, part, twin, mesh(), color)
