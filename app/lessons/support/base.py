"""What every scene's model and drawing share, so that a scene module holds only what differs:
its model (physics and readouts), its parts and how it poses them.

Models: :class:`SceneModel` (readouts constant along the motion, no plot), :class:`OwnSolid`
(the scene draws its body from a mesh of its own), :class:`OwnMotion` (not torque-free: the
scene poses the body itself, no Poinsot construction), :class:`TabulatedModel` (a motion on a
uniform grid, played by :mod:`~poinsot.app.lessons.support.tabulated`).

Drawings: :class:`PartsDrawing` (the nodes kept by part, shown, hidden and removed as a whole;
riding on the Poinsot construction's frames), :class:`RidingMesh` (a body's own mesh inside the
ellipsoid) and :class:`TabulatedDrawing` (a :class:`~.tabulated.Table` played frame by frame).
"""

from __future__ import annotations

import functools
from collections.abc import Callable

import numpy as np
import trimesh
import viser

from poinsot.app.construction import meshes
from poinsot.app.construction.geometry import Geometry, triple
from poinsot.app.construction.sampled.batch import Frame
from poinsot.app.lessons.support import colors
from poinsot.app.lessons.support.drawing import Parts
from poinsot.app.lessons.support.spec import Canvas, Drawing, Model, Part, Readout
from poinsot.app.lessons.support.tabulated import Player, Table, grid_row
from poinsot.app.model.elements import Element, Solid
from poinsot.physics import FreeRigidBody

#: The elements of Poinsot's construction every scene riding on it shows (each adds its own:
#: the polhode's trace, the full polhode, the presets' solid).
CONSTRUCTION: frozenset[Element] = frozenset(
    {
        Element.ELLIPSOID,
        Element.AXES,
        Element.PLANE,
        Element.CONTACT,
        Element.OMEGA,
        Element.L,
        Element.HERPOLHODE,
    }
)


class SceneModel:
    """Defaults of a scene's :class:`~poinsot.app.lessons.support.spec.Model`: the readouts are
    :attr:`rows`, computed once (a model whose rows change with time overrides
    :meth:`readouts`); no plot (a model that declares one overrides :meth:`plot`)."""

    @functools.cached_property
    def rows(self) -> tuple[Readout, ...]:
        raise NotImplementedError(f"{type(self).__name__} fills no readouts")

    def readouts(self, t: float) -> tuple[Readout, ...]:
        return self.rows

    def plot(self, key: str, t: float) -> tuple[np.ndarray, ...]:
        raise KeyError(f"{type(self).__name__} draws no plot {key!r}")


class OwnSolid:
    """A model whose body the scene draws from its own mesh: no solid of the construction."""

    @property
    def solid(self) -> Solid | None:
        return None


class OwnMotion(OwnSolid):
    """A model that is not torque-free: no Poinsot construction, the scene poses the body."""

    @property
    def body(self) -> FreeRigidBody | None:
        return None


class TabulatedModel(OwnMotion, SceneModel):
    """A motion on the grid ``times`` (N,), ``t_k = k dt``, looped with period ``N dt``."""

    times: np.ndarray

    @property
    def dt(self) -> float:
        return float(self.times[1] - self.times[0])

    @property
    def span(self) -> float:
        return len(self.times) * self.dt

    def row(self, t: float) -> int:
        """The row shown at clock time ``t`` (that of :meth:`Table.locate`)."""
        return grid_row(t, self.dt, len(self.times))

    def plotted(self, t: float, samples: int, *columns: np.ndarray) -> list[np.ndarray]:
        """``times`` and ``columns`` (N, …) thinned to about ``samples`` rows, up to ``t``."""
        stride = max(1, len(self.times) // samples)
        n = max(2, self.row(t) // stride + 1)
        return [column[::stride][:n] for column in (self.times, *columns)]


class PartsDrawing:
    """A scene's own nodes kept by part (:class:`~.drawing.Parts`); by default it rides on
    the Poinsot construction (its frame is the construction's)."""

    def __init__(self, canvas: Canvas) -> None:
        self.canvas = canvas
        self.parts = Parts(canvas.api)

    def geometry(self, geometry: Geometry | None) -> Geometry:
        """The construction's geometry, which a riding drawing needs to fit."""
        if geometry is None:
            raise ValueError(f"{type(self).__name__} rides in the Poinsot construction")
        return geometry

    def advance(self, t: float, frame: Frame | None) -> Frame:
        if frame is None:
            raise RuntimeError(f"{type(self).__name__} rides in the Poinsot construction")
        return frame

    def set_visible(self, part: str, visible: bool) -> None:
        self.parts.set_visible(part, visible)

    def is_visible(self, part: str) -> bool:
        return self.parts.is_visible(part)

    def remove(self) -> None:
        self.parts.remove()


class RidingMesh(PartsDrawing):
    """A body's own mesh inside the ellipsoid (body frame), scaled to fit it: the one node of
    ``part``."""

    def __init__(self, canvas: Canvas, part: Part, mesh: trimesh.Trimesh) -> None:
        super().__init__(canvas)
        (node,) = part.nodes
        self.vertices = np.asarray(mesh.vertices)
        self.mesh = self.parts.surface(
            part.key, node, (self.vertices, np.asarray(mesh.faces)), colors.SOLID
        )

    def fit(self, model: Model, geometry: Geometry | None) -> None:
        semi_axes = self.geometry(geometry).semi_axes
        self.mesh.scale = triple(np.full(3, meshes.fit_scale(self.vertices, semi_axes)))


def riding_mesh(part: Part, mesh: Callable[[], trimesh.Trimesh]) -> Callable[[Canvas], Drawing]:
    """A scene's ``draw``: ``mesh()`` drawn as ``part`` inside the construction's ellipsoid."""
    return lambda canvas: RidingMesh(canvas, part, mesh())


class TabulatedDrawing(PartsDrawing):
    """Plays a :class:`~.tabulated.Table` that :meth:`fit` sets in :attr:`player`: per frame the
    body's attitude, the arrows named in :attr:`arrows` and the trails; the frame's contact
    point is the table's points named :attr:`contact`."""

    contact: str

    def __init__(self, canvas: Canvas) -> None:
        super().__init__(canvas)
        self.player: Player | None = None
        self.arrows: dict[str, viser.ArrowsHandle] = {}

    def advance(self, t: float, frame: Frame | None) -> Frame:
        if self.player is None:
            raise RuntimeError("fit() a model before advance()")
        table = self.player.table
        row, samples = self.player.advance(t)
        self.canvas.body.wxyz = table.wxyz[row]
        for name, arrow in self.arrows.items():
            arrow.points = table.arrows[name][row]
        self.show_row(table, row)
        return table.frame(t, row, table.points[self.contact][row], samples)

    def show_row(self, table: Table, row: int) -> None:
        """What else a frame poses from the table's ``row`` (nothing by default)."""
