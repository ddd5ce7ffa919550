"""Exports and lecture controls in a real browser (Debian's Chromium via playwright, WebGL
through SwiftShader):

- the standalone HTML opened from a ``file://`` URL, with every network request refused,
  renders the scene and animates it;
- the in-app screenshot button hands the browser a PNG of the chosen size (current view,
  opaque on the theme's background; 1920×1080 transparent);
- space pauses, 1-4 move the camera (4 rides along with the body), the theme and text-size
  toggles change the page.
"""

from __future__ import annotations

import io
import re
import threading

import numpy as np
import pytest
from conftest import (
    FRAME_CAP_JS,
    NO_MSAA_JS,
    PAGE_OPEN_S,
    lecture_of,
    session_of,
    wait_until,
)
from PIL import Image

from poinsot.app.construction.cameras import BODY_VIEW, ride_along
from poinsot.app.exports import html as html_export
from poinsot.app.exports.screenshot import THEME_BACKGROUND
from poinsot.app.live.lecture.lecture import LARGE_TEXT_PERCENT
from poinsot.app.model.presets import preset_by_key

pytestmark = pytest.mark.browser

#: The scene counts as visible when this fraction of the picture has the ellipsoid's amber.
MIN_AMBER = 0.02


def amber_fraction(rgb: np.ndarray) -> float:
    """Fraction of pixels with the ellipsoid's hue (amber, 22-45 degrees), saturated and not
    dark (the translucent amber ellipsoid is the only amber thing in the scene)."""
    px = rgb[..., :3].reshape(-1, 3).astype(np.float64) / 255.0
    hi, lo = px.max(axis=1), px.min(axis=1)
    chroma = hi - lo
    with np.errstate(divide="ignore", invalid="ignore"):
        r, g, b = px.T
        hue = (
            np.where(
                hi == r,
                ((g - b) / chroma) % 6,
                np.where(hi == g, (b - r) / chroma + 2, (r - g) / chroma + 4),
            )
            * 60.0
        )
        saturation = np.where(hi > 0, chroma / hi, 0.0)
    amber = (hue > 22) & (hue < 45) & (saturation > 0.3) & (hi > 0.18) & (chroma > 0)
    return float(amber.mean())


def without_notice(page, rgb: np.ndarray) -> np.ndarray:
    """Black out viser's "software WebGL" notice (shown by SwiftShader, never by a GPU)."""
    notice = page.locator("#webgl-software-rendering")
    if notice.count() and notice.first.is_visible():
        box = notice.first.bounding_box()
        if box:
            y0, x0 = int(box["y"]), int(box["x"])
            rgb = rgb.copy()
            rgb[
                max(0, y0 - 4) : int(y0 + box["height"]) + 4,
                max(0, x0 - 4) : int(x0 + box["width"]) + 4,
            ] = 0
    return rgb


def screenshot_rgb(page) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(page.screenshot(type="png"))).convert("RGB"))


# -- standalone HTML ---------------------------------------------------------------------------
def test_html_export_plays_from_a_file_url_without_any_server(chromium, tmp_path):
    path = tmp_path / "poinsot.html"
    path.write_text(html_export.preset_html(preset_by_key("major"), 3.0, fps=20), encoding="utf-8")
    context = chromium.new_context(viewport={"width": 960, "height": 540})
    context.add_init_script(FRAME_CAP_JS)  # as the suite's other pages (the clip plays by time)
    context.add_init_script(NO_MSAA_JS)
    refused: list[str] = []

    def only_local(route) -> None:
        url = route.request.url
        if url.startswith(("file:", "data:", "blob:")):
            route.continue_()
        else:
            refused.append(url)
            route.abort()

    context.route("**/*", only_local)
    try:
        page = context.new_page()
        sockets: list[str] = []
        errors: list[str] = []
        page.on("websocket", lambda ws: sockets.append(ws.url))
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
        page.goto(path.as_uri())
        page.locator("canvas").first.wait_for(state="visible", timeout=PAGE_OPEN_S * 1000)
        amber = [0.0]

        def drawn() -> bool:
            amber[0] = amber_fraction(without_notice(page, screenshot_rgb(page)))
            return amber[0] > MIN_AMBER

        # A bound for a failure: a busy machine's software WebGL once drew nothing within 30 s.
        assert wait_until(drawn, 90, poll=0.5), (
            f"the scene never appeared ({amber[0]:.4f} of the view amber; errors {errors[:3]})"
        )
        first = without_notice(page, screenshot_rgb(page))
        changed = [0.0]

        def moved() -> bool:
            # The clip plays by the page's clock: the event is a picture that moved, however
            # few frames a loaded machine lets the page draw in a given time.
            second = without_notice(page, screenshot_rgb(page))
            changed[0] = float(np.mean(np.any(np.abs(second.astype(int) - first) > 24, axis=2)))
            return changed[0] > 0.002

        assert wait_until(moved, 30, poll=0.5), (
            f"the animation did not move ({changed[0]:.4f} of the view changed)"
        )
        assert refused == [] and sockets == [], (refused, sockets)
        assert errors == []
    finally:
        context.close()


