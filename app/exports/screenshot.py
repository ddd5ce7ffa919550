"""PNG pictures of the scene: the renders themselves, and ``poinsot screenshot``.

A picture is rendered by a browser (viser's ``get_render``: WebGL, at any size, without the
control panel or notices), comes back RGBA with a transparent background, and is laid on the
theme's background colour unless a transparent PNG is asked for (:func:`png_bytes`).

``poinsot screenshot`` starts a :class:`~poinsot.app.stage.served.Stage` (the app's own scene
construction on a viser server at a free port), seeks it to the requested time, opens it in headless
Chromium through playwright, renders, and writes the PNG. The camera is a named view
(:mod:`poinsot.app.construction.cameras`); unless ``--no-fit`` is given, its field of view is then
narrowed so that the construction fills the picture (narrowing the field of view scales the image
about its centre, so one small probe render tells the exact factor). Chromium and the server are
stopped in ``finally`` blocks, and SIGTERM is turned into a normal exit so that they are also
stopped when the command is killed.
"""

from __future__ import annotations

import dataclasses
import io
import math
import pathlib
import re
import sys
import time
from typing import TYPE_CHECKING

import numpy as np
import viser
from scipy.spatial.transform import Rotation

from poinsot.app.construction.cameras import space_view
from poinsot.app.construction.sampled.frames import wxyz as to_wxyz
from poinsot.app.construction.view import View
from poinsot.app.exports.chromium import (
    EXIT_NO_BROWSER,
    WINDOW_HEIGHT,
    BrowserMissing,
    find_chromium,
    headless_chromium,
    open_window,
    sigterm_exits,
)
from poinsot.app.exports.strobe import Strobe, StrobeError, add_strobe, body_of
from poinsot.app.lessons import scene_by_name
from poinsot.app.lessons.support.spec import SceneSpec
from poinsot.app.model.presets import PRESETS, Preset, preset_by_key
from poinsot.app.stage.scene_stage import SceneStage
from poinsot.app.stage.served import ClientOf, Stage

if TYPE_CHECKING:
    from playwright.sync_api import Browser

RGB = tuple[int, int, int]

#: The canvas background of viser's themes (measured in Chromium: dark #141414, light white).
THEME_BACKGROUND: dict[bool, RGB] = {True: (20, 20, 20), False: (255, 255, 255)}
#: Size choices of the in-app button: label -> (width, height), None = the browser's view.
SIZE_CHOICES: dict[str, tuple[int, int] | None] = {
    "current view": None,
    "1920×1080": (1920, 1080),
    "3840×2160": (3840, 2160),
}
#: Largest picture a render may ask for (WebGL drawing buffers beyond this fail on most GPUs).
MAX_SIDE = 8192


#: Probe renders (to wait until the scene is complete, and to measure the framing) have at
#: most this width.
PROBE_WIDTH = 480
#: The construction fills this fraction of the picture's half-width or half-height.
FIT_FILL = 0.9
#: Seconds to wait for one render, and for the scene to settle.
RENDER_TIMEOUT = 120.0
SETTLE_TIMEOUT = 90.0


# -- pictures -------------------------------------------------------------------------------
def png_bytes(rgba: np.ndarray, background: RGB | None) -> bytes:
    """Encode a render as PNG: laid on ``background`` (opaque RGB), or kept RGBA (None)."""
    from PIL import Image

    image = Image.fromarray(np.ascontiguousarray(rgba, dtype=np.uint8), mode="RGBA")
    if background is not None:
        ground = Image.new("RGBA", image.size, (*background, 255))
        image = Image.alpha_composite(ground, image).convert("RGB")
    out = io.BytesIO()
    image.save(out, format="PNG", optimize=False)
    return out.getvalue()


def filename(scene: str, t: float, suffix: str = "png") -> str:
    """``poinsot_<scene>_t<time>.<suffix>``, safe on every file system."""
    safe = re.sub(r"[^A-Za-z0-9_-]+", "-", scene).strip("-") or "scene"
    return f"poinsot_{safe}_t{t:.2f}.{suffix}"


def parse_size(text: str) -> tuple[int, int]:
    """``"1920x1080"`` (or with ×) -> (1920, 1080)."""
    match = re.fullmatch(r"\s*(\d+)\s*[x×X]\s*(\d+)\s*", text)
    if not match:
        raise ValueError(f"size must look like 1920x1080, got {text!r}")
    width, height = int(match.group(1)), int(match.group(2))
    if not (16 <= width <= MAX_SIDE and 16 <= height <= MAX_SIDE):
        raise ValueError(f"each side must be between 16 and {MAX_SIDE} pixels")
    return width, height


