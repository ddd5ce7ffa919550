"""Colours of the scenes' own parts, beside :mod:`poinsot.app.construction.palette` (whose colours
they reuse where a part is the same thing: the polhode's reddish purple).

Taken from Okabe and Ito's palette [OI08] at a middle lightness: a scene's parts keep one colour
on both themes, so each is at least 3 : 1 against the dark panel and against white
[WCAG21 §1.4.11]. At one lightness a colour-blind eye tells fewer hues apart, so parts of one
kind that could be confused are drawn differently too (the separatrix and the current D's
polhodes thicker than the families), and each part declares that cue in its legend rows
(:attr:`~poinsot.app.lessons.support.spec.Part.legend`).
"""

from __future__ import annotations

from poinsot.app.construction import palette

RGB = tuple[int, int, int]

#: Okabe and Ito's vermillion, bluish green and reddish purple, and their blue lightened to
#: 3 : 1 on the dark panel.
VERMILLION: RGB = palette.OKABE_ITO["vermillion"]
GREEN: RGB = palette.OKABE_ITO["bluish green"]
PURPLE: RGB = palette.OKABE_ITO["reddish purple"]
BLUE: RGB = (20, 125, 195)
#: A dark gold (Okabe and Ito's yellow, darkened to 3 : 1 on white), an amber (their orange,
#: likewise), a violet and a middle grey.
GOLD: RGB = (160, 135, 0)
AMBER: RGB = (180, 130, 30)
VIOLET: RGB = (150, 125, 255)
GREY: RGB = (140, 140, 140)

#: The polhode families: warm around the minor axis 1, violet around the major axis 3; the
#: separatrix between them, drawn thicker.
MINOR_FAMILY: RGB = VERMILLION
MAJOR_FAMILY: RGB = VIOLET
SEPARATRIX: RGB = GREEN
#: The polhode of the current D: the app's polhode colour.
CURRENT: RGB = palette.POLHODE
#: Landau's momentum sphere |L| = const (translucent) and his energy ellipsoid.
SPHERE: RGB = VIOLET
SPHERE_OPACITY = 0.22
ELLIPSOID: RGB = palette.ELLIPSOID
ELLIPSOID_OPACITY = 0.3
#: The moving point m = I ω on Landau's picture, and its trace (a polhode).
MOMENTUM: RGB = GOLD
MOMENTUM_TRACE: RGB = palette.POLHODE
#: The polhode through a start pointed at on Landau's sphere, drawn while dragging (bright,
#: to stand out of the family and the current D's curves).
POINTED: RGB = (255, 225, 60)
#: Cones of the symmetric top: the body cone (rides with the body), the space cone (fixed).
BODY_CONE: RGB = VIOLET
SPACE_CONE: RGB = GREEN
CONE_OPACITY = 0.33
#: The gyroscope: its symmetry axis, the torque, the drift of the axis and the axis's path.
SYMMETRY_AXIS: RGB = BLUE
TORQUE: RGB = VERMILLION
DRIFT: RGB = VIOLET
AXIS_PATH: RGB = GOLD
OMEGA: RGB = GREEN
L: RGB = palette.ANGULAR_MOMENTUM
#: The geometric phase: the cone L sweeps in the body and the cap it cuts from a sphere.
PHASE_CONE: RGB = GREEN
PHASE_CAP: RGB = VIOLET
PHASE_CAP_OPACITY = 0.55
#: The racket's twist: the handle's and the head normal's traces in space.
HANDLE_PATH: RGB = GREEN
NORMAL_PATH: RGB = VIOLET
#: Solid bodies drawn from their own meshes.
SOLID: RGB = palette.SOLID
#: A twin of a body, started a little off it (translucent over the first): bluish green, not
#: the herpolhode's blue.
TWIN: RGB = GREEN

#: Plot series (uPlot strokes), 3 : 1 or more on both themes' panels: what the motion shows
#: (reddish purple), the theory (blue, drawn dashed: :data:`THEORY_DASH`), a level (grey), a
#: second series (vermillion), a twin (bluish green).
PLOT_MEASURED = palette.css(PURPLE)
PLOT_THEORY = palette.css(BLUE)
PLOT_LEVEL = palette.css(GREY)
PLOT_SECOND = palette.css(VERMILLION)
PLOT_TWIN = palette.css(GREEN)
#: uPlot's dash pattern [px] of a theory's curve: a cue besides its colour.
THEORY_DASH = (8.0, 5.0)


def hex_color(rgb: RGB) -> str:
    return "#{:02x}{:02x}{:02x}".format(*rgb)
