"""Camera views for lectures: the default view (38 degrees above the invariable plane), the view
along L, the side view, and the ride-along view fixed in the body frame. One vocabulary: the
buttons in the browser and ``--view`` on the command line use the same names,
:data:`CAMERA_NAMES`.

The space-frame views are :data:`poinsot.app.scene.view.VIEWS`. The ride-along view is a
:class:`View` in *body* coordinates: every frame the attitude R(t) carries its position, look-at
point and up vector into space, so the body stands still on screen while the invariable plane, L and
the herpolhode turn around it. The attitude arrives as the scene's ``wxyz`` and becomes a rotation
through :func:`poinsot.app.scene.frames.rotation_from_wxyz`, the one place that knows the component
order.
"""

from __future__ import annotations

import numpy as np

from poinsot.app.scene.frames import rotation_from_wxyz
from poinsot.app.scene.geometry import triple
from poinsot.app.scene.view import DEFAULT_VIEW, VIEWS, View

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