def camera_wxyz(view: View) -> np.ndarray:
    """Orientation of a camera at ``view`` in viser's (OpenCV) convention: camera x right,
    y down, z forward; the columns of its matrix are these axes in world coordinates."""
    forward = np.subtract(view.look_at, view.position).astype(np.float64)
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, view.up)
    if np.linalg.norm(right) < 1e-9:
        raise ValueError("the camera's up direction is parallel to its view direction")
    right /= np.linalg.norm(right)
    down = np.cross(forward, right)
    return to_wxyz(Rotation.from_matrix(np.column_stack([right, down, forward])))


def content_extent(rgba: np.ndarray) -> float:
    """How far the drawn content reaches from the picture's centre: the largest of its
    horizontal and vertical reach, as a fraction of the half-width and half-height (0 for an
    empty picture)."""
    alpha = rgba[..., 3] > 8
    if not alpha.any():
        return 0.0
    height, width = alpha.shape
    rows = np.flatnonzero(alpha.any(axis=1))
    cols = np.flatnonzero(alpha.any(axis=0))
    x = max(abs(cols[0] - width / 2), abs(cols[-1] + 1 - width / 2)) / (width / 2)
    y = max(abs(rows[0] - height / 2), abs(rows[-1] + 1 - height / 2)) / (height / 2)
    return float(max(x, y))


def fitted_fov(fov: float, extent: float, fill: float = FIT_FILL) -> float:
    """The vertical field of view that scales content reaching ``extent`` to ``fill``: image
    coordinates scale with 1 / tan(fov / 2) about the centre."""
    if extent <= 0.0:
        return fov
    return 2.0 * math.atan(math.tan(fov / 2.0) * extent / fill)


@dataclasses.dataclass
class Shot:
    """What :func:`capture` did (printed by the CLI, checked by tests)."""

    png: bytes
    width: int
    height: int
    fov_degrees: float
    seconds: float


def _open(browser: Browser, stage: Stage | SceneStage, size: tuple[int, int]) -> viser.ClientHandle:
    """Open ``stage`` in a window of WINDOW_HEIGHT CSS pixels with the picture's aspect."""
    return open_window(browser, stage.server, size)


@dataclasses.dataclass(frozen=True)
class RenderCamera:
    """Renders of one browser's scene from one camera pose."""

    client: viser.ClientHandle
    wxyz: np.ndarray
    position: np.ndarray

    def render(self, width: int, height: int, fov: float) -> np.ndarray:
        return self.client.get_render(
            height,
            width,
            wxyz=self.wxyz,
            position=self.position,
            fov=fov,
            transport_format="png",
            timeout=RENDER_TIMEOUT,
        )

    def settled(self, width: int, height: int, fov: float) -> np.ndarray:
        """A render once the browser has decoded every mesh (it does so asynchronously): render
        until two renders agree."""
        deadline = time.monotonic() + SETTLE_TIMEOUT
        previous = self.render(width, height, fov)
        while True:
            current = self.render(width, height, fov)
            if np.array_equal(current, previous) and current[..., 3].any():
                return current
            if time.monotonic() > deadline:
                raise TimeoutError("the scene did not settle in the browser")
            previous = current


def capture(
    stage: Stage | SceneStage,
    view: View,
    size: tuple[int, int],
    *,
    chromium: str,
    background: RGB | None,
    fit: bool = True,
) -> Shot:
    """Open ``stage`` in headless Chromium and render it from ``view`` at ``size``."""
    start = time.perf_counter()
    width, height = size
    probe_w = min(width, PROBE_WIDTH)
    probe_h = max(16, round(height * probe_w / width))
    fov = math.radians(view.fov_degrees)
    with headless_chromium(chromium) as browser:
        client = _open(browser, stage, size)
        camera = RenderCamera(
            client, camera_wxyz(view), np.asarray(view.position, dtype=np.float64)
        )
        probe = camera.settled(probe_w, probe_h, fov)
        if fit:
            fov = fitted_fov(fov, content_extent(probe))
        rgba = camera.render(width, height, fov)
    if rgba.shape[:2] != (height, width):
        raise RuntimeError(
            f"the browser returned {rgba.shape[1]}x{rgba.shape[0]}, not {width}x{height}"
        )
    return Shot(
        png_bytes(rgba, background), width, height, math.degrees(fov), time.perf_counter() - start
    )


# -- the command ----------------------------------------------------------------------------
def resolve_scene(name: str) -> Preset | SceneSpec:
    """A scene (:mod:`poinsot.app.lessons`) by name or label, or a preset by key or label
    (case-insensitive)."""
    try:
        return scene_by_name(name)
    except KeyError:
        pass
    for preset in PRESETS:
        if name.lower() in (preset.key.lower(), preset.label.lower()):
            return preset
    return preset_by_key(name)  # raises KeyError listing the choices


