"""A motion tabulated once per parameter change and played back frame by frame.

The scenes whose motion is not a :class:`~poinsot.physics.FreeRigidBody` (a body under torque,
a body losing energy) ask physics for the whole motion on a uniform grid ``t_k = k dt`` at once
(one vectorised call), and the frames then only pick rows: the grid time just before the clock
(at most one grid step behind it), and the rows since the last frame as trail increments. The
table loops: after its span the motion starts again from ``t = 0`` and the trails restart. What
a frame sends is precomputed and checked finite here, so that no NaN reaches the scene.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping

import numpy as np

from poinsot.app.construction.geometry import SceneDataError
from poinsot.app.construction.sampled.batch import Frame
from poinsot.app.construction.trail import Trail

#: At most this many rows per frame go into a trail (after a long stall it takes a chord).
MAX_ROWS_PER_FRAME = 64


def grid_cycle_row(t: float, dt: float, rows: int) -> tuple[int, int]:
    """(cycle, row) of clock time ``t`` >= 0 on a grid of ``rows`` steps ``dt``, looped."""
    k = max(0, math.floor(float(t) / dt + 1e-9))
    cycle, row = divmod(k, rows)
    return int(cycle), int(row)


def grid_row(t: float, dt: float, rows: int) -> int:
    """The row of clock time ``t`` (see :func:`grid_cycle_row`)."""
    return grid_cycle_row(t, dt, rows)[1]


@dataclasses.dataclass(frozen=True)
class Table:
    """The motion on the grid ``t_k = k dt``, ``k = 0 … N-1`` (looped with period ``N dt``).

    ``wxyz`` (N, 4) the body's attitude as viser takes it; ``omega`` (N, 3) body-frame ω
    [physical units]; ``points`` named (N, 3) display-unit points (markers, trail points);
    ``arrows`` named (N, 1, 2, 3) arrows as viser takes them.
    """

    dt: float
    wxyz: np.ndarray
    omega: np.ndarray
    points: Mapping[str, np.ndarray]
    arrows: Mapping[str, np.ndarray]

    def __post_init__(self) -> None:
        n = len(self.wxyz)
        if not (math.isfinite(self.dt) and self.dt > 0.0) or n < 2:
            raise SceneDataError("a tabulated motion needs a positive step and two rows")
        named = {"attitude": self.wxyz, "omega": self.omega, **self.points, **self.arrows}
        for name, values in named.items():
            if len(values) != n:
                raise SceneDataError(f"the tabulated {name} has {len(values)} rows, not {n}")
            if not np.all(np.isfinite(values)):
                raise SceneDataError(f"the tabulated {name} is not finite; nothing is drawn")

    @property
    def rows(self) -> int:
        return len(self.wxyz)

    @property
    def span(self) -> float:
        """The time after which the table starts again."""
        return self.rows * self.dt

    def locate(self, t: float) -> tuple[int, int]:
        """(cycle, row) shown at clock time ``t`` >= 0."""
        return grid_cycle_row(t, self.dt, self.rows)

    def frame(self, t: float, row: int, contact: np.ndarray, samples: int) -> Frame:
        """The frame of ``row`` shown at clock time ``t``: its time is the grid time of that
        row in the current cycle."""
        cycle, _ = self.locate(t)
        time = cycle * self.span + row * self.dt
        return Frame(time, self.omega[row], self.wxyz[row], contact, samples)


class Player:
    """Plays a :class:`Table`: :meth:`advance` picks the row of a clock time and extends the
    trails (each fed from the table's ``points`` of the same name)."""

    def __init__(self, table: Table, trails: Mapping[str, Trail]) -> None:
        missing = set(trails) - set(table.points)
        if missing:
            raise SceneDataError(f"no tabulated points for the trails {sorted(missing)}")
        self.table = table
        self.trails = dict(trails)
        self._last: tuple[int, int] | None = None

    def advance(self, t: float) -> tuple[int, int]:
        """The row to show at ``t`` and how many rows this frame went through; the trails get
        the rows since the last frame (restarted when the table loops or the clock goes back).
        The same row again (paused) sends nothing."""
        table = self.table
        cycle, row = table.locate(t)
        last = self._last
        if last == (cycle, row):
            return row, 0
        if last is None or (cycle, row) < last or cycle != last[0]:
            for trail in self.trails.values():
                trail.clear()
            first = row
        else:
            first = max(last[1] + 1, row - MAX_ROWS_PER_FRAME + 1)
        for name, trail in self.trails.items():
            trail.append(table.points[name][first : row + 1])
        self._last = (cycle, row)
        return row, row - first + 1

    def restart(self) -> None:
        """Draw from scratch at the next :meth:`advance` (a new table, or the trails emptied)."""
        self._last = None
