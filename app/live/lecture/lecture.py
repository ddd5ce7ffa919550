"""Lecture comfort and exports in one session's panel: screenshot, CSV and GLB downloads, camera
views (default, along-L, side, ride-along: the same names as ``poinsot screenshot --view``),
dark/light theme, large text, the projector mode, the two views (space and body frame) and
keyboard shortcuts. How the picture looks is :mod:`poinsot.app.live.lecture.display`'s.

A session mounts everything with one call, :func:`add_lecture_controls`, and calls
:meth:`LectureControls.on_frame` after drawing each frame (the ride-along camera follows the
attitude there).

Keyboard shortcuts use viser 1.1's command palette (``GuiApi.add_command(hotkey=...)``): the
browser fires them while the page has focus and no text field is being edited. Space
plays/pauses, 1-4 choose the camera views, P switches the projector mode, V the two views.
The commands are also listed in the palette (Ctrl/Cmd+K).

Threads: button callbacks run on viser's thread pool. A screenshot waits there for the
browser's render, bounded by ``render_timeout``; one render at a time per session, and every
failure ends in a message in the panel, never in a hang. A video
(:mod:`poinsot.app.live.lecture.video_export`) is filmed on a thread of its own. The data come from
the session's body and clock (physics), never from the drawing.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import Literal, Protocol

import viser

from poinsot.app.construction.cameras import (
    BODY_VIEW,
    CAMERA_NAMES,
    RIDE_ALONG,
    body_and_traces,
    framed,
    ride_along,
    space_view,
)
from poinsot.app.construction.construction import PoinsotScene
from poinsot.app.construction.geometry import L_OVERSHOOT
from poinsot.app.construction.sampled.batch import Frame
from poinsot.app.construction.view import View
from poinsot.app.exports.glb import scene_glb
from poinsot.app.exports.run_csv import run_csv, run_span
from poinsot.app.exports.screenshot import SIZE_CHOICES, THEME_BACKGROUND, filename, png_bytes
from poinsot.app.live.classroom.links import link_of
from poinsot.app.live.lecture.challenges import ChallengeControls, ChallengeSession, add_challenges
from poinsot.app.live.lecture.display import LARGE_TEXT_PERCENT, Display, browser_camera
from poinsot.app.live.lecture.neighbour import Neighbour, add_neighbour
from poinsot.app.live.lecture.strobe_shot import strobe_render
from poinsot.app.live.lecture.video_export import VideoExport, browser_view
from poinsot.app.live.panel.clock import SimClock
from poinsot.app.live.panel.motion_window import MotionWindow
from poinsot.app.live.panel.widgets import Pressed, Sent, on_user, set_value
from poinsot.app.model.parameters import Parameters
from poinsot.app.model.presets import Preset
from poinsot.app.viser_private import copy_to_clipboard
from poinsot.physics import FreeRigidBody

#: Seconds a screenshot waits for the browser's render. A GPU browser answers a 4K render in
#: about a second; software WebGL on a loaded machine has been measured at up to 30 s.
RENDER_TIMEOUT = 60.0
__all__ = ["LARGE_TEXT_PERCENT", "LectureControls", "add_lecture_controls"]

#: The picture size a screenshot has unless another is chosen: a slide's, whatever the window.
DEFAULT_PICTURE_SIZE = "1920×1080"
#: Order of the lecture folder in the panel (after the session's own groups).
FOLDER_ORDER = 70.0
#: The views framed for the browser's 3D view and the body shown (:meth:`LectureControls.view`).
FRAMED_VIEWS = ("along-L", "side")
#: Hotkeys of the camera views, in CAMERA_NAMES order.
CAMERA_HOTKEYS: tuple[Literal["1", "2", "3", "4"], ...] = ("1", "2", "3", "4")


class LectureSession(ChallengeSession, Protocol):
    """What the lecture controls use of a session's front (and the challenges, the neighbour
    and the link they mount): its client, clock and construction, what it shows, and its
    queue."""

    client: viser.ClientHandle
    clock: SimClock
    scene: PoinsotScene

    @property
    def preset(self) -> Preset: ...
    @property
    def body(self) -> FreeRigidBody | None: ...
    @property
    def frame(self) -> Frame | None: ...
    @property
    def showcase(self) -> object | None: ...
    @property
    def params(self) -> Parameters: ...
    @property
    def camera(self) -> str: ...

    def toggle_pause(self) -> None: ...
    def post(self, action: Callable[[], None], key: object = None) -> None: ...


class LectureControls:
    def __init__(
        self,
        session: LectureSession,
        motion: MotionWindow,
        *,
        render_timeout: float = RENDER_TIMEOUT,
        order: float = FOLDER_ORDER,
    ) -> None:
        self.session = session
        self.challenges: ChallengeControls | None = None  # mounted by add_lecture_controls
        self.neighbour: Neighbour | None = None  # likewise
        self.client = session.client
        self.render_timeout = float(render_timeout)
        self.camera = "default"
        # A view chosen in the browser (viser's thread) and the frame thread's ride-along step
        # each check the view and send the camera under this lock, so that a ride-along camera
        # computed before a new view was chosen is never sent after it.
        self._camera_lock = threading.Lock()
        self._render_lock = threading.Lock()
        self.last_download: str = ""  # name of the last file handed to the browser
        #: The page's address as its browser sees it (set by :func:`.links.apply`), and the
        #: last link given by "Copy link".
        self.page = self.last_link = ""
        with self.client.gui.add_folder("Lecture: views and export", order=order):
            self._add_widgets(self.client.gui)
        self._pressed = Pressed()  # the camera's button shown pressed
        self._pressed.show(self.views, self.camera)
        self.display = Display(session.client, session.scene, motion, self.style)
        # Browser changes only, each value checked against its widget first (:func:`on_user`).
        for handle, callback in (
            (self.views, self._on_view),
            (self.screenshot, lambda _: self._discard(self.take_screenshot())),
            (self.csv, lambda _: self._discard(self.download_csv())),
            (self.glb, lambda _: self._discard(self.download_glb())),
            (
                self.link,
                lambda _: self.session.post(lambda: self._discard(self.copy_link()), "link"),
            ),
            (self.video.button, lambda _: self._discard(self.video.start())),
            (self.video.cancel_button, lambda _: self.video.cancel.set()),
            (self.dark, lambda sent: self.set_theme(dark=bool(sent.value))),
            (self.large, lambda sent: self.set_theme(large=bool(sent.value))),
            (self.projector, lambda sent: self.display.request(projector=bool(sent.value))),
            (self.two_views, lambda sent: self.display.request(two_views=bool(sent.value))),
        ):
            on_user(handle, callback, self._report)
        self.commands = self._add_hotkeys(self.client.gui)

    def _add_widgets(self, gui: viser.GuiApi) -> None:
        self.views = gui.add_button_group(
            "Camera",
            list(CAMERA_NAMES),
            hint="The default view, along L (from above), from the side, or riding on the body. "
            "Keys 1-4; the same names as `poinsot screenshot --view`.",
        )
        self.size = gui.add_dropdown(
            "Picture size",
            tuple(SIZE_CHOICES),
            initial_value=DEFAULT_PICTURE_SIZE,
            hint="Pixels of the PNG (a slide's unless chosen); 'current view': the 3D view's.",
        )
        self.transparent = gui.add_checkbox(
            "Transparent PNG", False, hint="Leave the background transparent (for slides)."
        )
        self.strobe = gui.add_checkbox(
            "Strobe: 8 copies",
            False,
            hint="The screenshot adds 8 copies of the body over the flip (or period) that ends "
            "now, the earliest faintest; the same as `poinsot screenshot --strobe 8`.",
        )
        self.screenshot = gui.add_button("Screenshot (PNG)", icon=viser.Icon.CAMERA)
        self.csv = gui.add_button(
            "Data: t, ω, q (CSV)",
            icon=viser.Icon.TABLE_EXPORT,
            hint="The run so far (one period if it has just started), exact solution.",
        )
        self.glb = gui.add_button(
            "Mesh: ellipsoid, plane, curves (GLB)",
            icon=viser.Icon.CUBE,
            hint="For Blender or any glTF viewer.",
        )
        self.link = gui.add_button(
            "Copy link",
            icon=viser.Icon.LINK,
            hint="A link that opens exactly this: the scene or body, the time, the view, the "
            "speed, paused or playing.",
        )
        self.video = VideoExport(self, gui)
        self.dark = gui.add_checkbox("Dark theme", True)
        self.large = gui.add_checkbox("Large text", False, hint="Scales every text of the panel.")
        self.projector = gui.add_checkbox(
            "Projector mode",
            False,
            hint="Large text, thick lines, high-contrast colours, the panels folded to slim "
            "strips (click a strip to open it). Key P.",
        )
        self.two_views = gui.add_checkbox(
            "Two views: space | body",
            False,
            hint="Beside the construction (space frame: the herpolhode stays on the plane), the "
            "body frame (the polhode stays on the ellipsoid, ω's tip runs along it). Key V.",
        )
        self.message = gui.add_markdown("")
        gui.add_markdown(
            "<small>Keys: **space** play/pause · **1-4** camera views · **P** projector · "
            "**V** two views</small>"
        )
        self.style = gui.add_html("")

    def _add_hotkeys(self, gui: viser.GuiApi) -> list[viser.CommandHandle]:
        """Space plays/pauses; 1-4 choose the camera views; P and V switch the projector mode
        and the two views (also in the command palette)."""
        play = gui.add_command("Play / pause", hotkey="space", icon=viser.Icon.PLAYER_PLAY)
        play.on_trigger(lambda _: self.session.toggle_pause())
        commands = [play]
        for key, name in zip(CAMERA_HOTKEYS, CAMERA_NAMES, strict=True):
            command = gui.add_command(f"Camera: {name}", hotkey=key, icon=viser.Icon.CAMERA)
            command.on_trigger(self._camera_callback(name))
            commands.append(command)
        projector = gui.add_command("Projector mode", hotkey="P", icon=viser.Icon.DEVICE_TV)
        projector.on_trigger(self._toggle_callback(self.projector))
        two = gui.add_command("Two views", hotkey="V", icon=viser.Icon.LAYOUT_COLUMNS)
        two.on_trigger(self._toggle_callback(self.two_views))
        return [*commands, projector, two]

    def _toggle_callback(self, box: viser.GuiCheckboxHandle) -> Callable[[object], None]:
        """Flip ``box`` and ask the display (the box's own callback asks too: no harm)."""

        def toggle(_: object) -> None:
            on = not box.value
            set_value(box, on)
            if box is self.projector:
                self.display.request(projector=on)
            else:
                self.display.request(two_views=on)

        return toggle

    def _camera_callback(self, name: str) -> Callable[[object], None]:
        return lambda _: self.set_camera(name)

    @staticmethod
    def _discard(_: object) -> None:
        """A button callback returns nothing (the actions' results are for tests)."""

    # -- messages ------------------------------------------------------------------------
    def show(self, text: str, error: bool = False) -> None:
        self.message.content = f"**⚠ {text}**" if error else text

    def copy_link(self) -> str:
        """(The session's frame thread) the link of what is on screen, shown under the tools
        and put on the browser's clipboard."""
        link = link_of(self.session, self.page)
        self.last_link = link
        copy_to_clipboard(self.client, link)
        self.show(f"Link to this state (copied to the clipboard):\n\n`{link}`")
        return link

    # -- camera --------------------------------------------------------------------------
    def _on_view(self, sent: Sent) -> None:
        if sent.value in CAMERA_NAMES:
            self.set_camera(sent.value)

    def _report(self, exc: Exception) -> None:
        """A callback's failure, shown under the lecture tools (never raised into viser)."""
        self.show(f"Failed: {type(exc).__name__}: {exc}", error=True)

    def set_camera(self, name: str) -> None:
        """Move this browser's camera to a view; "ride-along" rides along from now on."""
        if name not in CAMERA_NAMES:
            raise ValueError(f"no camera view {name!r}")
        with self._camera_lock:
            self.camera = name
            self._pressed.show(self.views, name)
            if name == RIDE_ALONG:
                frame = self.session.frame
                if frame is not None:
                    self._apply(ride_along(BODY_VIEW, frame.wxyz))
                return
            self._apply(self.view(name))

    def view(self, name: str) -> View:
        """The space-frame view ``name`` as this browser gets it: the side and along-L views
        moved along their direction to frame the body and its traces in the browser's 3D view
        (the default view is already framed so on a desktop's)."""
        view = space_view(name)
        geometry = self.session.scene.geometry
        camera = browser_camera(self.client)
        if name not in FRAMED_VIEWS or geometry is None or camera is None:
            return view
        h = geometry.plane_height
        points = body_and_traces(h, geometry.herpolhode_radius, h + L_OVERSHOOT)
        return framed(view, camera.width / camera.height, points)

    def _apply(self, view: View) -> None:
        with self.client.atomic():
            view.apply(self.client.camera)

    def on_frame(self, frame: Frame) -> None:
        """Per frame (the session's frame thread): carry the ride-along camera, and the
        display's work (a style asked for, the body-frame view, the labels' layout)."""
        with self._camera_lock:
            if self.camera == RIDE_ALONG:
                self._apply(ride_along(BODY_VIEW, frame.wxyz))
        self.display.on_frame(frame, time.monotonic())
        if self.neighbour is not None:
            self.neighbour.on_frame(frame)

    # -- theme ---------------------------------------------------------------------------
    @property
    def dark_mode(self) -> bool:
        return self.display.wanted.dark

    def set_theme(self, dark: bool | None = None, large: bool | None = None) -> None:
        """Ask for the dark or light theme, or large text (applied by the next frame)."""
        if dark is not None:
            self.display.request(dark=dark)
        if large is not None:
            self.display.request(large_text=large)

    # -- exports -------------------------------------------------------------------------
    def _now(self) -> tuple[FreeRigidBody, float, str]:
        body = self.session.scene.body or self.session.body
        if body is None:
            raise RuntimeError("no body is loaded yet")
        return body, float(self.session.clock.now()), self.session.preset.key

    def picture_size(self) -> tuple[int, int]:
        """(width, height) chosen in the dropdown; the 3D view's size for 'current view'."""
        size = SIZE_CHOICES.get(self.size.value)
        if size is not None:
            return size
        camera = self.client.camera
        try:
            width, height = int(camera.image_width), int(camera.image_height)
        except AssertionError:  # the browser has not reported its view yet
            width = height = 0
        if width <= 0 or height <= 0:
            raise RuntimeError("the browser has not reported the size of its view yet")
        return width, height

    def take_screenshot(self) -> str | None:
        """Render the current view at the chosen size and hand the PNG to the browser. Returns
        the file name, or None (with a message in the panel) on failure."""
        if not self._render_lock.acquire(blocking=False):
            self.show("A screenshot is already being rendered.")
            return None
        self.screenshot.disabled = True
        try:
            width, height = self.picture_size()
            _, t, key = self._now()
            self.show(f"Rendering {width}×{height} …")
            start = time.perf_counter()
            if self.strobe.value:
                rgba = strobe_render(
                    self.client,
                    self.session.scene,
                    t,
                    browser_view(self.client),
                    (width, height),
                    dark_mode=self.dark_mode,
                    timeout=self.render_timeout,
                )
            else:
                rgba = self.client.get_render(
                    height, width, transport_format="png", timeout=self.render_timeout
                )
            background = None if self.transparent.value else THEME_BACKGROUND[self.dark_mode]
            name = filename(key, t)
            self.client.send_file_download(name, png_bytes(rgba, background), save_immediately=True)
            self.last_download = name
            self.show(f"Saved **{name}** ({width}×{height}, {time.perf_counter() - start:.1f} s).")
            return name
        except TimeoutError:
            self.show(
                f"Screenshot failed: the browser did not return the picture within "
                f"{self.render_timeout:g} s. Try a smaller size.",
                error=True,
            )
        except Exception as exc:  # the GUI boundary: report, never raise into viser
            self.show(f"Screenshot failed: {type(exc).__name__}: {exc}", error=True)
        finally:
            self.screenshot.disabled = False
            self._render_lock.release()
        return None

    def download_csv(self) -> str | None:
        return self._download(
            "csv",
            lambda body, t, key: run_csv(
                body, run_span(body, t), name=key, source=self.session.preset.source
            ).encode("utf-8"),
        )

    def download_glb(self) -> str | None:
        return self._download(
            "glb",
            lambda body, t, key: scene_glb(body, t, geometry=self.session.scene.geometry),
        )

    def _download(
        self, suffix: str, make: Callable[[FreeRigidBody, float, str], bytes]
    ) -> str | None:
        try:
            body, t, key = self._now()
            data = make(body, t, key)
            name = filename(key, t, suffix)
            self.client.send_file_download(name, data, save_immediately=True)
            self.last_download = name
            self.show(f"Saved **{name}** ({len(data) / 1e3:.0f} kB).")
            return name
        except Exception as exc:  # the GUI boundary: report, never raise into viser
            self.show(f"{suffix.upper()} export failed: {type(exc).__name__}: {exc}", error=True)
            return None


def add_lecture_controls(
    session: LectureSession, motion: MotionWindow, **kwargs: float
) -> LectureControls:
    """Mount the lecture folder and hotkeys on the panel of the session whose front is
    ``session`` (``motion``: its "Motion" window, which the display restyles), the challenges
    (:mod:`~poinsot.app.live.lecture.challenges`, as ``.challenges``) and the neighbour
    (:mod:`~poinsot.app.live.lecture.neighbour`, as ``.neighbour``); keep the returned object and
    call its ``on_frame(frame)`` after each frame."""
    controls = LectureControls(session, motion, **kwargs)
    controls.challenges = add_challenges(session)
    controls.neighbour = add_neighbour(session, motion.legend.show_rows)
    return controls
