"""MP4 and GIF clips of the scene: frames rendered by headless Chromium, encoded by ffmpeg.

The frames come from the same offline browser as ``poinsot screenshot``
(:mod:`poinsot.app.exports.screenshot`): a stage (the app's own construction on a viser server at
a free port) is opened in ONE headless Chromium window, and for each frame the stage is advanced
to the frame's time and the browser renders it (viser's ``get_render``, PNG, laid on the theme's
background). The stage draws on that browser's own scene, so that a frame's updates and the
render request after them travel in one queue, in order: every frame shows its own time.

Where a frame's time goes: the software-WebGL draw of the render dominates. The offline page
draws nothing else (:data:`~poinsot.app.exports.chromium.OFF_VIEWPORT_CSS`) and draws it at
the clip's own pixels (pixel ratio 1, fixed: the frames keep one sharpness); laying a render on
the background and encoding it run on a thread of their own, one frame behind the renders
(:func:`one_behind`), so that they overlap the browser's next draw.

The encoder is the ffmpeg binary that the ``imageio-ffmpeg`` wheel ships (nothing is downloaded
at run time, no system ffmpeg is used). MP4: H.264 in yuv420p with the index at the front, which
PowerPoint, Keynote and every browser play (sides must be even). GIF: one palette made for the
whole clip (ffmpeg's ``palettegen``/``paletteuse``), looping forever.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import pathlib
import threading
import time
from collections.abc import Callable, Generator, Iterator, Sequence
from concurrent.futures import Future, ThreadPoolExecutor

import numpy as np

from poinsot.app.construction.cameras import BODY_VIEW, ride_along
from poinsot.app.construction.view import View
from poinsot.app.exports.chromium import headless_chromium, open_window
from poinsot.app.exports.screenshot import (
    RGB,
    RenderCamera,
    camera_wxyz,
    content_extent,
    fitted_fov,
)
from poinsot.app.stage.scene_stage import SceneStage
from poinsot.app.stage.served import ClientOf, Stage

#: The formats, by the output file's suffix.
FORMATS = (".mp4", ".gif")
#: Longest clip [s] and largest picture on the command line (4K) and from the browser.
MAX_SECONDS = 600.0
MAX_SIZE = (3840, 2160)
BROWSER_MAX_SECONDS = 30.0
BROWSER_MAX_SIZE = (1920, 1080)
#: Frames per second: the default and the range.
DEFAULT_FPS = 25.0
FPS_RANGE = (1.0, 60.0)
#: H.264 quality (constant rate factor: 0 lossless .. 51 worst; 23 is x264's default) and speed.
MP4_CRF = 23
MP4_PRESET = "medium"
#: GIF: one palette for the whole clip (only what changes counts), ordered dithering.
GIF_FILTER = (
    "split[a][b];[a]palettegen=stats_mode=diff[p];"
    "[b][p]paletteuse=dither=bayer:bayer_scale=4:diff_mode=rectangle"
)
#: Labels are laid out again every this many seconds of the clip (the live app: 2 Hz).
LABEL_EVERY_SECONDS = 0.5

Progress = Callable[[int, int], None]
#: Opens the stage to film, drawing on the browser that ``client_of`` opens.
StageFactory = Callable[[ClientOf], Stage | SceneStage]


class Cancelled(Exception):
    """The clip was cancelled (its cancel event was set) before its last frame."""


@dataclasses.dataclass(frozen=True)
class Clip:
    """What to film: ``seconds`` of wall time at ``fps`` frames per second and ``size`` (width,
    height) pixels, from simulation time ``t0``, ``speed`` simulation time units per second."""

    seconds: float
    fps: float
    size: tuple[int, int]
    t0: float = 0.0
    speed: float = 1.0

    @property
    def frames(self) -> int:
        return max(1, round(self.seconds * self.fps))

    def time(self, i: int) -> float:
        """Simulation time of frame ``i``."""
        return self.t0 + i / self.fps * self.speed


def check_clip(clip: Clip, suffix: str, *, browser: bool = False) -> None:
    """ValueError (one line) unless the clip can be made: the bounds of the command line, or the
    smaller ones of the browser's button."""
    max_seconds = BROWSER_MAX_SECONDS if browser else MAX_SECONDS
    max_w, max_h = BROWSER_MAX_SIZE if browser else MAX_SIZE
    width, height = clip.size
    if suffix not in FORMATS:
        raise ValueError(f"the output must end in .mp4 or .gif, not {suffix or 'nothing'!r}")
    if not (math.isfinite(clip.seconds) and 0 < clip.seconds <= max_seconds):
        raise ValueError(f"the clip length must be in (0, {max_seconds:g}] seconds")
    if not (math.isfinite(clip.fps) and FPS_RANGE[0] <= clip.fps <= FPS_RANGE[1]):
        raise ValueError(f"the frame rate must be between {FPS_RANGE[0]:g} and {FPS_RANGE[1]:g}")
    if not (16 <= width <= max_w and 16 <= height <= max_h):
        raise ValueError(f"a video is at most {max_w}x{max_h} pixels (and at least 16x16)")
    if suffix == ".mp4" and (width % 2 or height % 2):
        raise ValueError(f"an MP4 (yuv420p) needs even sides, got {width}x{height}")
    if not (math.isfinite(clip.t0) and clip.t0 >= 0):
        raise ValueError("the start time must be a finite number >= 0")


