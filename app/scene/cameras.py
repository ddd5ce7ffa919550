"""Camera presets for lectures: the three-quarter default, the view along L, the side view, and
the ride-along view fixed in the body frame.

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

#: Preset name -> button label, in the order the panel shows them.
CAMERA_LABELS: dict[str, str] = {
    "default": "¾ view",
    "top": "Along L",
    "side": "Side",
    "body": "Ride along",
}
#: Names accepted by ``--view`` and :func:`space_view`.
CAMERA_NAMES: tuple[str, ...] = tuple(CAMERA_LABELS)


def space_view(name: str, attitude_wxyz: np.ndarray | None = None) -> View:
    """The camera preset ``name`` in space coordinates; ``"body"`` needs the attitude."""
    if name == "body":
        if attitude_wxyz is None:
            raise ValueError("the ride-along view needs the body's attitude")
        return ride_along(BODY_VIEW, attitude_wxyz)
    if name == "default":
        return DEFAULT_VIEW
    if name not in VIEWS:
        raise ValueError(f"no camera view {name!r}; choose from {list(CAMERA_NAMES)}")
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
