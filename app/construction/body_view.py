"""The body frame beside the space frame: a second picture of the same motion, placed next to
Poinsot's construction in the same viser scene.

In the space frame (the construction, :mod:`poinsot.app.construction.construction`) the invariable
plane and L stand still: the herpolhode is fixed on the plane while the ellipsoid rolls. In the
body frame the ellipsoid stands still: the polhode is fixed on it, ω's tip runs along the
polhode, and L (with the plane, seen from the body) turns. This picture draws the body frame as
it was at t = 0 (so that at t = 0 the two pictures agree), :data:`OFFSET` to the right of the
construction in the default views.

Per frame it sends four small messages: ω's arrow, the contact point's position, the
orientation of the frame that carries L and a patch of the plane (the inverse attitude), and
the patch's position (round the contact point).
"""

from __future__ import annotations

import numpy as np
import viser

from poinsot.app.construction import meshes, palette, updates
from poinsot.app.construction.ellipsoid import add_ellipsoid, fit_ellipsoid
from poinsot.app.construction.geometry import (
    CONTACT_RADIUS,
    L_ARROW,
    L_OVERSHOOT,
    OMEGA_ARROW,
    POLHODE_INFLATE,
    Geometry,
)
from poinsot.app.construction.palette import Look
from poinsot.app.construction.sampled.batch import Frame
from poinsot.app.construction.sampled.frames import rotation_from_wxyz, wxyz

#: Where the body-frame picture stands [display units]: right of the construction.
OFFSET = (3.1, 0.0, 0.0)
ROOT = "/body_view"
#: Radius of the patch of the invariable plane drawn round the contact point.
PATCH_RADIUS = 0.55
#: Height of the pictures' titles above the fixed point [display units].
TITLE_HEIGHT = 1.95


