"""The page on a phone and a tablet, in Chromium with touch emulation: the scene fills the
screen, the legend opens in one tap, a tap on the ellipsoid sets a new start that the readouts
show, and no console error (app/live/lecture/layout.py, app/live/pointing/pointer.py)."""

from __future__ import annotations

import re

import numpy as np
import pytest
from conftest import BrowserPage, css_pixel, session_of, wait_until

from poinsot.app.live.session.session import Session
from poinsot.app.viser_private import RAIL_TITLE

IPHONE = (
    "Mozilla/5.0 (iPhone; CPU iPhone OS 17_0 like Mac OS X) AppleWebKit/605.1.15 "
    "(KHTML, like Gecko) Version/17.0 Mobile/15E148 Safari/604.1"
)
ANDROID_TABLET = (
    "Mozilla/5.0 (Linux; Android 13; SM-X700) AppleWebKit/537.36 (KHTML, like Gecko) "
    "Chrome/120.0.0.0 Safari/537.36"
)
DEVICES = {
    "phone-portrait": (390, 844, IPHONE),
    "phone-landscape": (844, 390, IPHONE),
    "tablet-portrait": (820, 1180, ANDROID_TABLET),
}
#: The scene must be the topmost element on at least this share of the screen.
SCENE_SHARE = 0.60
#: ... and on a phone held upright, its bottom sheet folded to its bar, on this share.
FOLDED_SHARE = 0.90
LEGEND_ENTRY = "herpolhode (plane)"

_SCENE_SHARE_JS = """() => {
  let hits = 0, n = 0;
  for (let i = 0; i < 24; i++) for (let j = 0; j < 24; j++) {
    const e = document.elementFromPoint((i + 0.5) * innerWidth / 24, (j + 0.5) * innerHeight / 24);
    n++;
    if (e && e.tagName === 'CANVAS') hits++;
  }
  return hits / n;
}"""

_LEGEND_SHOWN_JS = """(name) => {
  const e = document.querySelector(`[data-legend="${name}"]`);
  if (!e) return false;
  const r = e.getBoundingClientRect();
  if (r.width === 0 || r.height === 0 || r.bottom < 0 || r.top > innerHeight) return false;
  const top = document.elementFromPoint(r.left + r.width / 2, r.top + r.height / 2);
  return top !== null && (e.contains(top) || top.contains(e));
}"""


#: Every title written down a folded column's rail: [its text, whether it is cut].
_RAIL_TITLES_JS = f"""() => [...document.querySelectorAll('{RAIL_TITLE}')]
  .map((e) => [e.textContent, e.scrollHeight > e.clientHeight + 1])"""


def open_device(open_page, url: str, device: str, live_view: bool = True) -> BrowserPage:
    """A page as ``device`` shows it (``live_view``: as :func:`conftest.open_page`'s)."""
    width, height, agent = DEVICES[device]
    options = {"has_touch": True, "is_mobile": True, "user_agent": agent, "device_scale_factor": 1}
    return open_page(url, width, height, live_view=live_view, **options)


def screen_point(session: Session, page: BrowserPage, point: np.ndarray) -> tuple[float, float]:
    """Where the browser's camera draws the world ``point``, in the page's CSS pixels (once the
    page's view has settled: see :meth:`BrowserPage.settled_canvas`)."""
    return css_pixel(session.client.camera, page.settled_canvas(session.client), point)


def folded_share(device: str) -> float:
    """The share of the screen the scene is on top on once the page is folded (on a phone held
    upright, the bottom sheet down to its bar)."""
    return FOLDED_SHARE if DEVICES[device][0] < 576 else SCENE_SHARE


def sheet_toggle(page: BrowserPage, device: str, opening: bool):
    """What one tap opens or closes the sheet with: on a phone held upright, viser's bottom
    sheet's bar either way; otherwise the folded column's rail ("What you see", the first
    entry) opens it and the column's collapse control closes it."""
    if DEVICES[device][0] < 576:  # its header: t and the regime
        return page.page.get_by_text(re.compile(r"^t = \d+\.\d")).first
    if opening:
        return page.page.get_by_text("What you see", exact=True).first
    return page.page.locator('[aria-label="Collapse panel area"]').first


