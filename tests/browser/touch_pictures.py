"""The README's pictures of the phone layout and of a drag in progress, made again with
``.venv/bin/python tests/browser/touch_pictures.py`` (headless Chromium, software WebGL; writes
``assets/phone_390x844.png`` and ``assets/drag_1280x800.png``).

- The phone: an iPhone's 390 x 844 page with touch, as it opens (the scene framed for it, the
  sheet folded to its bar).
- The drag: a desktop page at 1280 x 800, the mouse pressed on the ellipsoid and moved, held
  while the polhode through the pointed start is drawn (the motion stands still).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
from playwright.sync_api import sync_playwright

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from conftest import (  # noqa: E402
    CHROMIUM,
    HIDE_SOFTWARE_WEBGL_NOTICE_JS,
    BrowserPage,
    wait_until,
)
from test_touch_page import IPHONE, screen_point  # noqa: E402

from poinsot.app.exports.chromium import CHROMIUM_ARGS  # noqa: E402
from poinsot.app.live.server import PoinsotApp  # noqa: E402

ASSETS = Path(__file__).resolve().parents[2] / "assets"


def _open(browser, app: PoinsotApp, width: int, height: int, **options) -> BrowserPage:
    context = browser.new_context(viewport={"width": width, "height": height}, **options)
    context.add_init_script(HIDE_SOFTWARE_WEBGL_NOTICE_JS)
    page = context.new_page()
    page.goto(app.url)
    page.locator("canvas").first.wait_for(state="visible", timeout=30000)
    return BrowserPage(page, [])


def phone(browser) -> None:
    app = PoinsotApp("127.0.0.1", 0)
    try:
        page = _open(browser, app, 390, 844, has_touch=True, is_mobile=True, user_agent=IPHONE)
        session = app.wait_for_sessions(1)[0]
        assert wait_until(lambda: session.layout.framings >= 1, 30)
        time.sleep(3.0)  # the traces grow a little
        page.page.screenshot(path=str(ASSETS / "phone_390x844.png"))
    finally:
        app.stop()


def drag(browser) -> None:
    app = PoinsotApp("127.0.0.1", 0)
    try:
        page = _open(browser, app, 1280, 800)
        session = app.wait_for_sessions(1)[0]
        time.sleep(2.0)
        x, y = screen_point(session, page, np.zeros(3))
        mouse = page.page.mouse
        mouse.move(x, y)
        mouse.down()
        mouse.move(x + 40, y - 25, steps=8)
        assert wait_until(lambda: session.pointer.previews >= 1, 30)
        time.sleep(1.0)
        page.page.screenshot(path=str(ASSETS / "drag_1280x800.png"))
        mouse.up()
    finally:
        app.stop()


def main() -> None:
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, headless=True, args=CHROMIUM_ARGS)
        phone(browser)
        drag(browser)
        browser.close()


if __name__ == "__main__":
    main()
