"""Colours and sizes of the scene and its plots, chosen for a dark background on a lecture
projector.

Saturated, mutually distinct hues (the axes keep the red/green/blue convention of
1/2/3), traces brighter than the surfaces they lie on, and line widths in screen pixels so
that they stay legible from the back of the room at any zoom.
"""

from __future__ import annotations

import viser.uplot

RGB = tuple[int, int, int]

ELLIPSOID: RGB = (255, 179, 71)
ELLIPSOID_OPACITY = 0.38
SOLID: RGB = (110, 130, 165)
AXES: tuple[RGB, RGB, RGB] = ((239, 83, 80), (102, 214, 106), (80, 170, 255))
POLHODE: RGB = (255, 64, 160)
POLHODE_FULL: RGB = (185, 100, 150)
HERPOLHODE: RGB = (0, 229, 255)
OMEGA: RGB = (255, 238, 70)
ANGULAR_MOMENTUM: RGB = (200, 150, 255)
PLANE: RGB = (120, 150, 175)
PLANE_OPACITY = 0.18
PLANE_GRID: RGB = (80, 100, 120)
PLANE_RIM: RGB = (190, 210, 225)
CONTACT: RGB = (255, 255, 255)
ORIGIN: RGB = (230, 230, 230)
BRAND: RGB = (255, 179, 71)

#: The numerical ghost: an ice-blue, distinct from the amber ellipsoid, the traces and the RGB
#: axes; a faint shell, its principal sections and axes drawn as lines.
GHOST: RGB = (150, 205, 255)
GHOST_OPACITY = 0.16

#: Trace and axis line widths, in screen pixels.
TRACE_WIDTH_PX = 3.5
FULL_POLHODE_WIDTH_PX = 2.0
AXIS_WIDTH_PX = 2.5
GRID_WIDTH_PX = 1.0
RIM_WIDTH_PX = 2.0
GHOST_WIDTH_PX = 2.0

#: Plot series colours, matching the body axes 1, 2, 3.
PLOT_SERIES = tuple("#{:02x}{:02x}{:02x}".format(*c) for c in AXES)
#: The ghost's error plot: ω error, attitude error, energy error.
GHOST_PLOT_SERIES = ("#ffd84a", "#bfe1ff", "#ff6fb0")
#: Axis labels and grid of the plots, on the panel's dark background.
PLOT_AXIS_STROKE = "#c8d0da"
PLOT_GRID_STROKE = "#3a4048"


def plot_axes() -> tuple[viser.uplot.Axis, viser.uplot.Axis]:
    """The x and y axes of every plot: light labels, a faint grid."""
    axis = viser.uplot.Axis(
        stroke=PLOT_AXIS_STROKE,
        grid=viser.uplot.Axis_Grid(stroke=PLOT_GRID_STROKE, width=1),
        ticks=viser.uplot.Axis_Ticks(stroke=PLOT_GRID_STROKE),
    )
    return axis, axis


def plot_scales() -> dict[str, viser.uplot.Scale]:
    """x is simulated time (a number, not a date); both ranges follow the data."""
    return {"x": viser.uplot.Scale(time=False, auto=True), "y": viser.uplot.Scale(auto=True)}