# -- encoding -------------------------------------------------------------------------------
@contextlib.contextmanager
def encoder(
    path: pathlib.Path, size: tuple[int, int], fps: float
) -> Iterator[Generator[None, np.ndarray, None]]:
    """A generator that takes RGB frames (height, width, 3) uint8 by ``send`` and writes them
    into ``path`` (.mp4 or .gif) through the ffmpeg of imageio-ffmpeg; the file is complete when
    the block ends."""
    import imageio_ffmpeg

    if path.suffix.lower() == ".gif":
        options: dict = {
            "codec": "gif",
            "pix_fmt_out": "pal8",
            "quality": None,
            "output_params": ["-filter_complex", GIF_FILTER, "-loop", "0"],
        }
    else:
        options = {
            "codec": "libx264",
            "pix_fmt_out": "yuv420p",
            "quality": None,
            "output_params": [
                *("-crf", str(MP4_CRF), "-preset", MP4_PRESET),
                *("-profile:v", "high", "-movflags", "+faststart"),
            ],
        }
    writer = imageio_ffmpeg.write_frames(
        str(path), size, fps=fps, macro_block_size=1, ffmpeg_log_level="error", **options
    )
    writer.send(None)  # start ffmpeg
    try:
        yield writer
    finally:
        writer.close()


def rgb_on(rgba: np.ndarray, background: RGB) -> np.ndarray:
    """An RGBA render laid on an opaque background: (height, width, 3) uint8, each channel
    ``(c a + g (255 - a)) / 255`` rounded (Pillow's paste through the alpha mask)."""
    from PIL import Image

    image = Image.fromarray(np.ascontiguousarray(rgba, dtype=np.uint8), mode="RGBA")
    ground = Image.new("RGB", image.size, tuple(background))
    ground.paste(image, mask=image.getchannel("A"))
    return np.asarray(ground)


@contextlib.contextmanager
def one_behind(
    encoders: Sequence[Generator[None, np.ndarray, None]], background: RGB
) -> Iterator[Callable[[np.ndarray], None]]:
    """A function that takes RGBA renders in order and hands them, laid on ``background``, to
    each of the ``encoders`` on a thread of its own, one render behind: the browser draws the
    next frame while this one is encoded. A failure of an encoder is raised by the next call,
    or at the end of the block."""
    pending: Future[None] | None = None

    def encode(rgba: np.ndarray) -> None:
        rgb = rgb_on(rgba, background)
        for frames in encoders:
            frames.send(rgb)

    with ThreadPoolExecutor(max_workers=1, thread_name_prefix="poinsot-encode") as pool:

        def put(rgba: np.ndarray) -> None:
            nonlocal pending
            if pending is not None:
                pending.result()
            pending = pool.submit(encode, rgba)

        yield put
        if pending is not None:
            pending.result()


# -- filming --------------------------------------------------------------------------------
@dataclasses.dataclass
class Filmed:
    """What :func:`film` did (printed by the command, checked by tests and the benchmark)."""

    paths: tuple[pathlib.Path, ...]  # every output, the first one first
    frames: int
    width: int
    height: int
    bytes: int  # of the first output
    seconds: float  # wall time of the whole clip, browser start included
    render_seconds: float  # wall time of the frames alone (advance, render, encode)

    @property
    def seconds_per_frame(self) -> float:
        return self.render_seconds / self.frames

    @property
    def path(self) -> pathlib.Path:
        """The first output."""
        return self.paths[0]


