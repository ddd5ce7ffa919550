"""Colours and sizes of the scene, chosen for a dark background on a lecture projector.

Saturated, mutually distinct hues (the axes keep the red/green/blue convention of
1/2/3), traces brighter than the surfaces they lie on, and line widths in screen pixels so
that they stay legible from the back of the room at any zoom.
"""

from __future__ import annotations

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

#: Trace and axis line widths, in screen pixels.
TRACE_WIDTH_PX = 3.5
FULL_POLHODE_WIDTH_PX = 2.0
AXIS_WIDTH_PX = 2.5
GRID_WIDTH_PX = 1.0

#: Plot series colours, matching the body axes 1, 2, 3.
PLOT_SERIES = tuple("#{:02x}{:02x}{:02x}".format(*c) for c in AXES)