# -- the in-app controls -----------------------------------------------------------------------
def download_png(page, button: str = "Screenshot (PNG)") -> tuple[str, Image.Image]:
    with page.page.expect_download(timeout=120000) as info:
        page.click_button(button)
    download = info.value
    data = open(download.path(), "rb").read()
    return download.suggested_filename, Image.open(io.BytesIO(data))


def started_session(app):
    session = session_of(app)
    assert wait_until(lambda: session.stats.frames >= 10, 20), "the scene is not animating"
    return session


def test_screenshot_button_downloads_pngs_of_the_chosen_size(poinsot_app, open_page):
    page = open_page(poinsot_app.url, width=960, height=540, live_view=False)
    session = started_session(poinsot_app)
    lecture = lecture_of(session)
    # A slide's size unless another is chosen, whatever the window.
    assert page.dropdown_value("Picture size") == "1920×1080"
    # Current view: the 3D view's size, opaque on the dark theme's background.
    page.choose("Picture size", "current view")
    assert wait_until(lambda: lecture.size.value == "current view", 30)
    name, image = download_png(page)
    width, height = session.client.camera.image_width, session.client.camera.image_height
    view = page.canvas_box()  # the 3D view, between the docked columns
    assert (width, height) == (round(view["width"]), round(view["height"]))
    assert re.fullmatch(r"poinsot_major_t\d+\.\d\d\.png", name), name
    t_name = float(name[len("poinsot_major_t") : -4])
    assert 0.0 < t_name <= session.clock.now()
    assert image.size == (width, height) and image.mode == "RGB"
    rgb = np.asarray(image)
    assert tuple(rgb[0, 0]) == THEME_BACKGROUND[True]
    assert amber_fraction(rgb) > MIN_AMBER
    # The message is written just after the download is sent: wait for it.
    assert wait_until(lambda: name in lecture.message.content, 30), lecture.message.content
    assert page.errors == []
    # 1920×1080, transparent: RGBA, clear where nothing is drawn.
    page.choose("Picture size", "1920×1080")
    page.set_checkbox("Transparent PNG", True)
    assert wait_until(lambda: lecture.transparent.value and lecture.size.value == "1920×1080", 30)
    name, image = download_png(page)
    assert image.size == (1920, 1080) and image.mode == "RGBA"
    rgba = np.asarray(image)
    assert rgba[0, 0, 3] == 0 and rgba[-1, -1, 3] == 0
    # Laid on the dark background afterwards, it is the same scene.
    ground = Image.new("RGBA", image.size, (*THEME_BACKGROUND[True], 255))
    assert amber_fraction(np.asarray(Image.alpha_composite(ground, image))) > MIN_AMBER
    assert page.errors == []


