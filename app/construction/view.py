"""Camera views and the look of the page (theme, lights)."""

from __future__ import annotations

import dataclasses

import viser

from poinsot.app.construction import palette


@dataclasses.dataclass(frozen=True)
class View:
    """A camera pose in display units (the scene's largest semi-axis is 1, L is +z)."""

    position: tuple[float, float, float]
    look_at: tuple[float, float, float]
    up: tuple[float, float, float] = (0.0, 0.0, 1.0)
    fov_degrees: float = 45.0

    def apply(self, camera: viser.CameraHandle) -> None:
        camera.up_direction = self.up
        camera.position = self.position
        camera.look_at = self.look_at
        camera.fov = self.fov_degrees * 3.141592653589793 / 180.0


#: From 38 degrees above the invariable plane (a grazing view squashed the herpolhode into a
#: sliver): the herpolhode's ring reads as a ring, the polhode is seen on the ellipsoid's cap
#: through the translucent plane, and the whole rolling ellipsoid and the L arrow are in frame
#: in the 3D view between the two docked columns, at 1280 x 800 as at 1920 x 1080. The
#: camera looks mostly along +y, so that body axis 1 and the x direction run across the view.
DEFAULT_VIEW = View(position=(1.06, -2.63, 2.42), look_at=(0.0, 0.0, 0.2))
VIEWS: dict[str, View] = {
    "default": DEFAULT_VIEW,
    "along-L": View(position=(0.0, -0.01, 5.4), look_at=(0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0)),
    "side": View(position=(0.0, -5.6, 0.9), look_at=(0.0, 0.0, 0.3)),
}


def apply_theme(client: viser.ClientHandle) -> None:
    """Dark theme, the panel's title, and the lights (see :func:`configure_theme` and
    :func:`apply_lighting`)."""
    configure_theme(client.gui)
    client.gui.set_panel_label("Poinsot: free rigid body")
    apply_lighting(client.scene)


def configure_theme(
    gui: viser.GuiApi, *, dark_mode: bool = True, large_controls: bool = False
) -> None:
    """No share button (it needs the internet), the brand colour of the theme
    (:func:`palette.brand`); dark unless a lecturer switches to light, wide controls for the
    projector's large text."""
    gui.configure_theme(
        dark_mode=dark_mode,
        show_share_button=False,
        show_logo=False,
        brand_color=palette.brand(dark_mode),
        control_width="large" if large_controls else "medium",
    )


def apply_lighting(scene: viser.SceneApi) -> None:
    """viser's default lights without shadow maps (nothing here casts a useful shadow, and
    re-rendering the shadow maps every frame tripled the frame time of a software-WebGL
    browser), and a hemisphere fill light instead of an environment map (which halved it again).
    Used on each browser's scene and on the export stage's shared scene alike."""
    scene.configure_default_lights(enabled=True, cast_shadow=False)
    scene.configure_environment_map(None)
    scene.add_light_hemisphere(
        "/lights/fill", sky_color=(200, 215, 255), ground_color=(70, 55, 40), intensity=1.2
    )
