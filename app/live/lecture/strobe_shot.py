"""The screenshot button's strobe: the picture of this browser's construction at the current
time with copies of the body over the flip (or period) that ends now, the earliest faintest
(the same picture as ``poinsot screenshot --strobe``, :mod:`poinsot.app.exports.strobe`).

The copies are added to this browser's own scene below the construction as its camera sees it,
the browser renders from that camera moved sideways and widened to hold both, and the copies
are removed again (they show in the live view for the moment of the render).
"""

from __future__ import annotations

import numpy as np
import viser

from poinsot.app.construction.construction import PoinsotScene
from poinsot.app.construction.sampled.frames import wxyz
from poinsot.app.construction.view import View
from poinsot.app.exports.screenshot import camera_wxyz
from poinsot.app.exports.strobe import (
    Strobe,
    StrobeError,
    add_copies,
    construction_points,
    framing_fov,
)

#: Copies in the browser's strobe picture.
COPIES = 8


def strobe_render(
    client: viser.ClientHandle,
    scene: PoinsotScene,
    t: float,
    view: View,
    size: tuple[int, int],
    *,
    dark_mode: bool,
    timeout: float,
    copies: int = COPIES,
) -> np.ndarray:
    """Render (RGBA) ``scene`` as shown now, at time ``t``, with ``copies`` copies of its body
    over the interval that ends at ``t``, seen from ``view`` moved to frame both."""
    body, geometry = scene.body, scene.geometry
    if body is None or geometry is None:
        raise StrobeError("the strobe draws a rigid body; this scene has none")
    times = Strobe(copies, t1=max(float(t), 1e-9)).times(body)
    attitudes = list(wxyz(body.attitude(times)))
    width, height = size
    with client.atomic():
        row, handles = add_copies(client.scene, geometry, attitudes, view, dark_mode)
    try:
        points = np.vstack([construction_points(geometry), row.bounds()])
        fov = framing_fov(row.camera, points, width / height)
        return client.get_render(
            height,
            width,
            wxyz=camera_wxyz(row.camera),
            position=np.asarray(row.camera.position, float),
            fov=np.radians(fov),
            transport_format="png",
            timeout=timeout,
        )
    finally:
        with client.atomic():
            for handle in handles:
                handle.remove()