def test_keys_cameras_theme_and_text_size(poinsot_app, open_page):
    # A laptop's page: with large text its docked columns still leave the picture between them
    # wide enough (at 960 x 540 they leave 127 px, and the page is laid out compact). Its pixel
    # ratio held: the theme's pixels are read from two pictures (viser otherwise lowers the
    # ratio of a page that draws few frames, and a canvas resized shows nothing until its next
    # frame: once, its whole bottom row read grey 49 where the background reads 20).
    page = open_page(poinsot_app.url + "?fixedDpr=1", width=1280, height=720)
    session = started_session(poinsot_app)
    lecture = lecture_of(session)
    camera = session.client.camera
    box = page.canvas_box()
    # Focus the 3D view (not a widget): its bottom centre, between the floating panels.
    page.page.mouse.click(box["x"] + box["width"] / 2, box["y"] + box["height"] - 8)

    def near(target, atol=1e-3):
        return lambda: np.allclose(camera.position, target, atol=atol)

    # Space: play/pause, through viser's command hotkeys.
    page.page.keyboard.press("Space")
    assert wait_until(lambda: session.clock.paused, 30), "space did not pause"
    page.page.keyboard.press("Space")
    assert wait_until(lambda: not session.clock.paused, 30), "space did not resume"
    # 2: view along L. The browser reports its camera back to the server.
    page.page.keyboard.press("2")
    top = lecture.view("along-L")  # framed for this browser's view and the body shown
    # The browser reports its camera while the view animates: wait for the settled state
    # (position and look-at both at the view's), not the first report that passes one.
    assert wait_until(
        lambda: near(top.position)() and np.allclose(camera.look_at, top.look_at, atol=1e-3), 10
    ), ("top view", camera.position, camera.look_at)
    # 4: ride along. Paused, the camera sits exactly where the body carries BODY_VIEW ...
    page.page.keyboard.press("Space")
    assert wait_until(lambda: session.clock.paused, 30), "space did not pause"
    page.page.keyboard.press("4")
    # (The body's attitude of the session's last frame: one more frame, at the time the clock
    # stopped, may follow the pause.)
    expected = ride_along(BODY_VIEW, session.frame.wxyz)

    def at_the_ride_s_view() -> bool:
        nonlocal expected
        expected = ride_along(BODY_VIEW, session.frame.wxyz)
        return near(expected.position)()

    assert wait_until(at_the_ride_s_view, 10), ("ride along", camera.position, expected)
    # ... and, running, it turns with the body.
    page.page.keyboard.press("Space")
    assert wait_until(lambda: not session.clock.paused, 30), "space did not resume"
    # The camera turns with the body at the ride's distance (the browser may first report a
    # position of its move from the top view: wait for one that has arrived and moved on).
    distance = float(np.linalg.norm(BODY_VIEW.position))

    def riding() -> bool:
        position = np.asarray(camera.position)
        at_distance = abs(float(np.linalg.norm(position)) - distance) < 1e-3 * distance
        return at_distance and not near(expected.position, 0.05)()

    assert wait_until(riding, 10), ("the camera did not ride", camera.position, distance)
    # 3: side view ends the ride.
    page.page.keyboard.press("3")
    side = lecture.view("side")  # framed likewise
    assert wait_until(near(side.position), 10), ("side view", camera.position, side.position)
    # Theme: the page's background turns light.
    page.page.keyboard.press("Space")
    assert wait_until(lambda: session.clock.paused, 30), "space did not pause"
    page.drawn_after(session.client)  # the side view's picture, drawn
    # The darkest pixel of the 3D view's bottom row is its background (the side view may
    # frame the plane down to the edge; the panels may have docked since the first box).
    box = page.canvas_box()
    left, right = int(box["x"]) + 2, int(box["x"] + box["width"]) - 2
    row = screenshot_rgb(page.page)[-3, left:right]
    darkest = int(np.argmin(row.mean(axis=1)))
    corner, dark = (-3, left + darkest), row[darkest]
    page.set_checkbox("Dark theme", False)
    assert wait_until(lambda: screenshot_rgb(page.page)[corner].mean() > 200, 10), dark
    assert dark.mean() < 40, dark
    # Large text: the root font size (all panel text is in rem) grows.
    root = "parseFloat(getComputedStyle(document.documentElement).fontSize)"
    before = page.page.evaluate(root)
    layout = session.layout
    assert layout is not None and layout.size is not None and not layout.compact
    picture = layout.size  # the canvas between the docked columns, as the browser reports it
    page.set_checkbox("Large text", True)
    grown = before * LARGE_TEXT_PERCENT / 100
    assert wait_until(lambda: page.page.evaluate(root) >= grown - 0.5, 10), before
    # The columns widen with the text: the browser reports the narrower picture, and once the
    # session has taken that report (an action posted after it runs after it), the page is
    # still docked, not folded compact.
    assert wait_until(lambda: layout.size is not None and layout.size[0] < picture[0], 10)
    taken = threading.Event()
    session.post(taken.set)
    assert taken.wait(10) and not layout.compact, (picture, layout.size)
    # The panel's labels follow.
    label = (
        "(() => { const l = [...document.querySelectorAll('label')].find("
        "l => l.textContent === 'Dark theme');"
        " return l ? parseFloat(getComputedStyle(l).fontSize) : 0; })()"
    )
    assert wait_until(lambda: page.page.evaluate(label) >= 1.2 * 12, 10), page.page.evaluate(label)
    assert page.errors == []
    assert session.stats.errors == 0, session.stats.last_error
