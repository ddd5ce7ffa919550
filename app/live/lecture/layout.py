"""The page on a phone or a tablet: the scene fills the screen, one sheet holds the rest.

A browser is laid out *compact* when its handshake names a phone or a tablet (its
``User-Agent``, read by the wire guard), or when the picture it reports is much narrower or
wider than a desktop's (:data:`NARROW_ASPECT`, :data:`WIDE_ASPECT`: a desktop window made
narrow). A desktop browser at 1280 x 800 and up is neither, and nothing of this module reaches
it: no message, no widget.

Compact, the page differs in three ways (once, for that browser only):

- **One sheet.** viser shows a narrow screen (under 36 em: a phone held upright) as one bottom
  sheet that holds the controls and, as sections, the panels; one tap on its bar closes it and
  the next opens it. viser mounts it open, and that state is the page's own (no message folds
  it; a sheet hidden by style against it would be inert to taps), so a line of the page's
  JavaScript taps its bar once (:func:`~poinsot.app.viser_private.fold_bottom_sheet`): the page
  opens on the scene and the sheet's bar. Opened, it is held low. A wider screen (a tablet, a
  phone on its side) gets viser's docked columns: the "What you see" panel is docked above the
  controls in their column, and the column is folded to a slim rail that one tap opens.
- **The legend in one tap.** The legend is mirrored at the top of the controls (shown on the
  bottom sheet only, where the "What you see" section comes last, folded), in larger text; on
  the rail, "What you see" comes first.
- **The camera frames the construction** (the turning ellipsoid, the plane's disc, L, and the
  pictures a scene draws beside it: Landau's sphere, say) for the picture's aspect ratio
  (:func:`poinsot.app.construction.cameras.framed`), from the direction of the scene's own view;
  again when the browser reports another aspect (the phone was turned), and when another preset or
  scene is shown.

Touch needs nothing here: viser's camera turns under one finger and zooms under two, and a tap
is a click (:mod:`poinsot.app.live.pointing.pointer`).

Threads: the camera callback (viser's event loop) only compares the size and posts; the
layout is the session thread's.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Hashable
from typing import Protocol

import numpy as np
import viser

from poinsot.app.construction.cameras import (
    body_and_traces,
    framed,
    framed_above,
    sphere_points,
)
from poinsot.app.construction.construction import PoinsotScene
from poinsot.app.construction.geometry import L_OVERSHOOT
from poinsot.app.construction.view import DEFAULT_VIEW, View
from poinsot.app.live.panel.motion_window import MotionWindow
from poinsot.app.live.panel.readouts import REGIME_TEXT
from poinsot.app.live.panel.showcase import LiveShowcase
from poinsot.app.model.presets import Preset
from poinsot.app.viser_private import fold_bottom_sheet

#: A phone's or a tablet's browser says so in its User-Agent.
TOUCH_AGENT = re.compile(r"Mobi|Android|iPhone|iPad|iPod|Silk|Kindle|Tablet", re.IGNORECASE)
#: A picture narrower or wider than these (width / height of the canvas reported) is laid out
#: compact whatever the browser (a desktop's is 0.6-1.4 between its two docked columns).
NARROW_ASPECT = 0.5
WIDE_ASPECT = 2.0
#: Where the mirrored legend sits in the controls: first.
MIRROR_ORDER = -100.0

#: viser's bottom sheet (under its 36 em breakpoint) is ``position: fixed; bottom: 0``, open
#: at first and up to 60 % of the screen high: here it is held to :data:`SHEET_HEIGHT` (it
#: scrolls), the mirrored legend at its top, in larger text than the docked column's.
SHEET_HEIGHT = "34%"
#: viser's sheet is 20 em wide, right-aligned (on a phone held upright, 266 of 390 px): here it
#: takes the screen's width, its contents too. Its folded bar (3.5 em, :data:`SHEET_BAR_PX`)
#: shows the panel's label, which a compact page makes t and the regime
#: (:meth:`Layout.show_header`).
SHEET = '.mantine-Paper-root[style*="bottom: 0px"]'
#: A finger's target [CSS px]: buttons, menu rows, fields, sliders, check boxes and folder
#: headers of a touch page are at least this tall (WCAG 2.5.5's 44 px).
TOUCH_TARGET_PX = 44
SHEET_CSS = f"""<style>
.poinsot-mirror {{ display: none; }}
@media (max-width: 36em) {{
  .poinsot-mirror {{ display: block; }}
  .poinsot-mirror .poinsot-legend {{ font-size: 0.95rem !important; }}
  {SHEET} {{ max-height: {SHEET_HEIGHT} !important; width: 100% !important; left: 0; }}
  {SHEET} [style*="width: 20em"] {{ width: 100% !important; }}
}}
</style>"""
#: Touch targets, on a compact page only (a desktop's mouse keeps viser's dense panel).
TOUCH_CSS = f"""<style>
.mantine-Button-root, [role="option"], .mantine-Input-input,
.mantine-Slider-root, .mantine-Checkbox-root, .mantine-ActionIcon-root {{
  min-height: {TOUCH_TARGET_PX}px !important;
}}
[role="option"] {{ display: flex; align-items: center; }}
.mantine-Slider-root, .mantine-Checkbox-root {{ display: flex; align-items: center; }}
.mantine-Checkbox-body {{ align-items: center; }}
.mantine-ActionIcon-root {{ min-width: {TOUCH_TARGET_PX}px !important; }}
</style>"""
#: The bottom sheet's bar, folded [CSS px]: 3.5 em of 16 px.
SHEET_BAR_PX = 56.0
#: A page narrower than this [CSS px] shows the bottom sheet (viser's 36 em breakpoint).
SHEET_BREAKPOINT_PX = 36 * 16
#: The sheet's header is rewritten at most this often [Hz] (t in tenths).
HEADER_HZ = 5.0


def touch_agent(user_agent: str) -> bool:
    """Does this User-Agent name a phone or a tablet?"""
    return bool(TOUCH_AGENT.search(user_agent))


def compact_aspect(width: float, height: float) -> bool:
    """Is a picture this wide and high (any unit) laid out compact whatever the browser?"""
    if width <= 0 or height <= 0:
        return False
    return not NARROW_ASPECT <= width / height <= WIDE_ASPECT


def mirrored(legend_html: str) -> str:
    """The legend as the sheet shows it, with the sheet's style and the touch targets'."""
    return f'{SHEET_CSS}{TOUCH_CSS}<div class="poinsot-mirror">{legend_html}</div>'


def header_text(t: float, regime: str) -> str:
    """The sheet's header (the panel's label on a compact page): t, and the regime if the
    readouts show it (a challenge hides it until answered)."""
    time = f"t = {t:.1f}"
    return f"{time} · {regime}" if regime else time


class LayoutSession(Protocol):
    """What the layout uses of a session."""

    client: viser.ClientHandle
    scene: PoinsotScene

    @property
    def showcase(self) -> LiveShowcase | None: ...
    @property
    def preset(self) -> Preset: ...

    def post(self, action: Callable[[], None], key: Hashable | None = None) -> None: ...


class Layout:
    """The layout of one browser (see the module's docstring)."""

    def __init__(self, session: LayoutSession, motion: MotionWindow, user_agent: str = "") -> None:
        """``motion``: the session's "What you see" panel; ``user_agent``: its browser's."""
        self.session = session
        self.motion = motion
        self.touch = touch_agent(user_agent)
        self.compact = False
        self.size: tuple[int, int] | None = None  # the canvas last reported [px]
        self.mirror: viser.GuiHtmlHandle | None = None
        self.framings = 0  # camera framings sent (tests)
        #: The canvas size [px] and the camera of the last framing (sent to the browser);
        #: ``client.camera`` mirrors what the browser reports, which can lag a framing.
        self.framed: tuple[tuple[int, int], View] | None = None
        self.header = ""  # the sheet's header last sent
        self._header_at = -1.0  # monotonic time it was
        session.client.camera.on_update(self._on_camera)
        session.post(self._first)

    def _first(self) -> None:
        """A touch browser is folded at once; the size the browser reported before the
        callback was there (if it has) is taken as if it had just come."""
        if self.touch:
            self.fold()
        try:
            camera = self.session.client.camera
            size = (int(camera.image_width), int(camera.image_height))
        except AssertionError:  # not yet: the callback will have it
            return
        if self.size is None:
            self.size = size
            self.update()

    async def _on_camera(self, camera: viser.CameraHandle) -> None:
        try:
            size = (int(camera.image_width), int(camera.image_height))
        except AssertionError:  # no size reported yet
            return
        if size != self.size:
            self.size = size
            self.session.post(self.update, "layout")

    # -- the session's thread ------------------------------------------------------------------
    def update(self) -> None:
        """The browser reported a new size: fold the page if it is compact now, and frame the
        construction for the new aspect."""
        if self.size is None:
            return
        width, height = self.size
        if not self.compact and (self.touch or compact_aspect(width, height)):
            self.fold()
        if self.compact and width > 0 and height > 0:
            self.frame(width / height)

    def fold(self) -> None:
        """Lay the page out compact (once)."""
        if self.compact:
            return
        self.compact = True
        gui = self.session.client.gui
        motion = self.motion
        self.mirror = gui.add_html("", order=MIRROR_ORDER)
        motion.legend.mirror(self.mirror, mirrored)
        motion.window.dock_above(gui.main_panel)
        gui.main_panel.minimize()
        fold_bottom_sheet(self.session.client)

    def reframe(self) -> None:
        """Another preset or scene is shown (its own view just applied): compact, it is framed
        for the picture's aspect too."""
        if self.compact and self.size is not None and min(self.size) > 0:
            self.frame(self.size[0] / self.size[1])

    def frame(self, aspect: float) -> None:
        """Frame the body and its traces for a picture ``aspect`` wide, from the direction of
        the scene's view, with the pictures a scene draws beside it; on a page with a bottom
        sheet, in the part of the screen above its folded bar."""
        geometry = self.session.scene.geometry
        h = 1.0 if geometry is None else geometry.plane_height
        ring = 0.0 if geometry is None else geometry.herpolhode_radius
        points = [body_and_traces(h, ring, h + L_OVERSHOOT)]
        showcase = self.session.showcase
        view = DEFAULT_VIEW if showcase is None else showcase.spec.view
        if showcase is not None:
            points += [sphere_points(centre, radius) for centre, radius in showcase.spec.beside]
        width, height = self.size if self.size is not None else (0, 0)
        every = np.concatenate(points)
        if 0 < width < SHEET_BREAKPOINT_PX and height > 4 * SHEET_BAR_PX:
            chosen = framed_above(view, width, height, SHEET_BAR_PX, every)
        else:
            chosen = framed(view, aspect, every)
        chosen.apply(self.session.client.camera)
        self.framed = ((width, height), chosen)
        self.framings += 1

    def show_header(self, now: float, t: float) -> None:
        """(After a frame) a compact page's panel label, the sheet's header: t and the regime
        (:func:`header_text`), at most :data:`HEADER_HZ` times a second, when it changed."""
        if not self.compact or now - self._header_at < 1.0 / HEADER_HZ:
            return
        self._header_at = now
        body = self.session.scene.body
        readouts = self.motion.readouts
        withheld = self.session.preset.withheld  # a challenge's: the regime tells the answer
        shown = body is not None and readouts.visible and bool(readouts.content) and not withheld
        regime = REGIME_TEXT.get(body.regime, "") if shown and body is not None else ""
        text = header_text(t, regime)
        if text != self.header:
            self.header = text
            self.session.client.gui.set_panel_label(text)
