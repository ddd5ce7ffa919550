"""How one session's picture looks: the theme, the projector mode, the second (body-frame)
view, and the labels' layout for the browser's camera.

- Theme: dark or light (:func:`poinsot.app.construction.view.configure_theme`), and the
  scene's colours for it (:func:`poinsot.app.construction.palette.look`), which the legend
  follows.
- Large text: the page's root font size scaled (every panel size is in rem), both docked
  columns widened in proportion (so that no line of the panels is cut and the sliders keep their
  tracks), and the scene's labels scaled alike.
- Projector mode, one switch: larger text still, thick curves and lines, the high-contrast
  colours, the control panel minimized to a slim strip and the left column kept as a compact
  legend and t (its caption, readouts and plot hidden) so that the 3D view takes the screen.
- Two views: the body frame's picture beside the space frame's
  (:class:`~poinsot.app.construction.body_view.BodyView`), the camera stepped back to frame both and
  the left column folded (its strip opens it again) for a wide picture.
- Labels: a few times a second the scene's labels are laid out for the camera the browser
  reports (:meth:`~poinsot.app.construction.construction.PoinsotScene.label_steps`), one step of the
  layout every other frame, on frames that send no traces: no frame carries a whole layout,
  and the plot (which waits for a frame that carries neither) finds one between two steps.

Frame thread only, except :meth:`Display.request`, which records a wish for the frame thread.
"""

from __future__ import annotations

import dataclasses
import math
import threading

import numpy as np
import viser

from poinsot.app.construction import palette
from poinsot.app.construction.body_view import OFFSET, TITLE_HEIGHT, BodyView
from poinsot.app.construction.cameras import body_and_traces, framed, sphere_points
from poinsot.app.construction.construction import PoinsotScene
from poinsot.app.construction.geometry import L_OVERSHOOT, Geometry
from poinsot.app.construction.labels.layout import Camera, Steps, finish
from poinsot.app.construction.sampled.batch import Frame
from poinsot.app.construction.sampled.frames import wxyz
from poinsot.app.construction.view import DEFAULT_VIEW, View, configure_theme
from poinsot.app.live.panel.motion_window import WINDOW_WIDTH, MotionWindow

#: Root font size of the large-text mode: every panel size is in rem, so all text scales.
LARGE_TEXT_PERCENT = 130
#: ... and of the projector mode.
PROJECTOR_TEXT_PERCENT = 150
#: Width of viser's docked control panel at the normal text size [CSS px]: 20 em of 16 px
#: (its theme's "medium" control width), which large text widens in proportion.
MAIN_WIDTH = 320
#: ... widened this much faster than the text grows.
MAIN_GROWTH = 1.2
#: Width of the projector's compact left column (legend and t) [CSS px at the normal size].
PROJECTOR_LEGEND_WIDTH = 290
#: Labels are laid out this often [Hz] while the browser's camera moves (the user turns the
#: view: the boxes follow it), at most every LABEL_MIN_FRAMES frames; under a still camera,
#: when only the time runs, LABEL_STILL_HZ and every LABEL_STILL_FRAMES frames at most (the boxes
#: ride on their frames in between: only their anchors wait for the next layout); never for
#: the same camera and time. A layout costs 1-2 ms, taken in five steps, one every other frame
#: (one layout at a time: the next begins once the last has ended), so a client whose frame
#: rate is lowered (a busy server, a slow browser) gets fewer layouts too.
LABEL_HZ = 6.0
LABEL_MIN_FRAMES = 5
LABEL_STILL_HZ = 2.0
LABEL_STILL_FRAMES = 30
#: The two-view camera: from the front (x runs across the screen, the body frame's picture on
#: the right), this high above the plane [degrees] and this far from the middle between the
#: pictures [display units].
TWO_VIEW_ELEVATION = 28.0
TWO_VIEW_DISTANCE = 6.6


@dataclasses.dataclass(frozen=True)
class Style:
    """What the lecturer chose: theme, text size, projector mode, two views."""

    dark: bool = True
    large_text: bool = False
    projector: bool = False
    two_views: bool = False


def two_view_camera(geometry: Geometry | None = None, aspect: float | None = None) -> View:
    """From the front, stepped back to frame the space and the body pictures side by side;
    given the body's ``geometry`` and the picture's ``aspect``, moved along that direction to
    frame both pictures of that body (each body and its traces, L, the titles) and no more."""
    target = np.array([0.5 * OFFSET[0], 0.0, 0.1])
    elevation = math.radians(TWO_VIEW_ELEVATION)
    step = TWO_VIEW_DISTANCE * np.array([0.0, -math.cos(elevation), math.sin(elevation)])
    x, y, z = (float(v) for v in target + step)
    tx, ty, tz = (float(v) for v in target)
    view = View(position=(x, y, z), look_at=(tx, ty, tz))
    if geometry is None or aspect is None:
        return view
    top = geometry.plane_height + L_OVERSHOOT
    space = body_and_traces(geometry.plane_height, geometry.herpolhode_radius, top)
    body = sphere_points(OFFSET, max(1.0, top))  # L turns in the body frame
    titles = np.array([[0.0, 0.0, TITLE_HEIGHT], np.add(OFFSET, (0.0, 0.0, TITLE_HEIGHT))])
    return framed(view, aspect, np.concatenate([space, body, titles]))


