"""Colours and sizes of the scene and its plots, chosen for a dark background on a lecture
projector, and the :class:`Look` of the scene on each theme.

Saturated, mutually distinct hues (the axes keep the red/green/blue convention of
1/2/3), traces brighter than the surfaces they lie on, and line widths in screen pixels so
that they stay legible from the back of the room at any zoom. The constants below are the
dark theme's; :func:`look` gives the light theme's and the projector's (high contrast, thick
lines, large labels), which the scene, the legend and the exports follow.
"""

from __future__ import annotations

import dataclasses

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
#: The brand colour on the light theme. viser derives ten shades from the brand colour and the
#: light theme draws buttons, outlined button text and sliders in shade 6, which is lighter
#: than the brand itself: a deep orange-brown gives shade 6 = (176, 88, 0), 4.9 : 1 against
#: white (the amber gave 1.6 : 1, pale orange text on white).
BRAND_LIGHT: RGB = (82, 41, 0)

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


def brand(dark_mode: bool) -> RGB:
    """The brand colour of the dark or the light theme."""
    return BRAND if dark_mode else BRAND_LIGHT


def plot_axes() -> tuple[viser.uplot.Axis, viser.uplot.Axis]:
    """The x and y axes of every plot: a one-pixel grid. No colour is given for the labels,
    ticks and grid, so that viser's plot takes its theme's (light text on the dark panel,
    dark text on the light one) and follows a change of theme."""
    axis = viser.uplot.Axis(grid=viser.uplot.Axis_Grid(width=1))
    return axis, axis


def plot_scales() -> dict[str, viser.uplot.Scale]:
    """x is simulated time (a number, not a date); both ranges follow the data."""
    return {"x": viser.uplot.Scale(time=False, auto=True), "y": viser.uplot.Scale(auto=True)}


@dataclasses.dataclass(frozen=True)
class Look:
    """The colours, line widths [screen px] and label size of the scene on one theme."""

    ellipsoid: RGB = ELLIPSOID
    ellipsoid_opacity: float = ELLIPSOID_OPACITY
    solid: RGB = SOLID
    axes: tuple[RGB, RGB, RGB] = AXES
    polhode: RGB = POLHODE
    polhode_full: RGB = POLHODE_FULL
    herpolhode: RGB = HERPOLHODE
    omega: RGB = OMEGA
    angular_momentum: RGB = ANGULAR_MOMENTUM
    plane: RGB = PLANE
    plane_opacity: float = PLANE_OPACITY
    plane_grid: RGB = PLANE_GRID
    plane_rim: RGB = PLANE_RIM
    contact: RGB = CONTACT
    origin: RGB = ORIGIN
    trace_width: float = TRACE_WIDTH_PX
    full_polhode_width: float = FULL_POLHODE_WIDTH_PX
    axis_width: float = AXIS_WIDTH_PX
    grid_width: float = GRID_WIDTH_PX
    rim_width: float = RIM_WIDTH_PX
    #: Factor on every label's size (1: the labels' own sizes).
    label_scale: float = 1.0


#: The dark theme: the constants above.
DARK = Look()
#: The light theme: the hues of the dark one, darkened where they would fade on white (the
#: cyan herpolhode, the yellow omega, the white contact point, the pale rim).
LIGHT = dataclasses.replace(
    DARK,
    ellipsoid=(240, 150, 30),
    ellipsoid_opacity=0.32,
    axes=((215, 45, 40), (40, 160, 50), (30, 110, 220)),
    polhode=(225, 0, 120),
    polhode_full=(170, 70, 130),
    herpolhode=(0, 150, 200),
    omega=(205, 150, 0),
    angular_momentum=(120, 60, 220),
    plane=(110, 135, 160),
    plane_grid=(150, 165, 180),
    plane_rim=(70, 90, 110),
    contact=(30, 30, 30),
    origin=(60, 60, 60),
)


def _projector(base: Look, polhode: RGB, herpolhode: RGB, omega: RGB) -> Look:
    """A projector in daylight: fully saturated traces, lines twice as thick, labels half again
    as large (on either theme; the theme's background stays)."""
    return dataclasses.replace(
        base,
        polhode=polhode,
        herpolhode=herpolhode,
        omega=omega,
        trace_width=7.0,
        full_polhode_width=4.0,
        axis_width=5.0,
        grid_width=1.5,
        rim_width=3.5,
        label_scale=1.5,
    )


PROJECTOR_DARK = _projector(DARK, (255, 0, 150), (0, 200, 255), (255, 240, 0))
PROJECTOR_LIGHT = _projector(LIGHT, (210, 0, 110), (0, 120, 190), (205, 150, 0))


def look(dark_mode: bool = True, projector: bool = False) -> Look:
    """The scene's look on the dark or light theme, for a projector or not."""
    if projector:
        return PROJECTOR_DARK if dark_mode else PROJECTOR_LIGHT
    return DARK if dark_mode else LIGHT


def css(rgb: RGB) -> str:
    """``#rrggbb`` for HTML."""
    return "#{:02x}{:02x}{:02x}".format(*rgb)
