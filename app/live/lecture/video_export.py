"""The "Video" button of the lecture folder: an MP4 or GIF of what this browser shows, from the
current time and camera, handed down to the browser as a file.

The clip is filmed as ``poinsot video`` films it (:mod:`poinsot.app.exports.video`): a stage of
the session's current body (or scene, at its current settings) on its own viser server, rendered
by a headless Chromium on the server's machine. That runs on a thread of its own, never on the
session's frame thread nor on viser's callback pool, so that no browser stalls; one clip at a
time per server (Chromium is heavy), with its progress in the panel and a cancel button. From
the browser a clip is at most 30 s and 1920×1080.
"""

from __future__ import annotations

import contextlib
import math
import pathlib
import tempfile
import threading
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Protocol

import viser

from poinsot.app.construction.cameras import RIDE_ALONG
from poinsot.app.construction.geometry import triple
from poinsot.app.construction.view import View
from poinsot.app.exports.chromium import find_chromium
from poinsot.app.exports.screenshot import THEME_BACKGROUND, filename
from poinsot.app.exports.video import (
    BROWSER_MAX_SECONDS,
    BROWSER_MAX_SIZE,
    DEFAULT_FPS,
    Cancelled,
    Clip,
    StageFactory,
    check_clip,
    film,
)
from poinsot.app.model.parameters import Parameters, drawn_solid
from poinsot.app.model.presets import CUSTOM
from poinsot.app.stage.scene_stage import SceneStage
from poinsot.app.stage.served import ClientOf, Stage

if TYPE_CHECKING:
    from poinsot.app.construction.construction import PoinsotScene
    from poinsot.app.live.panel.clock import SimClock
    from poinsot.app.model.presets import Preset


class FilmedSession(Protocol):
    """What the video reads of the session it films (its parameters, read where it has them)."""

    @property
    def clock(self) -> SimClock: ...
    @property
    def scene(self) -> PoinsotScene: ...
    @property
    def preset(self) -> Preset: ...
    @property
    def params(self) -> Parameters: ...


class Filming(Protocol):
    """What the video button asks of the lecture folder it sits in."""

    @property
    def client(self) -> viser.ClientHandle: ...
    @property
    def camera(self) -> str: ...
    @property
    def session(self) -> FilmedSession: ...
    @property
    def dark_mode(self) -> bool: ...
    def picture_size(self) -> tuple[int, int]: ...
    def show(self, text: str, error: bool = False) -> None: ...


#: Formats offered: label -> file suffix.
FORMAT_CHOICES = {"MP4 (slides, web)": ".mp4", "GIF (loops)": ".gif"}
#: One clip at a time in this process: each holds a headless Chromium.
_FILMING = threading.Semaphore(1)


def fit_within(size: tuple[int, int], bound: tuple[int, int], even: bool) -> tuple[int, int]:
    """``size`` scaled down (aspect kept) to fit ``bound``; sides made even if ``even``."""
    width, height = size
    factor = min(1.0, bound[0] / width, bound[1] / height)
    width, height = max(16, math.floor(width * factor)), max(16, math.floor(height * factor))
    if even:
        width, height = width - width % 2, height - height % 2
    return width, height


def browser_view(client: viser.ClientHandle) -> View:
    """The camera this browser shows now, as a view."""
    camera = client.camera
    return View(
        position=triple(camera.position),
        look_at=triple(camera.look_at),
        up=triple(camera.up_direction),
        fov_degrees=math.degrees(float(camera.fov)),
    )