def text_percent(style: Style) -> int:
    """The page's root font size [% of the browser's]."""
    if style.projector:
        return PROJECTOR_TEXT_PERCENT
    return LARGE_TEXT_PERCENT if style.large_text else 100


def text_css(style: Style) -> str:
    """A style element that scales the page's root font size (empty at the normal size)."""
    percent = text_percent(style)
    if percent == 100:
        return ""
    return f"<style>html {{ font-size: {percent}% !important; }}</style>"


def column_widths(style: Style) -> tuple[int, int]:
    """(left column, control panel) widths [CSS px] for ``style``'s text size: both in
    proportion to the text, the projector's left column a compact legend."""
    scale = text_percent(style) / 100.0
    left = PROJECTOR_LEGEND_WIDTH if style.projector else WINDOW_WIDTH
    # The control panel's rows hold more fixed padding per text (its buttons' 40 px): a
    # little more than in proportion (at 130 %, a button's "Mesh: ... (GLB)" was 2 px short).
    main = round(MAIN_WIDTH * (1.0 + MAIN_GROWTH * (scale - 1.0)))
    if style.projector:  # opened from its strip beside the legend, at 1280 px the picture
        # between them stays wider than half its height (else the page is laid out compact)
        main = min(main, column_widths(Style(large_text=True))[1])
    return round(left * scale), main


def scene_look(style: Style) -> palette.Look:
    """The scene's colours and label size for ``style``: the labels grow with large text."""
    look = palette.look(style.dark, style.projector)
    if style.large_text and not style.projector:
        look = dataclasses.replace(look, label_scale=look.label_scale * LARGE_TEXT_PERCENT / 100)
    return look


def browser_camera(client: viser.ClientHandle) -> Camera | None:
    """The camera the browser reports, or None before it has reported its view's size."""
    camera = client.camera
    try:
        width, height = float(camera.image_width), float(camera.image_height)
    except AssertionError:
        return None
    if width <= 0 or height <= 0:
        return None
    return Camera(
        np.asarray(camera.position, float),
        np.asarray(camera.look_at, float),
        np.asarray(camera.up_direction, float),
        float(camera.fov),
        width,
        height,
    )


def _camera_key(camera: Camera) -> tuple[float, ...]:
    """What a layout depends on of the camera: its pose, its field of view and the view's size
    (a phone's or a tablet's view changes its height alone as its sheet folds or opens)."""
    return (
        *camera.position,
        *camera.look_at,
        *camera.up,
        camera.fov,
        camera.width,
        camera.height,
    )


