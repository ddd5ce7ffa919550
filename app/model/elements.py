"""The vocabulary of a scene: what a preset may declare (elements, controls, plots) and the solid
drawn inside the ellipsoid.

A preset (:mod:`poinsot.app.model.presets`) is a set of these words; the session creates exactly the
scene nodes and GUI groups they name, and nothing else.
"""

from __future__ import annotations

import dataclasses
import hashlib
from enum import StrEnum
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray


class Element(StrEnum):
    """A scene element that a preset may declare (each is a node, or a group of nodes)."""

    ELLIPSOID = "ellipsoid"
    AXES = "axes"
    PLANE = "plane"
    CONTACT = "contact"
    OMEGA = "omega"
    L = "L"
    POLHODE = "polhode"
    POLHODE_FULL = "polhode_full"
    HERPOLHODE = "herpolhode"
    SOLID = "solid"


class Control(StrEnum):
    """A group of GUI controls that a preset may declare."""

    INERTIA = "inertia"  # sliders I1, I2, I3
    ENERGY = "energy"  # D = |L|^2 / 2T in [min I, max I]
    SIDE = "side"  # which side of the separatrix, and which of the two polhodes
    OMEGA_NORM = "omega_norm"  # |omega0|
    SPEED = "speed"  # simulation seconds per wall-clock second
    PLAYBACK = "playback"  # play/pause, step, reset
    TRAIL = "trail"  # trail length
    VISIBILITY = "visibility"  # show/hide of each declared element
    TOSS = "toss"  # "Your own toss": upload a gyroscope recording, see the fitted body
    MESH = "mesh"  # any body from its mesh: the bundled bodies, or upload STL/OBJ/PLY/GLB


class Plot(StrEnum):
    """A live plot that a preset may declare."""

    OMEGA = "omega"  # live uPlot of omega_1, omega_2, omega_3 against time
    #: the same plot with the measured omega of an uploaded toss drawn over the exact one
    MEASURED = "measured"


ALL_ELEMENTS: frozenset[Element] = frozenset(Element)
ALL_CONTROLS: frozenset[Control] = frozenset(Control)
ALL_PLOTS: frozenset[Plot] = frozenset(Plot)
#: The controls that bring a body of one's own (declared by the Custom view and the entries
#: for an uploaded toss or mesh, not by the classical presets).
OWN_BODY_CONTROLS: frozenset[Control] = frozenset({Control.TOSS, Control.MESH})
STANDARD_CONTROLS: frozenset[Control] = ALL_CONTROLS - OWN_BODY_CONTROLS
#: The plot every preset shows (the measured overlay needs a recording).
STANDARD_PLOTS: frozenset[Plot] = frozenset({Plot.OMEGA})

#: Elements that need a non-trivial polhode/herpolhode (left out where omega is constant).
TRACE_ELEMENTS: frozenset[Element] = frozenset(
    {Element.POLHODE, Element.POLHODE_FULL, Element.HERPOLHODE}
)


@dataclasses.dataclass(frozen=True)
class Solid:
    """A homogeneous solid drawn inside the ellipsoid, in the body's principal axes.

    ``kind`` and ``dims`` (scene units, before the display scaling):
    - ``"box"``: full side lengths along body axes 1, 2, 3;
    - ``"cylinder"``: (radius, length), symmetry axis = body axis ``axis``;
    - ``"t_handle"``: (bar length, bar radius, stem length, stem radius); the bar lies along
      body axis 1, the stem along -axis 2, the mesh is shifted by ``offset`` so that the
      centre of mass is at the origin;
    - ``"mesh"``: the surface ``mesh`` (a :class:`MeshShape`, already in the principal frame);
      ``dims`` is empty.
    """

    kind: Literal["box", "cylinder", "t_handle", "mesh"]
    dims: tuple[float, ...]
    axis: int = 2
    offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    mesh: MeshShape | None = None

    def __post_init__(self) -> None:
        if (self.kind == "mesh") != (self.mesh is not None):
            raise ValueError("a solid of kind 'mesh' carries a MeshShape, and only it does")


@dataclasses.dataclass(frozen=True, eq=False)
class MeshShape:
    """A closed triangle surface in a body's principal frame (centre of mass at the origin,
    axes 1, 2, 3 along x, y, z), as drawn for a body made from its mesh.

    ``vertices`` (n, 3) float64 and ``faces`` (m, 3) int64 are read-only copies; ``digest``
    identifies the shape, so that a scene sends a mesh it already shows only once. Shapes
    compare by identity (their arrays are not compared element by element).
    """

    name: str
    vertices: NDArray[np.float64]
    faces: NDArray[np.int64]
    digest: str

    @classmethod
    def of(cls, vertices: ArrayLike, faces: ArrayLike, name: str) -> MeshShape:
        v = np.array(vertices, dtype=np.float64).reshape(-1, 3)
        f = np.array(faces, dtype=np.int64).reshape(-1, 3)
        if not np.all(np.isfinite(v)) or (f.size and (f.min() < 0 or f.max() >= len(v))):
            raise ValueError(f"{name!r}: the mesh has non-finite vertices or bad faces")
        v.flags.writeable = False
        f.flags.writeable = False
        digest = hashlib.sha256(v.tobytes() + b"|" + f.tobytes()).hexdigest()[:16]
        return cls(name, v, f, digest)