class BodyView:
    """Create on a scene API, :meth:`fit` to a body, :meth:`advance` every frame, then
    :meth:`remove`. Frame thread only."""

    def __init__(self, api: viser.SceneApi, look: Look = palette.DARK) -> None:
        self.api = api
        self.frame = api.add_frame(ROOT, show_axes=False, position=OFFSET)
        self._add_body(api, look)
        self._add_space(api, look)
        self.titles = _titles(api)
        self.geometry: Geometry | None = None

    def _add_body(self, api: viser.SceneApi, look: Look) -> None:
        """The body's nodes: the ellipsoid, its axes, the polhode, ω and the contact point."""
        self.ellipsoid = add_ellipsoid(
            api, f"{ROOT}/ellipsoid", look.ellipsoid, look.ellipsoid_opacity
        )
        empty = np.zeros((1, 2, 3), np.float32)
        self.axes = [
            api.add_line_segments(
                f"{ROOT}/axis{i + 1}",
                empty,
                look.axes[i],
                thickness=look.axis_width,
                thickness_units="screen",
            )
            for i in range(3)
        ]
        self.polhode = api.add_line_segments(
            f"{ROOT}/polhode",
            empty,
            look.polhode,
            thickness=look.trace_width,
            thickness_units="screen",
            scale=POLHODE_INFLATE,
        )
        self.omega = api.add_arrows(
            f"{ROOT}/omega",
            np.array([[[0.0, 0.0, 0.0], [0.0, 0.0, 1.0]]], np.float32),
            look.omega,
            shaft_radius=OMEGA_ARROW.shaft_radius,
            head_radius=OMEGA_ARROW.head_radius,
            head_length=OMEGA_ARROW.head_length,
        )
        self.tip = api.add_icosphere(
            f"{ROOT}/contact", radius=CONTACT_RADIUS, color=look.contact, cast_shadow=False
        )

    def _add_space(self, api: viser.SceneApi, look: Look) -> None:
        """L and a patch of the plane as the body sees them: in a frame turned by the inverse
        attitude."""
        self.space = api.add_frame(f"{ROOT}/space", show_axes=False)
        self.momentum = api.add_arrows(
            f"{ROOT}/space/L",
            np.array([[[0.0, 0.0, 0.0], [0.0, 0.0, 1.0]]], np.float32),
            look.angular_momentum,
            shaft_radius=L_ARROW.shaft_radius,
            head_radius=L_ARROW.head_radius,
            head_length=L_ARROW.head_length,
        )
        vertices, faces = meshes.disc_mesh(PATCH_RADIUS)
        self.patch = api.add_frame(f"{ROOT}/space/plane", show_axes=False)
        self.disc = api.add_mesh_simple(
            f"{ROOT}/space/plane/disc",
            vertices,
            faces,
            color=look.plane,
            opacity=look.plane_opacity * 2.0,
            side="double",
            cast_shadow=False,
            receive_shadow=False,
        )
        self.rim = api.add_line_segments(
            f"{ROOT}/space/plane/rim",
            meshes.circle_segments(PATCH_RADIUS),
            look.plane_rim,
            thickness=look.rim_width,
            thickness_units="screen",
        )

    def fit(self, geometry: Geometry, attitude0: np.ndarray) -> None:
        """Show the body of ``geometry`` as it was at t = 0 (attitude ``attitude0``, wxyz)."""
        self.geometry = geometry
        self.frame.wxyz = np.asarray(attitude0, dtype=np.float64)
        fit_ellipsoid(self.ellipsoid, geometry.semi_axes)
        for line, end in zip(self.axes, geometry.axis_ends(), strict=True):
            line.points = np.array([[-end, end]], dtype=np.float32)
        self.polhode.points = geometry.polhode_segments()
        top = geometry.plane_height + L_OVERSHOOT
        self.momentum.points = np.array([[[0.0, 0.0, 0.0], [0.0, 0.0, top]]], np.float32)

    def advance(self, frame: Frame) -> None:
        """ω's tip on the polhode (body coordinates), and L with the plane turned back by the
        attitude of ``frame``."""
        geometry = self.geometry
        if geometry is None:
            return
        tip = np.asarray(frame.omega, dtype=np.float64) * geometry.scale
        updates.set_points(self.omega, np.array([[[0.0, 0.0, 0.0], tip]], np.float32))
        updates.set_position(self.tip, tip)
        inverse = rotation_from_wxyz(frame.wxyz).inv()
        updates.set_wxyz(self.space, wxyz(inverse))
        # The plane's patch round the contact point: in the turned frame, at height h.
        patch = inverse.inv().apply(tip)
        updates.set_position(self.patch, np.array([patch[0], patch[1], geometry.plane_height]))

    def restyle(self, look: Look) -> None:
        self.ellipsoid.color, self.ellipsoid.opacity = look.ellipsoid, look.ellipsoid_opacity
        for line, color in zip(self.axes, look.axes, strict=True):
            line.colors = np.array(color, dtype=np.uint8)
            line.thickness = look.axis_width
        self.polhode.colors = np.array(look.polhode, dtype=np.uint8)
        self.polhode.thickness = look.trace_width
        self.omega.colors = np.array(look.omega, dtype=np.uint8)
        self.momentum.colors = np.array(look.angular_momentum, dtype=np.uint8)
        self.tip.color = look.contact
        self.disc.color = look.plane
        self.rim.colors = np.array(look.plane_rim, dtype=np.uint8)
        self.rim.thickness = look.rim_width
        for title in self.titles:
            title.font_screen_scale = 1.15 * look.label_scale

    def remove(self) -> None:
        for title in self.titles:
            title.remove()
        self.frame.remove()  # and every node under it


def _titles(api: viser.SceneApi) -> tuple[viser.LabelHandle, viser.LabelHandle]:
    """The two pictures' titles, above each."""
    return (
        api.add_label(
            "/view_titles/space",
            "space frame: herpolhode fixed on the plane",
            position=(0.0, 0.0, TITLE_HEIGHT),
            anchor="bottom-center",
            font_screen_scale=1.15,
        ),
        api.add_label(
            "/view_titles/body",
            "body frame: polhode fixed on the body",
            position=(OFFSET[0], OFFSET[1], TITLE_HEIGHT),
            anchor="bottom-center",
            font_screen_scale=1.15,
        ),
    )
