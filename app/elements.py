"""The vocabulary of a scene: what a preset may declare (elements, controls, plots) and the solid
drawn inside the ellipsoid.

A preset (:mod:`poinsot.app.presets`) is a set of these words; the session creates exactly the
scene nodes and GUI groups they name, and nothing else.
"""

from __future__ import annotations

import dataclasses
from enum import StrEnum
from typing import Literal


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


class Plot(StrEnum):
    """A live plot that a preset may declare."""

    OMEGA = "omega"  # live uPlot of omega_1, omega_2, omega_3 against time


ALL_ELEMENTS: frozenset[Element] = frozenset(Element)
ALL_CONTROLS: frozenset[Control] = frozenset(Control)
ALL_PLOTS: frozenset[Plot] = frozenset(Plot)

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
      centre of mass is at the origin.
    """

    kind: Literal["box", "cylinder", "t_handle"]
    dims: tuple[float, ...]
    axis: int = 2
    offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
