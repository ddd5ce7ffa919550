"""Camera views for lectures: the default view (38 degrees above the invariable plane), the view
along L, the side view, and the ride-along view fixed in the body frame. One vocabulary: the
buttons in the browser and ``--view`` on the command line use the same names,
:data:`CAMERA_NAMES`.

The space-frame views are :data:`poinsot.app.construction.view.VIEWS`. The ride-along view is a
:class:`View` in *body* coordinates: every frame the attitude R(t) carries its position, look-at
point and up vector into space, so the body stands still on screen while the invariable plane, L and
the herpolhode turn around it. The attitude arrives as the scene's ``wxyz`` and becomes a rotation
through :func:`poinsot.app.construction.sampled.frames.rotation_from_wxyz`, the one place that knows
the component order.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from numpy.typing import ArrayLike

from poinsot.app.construction.geometry import triple
from poinsot.app.construction.sampled.frames import rotation_from_wxyz
from poinsot.app.construction.view import DEFAULT_VIEW, VIEWS, View

#: Ride-along camera in body coordinates (display units; the largest semi-axis is 1): a
#: three-quarter view onto the body's centre with body axis 3 up.
BODY_VIEW = View(position=(2.7, -3.3, 1.9), look_at=(0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0))

#: The riding camera's name.
RIDE_ALONG = "ride-along"
#: The views' names, in the order of the panel's buttons and the hotkeys 1-4 (``--view`` takes
#: the same words).
CAMERA_NAMES: tuple[str, ...] = ("default", "along-L", "side", RIDE_ALONG)
#: Older names still accepted on the command line.
ALIASES: dict[str, str] = {"top": "along-L", "body": RIDE_ALONG}


def canonical(name: str) -> str:
    """The view's name in :data:`CAMERA_NAMES` (an older alias is translated)."""
    name = ALIASES.get(name, name)
    if name not in CAMERA_NAMES:
        raise ValueError(f"no camera view {name!r}; choose from {', '.join(CAMERA_NAMES)}")
    return name


def space_view(name: str, attitude_wxyz: np.ndarray | None = None) -> View:
    """The camera view ``name`` in space coordinates; ``"ride-along"`` needs the attitude."""
    name = canonical(name)
    if name == RIDE_ALONG:
        if attitude_wxyz is None:
            raise ValueError("the ride-along view needs the body's attitude")
        return ride_along(BODY_VIEW, attitude_wxyz)
    if name == "default":
        return DEFAULT_VIEW
    return VIEWS[name]


def ride_along(body_view: View, attitude_wxyz: np.ndarray) -> View:
    """``body_view`` (body coordinates) carried into space by the attitude (body -> space)."""
    rotation = rotation_from_wxyz(np.asarray(attitude_wxyz, dtype=np.float64))
    position, look_at, up = rotation.apply(
        np.array([body_view.position, body_view.look_at, body_view.up], dtype=np.float64)
    )
    return View(
        position=triple(position),
        look_at=triple(look_at),
        up=triple(up),
        fov_degrees=body_view.fov_degrees,
    )


def framed(view: View, aspect: float, points: np.ndarray, margin: float = 0.06) -> View:
    """``view``'s direction, moved along it so that all ``points`` (N, 3) are in frame for a
    picture ``aspect`` (width / height) wide, with ``margin`` of the half-width free at the
    tightest edge; it looks at the middle of the points' bounding box.

    Each point asks for a distance: at distance ``d`` from the centre ``c`` along the view's
    forward ``f``, a point ``c + q`` is ``d + q·f`` deep and must lie within ``tan(fov/2)``
    (vertically; times ``aspect`` across) of that depth.
    """
    pts = np.asarray(points, dtype=np.float64)
    centre = 0.5 * (pts.min(axis=0) + pts.max(axis=0))
    forward = np.subtract(view.look_at, view.position)
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, view.up)
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    q = pts - centre
    depth = q @ forward
    ty = np.tan(np.radians(view.fov_degrees) / 2.0) * (1.0 - margin)
    tx = ty * max(float(aspect), 1e-3)
    need = np.maximum(np.abs(q @ right) / tx, np.abs(q @ up) / ty) - depth
    distance = float(np.max(need))
    return View(
        position=triple(centre - distance * forward),
        look_at=triple(centre),
        up=view.up,
        fov_degrees=view.fov_degrees,
    )


