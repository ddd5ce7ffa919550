"""Colours and sizes of the scene and its plots, and the :class:`Look` of the scene on each
theme.

The hues are Okabe and Ito's palette for colour vision deficiency [OI08] (its reddish purple,
sky blue, yellow, vermillion, orange, bluish green and blue), lightened on the dark theme and
darkened on the light one so that every line, arrow and marker keeps at least 3 : 1 against
its panel [WCAG21 §1.4.11]. Elements of one kind (the curves, the arrows, the
surfaces) stay at least CIEDE2000 15 apart for normal vision and under simulated
deuteranopia, protanopia and tritanopia [MOF09; SWD05]; the whole polhode shares the polhode's hue
and is told apart by its thinner line, the axes by their labels 1, 2, 3 (each legend row
declares its cue: :class:`Entry`). Line widths are in screen pixels, so that they stay legible
from the back of the room at any zoom. The constants below are the dark theme's; :func:`look`
gives the light theme's and the projector's (thick lines, large labels), which the scene, the
legend and the exports follow.
"""

from __future__ import annotations

import dataclasses
from typing import Literal

import viser.uplot

RGB = tuple[int, int, int]

#: Okabe and Ito's eight colours [OI08], as published.
OKABE_ITO: dict[str, RGB] = {
    "black": (0, 0, 0),
    "orange": (230, 159, 0),
    "sky blue": (86, 180, 233),
    "bluish green": (0, 158, 115),
    "yellow": (240, 228, 66),
    "blue": (0, 114, 178),
    "vermillion": (213, 94, 0),
    "reddish purple": (204, 121, 167),
}

#: The panels' backgrounds the colours are chosen against: viser's dark theme and white.
DARK_BACKGROUND: RGB = (36, 36, 36)
LIGHT_BACKGROUND: RGB = (255, 255, 255)

ELLIPSOID: RGB = (180, 130, 30)
ELLIPSOID_OPACITY = 0.38
SOLID: RGB = (110, 120, 140)
AXES: tuple[RGB, RGB, RGB] = ((224, 134, 64), (0, 158, 115), (77, 162, 210))
POLHODE: RGB = OKABE_ITO["reddish purple"]
POLHODE_FULL: RGB = POLHODE
HERPOLHODE: RGB = (154, 210, 242)
OMEGA: RGB = OKABE_ITO["yellow"]
ANGULAR_MOMENTUM: RGB = OKABE_ITO["vermillion"]
PLANE: RGB = (179, 179, 179)
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

#: The numerical ghost: an ice-blue, distinct from the pale amber ellipsoid and the axes; a faint
#: shell, its principal sections and axes drawn as lines.
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

Shape = Literal["line", "arrow", "dot", "patch", "axes"]
#: How a line is drawn besides its colour: "thin" and "thick" against the traces' width,
#: "dashed"; "labelled": its parts carry their names in the scene (the axes 1, 2, 3);
#: "translucent": a surface seen through (an opaque one is "solid").
Style = Literal["solid", "thin", "thick", "dashed", "labelled", "translucent"]


@dataclasses.dataclass(frozen=True)
class Entry:
    """One row of a legend: a swatch of ``colors`` drawn as ``shape`` in ``style``, and its
    name. Two rows whose shape or style differ are told apart without their colours."""

    name: str
    colors: tuple[RGB, ...]
    shape: Shape
    style: Style = "solid"

    @property
    def cue(self) -> tuple[str, str]:
        """What tells this row from another one of the same colour: its shape and style."""
        return self.shape, self.style


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
#: The light theme: the hues of the dark one, darkened to 3 : 1 or more on white (the sky-blue
#: herpolhode becomes Okabe and Ito's blue, the yellow omega an olive, the white contact point
#: black, the pale rim dark).
LIGHT = dataclasses.replace(
    DARK,
    ellipsoid_opacity=0.32,
    solid=(55, 65, 82),
    axes=((192, 85, 0), (0, 120, 85), (64, 149, 197)),
    polhode=OKABE_ITO["reddish purple"],
    polhode_full=OKABE_ITO["reddish purple"],
    herpolhode=(0, 103, 160),
    omega=(156, 148, 43),
    angular_momentum=(106, 47, 0),
    plane=(115, 115, 115),
    plane_grid=(150, 165, 180),
    plane_rim=(70, 90, 110),
    contact=(30, 30, 30),
    origin=(60, 60, 60),
)


def _projector(base: Look) -> Look:
    """A projector in daylight: the theme's colours (already of full contrast), lines twice as
    thick, labels half again as large (on either theme; the theme's background stays)."""
    return dataclasses.replace(
        base,
        trace_width=7.0,
        full_polhode_width=4.0,
        axis_width=5.0,
        grid_width=1.5,
        rim_width=3.5,
        label_scale=1.5,
    )


PROJECTOR_DARK = _projector(DARK)
PROJECTOR_LIGHT = _projector(LIGHT)
LOOKS: dict[str, Look] = {
    "dark": DARK,
    "light": LIGHT,
    "projector, dark": PROJECTOR_DARK,
    "projector, light": PROJECTOR_LIGHT,
}


def background(look: Look) -> RGB:
    """The panel's background behind ``look``'s legend."""
    return LIGHT_BACKGROUND if look in (LIGHT, PROJECTOR_LIGHT) else DARK_BACKGROUND


def look(dark_mode: bool = True, projector: bool = False) -> Look:
    """The scene's look on the dark or light theme, for a projector or not."""
    if projector:
        return PROJECTOR_DARK if dark_mode else PROJECTOR_LIGHT
    return DARK if dark_mode else LIGHT


def css(rgb: RGB) -> str:
    """``#rrggbb`` for HTML."""
    return "#{:02x}{:02x}{:02x}".format(*rgb)