@pytest.mark.parametrize("device", list(DEVICES))
def test_the_page_on_a_phone_and_a_tablet(poinsot_app, open_page, device) -> None:
    page = open_device(open_page, poinsot_app.url, device)
    session = session_of(poinsot_app)
    assert wait_until(lambda: session.layout.compact and session.layout.framings >= 1, 20)
    assert wait_until(lambda: page.page.evaluate(_SCENE_SHARE_JS) >= SCENE_SHARE, 10), (
        f"the scene is on top on only {page.page.evaluate(_SCENE_SHARE_JS):.0%} of the screen"
    )
    # The page opens folded (on a phone held upright, viser's bottom sheet down to its bar).
    assert wait_until(lambda: not page.page.evaluate(_LEGEND_SHOWN_JS, LEGEND_ENTRY), 10)
    if device == "tablet-portrait":  # its column folded to a rail: the label whole down it
        titles = lambda: page.page.evaluate(_RAIL_TITLES_JS)  # noqa: E731
        assert wait_until(lambda: any("·" in text for text, _ in titles()), 20), titles()
        for text, cut in titles():
            assert not cut, text
    assert wait_until(lambda: page.page.evaluate(_SCENE_SHARE_JS) >= folded_share(device), 10)
    # One tap opens the sheet, and the legend is on screen; one tap closes it.
    sheet_toggle(page, device, opening=True).tap()
    assert wait_until(lambda: page.page.evaluate(_LEGEND_SHOWN_JS, LEGEND_ENTRY), 10)
    sheet_toggle(page, device, opening=False).tap()
    assert wait_until(lambda: page.page.evaluate(_SCENE_SHARE_JS) >= folded_share(device), 10)
    # A tap on the ellipsoid (at the picture of its centre) starts the motion there.
    body = session.body
    assert body is not None
    x, y = screen_point(session, page, np.zeros(3))
    page.page.touchscreen.tap(x, y)
    assert wait_until(lambda: session.pointer.starts == 1 and session.body is not body, 10)
    new = session.body
    assert new is not None and new.energy == pytest.approx(body.energy, rel=1e-12)
    shown = f"{new.D:.4g}"  # as the panel shows it: 4 significant figures
    assert shown != f"{body.D:.4g}"
    # ... and the readouts in the sheet show its D (on the bottom sheet, in its "What you see"
    # section, which opens with one more tap).
    sheet_toggle(page, device, opening=True).tap()
    if DEVICES[device][0] < 576:  # once the sheet is open (a tap while it moves is not taken)
        assert wait_until(lambda: page.page.evaluate(_LEGEND_SHOWN_JS, LEGEND_ENTRY), 10)
        page.page.get_by_text("What you see", exact=True).first.tap()
    assert wait_until(lambda: shown in page.page.evaluate("() => document.body.innerText"), 10)
    assert page.errors == []


def test_the_camera_frames_the_construction_again_when_the_phone_turns(
    poinsot_app, open_page
) -> None:
    """The framings the session sent, read from the session: its camera mirrors what the
    browser reports, and a report sent as the page turned may come after the new framing."""
    page = open_device(open_page, poinsot_app.url, "phone-portrait")
    layout = session_of(poinsot_app).layout

    def framed(upright: bool) -> np.ndarray | None:
        """The camera's position last framed, if framed for a canvas held so."""
        size, view = layout.framed or ((0, 0), None)
        return None if view is None or (size[0] < size[1]) != upright else view.position

    assert wait_until(lambda: framed(upright=True) is not None, 20)
    upright_distance = np.linalg.norm(framed(upright=True))
    page.page.set_viewport_size({"width": 844, "height": 390})
    assert wait_until(lambda: framed(upright=False) is not None, 20)
    # Wide, the construction needs less distance than upright (its width limits it there).
    assert np.linalg.norm(framed(upright=False)) < 0.8 * upright_distance
    assert page.errors == []