def default_time(period: float) -> float:
    """One period of omega (the polhode closes), or 20 time units where there is none."""
    return period if math.isfinite(period) and 0 < period <= 120 else 20.0


def open_stage(
    scene: Preset | SceneSpec, dark_mode: bool, client_of: ClientOf | None = None
) -> Stage | SceneStage:
    """The stage that draws a preset or a scene (stop it when done); ``client_of``: on one
    browser's own scene (:data:`~poinsot.app.stage.served.ClientOf`)."""
    if isinstance(scene, SceneSpec):
        return SceneStage(scene, dark_mode=dark_mode, client_of=client_of)
    return Stage.from_preset(scene, dark_mode=dark_mode, client_of=client_of)


def picture_time(stage: Stage | SceneStage) -> float:
    """The default time of a picture: the scene's own, or a preset's :func:`default_time`."""
    if isinstance(stage, SceneStage):
        return stage.spec.picture_time
    return default_time(float(stage.body.period))


def pose_stage(
    stage: Stage | SceneStage,
    scene: Preset | SceneSpec,
    t: float | None,
    view: str,
    size: tuple[int, int],
    strobe: Strobe | None,
) -> tuple[View, float]:
    """Seek ``stage`` to the picture's time (with the strobe's copies, if any), lay out its
    labels, and return the picture's camera and time."""
    if strobe is not None:
        fixed = scene.view if isinstance(scene, SceneSpec) and view == "default" else None
        aspect = size[0] / size[1]
        camera = add_strobe(stage, strobe, fixed or space_view(view), stage.dark_mode, aspect)
        t = stage.frame.t
    else:
        t = t if t is not None else picture_time(stage)
        camera = space_view(view, stage.seek(t).wxyz)
        if isinstance(scene, SceneSpec) and view == "default":
            camera = scene.view
    stage.set_initial_camera(camera)
    if isinstance(stage, Stage):  # the labels laid out for this camera and window
        stage.lay_out_labels(camera, (round(WINDOW_HEIGHT * size[0] / size[1]), WINDOW_HEIGHT))
    return camera, t


def screenshot_command(
    out: pathlib.Path,
    scene: Preset | SceneSpec,
    *,
    t: float | None = None,
    size: tuple[int, int] = (1920, 1080),
    view: str = "default",
    background: str = "dark",
    fit: bool = True,
    strobe: Strobe | None = None,
) -> int:
    """``poinsot screenshot``: 0 on success, EXIT_NO_BROWSER without Chromium, 1 on failure,
    2 for a strobe that cannot be drawn.

    ``t``: simulation time of the picture (None: one period of omega, or a scene's own
    time); ``view``: a camera of :data:`~poinsot.app.construction.cameras.CAMERA_NAMES` ("default"
    is a scene's own framing); ``background``: "dark", "light" or
    "transparent"; ``fit``: frame the construction (else keep the view's field of view);
    ``strobe``: copies of the body over an interval (:mod:`poinsot.app.exports.strobe`), the
    picture taken at its end.
    """
    try:
        chromium = find_chromium()
    except BrowserMissing as exc:
        print(f"poinsot screenshot: {exc}", file=sys.stderr)
        return EXIT_NO_BROWSER
    with sigterm_exits():
        stage = open_stage(scene, dark_mode=background != "light")
        try:
            camera, t = pose_stage(stage, scene, t, view, size, strobe)
            ground = None if background == "transparent" else THEME_BACKGROUND[background == "dark"]
            shot = capture(stage, camera, size, chromium=chromium, background=ground, fit=fit)
        except BrowserMissing as exc:
            print(f"poinsot screenshot: {exc}", file=sys.stderr)
            return EXIT_NO_BROWSER
        except StrobeError as exc:
            print(f"poinsot screenshot: error: {exc}", file=sys.stderr)
            return 2
        except Exception as exc:  # the command's boundary: say what failed, exit non-zero
            print(f"poinsot screenshot: failed: {type(exc).__name__}: {exc}", file=sys.stderr)
            return 1
        finally:
            stage.stop()
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_bytes(shot.png)
    strobe_text = ""
    if strobe is not None:
        t0, t1 = strobe.interval(body_of(stage))
        strobe_text = f", strobe of {strobe.copies} copies over [{t0:.3f}, {t1:.3f}]"
    print(
        f"wrote {out} ({shot.width}x{shot.height}, scene {scene.key}, t = {t:g}, "
        f"view {view}, fov {shot.fov_degrees:.1f} deg{strobe_text}) in {shot.seconds:.1f} s"
    )
    return 0
