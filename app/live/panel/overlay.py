"""The measured ω of an uploaded toss drawn over the exact one, in the Motion window's plot.

The plot then has seven columns: time, the exact ω₁, ω₂, ω₃ (lines, as in every plot) and the
measured ω₁, ω₂, ω₃ (dots). uPlot shares one time column among all series, so the live
samples of the exact solution and the recording's samples are merged in time order:

- at a recording's sample the exact columns hold the fitted solution there (evaluated once,
  when the toss was fitted) and the measured columns the measurement;
- at a live sample (the motion as it plays, which goes on past the end of the recording) the
  exact columns hold the live value and the measured columns hold NaN: no measurement at
  that time. NaN is the one marker a float column can carry (viser sends the plot's columns
  as float64); uPlot draws no dot for it (the measured series are dots only, so no line
  bridges a gap), but its automatic range would turn NaN too, so this plot's ω axis is
  fixed to ``± bound``, which no component of ω exceeds, and its legend shows no values
  under the cursor. NaN never appears in the exact columns nor in the 3D scene.

Recording samples are shown from the live window's first time on, so the two stay one picture
as the window scrolls.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import viser.uplot
from numpy.typing import NDArray

from poinsot.app.construction import palette

#: Size of a measured dot [CSS px].
DOT_SIZE = 4.0
#: The ω axis reaches this much past the largest component.
MARGIN = 1.08


@dataclasses.dataclass(frozen=True)
class Measured:
    """A recording's samples on the session's clock: ``tau`` (n,) [s] from the fitted motion's
    start, ``omega`` (n, 3) measured and ``exact`` (n, 3) the fitted solution there, and
    ``bound`` [rad/s], which no component of ω (measured or exact, now or later) exceeds;
    all finite (checked)."""

    tau: NDArray[np.float64]
    omega: NDArray[np.float64]
    exact: NDArray[np.float64]
    bound: float = 1.0

    def __post_init__(self) -> None:
        n = self.tau.shape[0]
        if self.tau.shape != (n,) or self.omega.shape != (n, 3) or self.exact.shape != (n, 3):
            raise ValueError("measured samples need tau (n,), omega (n, 3) and exact (n, 3)")
        for array in (self.tau, self.omega, self.exact):
            if not np.all(np.isfinite(array)):
                raise ValueError("measured samples must be finite")
        if not (np.isfinite(self.bound) and self.bound > 0.0):
            raise ValueError("the bound on ω must be positive and finite")

    def scales(self) -> dict[str, viser.uplot.Scale]:
        """Time follows the data; the ω axis is fixed to ± the bound (see the module)."""
        top = MARGIN * float(self.bound)
        return {
            "x": viser.uplot.Scale(time=False, auto=True),
            "y": viser.uplot.Scale(auto=False, range=(-top, top)),
        }


#: A measured plot's legend: the series' names, no values under the cursor (NaN there).
LEGEND = viser.uplot.Legend(show=True, live=False)


def measured_series() -> list[viser.uplot.Series]:
    """The three measured series: dots in the colours of the body's axes, no line."""
    return [
        viser.uplot.Series(
            label=f"ω{'₁₂₃'[i]} measured",
            stroke=color,
            width=0,
            points=viser.uplot.Series_Points(show=True, size=DOT_SIZE, fill=color, stroke=color),
        )
        for i, color in enumerate(palette.PLOT_SERIES)
    ]


def merge(
    t: NDArray[np.float64], omega: NDArray[np.float64], measured: Measured
) -> tuple[NDArray[np.float64], ...]:
    """The seven columns: live samples ``t`` (m,) with the exact ``omega`` (m, 3), merged in
    time with the recording's samples from ``t[0]`` on (all of them before the first live
    sample exists)."""
    lo = float(t[0]) if t.size else -np.inf
    keep = measured.tau >= lo
    tau = measured.tau[keep]
    x = np.concatenate([t, tau])
    order = np.argsort(x, kind="stable")
    exact = np.concatenate([omega.reshape(-1, 3), measured.exact[keep]])[order]
    gaps = np.full((t.size, 3), np.nan)
    seen = np.concatenate([gaps, measured.omega[keep]])[order]
    return (
        x[order],
        exact[:, 0].copy(),
        exact[:, 1].copy(),
        exact[:, 2].copy(),
        seen[:, 0].copy(),
        seen[:, 1].copy(),
        seen[:, 2].copy(),
    )