class VideoExport:
    """The video widgets (length, format, the button, progress and cancel) in the lecture
    folder; :meth:`start` films on a thread of its own."""

    def __init__(self, lecture: Filming, gui: viser.GuiApi) -> None:
        self.lecture = lecture
        self.seconds = gui.add_slider(
            "Video length [s]",
            1,
            int(BROWSER_MAX_SECONDS),
            1,
            5,
            hint="Wall seconds of the clip, at the current speed (at most 30 s).",
        )
        self.format = gui.add_dropdown(
            "Video format", tuple(FORMAT_CHOICES), initial_value=next(iter(FORMAT_CHOICES))
        )
        self.button = gui.add_button(
            "Video",
            icon=viser.Icon.MOVIE,
            hint="From the current time and camera, at the picture size (at most 1920×1080), "
            "25 frames per second; the same as `poinsot video`.",
        )
        self.progress = gui.add_progress_bar(0.0, visible=False, animated=True)
        self.cancel_button = gui.add_button("Cancel video", icon=viser.Icon.X, visible=False)
        self.cancel = threading.Event()
        self.thread: threading.Thread | None = None
        self.last_file: str = ""

    # -- what to film ----------------------------------------------------------------------
    def _camera(self) -> View | None:
        """The browser's camera now (None: riding along with the body)."""
        if self.lecture.camera == RIDE_ALONG:
            return None
        return browser_view(self.lecture.client)

    def _stage_factory(self) -> StageFactory:
        """Opens a stage of what the session shows now (read now, on the caller's thread)."""
        session, dark = self.lecture.session, self.lecture.dark_mode
        showcase = getattr(session, "showcase", None)
        if showcase is not None:
            spec, settings = showcase.spec, dict(showcase.showcase.settings)
            return lambda client_of: SceneStage(spec, settings, dark_mode=dark, client_of=client_of)
        params: Parameters = session.params
        preset = session.preset
        if preset is CUSTOM:
            solid = drawn_solid(params.inertia, CUSTOM, params.inertia)
        else:
            solid = drawn_solid(params.inertia, preset, Parameters.from_preset(preset).inertia)
        scene = session.scene
        elements = frozenset(e for e in scene.elements if scene.is_visible(e))
        trail = scene.trail_points

        def open_stage(client_of: ClientOf) -> Stage:
            return Stage(
                params, solid, elements, trail_points=trail, dark_mode=dark, client_of=client_of
            )

        return open_stage

    def plan(self) -> tuple[Clip, str, StageFactory, View | None]:
        """The clip, its suffix, its stage and its camera, as the browser shows them now;
        ValueError for a clip the browser may not ask for."""
        suffix = FORMAT_CHOICES.get(self.format.value, ".mp4")
        size = fit_within(self.lecture.picture_size(), BROWSER_MAX_SIZE, suffix == ".mp4")
        session = self.lecture.session
        t0, speed = float(session.clock.now()), float(session.clock.speed)
        clip = Clip(float(self.seconds.value), DEFAULT_FPS, size, t0=t0, speed=speed)
        check_clip(clip, suffix, browser=True)
        return clip, suffix, self._stage_factory(), self._camera()

    # -- filming ---------------------------------------------------------------------------
    def start(self) -> bool:
        """Film the clip on its own thread (False, with a message, if it cannot start)."""
        if self.thread is not None and self.thread.is_alive():
            self.lecture.show("A video is already being rendered for this browser.")
            return False
        try:
            plan = self.plan()
            chromium = find_chromium()
        except Exception as exc:  # the GUI boundary: report, never raise into viser
            self.lecture.show(f"Video failed: {type(exc).__name__}: {exc}", error=True)
            return False
        if not _FILMING.acquire(blocking=False):
            self.lecture.show("Another browser's video is being rendered: try again in a moment.")
            return False
        self.cancel.clear()
        self.thread = threading.Thread(
            target=self._film, args=(*plan, chromium), name="poinsot-video", daemon=True
        )
        self._busy(True)
        self.thread.start()
        return True

    def _set_progress(self, percent: float) -> None:
        # viser 1.1 declares the setter apart from the getter (read-only to a type checker).
        self.progress.value = percent  # type: ignore[misc]

    def _busy(self, busy: bool) -> None:
        self.button.disabled = busy
        self._set_progress(0.0)
        self.progress.visible = busy
        self.cancel_button.visible = busy

    def _film(
        self,
        clip: Clip,
        suffix: str,
        open_stage: StageFactory,
        camera: View | None,
        chromium: str,
    ) -> None:
        show = self._say
        name = filename(self.lecture.session.preset.key, clip.t0, suffix.lstrip("."))
        width, height = clip.size
        show(f"Rendering a {clip.seconds:g} s video, {width}×{height} …")
        start = time.perf_counter()
        try:
            with tempfile.TemporaryDirectory(prefix="poinsot-video-") as folder:
                out = pathlib.Path(folder) / name
                film(
                    open_stage,
                    clip,
                    camera,
                    out,
                    chromium=chromium,
                    background=THEME_BACKGROUND[self.lecture.dark_mode],
                    fit=False,
                    progress=self._progress(show, clip.frames),
                    cancel=self.cancel,
                )
                data = out.read_bytes()
            self.lecture.client.send_file_download(name, data, save_immediately=True)
            self.last_file = name
            show(
                f"Saved **{name}** ({width}×{height}, {clip.frames} frames, "
                f"{len(data) / 1e6:.1f} MB, {time.perf_counter() - start:.0f} s)."
            )
        except Cancelled:
            show("Video cancelled.")
        except Exception as exc:  # its own thread's boundary: report in the panel
            show(f"Video failed: {type(exc).__name__}: {exc}", error=True)
        finally:
            _FILMING.release()
            with contextlib.suppress(Exception):  # the browser may have left meanwhile
                self._busy(False)

    def _say(self, text: str, error: bool = False) -> None:
        """A message in the panel, if the browser is still there to read it."""
        with contextlib.suppress(Exception):
            self.lecture.show(text, error=error)

    def _progress(self, show: Callable[[str], None], total: int) -> Callable[[int, int], None]:
        """The bar and the message after the first frame (software WebGL takes seconds for
        one frame of a slide's size: the user sees at once that it has begun), then every
        twentieth of the clip, and at its end."""
        step = max(1, total // 20)

        def progress(done: int, _total: int) -> None:
            if not getattr(self.lecture.session, "running", True):
                self.cancel.set()  # the browser has left: nobody to hand the clip to
            if done == 1 or done % step == 0 or done == total:
                with contextlib.suppress(Exception):
                    self._set_progress(100.0 * done / total)
                show(f"Rendering the video: frame {done} of {total} …")

        return progress