def construction_points(
    plane_height: float, plane_radius: float, arrow_top: float, n: int = 48
) -> np.ndarray:
    """Points that bound Poinsot's construction in space (display units): the sphere that holds
    the turning ellipsoid (radius 1), the plane's disc at ``plane_height`` and L's tip."""
    disc = _ring(n) * plane_radius + [0.0, 0.0, plane_height]
    return np.concatenate([sphere_points((0.0, 0.0, 0.0), 1.0, n), disc, [[0.0, 0.0, arrow_top]]])


#: The smallest ring a framing keeps around L's axis [display units]: a herpolhode that is
#: almost a point (a spin near an axis) still leaves the plane's middle in frame.
MIN_TRACE_RING = 0.5


def body_and_traces(
    plane_height: float, herpolhode_radius: float, arrow_top: float, n: int = 48
) -> np.ndarray:
    """Points that bound what a student watches (display units): the sphere that holds the
    turning ellipsoid (radius 1), the herpolhode's ring on the plane and L's tip; not the whole
    plane's disc, whose rim would leave the body small in its view."""
    radius = max(float(herpolhode_radius), MIN_TRACE_RING)
    ring = _ring(n) * radius + [0.0, 0.0, plane_height]
    return np.concatenate([sphere_points((0.0, 0.0, 0.0), 1.0, n), ring, [[0.0, 0.0, arrow_top]]])


def framed_above(view: View, width: float, height: float, bar: float, points: np.ndarray) -> View:
    """:func:`framed` for the part of a ``width`` x ``height`` picture above a ``bar`` at its
    bottom (a phone's bottom sheet): framed for that part's field of view and shape, then moved
    so that the part's middle is the picture's centre of what it frames."""
    inner = math.tan(math.radians(view.fov_degrees) / 2.0) * (height - bar) / height
    narrow = dataclasses.replace(view, fov_degrees=2.0 * math.degrees(math.atan(inner)))
    chosen = framed(narrow, width / (height - bar), points)
    chosen = dataclasses.replace(chosen, fov_degrees=view.fov_degrees)
    return shifted_up(chosen, bar / 2.0, height)


def shifted_up(view: View, pixels: float, height: float) -> View:
    """``view`` moved down in its screen plane so that what it centred is drawn ``pixels``
    higher in a picture ``height`` pixels high (a sheet covers the bottom of a phone's
    screen: the picture is centred in the part above it)."""
    forward = np.subtract(view.look_at, view.position)
    distance = float(np.linalg.norm(forward))
    forward /= distance
    right = np.cross(forward, view.up)
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    world_per_px = 2.0 * distance * np.tan(np.radians(view.fov_degrees) / 2.0) / height
    step = -up * pixels * world_per_px
    return View(
        position=triple(np.add(view.position, step)),
        look_at=triple(np.add(view.look_at, step)),
        up=view.up,
        fov_degrees=view.fov_degrees,
    )


def sphere_points(centre: ArrayLike, radius: float, n: int = 48) -> np.ndarray:
    """Points (N, 3) on the sphere of ``radius`` about ``centre``: nine rings of ``n``."""
    ring = _ring(n)
    u = np.linspace(-1.0, 1.0, 9)
    unit = np.concatenate([ring * np.sqrt(1.0 - z * z) + [0.0, 0.0, z] for z in u])
    return unit * float(radius) + np.asarray(centre, dtype=np.float64)


def _ring(n: int) -> np.ndarray:
    a = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    return np.stack([np.cos(a), np.sin(a), np.zeros(n)], axis=1)