class Display:
    """The look of one session's picture (see the module's docstring)."""

    def __init__(
        self,
        client: viser.ClientHandle,
        scene: PoinsotScene,
        motion: MotionWindow,
        style_html: viser.GuiHtmlHandle,
    ):
        """``scene``: the session's construction, which the display restyles and lays out."""
        self.client, self.scene = client, scene
        self.motion = motion
        self.style_html = style_html
        self.style = Style()
        self._wanted = Style()
        self._lock = threading.Lock()
        self.body_view: BodyView | None = None
        self._last_layout = -math.inf  # monotonic time of the last layout
        self._frames_since_layout = LABEL_STILL_FRAMES
        self._laid_out: tuple = (None,)  # (*camera, time) of the last layout
        self._steps: Steps[dict] | None = None  # the layout under way
        self.laid_out_now = False  # this frame took a step of a layout

    # -- wishes (any thread) ---------------------------------------------------------------
    def request(self, **changes: bool) -> None:
        """Ask for a change of style (any thread); the frame thread applies it."""
        with self._lock:
            self._wanted = dataclasses.replace(self._wanted, **changes)

    @property
    def wanted(self) -> Style:
        with self._lock:
            return self._wanted

    # -- frame thread ----------------------------------------------------------------------
    def on_frame(self, frame: Frame | None, now: float) -> None:
        """Apply a wished style, carry the body-frame picture, lay out the labels."""
        wanted = self.wanted
        if wanted != self.style:
            self.apply(wanted)
        elif wanted.projector:  # a plot added since (another preset) is hidden too
            self._compact_legend(True)
        view = self.body_view
        scene = self.scene
        if view is not None and frame is not None and scene.geometry is not None:
            if view.geometry is not scene.geometry:
                view.fit(scene.geometry, self._attitude0(frame))
            view.advance(frame)
        self._frames_since_layout += 1
        stepped, self.laid_out_now = self.laid_out_now, False
        if self.scene.sent_traces:
            return  # this frame is heavier than most already: the labels wait for the next
        if self._steps is not None:
            if not stepped:  # every other frame: the plot finds one free between two steps
                self._step()
            return
        if now < self._last_layout + 1.0 / LABEL_HZ or self._frames_since_layout < LABEL_MIN_FRAMES:
            return
        camera = browser_camera(self.client)
        if camera is None:
            return
        if _camera_key(camera) == self._laid_out[:-1] and (
            now < self._last_layout + 1.0 / LABEL_STILL_HZ
            or self._frames_since_layout < LABEL_STILL_FRAMES
        ):
            return  # a still camera: the next layout for the time alone comes later
        self._steps = self._begin_layout(None if frame is None else frame.t, camera)
        if self._steps is not None:
            self._last_layout = now
            self._frames_since_layout = 0
            self._step()

    def _step(self) -> None:
        """One step of the layout under way (:attr:`laid_out_now`: a step was taken)."""
        assert self._steps is not None
        self.laid_out_now = True
        try:
            next(self._steps)
        except StopIteration:
            self._steps = None

    def _begin_layout(self, t: float | None, camera: Camera) -> Steps[dict] | None:
        """The steps of a layout for ``camera``; None for a camera with no finite position,
        or the same camera and time ``t``, when given, as the last layout (a paused, unmoved
        picture)."""
        if not all(math.isfinite(v) for v in camera.position):
            return None
        key = (*_camera_key(camera), t)
        if t is not None and key == self._laid_out:
            return None
        self._laid_out = key
        return self.scene.label_steps(camera)

    def lay_out_labels(self, t: float | None = None, camera: Camera | None = None) -> dict:
        """Lay the labels out at once for the browser's camera (or ``camera``), not again for
        the same camera and time ``t``, when given; a layout under way is dropped."""
        camera = browser_camera(self.client) if camera is None else camera
        steps = None if camera is None else self._begin_layout(t, camera)
        if steps is None:
            return {}
        self._steps = None
        return finish(steps)

    def _attitude0(self, frame: Frame) -> np.ndarray:
        """The attitude at t = 0 (the body-frame picture is the body as it was then)."""
        body = self.scene.body
        return np.asarray(frame.wxyz) if body is None else wxyz(body.attitude(0.0))

    def apply(self, style: Style) -> None:
        """Show ``style``: theme, text size, the scene's look, the columns, the second view."""
        old, self.style = self.style, style
        gui = self.client.gui
        configure_theme(
            gui, dark_mode=style.dark, large_controls=style.large_text or style.projector
        )
        for html in (self.style_html, self.motion.style):  # whichever column is open
            html.content = text_css(style)
        look = scene_look(style)
        self.scene.restyle(look)
        self.motion.legend.restyle(look)
        if self.body_view is not None:
            self.body_view.restyle(look)
        if column_widths(style) != column_widths(old):
            left, main = column_widths(style)
            self.motion.window.set_width(left)
            gui.main_panel.set_width(main)
        self._compact_legend(style.projector)
        # Projector: the control panel folded; two views: the left column, for a wide picture.
        if style.projector != old.projector or style.two_views != old.two_views:
            folded = {"main": style.projector, "left": style.two_views}
            for key, panel in (("main", gui.main_panel), ("left", self.motion.window)):
                if folded[key]:
                    panel.minimize()
                else:
                    panel.expand()
        if style.two_views != old.two_views:
            self._two_views(style.two_views, look)

    def _compact_legend(self, on: bool) -> None:
        """The projector's left column: the legend and t only (the caption, the readouts and
        the plot hidden), or all of it again."""
        motion = self.motion
        for handle in (motion.legend.caption, motion.readouts, motion.plot):
            if handle is not None and handle.visible == on:
                handle.visible = not on
        motion.choice.show(not on and motion.plot is not None)

    def _two_views(self, on: bool, look: palette.Look) -> None:
        if on and self.body_view is None:
            self.body_view = BodyView(self.client.scene, look)
        elif not on and self.body_view is not None:
            self.body_view.remove()
            self.body_view = None
        view = DEFAULT_VIEW
        if on:  # the left column folds: the picture gains its width (less the strip)
            camera = browser_camera(self.client)
            aspect = None
            if camera is not None:
                aspect = (camera.width + column_widths(self.style)[0] - 40.0) / camera.height
            view = two_view_camera(self.scene.geometry, aspect)
        with self.client.atomic():
            view.apply(self.client.camera)
