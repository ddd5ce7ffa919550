"""Landau's picture in momentum space [LL76 §37, Fig. 51], as a group of nodes beside the
construction, and the polhode family coloured by kind.

In the body frame the angular momentum ``m = I ω`` lies on the sphere ``|m| = G`` (fixed while
no torque acts) and on the energy ellipsoid ``Σ mᵢ²/Iᵢ = 2T`` (semi-axes ``sqrt(2T Iᵢ)``); the
curve where the two meet is the polhode, mapped by ``I``. The group shows the sphere, the
ellipsoid, their intersection (or the whole family), the body axes and the moving point
``m(t)``, scaled so that the sphere has a given radius (display units). Every number comes
from :mod:`poinsot.physics.models.family`.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np
import viser
from numpy.typing import ArrayLike

from poinsot.app.construction import palette
from poinsot.app.construction.geometry import triple
from poinsot.app.construction.palette import Entry
from poinsot.app.lessons.support import colors
from poinsot.app.lessons.support.drawing import Parts, many_segments, unit_sphere
from poinsot.physics import Regime
from poinsot.physics.models.family import PolhodeCurve

#: Radius of the momentum sphere on screen [display units], unless a scene says otherwise.
SPHERE_RADIUS = 0.8
#: The picture's title stands this many radii above the sphere's centre, centred over it.
TITLE_HEIGHT = 1.35
#: Half the width of a title, in the picture's radii per character: its text is drawn at a
#: size of its own on the screen, and this is its half-width beside the sphere on a phone held
#: upright whose view is framed to hold the picture (390 x 844).
TITLE_REACH_PER_CHARACTER = 0.073


def extent(
    offset: ArrayLike, title: str, radius: float = SPHERE_RADIUS
) -> tuple[tuple[float, float, float], float]:
    """The sphere (centre, radius; display units) that holds a picture at ``offset`` and its
    ``title`` over it: what a framed view keeps in frame (``SceneSpec.beside``)."""
    reach = max(TITLE_HEIGHT + 0.15, TITLE_REACH_PER_CHARACTER * len(title))
    return triple(offset), reach * float(radius)


#: The body axes reach this far past the sphere.
AXIS_REACH = 1.25
#: Widths of the curves [screen px] (the separatrix a little wider: it splits the families).
FAMILY_WIDTH_PX = 2.0
SEPARATRIX_WIDTH_PX = 3.0
CURRENT_WIDTH_PX = 4.5
#: Family kinds, their node suffix and colour.
KINDS: dict[str, tuple[tuple[Regime, ...], tuple[int, int, int]]] = {
    "minor": ((Regime.MINOR_AXIS,), colors.MINOR_FAMILY),
    "major": ((Regime.MAJOR_AXIS,), colors.MAJOR_FAMILY),
    "separatrix": ((Regime.SEPARATRIX,), colors.SEPARATRIX),
}


def family_width(kind: str) -> float:
    """The line width of a family kind [screen px]."""
    return SEPARATRIX_WIDTH_PX if kind == "separatrix" else FAMILY_WIDTH_PX


def family_lines(parts: Parts, part: str, root: str) -> dict[str, viser.LineSegmentsHandle]:
    """One line node per family kind, ``<root>/<kind>``, in its colour and width."""
    return {
        kind: parts.lines(part, f"{root}/{kind}", color, family_width(kind))
        for kind, (_, color) in KINDS.items()
    }


def family_segments(
    curves: Iterable[PolhodeCurve], scale: float, momentum: bool = False
) -> dict[str, np.ndarray]:
    """The curves of a family, by kind ("minor", "major", "separatrix"), as line segments in
    display units (ω, or ``m = I ω`` if ``momentum``, times ``scale``). A permanent rotation
    (a point) draws nothing."""
    by_kind: dict[str, list[tuple[np.ndarray, bool]]] = {kind: [] for kind in KINDS}
    for curve in curves:
        points = curve.momentum if momentum else curve.omega
        for kind, (regimes, _) in KINDS.items():
            if curve.regime in regimes and len(points) > 1:
                by_kind[kind].append((points * scale, curve.closed))
    return {kind: many_segments(parts) for kind, parts in by_kind.items()}


def current_segments(curves: Iterable[PolhodeCurve], scale: float, momentum: bool) -> np.ndarray:
    """All curves of one D in one line-segments array (display units)."""
    return many_segments(
        ((c.momentum if momentum else c.omega) * scale, c.closed)
        for c in curves
        if len(c.omega) > 1
    )


def momentum_rows(
    *, family: bool, current: bool, trace: bool, ellipsoid: bool = True
) -> tuple[Entry, ...]:
    """The legend rows of a :class:`MomentumPicture`: each thing it draws, in its colour."""
    rows = [
        Entry("momentum sphere", (colors.SPHERE,), "patch", "translucent"),
        Entry("momentum axes", (colors.GREY,), "axes"),
        Entry("m = Iω", (colors.MOMENTUM,), "dot"),
    ]
    if ellipsoid:
        rows.append(Entry("energy ellipsoid", (colors.ELLIPSOID,), "patch", "translucent"))
    if family:
        rows += [
            Entry("minor-axis polhodes", (colors.MINOR_FAMILY,), "line"),
            Entry("major-axis polhodes", (colors.MAJOR_FAMILY,), "line"),
            Entry("separatrix", (colors.SEPARATRIX,), "line", "thick"),
        ]
    if current:
        rows.append(Entry("this D's polhodes", (colors.CURRENT,), "line", "thick"))
    if trace:
        rows.append(Entry("trace of m", (colors.MOMENTUM_TRACE,), "line", "thick"))
    return tuple(rows)


def momentum_nodes(
    root: str, *, family: bool, current: bool, trace: bool, ellipsoid: bool = True
) -> tuple[str, ...]:
    """The node names of a :class:`MomentumPicture` under ``root`` (its group)."""
    names = [root, f"{root}/sphere", f"{root}/m", f"{root}/label"]
    names += [f"{root}/axis{i}" for i in (1, 2, 3)]
    if ellipsoid:
        names.append(f"{root}/ellipsoid")
    if family:
        names += [f"{root}/{kind}" for kind in KINDS]
    if current:
        names.append(f"{root}/polhode")
    if trace:
        names.append(f"{root}/trace")
    return tuple(names)


class MomentumPicture:
    """The nodes of Landau's picture under the group ``root``, posed at ``offset`` in space."""

    def __init__(
        self,
        parts: Parts,
        part: str,
        root: str,
        offset: ArrayLike,
        *,
        title: str,
        family: bool = False,
        current: bool = False,
        trace_points: int = 0,
        ellipsoid: bool = True,
        radius: float = SPHERE_RADIUS,
        turn: float = 0.0,
    ) -> None:
        """``turn``: the group is turned by this angle [rad] about the vertical, to show the
        curves around the first axis less edge-on."""
        self.root = root
        self.radius = float(radius)
        half = 0.5 * float(turn)
        #: The group's pose in space (display units): the sphere's centre and its turn.
        self.offset = tuple(float(v) for v in np.asarray(offset, dtype=float))
        self.wxyz = (math.cos(half), 0.0, 0.0, math.sin(half))
        parts.frame(part, root, self.offset, self.wxyz)
        sphere = unit_sphere()
        self.sphere = parts.surface(
            part, f"{root}/sphere", sphere, colors.SPHERE, colors.SPHERE_OPACITY
        )
        self.ellipsoid = (
            parts.surface(
                part, f"{root}/ellipsoid", sphere, colors.ELLIPSOID, colors.ELLIPSOID_OPACITY
            )
            if ellipsoid
            else None
        )
        self.axes = [
            parts.lines(part, f"{root}/axis{i + 1}", colors.GREY, palette.AXIS_WIDTH_PX)
            for i in range(3)
        ]
        self.family = family_lines(parts, part, root) if family else {}
        self.current = (
            parts.lines(part, f"{root}/polhode", colors.CURRENT, CURRENT_WIDTH_PX)
            if current
            else None
        )
        self.trace = (
            parts.trail(part, f"{root}/trace", colors.MOMENTUM_TRACE, 3.0, trace_points)
            if trace_points
            else None
        )
        self.marker = parts.marker(part, f"{root}/m", colors.MOMENTUM)
        self.label = parts.label(
            part, f"{root}/label", title, (0.0, 0.0, TITLE_HEIGHT * self.radius), centred=True
        )
        self.scale = 1.0

    def fit(self, G: float, curves: list[PolhodeCurve], semi_axes: ArrayLike | None = None) -> None:
        """Sphere ``|m| = G``, the curves (the family coloured by kind, or the current D's
        curves, whichever this picture draws) and the ellipsoid's semi-axes (physical; if it
        draws one)."""
        scale = self.radius / float(G)
        extent = self.radius
        if self.ellipsoid is not None and semi_axes is not None:
            semi = np.asarray(semi_axes, dtype=float) * scale
            self.ellipsoid.scale = triple(semi)
            extent = max(extent, float(np.max(semi)))
        reach = AXIS_REACH * extent
        self.scale = scale
        self.sphere.scale = (self.radius,) * 3
        for i, line in enumerate(self.axes):
            end = np.zeros(3)
            end[i] = reach
            line.points = np.array([[-end, end]], dtype=np.float32)
        if self.family:
            for kind, segs in family_segments(curves, scale, momentum=True).items():
                self.family[kind].points = segs
        if self.current is not None:
            self.current.points = current_segments(curves, scale, momentum=True)

    def show_m(self, m: ArrayLike) -> None:
        """The point ``m`` (physical, body frame): one position message."""
        self.marker.position = triple(np.asarray(m, dtype=float) * self.scale)
