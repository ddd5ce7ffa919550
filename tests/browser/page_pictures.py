"""The README's pictures of the page, made again with ``make pictures`` (or
``.venv/bin/python tests/browser/page_pictures.py [NAME ...]``): headless Chromium with software
WebGL, one page per picture, written to ``assets/page/`` as palette PNGs (256 colours: a few
hundred kB each).

Every size and theme a lecturer or a student meets, dark and light each:

- ``1920x1080``: a projector or a large screen, as the page opens; ``1920x1080_large``: the
  same with "Large text"; ``1920x1080_projector``: the projector mode;
- ``1280x800``: a laptop;
- ``820x1180``: a tablet held upright (touch, the column folded to its rail);
- ``390x844``: a phone held upright (touch, the bottom sheet folded to its header, which shows
  t and the regime).

And ``drag_1280x800.png``: a desktop page with the mouse pressed on the ellipsoid and moved, the
polhode through the pointed start drawn (the motion stands still).

Each picture is taken once the page has drawn the state asked for and a few seconds of motion
(the traces grow): no page event says "the traces are long enough", hence the pauses.
"""

from __future__ import annotations

import io
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
from PIL import Image
from playwright.sync_api import sync_playwright

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from conftest import (  # noqa: E402
    CHROMIUM,
    FRAME_CAP_JS,
    HIDE_SOFTWARE_WEBGL_NOTICE_JS,
    BrowserPage,
    wait_until,
)
from test_picture_page import lay_out_on_the_frame_thread  # noqa: E402
from test_touch_page import ANDROID_TABLET, IPHONE, screen_point  # noqa: E402

from poinsot.app.exports.chromium import CHROMIUM_ARGS  # noqa: E402
from poinsot.app.live.panel.widgets import set_value  # noqa: E402
from poinsot.app.live.server import PoinsotApp  # noqa: E402
from poinsot.app.live.session.session import Session  # noqa: E402

ASSETS = Path(__file__).resolve().parents[2] / "assets"
PAGES = ASSETS / "page"
#: Seconds of motion before a picture: the traces grow a little.
TRACE_SECONDS = 4.0
#: Seconds for the labels laid out for the paused picture to reach the page and be drawn (a
#: paused page draws a frame a second).
LABEL_SECONDS = 2.0


#: name: (width, height, touch User-Agent or "" for a desktop, what to switch on)
SHOTS: dict[str, tuple[int, int, str, str]] = {
    "1920x1080": (1920, 1080, "", ""),
    "1920x1080_large": (1920, 1080, "", "large"),
    "1920x1080_projector": (1920, 1080, "", "projector"),
    "1280x800": (1280, 800, "", ""),
    "820x1180": (820, 1180, ANDROID_TABLET, ""),
    "390x844": (390, 844, IPHONE, ""),
}


def _open(browser, app: PoinsotApp, width: int, height: int, agent: str) -> BrowserPage:
    touch = {"has_touch": True, "is_mobile": True, "user_agent": agent} if agent else {}
    context = browser.new_context(
        viewport={"width": width, "height": height}, device_scale_factor=1, **touch
    )
    context.add_init_script(HIDE_SOFTWARE_WEBGL_NOTICE_JS)
    context.add_init_script(FRAME_CAP_JS)  # a busy machine: 5 frames a second are enough
    page = context.new_page()
    page.set_default_timeout(180000)
    page.goto(app.url)
    page.locator("canvas").first.wait_for(state="visible")
    return BrowserPage(page, [])


def _style(session: Session, dark: bool, switch: str) -> None:
    """The theme and the text size or projector mode, as the lecturer's boxes set them."""
    lecture = session.lecture
    set_value(lecture.dark, dark)
    lecture.set_theme(dark=dark)
    if switch == "large":
        set_value(lecture.large, True)
        lecture.set_theme(large=True)
    elif switch == "projector":
        set_value(lecture.projector, True)
        lecture.display.request(projector=True)
    assert wait_until(lambda: lecture.display.style == lecture.display.wanted, 60)


def save(png: bytes, path: Path) -> None:
    """``png`` as a palette PNG (256 colours, no dithering: flat panels stay flat)."""
    image = Image.open(io.BytesIO(png)).convert("RGB")
    image = image.quantize(256, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE)
    image.save(path, optimize=True)
    print(f"{path.relative_to(ASSETS.parent)}: {image.size[0]}x{image.size[1]}")


def shot(browser, name: str, dark: bool) -> None:
    width, height, agent, switch = SHOTS[name]
    app = PoinsotApp("127.0.0.1", 0)
    page = None
    try:
        page = _open(browser, app, width, height, agent)
        session = app.wait_for_sessions(1, 120)[0]
        assert wait_until(lambda: session.running, 60)
        _style(session, dark, switch)
        if agent:  # framed for the canvas's final size (its column folded to a rail)

            def framed_for_canvas() -> bool:
                box = page.canvas_box()
                size = (round(box["width"]), round(box["height"]))
                return session.layout.size == size and session.layout.framings >= 1

            assert wait_until(framed_for_canvas, 60)
        time.sleep(TRACE_SECONDS)
        session.toggle_pause()  # a paused page draws a frame a second: a busy machine's
        assert wait_until(lambda: session.clock.paused, 60)  # screenshot comes sooner
        lay_out_on_the_frame_thread(session)  # the labels, for the style and the paused time
        time.sleep(LABEL_SECONDS)  # (a light projector picture was once taken without them)
        theme = "dark" if dark else "light"
        save(page.page.screenshot(), PAGES / f"{theme}_{name}.png")
    finally:
        if page is not None:
            page.page.context.close()  # its page stops drawing: the next picture has the cores
        app.stop()


def drag(browser) -> None:
    app = PoinsotApp("127.0.0.1", 0)
    try:
        page = _open(browser, app, 1280, 800, "")
        session = app.wait_for_sessions(1, 120)[0]
        time.sleep(2.0)
        x, y = screen_point(session, page, np.zeros(3))
        mouse = page.page.mouse
        mouse.move(x, y)
        mouse.down()
        mouse.move(x + 40, y - 25, steps=8)
        assert wait_until(lambda: session.pointer.previews >= 1, 30)
        time.sleep(1.0)
        save(page.page.screenshot(), ASSETS / "drag_1280x800.png")
        mouse.up()
        page.page.context.close()
    finally:
        app.stop()


def jobs() -> dict[str, Callable]:
    """Every picture by name (``dark_1280x800``, ``drag``...)."""
    out: dict[str, Callable] = {"drag": drag}
    for name in SHOTS:
        for dark in (True, False):
            theme = "dark" if dark else "light"
            out[f"{theme}_{name}"] = lambda b, n=name, d=dark: shot(b, n, d)
    return out


def main(names: list[str]) -> None:
    todo = jobs()
    unknown = [n for n in names if n not in todo]
    if unknown:
        raise SystemExit(f"no picture named {unknown}; choose among {sorted(todo)}")
    PAGES.mkdir(exist_ok=True)
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, headless=True, args=CHROMIUM_ARGS)
        failed = []
        for name in names or list(todo):
            try:
                todo[name](browser)
            except Exception as exc:  # the others are still made; this one is named below
                print(f"{name}: failed ({type(exc).__name__}: {str(exc)[:200]})")
                failed.append(name)
        browser.close()
    if failed:
        raise SystemExit(f'not made: {" ".join(failed)} (make pictures NAMES="..." again)')


if __name__ == "__main__":
    main(sys.argv[1:])
