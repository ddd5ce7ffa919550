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

from poinsot.app.construction.cameras import construction_points, framed, sphere_points
from poinsot.app.construction.construction import PoinsotScene
from poinsot.app.construction.geometry import L_OVERSHOOT, PLANE_RADIUS
from poinsot.app.construction.view import DEFAULT_VIEW
from poinsot.app.live.panel.motion_window import MotionWindow
from poinsot.app.live.panel.showcase import LiveShowcase
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
SHEET_CSS = f"""<style>
.poinsot-mirror {{ display: none; }}
@media (max-width: 36em) {{
  .poinsot-mirror {{ display: block; }}
  .poinsot-mirror .poinsot-legend {{ font-size: 0.95rem !important; }}
  .mantine-Paper-root[style*="bottom: 0px"] {{ max-height: {SHEET_HEIGHT} !important; }}
}}
</style>"""


def touch_agent(user_agent: str) -> bool:
    """Does this User-Agent name a phone or a tablet?"""
    return bool(TOUCH_AGENT.search(user_agent))


def compact_aspect(width: float, height: float) -> bool:
    """Is a picture this wide and high (any unit) laid out compact whatever the browser?"""
    if width <= 0 or height <= 0:
        return False
    return not NARROW_ASPECT <= width / height <= WIDE_ASPECT


def mirrored(legend_html: str) -> str:
    """The legend as the sheet shows it, with the sheet's style."""
    return f'{SHEET_CSS}<div class="poinsot-mirror">{legend_html}</div>'


class LayoutSession(Protocol):
    """What the layout uses of a session."""

    client: viser.ClientHandle
    scene: PoinsotScene

    @property
    def showcase(self) -> LiveShowcase | None: ...

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
        """Frame the whole construction for a picture ``aspect`` wide, from the direction of the
        scene's view, with the pictures a scene draws beside it."""
        geometry = self.session.scene.geometry
        h = 1.0 if geometry is None else geometry.plane_height
        top = h + L_OVERSHOOT  # L's tip
        points = [construction_points(h, PLANE_RADIUS, top)]
        showcase = self.session.showcase
        view = DEFAULT_VIEW if showcase is None else showcase.spec.view
        if showcase is not None:
            points += [sphere_points(centre, radius) for centre, radius in showcase.spec.beside]
        framed(view, aspect, np.concatenate(points)).apply(self.session.client.camera)
        self.framings += 1
