"""Colours of the scenes' own parts, beside :mod:`poinsot.app.construction.palette` (whose colours
they reuse where a part is the same thing: the polhode's pink, the ellipsoid's amber).

The polhode families take the hue of the axis they circle (warm around the minor axis 1, blue
around the major axis 3), the separatrix is white: a family reads at a glance on a projector.
"""

from __future__ import annotations

from poinsot.app.construction import palette

RGB = tuple[int, int, int]

MINOR_FAMILY: RGB = (255, 140, 90)
MAJOR_FAMILY: RGB = (110, 190, 255)
SEPARATRIX: RGB = (245, 245, 245)
#: The polhode of the current D: the app's polhode pink.
CURRENT: RGB = palette.POLHODE
#: Landau's momentum sphere |m| = G (translucent) and his energy ellipsoid (the amber).
SPHERE: RGB = (150, 125, 255)
SPHERE_OPACITY = 0.22
ELLIPSOID: RGB = palette.ELLIPSOID
ELLIPSOID_OPACITY = 0.3
#: The moving point m = I ω on Landau's picture, and its trace (a polhode: the polhode pink).
MOMENTUM: RGB = (255, 255, 255)
MOMENTUM_TRACE: RGB = palette.POLHODE
#: The polhode through a start pointed at on Landau's sphere, drawn while dragging (bright,
#: to stand out of the family and the current D's pink curves).
POINTED: RGB = (255, 225, 60)
#: Cones of the symmetric top: the body cone (rides with the body), the space cone (fixed).
BODY_CONE: RGB = (255, 120, 200)
SPACE_CONE: RGB = (90, 230, 160)
CONE_OPACITY = 0.33
#: The gyroscope: its symmetry axis, the torque, the drift of the axis and the axis's path.
SYMMETRY_AXIS: RGB = palette.AXES[2]
TORQUE: RGB = (255, 90, 60)
DRIFT: RGB = (120, 255, 120)
AXIS_PATH: RGB = (255, 210, 60)
OMEGA: RGB = palette.OMEGA
L: RGB = palette.ANGULAR_MOMENTUM
#: The geometric phase: the cone L sweeps in the body and the cap it cuts from a sphere.
PHASE_CONE: RGB = (120, 200, 255)
PHASE_CAP: RGB = (110, 235, 120)
PHASE_CAP_OPACITY = 0.55
#: The racket's twist: the handle's and the head normal's traces in space.
HANDLE_PATH: RGB = (255, 210, 60)
NORMAL_PATH: RGB = (140, 235, 165)
#: Solid bodies drawn from their own meshes.
SOLID: RGB = palette.SOLID
#: A twin of a body, started a little off it (translucent over the first).
TWIN: RGB = (80, 220, 255)

#: Plot series (uPlot strokes).
PLOT_MEASURED = "#ff40a0"
PLOT_THEORY = "#ffe64a"
PLOT_LEVEL = "#9aa4ae"
PLOT_SECOND = "#00e5ff"
PLOT_TWIN = "#50dcff"


def hex_color(rgb: RGB) -> str:
    return "#{:02x}{:02x}{:02x}".format(*rgb)