@dataclasses.dataclass
class _Shots:
    """One browser's renders of a stage, from a fixed view or riding along with the body."""

    stage: Stage | SceneStage
    camera: RenderCamera
    view: View | None  # None: ride along
    fov: float
    size: tuple[int, int]
    window: tuple[int, int]  # the browser window's CSS pixels, which the labels are sized in
    label_every: int

    def view_at(self, wxyz: np.ndarray) -> View:
        return self.view if self.view is not None else ride_along(BODY_VIEW, wxyz)

    def shoot(self, i: int, t: float) -> np.ndarray:
        """Advance to ``t`` (frame ``i``) and render it (RGBA)."""
        frame = self.stage.advance(t)
        view = self.view_at(frame.wxyz)
        if isinstance(self.stage, Stage) and i % self.label_every == 0:
            self.stage.lay_out_labels(view, self.window)
        camera = self.camera
        if self.view is None:
            camera = RenderCamera(camera.client, camera_wxyz(view), np.asarray(view.position))
        width, height = self.size
        rgba = camera.render(width, height, self.fov)
        if rgba.shape[:2] != (height, width):
            raise RuntimeError(
                f"the browser returned {rgba.shape[1]}x{rgba.shape[0]}, not {width}x{height}"
            )
        return rgba


def _first_shot(
    stage: Stage | SceneStage, clip: Clip, view: View | None, window: tuple[int, int], fit: bool
) -> _Shots:
    """Seek to the clip's start, wait until the browser has the whole scene, and frame it."""
    frame = stage.seek(clip.t0)
    first = view if view is not None else ride_along(BODY_VIEW, frame.wxyz)
    if isinstance(stage, Stage):
        stage.lay_out_labels(first, window)
    assert stage.client is not None
    camera = RenderCamera(stage.client, camera_wxyz(first), np.asarray(first.position, float))
    fov = math.radians(first.fov_degrees)
    width, height = clip.size
    probe_w = min(width, 480)
    probe = camera.settled(probe_w, max(16, round(height * probe_w / width)), fov)
    if fit and view is not None:
        fov = fitted_fov(fov, content_extent(probe))
    every = max(1, round(LABEL_EVERY_SECONDS * clip.fps))
    return _Shots(stage, camera, view, fov, clip.size, window, every)


def film(
    open_stage: StageFactory,
    clip: Clip,
    view: View | None,
    out: pathlib.Path | Sequence[pathlib.Path],
    *,
    chromium: str,
    background: RGB,
    fit: bool = True,
    progress: Progress | None = None,
    cancel: threading.Event | None = None,
) -> Filmed:
    """Film ``clip`` of the stage that ``open_stage`` opens, from ``view`` (None: riding along
    with the body), into ``out`` (.mp4 or .gif; several files: each frame is rendered once and
    encoded into each). ``fit``: narrow a fixed view's field of view so that the construction
    at the start fills the picture. ``progress(done, total)`` is called after each frame;
    setting ``cancel`` stops before the browser starts, before the stage opens, before the
    first frame or at the next one (Cancelled, no file left)."""
    start = time.perf_counter()
    outs = (out,) if isinstance(out, pathlib.Path) else tuple(out)
    width, height = clip.size
    window = (max(16, round(720 * width / height)), 720)
    _check(cancel, 0, clip.frames)
    with headless_chromium(chromium) as browser:
        _check(cancel, 0, clip.frames)
        stage = open_stage(lambda server: open_window(browser, server, clip.size, 1.0))
        try:
            shots = _first_shot(stage, clip, view, window, fit)
            began = time.perf_counter()
            try:
                _frames(shots, clip, outs, background, progress, cancel)
            except BaseException:
                for path in outs:
                    path.unlink(missing_ok=True)
                raise
            rendered = time.perf_counter() - began
        finally:
            stage.stop()
    size = outs[0].stat().st_size
    return Filmed(outs, clip.frames, width, height, size, time.perf_counter() - start, rendered)


def _check(cancel: threading.Event | None, done: int, total: int) -> None:
    """Cancelled if ``cancel`` is set (``done`` of ``total`` frames filmed)."""
    if cancel is not None and cancel.is_set():
        raise Cancelled(f"cancelled after {done} of {total} frames")


def _frames(
    shots: _Shots,
    clip: Clip,
    outs: tuple[pathlib.Path, ...],
    background: RGB,
    progress: Progress | None,
    cancel: threading.Event | None,
) -> None:
    """Render the clip's frames and encode each into every one of ``outs``."""
    total = clip.frames
    with contextlib.ExitStack() as stack:
        encoders = [stack.enter_context(encoder(path, clip.size, clip.fps)) for path in outs]
        put = stack.enter_context(one_behind(encoders, background))
        for i in range(total):
            _check(cancel, i, total)
            put(shots.shoot(i, clip.time(i)))
            if progress is not None:
                progress(i + 1, total)
