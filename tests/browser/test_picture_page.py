"""What a lecture sees, in a real browser (Debian's Chromium, software WebGL) at a projector's
1280 x 800 and at 1920 x 1080, dark and light: the legend and the caption, the herpolhode's size
on screen and nothing covering it, the D slider's marks, the separatrix at the I₂ mark, what a
symmetric body leaves out, labels that do not pile up, readable plots and buttons on the light
theme, no console error when the sphere and a custom body alternate, the projector mode and the
two views. Each test checks pixels or the DOM, not only the server's state."""

from __future__ import annotations

import colorsys
import re

import numpy as np
import pytest
from conftest import BrowserPage, session_of, wait_until
from scipy import ndimage

from poinsot.app.construction import palette
from poinsot.app.construction.view import VIEWS
from poinsot.app.live.lecture.display import PROJECTOR_TEXT_PERCENT, browser_camera
from poinsot.app.live.panel.legend import CAPTIONS
from poinsot.app.model.elements import Element
from poinsot.app.model.parameters import Parameters
from poinsot.app.model.presets import CUSTOM, DEFAULT_PRESET, preset_by_key
from poinsot.physics import Regime

pytestmark = pytest.mark.browser

SIZES = [(1280, 800), (1920, 1080)]
THEMES = ["dark", "light"]
#: The herpolhode of the default preset, seen in the default view after two periods, spans at
#: least these fractions of the 3D view's width and height (measured at 1280 x 800: 0.17 and
#: 0.075 of a 652 x 800 view, a ring of 109 x 60 px; at 1920 x 1080 about 0.11 and 0.075; the
#: grazing view of before gave a sliver a few pixels high).
HERPOLHODE_MIN_WIDTH = 0.10
HERPOLHODE_MIN_HEIGHT = 0.06


# -- one served app, one page at a time ------------------------------------------------------
class Pages:
    """The module's pages on its one app, one open at a time (an open page animates, and
    software WebGL draws it on a core): a test asks for a page of a size and address and gets
    the open one if it has them, put back to the first screen's state (the default preset,
    running at its speed, the default view, dark theme), else a new one (the old closed).
    A page draws no live frames (see :meth:`BrowserPage.set_live_view`) until a test that
    reads the 3D view's pixels switches them on."""

    def __init__(self, app, open_page) -> None:
        self.app, self.open_page = app, open_page
        self.key: tuple | None = None
        self.page: BrowserPage | None = None
        self.session = None

    def get(self, width: int = 1280, height: int = 800, query: str = "", fresh: bool = False):
        """(page, session) of ``width`` x ``height`` at the app's address + ``query``; a new
        page if ``fresh`` (a test that clicks where the page first lays a widget out)."""
        key = (width, height, query)
        if fresh or key != self.key or self.page is None or self.page.page.is_closed():
            self.close()
            before = set(self.app.sessions())
            self.page = self.open_page(
                f"{self.app.url}{query}", width=width, height=height, live_view=False
            )
            assert wait_until(lambda: self.newest_id() not in before, 20), "no new session"
            self.session, self.key = session_of(self.app), key
        else:
            self.back_to_the_first_screen()
        return self.page, self.session

    def newest_id(self) -> int | None:
        return max(self.app.sessions(), default=None)

    def back_to_the_first_screen(self) -> None:
        page, session = self.page, self.session
        assert page is not None and session is not None
        first = Parameters.from_preset(DEFAULT_PRESET)
        if session.preset is not DEFAULT_PRESET or session.params != first:
            session.choose_preset(DEFAULT_PRESET)
            assert wait_until(
                lambda: session.preset is DEFAULT_PRESET and session.params == first, 10
            )
            # ... and the page shows it: the I₂ slider and the D slider's marks of its body.
            lo, mid, hi = sorted(first.inertia)
            assert wait_until(lambda: page.slider_value("I₂") == pytest.approx(mid), 20)
            assert wait_until(lambda: shows_the_marks_of(page, lo, mid, hi), 20), slider_marks(page)
        if session.clock.paused:
            page.click_button("Play")
            assert wait_until(lambda: not session.clock.paused, 10)
        session.set_speed(DEFAULT_PRESET.speed)
        assert wait_until(lambda: session.clock.speed == DEFAULT_PRESET.speed, 10)
        set_theme(page, session, "dark")
        target, camera = VIEWS["default"], session.client.camera
        if not at_view(camera, target):
            page.set_live_view(True)  # the camera's move to the view is animated frame by frame
            session.lecture.set_camera("default")  # (the Views folder may be folded by now)
            assert wait_until(lambda: at_view(camera, target), 20)
        page.set_live_view(False)

    def close(self) -> None:
        if self.page is not None:
            self.page.page.context.close()
        self.page, self.session, self.key = None, None, None


@pytest.fixture(scope="module", params=SIZES, ids=["1280x800", "1920x1080"])
def size(request) -> tuple[int, int]:
    """A page's size, module-scoped: the tests of one size run one after the other, on one
    page."""
    return request.param


@pytest.fixture(scope="module")
def module_pages(make_module_app, open_module_page):
    shared = Pages(make_module_app(), open_module_page)
    yield shared
    shared.close()


@pytest.fixture
def pages(module_pages, request):
    """The module's pages; a failed test's page is closed, not handed on."""
    failed = request.session.testsfailed
    yield module_pages
    if request.session.testsfailed > failed:
        module_pages.close()


# -- helpers -----------------------------------------------------------------------------------
def at_view(camera, view) -> bool:
    """The browser's camera has settled at ``view``."""
    return np.allclose(camera.position, view.position, atol=1e-3) and np.allclose(
        camera.look_at, view.look_at, atol=1e-3
    )


def started(session, frames: int = 20):
    """``frames`` more frames drawn (a page can come from an earlier test)."""
    first = session.stats.frames
    assert wait_until(lambda: session.stats.frames >= first + frames, 20), "not animating"
    return session


def set_theme(page, session, theme: str) -> None:
    """The theme by the page's checkbox (a page can come from a test on the other theme)."""
    dark = theme == "dark"
    if session.lecture.display.style.dark is not dark:
        page.set_checkbox("Dark theme", dark)
        assert wait_until(lambda: session.lecture.display.style.dark is dark, 10)
        page.drawn_after(session.client)


def pause(page, session) -> None:
    """Pause from the page's button, once the page has applied all the server sent it (a
    preset just chosen rebuilds the panel around the button)."""
    assert not session.clock.paused, "already paused"
    page.drawn_after(session.client)
    page.click_button("Pause")
    if not wait_until(lambda: session.clock.paused, 30):
        shown = page.page.get_by_role("button", name="Play", exact=True).count()
        raise AssertionError(f"not paused ({shown} Play buttons, {session.stats.errors} errors)")
    # The traces are sent in chunks: paused, the last one goes out at the next frame. Until
    # then a picture could change between two screenshots for a reason of its own.
    assert wait_until(lambda: session.scene.traces_complete, 10)


def near(rgb: np.ndarray, color: tuple[int, int, int], tolerance: float = 60.0) -> np.ndarray:
    """Pixels within ``tolerance`` (Euclidean, 0-255) of ``color``."""
    return np.linalg.norm(rgb.astype(float) - np.array(color, float), axis=2) < tolerance


def hue_mask(
    rgb: np.ndarray,
    colour,
    tolerance: float = 10.0,
    saturation: float = 0.25,
    brightness: float = 0.45,
):
    """Pixels of ``colour``'s hue (within ``tolerance`` degrees), saturated and bright: a line
    drawn in that colour as it comes out on screen (lit, blended, anti-aliased)."""
    target = colorsys.rgb_to_hsv(*(c / 255.0 for c in colour))[0] * 360.0
    view = rgb.astype(float) / 255.0
    mx, mn = view.max(axis=2), view.min(axis=2)
    chroma = np.maximum(mx - mn, 1e-9)
    r, g, b = view[..., 0], view[..., 1], view[..., 2]
    hue = (
        np.where(
            mx == r,
            ((g - b) / chroma) % 6,
            np.where(mx == g, (b - r) / chroma + 2, (r - g) / chroma + 4),
        )
        * 60.0
    )
    distance = np.abs((hue - target + 180.0) % 360.0 - 180.0)
    sat = np.where(mx > 0, (mx - mn) / np.maximum(mx, 1e-9), 0.0)
    return (distance < tolerance) & (sat > saturation) & (mx > brightness)


def scene_only(session, width: int, height: int) -> np.ndarray:
    """The 3D view alone, rendered by the page at ``width`` x ``height`` from the browser's
    camera: no panel floats over it (a legend's swatches have the lines' colours)."""
    rgba = session.client.get_render(int(height), int(width), transport_format="png", timeout=60.0)
    return np.asarray(rgba)[..., :3]


def canvas_slice(page) -> tuple[np.ndarray, dict]:
    """The page's pixels and the 3D view's box (between the docked columns)."""
    return page.screenshot_rgb(), page.canvas_box()


def in_patches(mask: np.ndarray, min_patch: int) -> np.ndarray:
    """``mask``'s pixels that lie in patches of at least ``min_patch`` pixels (a stray
    anti-aliased pixel of another line, where two lines cross, is not a curve)."""
    patches, count = ndimage.label(ndimage.binary_dilation(mask, iterations=2))
    sizes = ndimage.sum(mask, patches, range(1, count + 1))
    return mask & np.isin(patches, 1 + np.flatnonzero(sizes >= min_patch))


def line_thickness(mask: np.ndarray) -> float:
    """The mean thickness of ``mask``'s lines [pixels]: twice their area over their edge
    pixels (a band of width w and length l has w·l pixels and about 2·l on its edges), however
    long the lines are and wherever a label covers them."""
    edge = mask & ~ndimage.binary_erosion(mask)
    return 2.0 * float(mask.sum()) / max(int(edge.sum()), 1)


def bounding_box(mask: np.ndarray, min_patch: int = 0) -> tuple[int, int, int, int] | None:
    """The box round ``mask``'s pixels (only those in patches of at least ``min_patch``
    pixels, when given)."""
    if min_patch:
        mask = in_patches(mask, min_patch)
    ys, xs = np.nonzero(mask)
    if len(xs) == 0:
        return None
    return int(xs.min()), int(ys.min()), int(xs.max()), int(ys.max())


def contrast(a: tuple[float, ...], b: tuple[float, ...]) -> float:
    """WCAG contrast ratio of two sRGB colours (0-255)."""

    def luminance(rgb):
        def channel(v):
            v /= 255.0
            return v / 12.92 if v <= 0.03928 else ((v + 0.055) / 1.055) ** 2.4

        r, g, b = (channel(float(c)) for c in rgb[:3])
        return 0.2126 * r + 0.7152 * g + 0.0722 * b

    hi, lo = sorted((luminance(a), luminance(b)), reverse=True)
    return (hi + 0.05) / (lo + 0.05)


def css_rgb(text: str) -> tuple[float, ...]:
    return tuple(float(v) for v in re.findall(r"[\d.]+", text)[:3])


# -- 1. the legend and the caption -----------------------------------------------------------
#: name -> [how many legend entries carry it, the box of the first as playwright's bounding_box
#: gives it (viewport pixels; null when it has no layout box)], for each name.
LEGEND_JS = """(names) => Object.fromEntries(names.map((name) => {
  const found = [...document.querySelectorAll('[data-legend]')].filter(
    (e) => e.getAttribute('data-legend') === name);
  const rect = found.length && found[0].getClientRects().length
    ? found[0].getBoundingClientRect() : null;
  return [name, [found.length,
    rect && {x: rect.x, y: rect.y, width: rect.width, height: rect.height}]];
}))"""


@pytest.mark.parametrize("theme", THEMES)
def test_the_legend_names_and_colours_every_element_on_the_first_screen(pages, size, theme):
    page, session = pages.get(*size)
    started(session)
    set_theme(page, session, theme)
    look = session.scene.look
    assert look is palette.look(theme == "dark")
    colours = {
        "polhode (body)": look.polhode,
        "herpolhode (plane)": look.herpolhode,
        "ω ang. velocity": look.omega,
        "L ang. momentum": look.angular_momentum,
        "contact point": look.contact,
        "invariable plane": look.plane,
    }
    rgb = page.screenshot_rgb()
    entries: dict = {}  # name -> [how many entries, the box of the one] (one page call for all)
    assert wait_until(
        lambda: (
            entries.update(page.page.evaluate(LEGEND_JS, list(colours)))
            or all(count == 1 for count, _ in entries.values())
        ),
        10,
    ), entries
    for name, colour in colours.items():
        box = entries[name][1]
        assert box is not None and box["y"] + box["height"] <= size[1], (name, box)
        assert box["x"] >= 0 and box["x"] + box["width"] <= size[0], (name, box)
        # The swatch (the entry's first 2 em) shows the element's colour.
        x0, y0 = int(box["x"]), int(box["y"])
        swatch = rgb[y0 : y0 + int(box["height"]), x0 : x0 + 26]
        assert near(swatch, colour, 40).sum() >= 6, (name, colour)
    # The words are on the first screen, in the caption too.
    # (The readouts' headline may say the same words in the panel: the caption is the first.)
    caption = page.page.get_by_text(CAPTIONS["major"][:40])
    assert caption.count() >= 1 and caption.first.bounding_box()["y"] < size[1] / 2
    assert page.errors == []


def test_the_caption_follows_the_preset(pages):
    page, session = pages.get(1280, 800)
    started(session)
    page.choose("Preset", preset_by_key("oblate").label)
    assert wait_until(lambda: session.preset.key == "oblate", 10)

    # The new caption and the old one's removal may reach the page in separate windows.
    def counts() -> tuple[int, int]:
        return tuple(
            page.page.get_by_text(CAPTIONS[key][:30]).count() for key in ("oblate", "major")
        )

    assert wait_until(lambda: counts() == (1, 0), 10), counts()
    assert page.errors == []


# -- 2. the herpolhode is legible and nothing covers it ----------------------------------------
@pytest.mark.parametrize("theme", THEMES)
def test_the_herpolhode_is_legible_in_the_default_view(pages, size, theme):
    page, session = pages.get(*size)
    started(session)
    set_theme(page, session, theme)
    session.set_speed(4.0)  # two periods of ω in about five seconds
    assert wait_until(lambda: session.frame is not None and session.frame.t > 2.2 * 8.921, 30)
    pause(page, session)
    page.set_live_view(True)
    page.drawn_after(session.client)
    rgb, box = canvas_slice(page)
    x0, x1 = int(box["x"]), int(box["x"] + box["width"])
    # The 3D view lies between the two docked columns: no panel over it.
    left = page.page.get_by_text("What you see", exact=True).bounding_box()
    preset = page.page.locator("label").filter(has_text=re.compile("^Preset$")).bounding_box()
    assert left["x"] + left["width"] <= x0 + 1 and preset["x"] >= x1 - 1, (left, preset, box)
    assert box["width"] >= 0.45 * size[0]
    herpolhode = hue_mask(rgb, session.scene.look.herpolhode)
    herpolhode[:, :x0] = herpolhode[:, x1:] = False
    found = bounding_box(herpolhode, min_patch=30)
    assert found is not None, "no herpolhode on screen"
    width, height = (found[2] - found[0]) / box["width"], (found[3] - found[1]) / box["height"]
    assert width > HERPOLHODE_MIN_WIDTH and height > HERPOLHODE_MIN_HEIGHT, (width, height)
    assert page.errors == []


# -- 3. the D slider's marks -------------------------------------------------------------------
MARKS_JS = """(label) => {
  const l = [...document.querySelectorAll('label')].find(e => e.textContent === label);
  const root = document.getElementById(l.getAttribute('for'));
  const thumb = root.querySelector('[role=slider]');
  return {min: +thumb.getAttribute('aria-valuemin'), max: +thumb.getAttribute('aria-valuemax'),
    marks: [...root.querySelectorAll('.mantine-Slider-markWrapper')].map(
      w => [parseFloat(w.style.getPropertyValue('--mark-offset')), w.textContent])};
}"""


def slider_marks(page, label: str = "D = |L|²/2T") -> dict:
    return page.page.evaluate(MARKS_JS, label)


def shows_the_marks_of(page, lo: float, mid: float, hi: float) -> bool:
    """The D slider runs from ``lo`` to ``hi`` with the I₂ mark at ``mid``."""
    marks = slider_marks(page)
    return (
        marks["min"] == pytest.approx(lo)
        and marks["max"] == pytest.approx(hi)
        and [label for _, label in marks["marks"]] == ["min I", "I₂", "max I"]
        and marks["marks"][1][0] == pytest.approx(100.0 * (mid - lo) / (hi - lo))
    )


def test_the_D_marks_follow_the_body(pages):
    page, session = pages.get(1280, 800)
    started(session)
    for key in ("t_handle", "oblate", "prolate"):
        preset = preset_by_key(key)
        page.choose("Preset", preset.label)
        assert wait_until(lambda p=preset: session.params.inertia == p.inertia, 10)
        lo, hi = min(preset.inertia), max(preset.inertia)
        assert wait_until(lambda lo=lo, hi=hi: slider_marks(page)["max"] == pytest.approx(hi), 10)
    marks = slider_marks(page)
    assert marks["min"] == pytest.approx(0.16829) and marks["max"] == pytest.approx(1.0)
    # A rod is symmetric: min I and max I only, both inside the slider's range.
    assert [label for _, label in marks["marks"]] == ["min I", "max I"]
    assert all(0.0 <= offset <= 100.0 for offset, _ in marks["marks"]), marks
    # A triaxial body has the I₂ mark, and it moves with I₂.
    page.choose("Preset", preset_by_key("major").label)
    assert wait_until(lambda: [m[1] for m in slider_marks(page)["marks"]][1:2] == ["I₂"], 10)
    before = slider_marks(page)["marks"][1][0]
    assert before == pytest.approx(62.5)  # (2 - 1) / (2.6 - 1)
    page.press_slider_to("I₂", 2.2, 0.01, lambda: session.params.inertia[1])  # 20 steps up
    assert wait_until(lambda: session.params.inertia[1] == pytest.approx(2.2), 10)
    assert wait_until(lambda: slider_marks(page)["marks"][1][0] == pytest.approx(75.0), 10)
    assert page.errors == []


# -- 4. the I₂ mark is the separatrix ---------------------------------------------------------
def test_D_at_the_I2_mark_is_the_exact_separatrix(pages):
    """I = (1, 2, 2.6): a click on the D slider's I₂ mark, then the arrow keys until the slider
    shows 2.000: D is I₂ exactly and the readout says separatrix (it said 'polhode around the
    minor axis, period 151')."""
    page, session = pages.get(1280, 800, fresh=True)
    started(session)
    label = "D = |L|²/2T"
    root = page.page.locator(f"[id='{page.widget_id(label)}']")
    mark = root.locator(".mantine-Slider-markWrapper").nth(1)
    assert mark.text_content() == "I₂"
    track = root.locator(".mantine-Slider-track").bounding_box()
    offset = float(mark.evaluate("w => parseFloat(w.style.getPropertyValue('--mark-offset'))"))
    x = track["x"] + track["width"] * offset / 100.0
    page.page.mouse.click(x, track["y"] + track["height"] / 2)
    assert wait_until(lambda: abs(page.slider_value(label) - 2.0) < 0.05, 10)
    page.press_slider_to(label, 2.0, 0.001, lambda: session.params.D)
    assert wait_until(lambda: page.slider_value(label) == 2.0, 10)
    assert wait_until(lambda: session.params.D == 2.0, 10), session.params
    assert session.body.regime is Regime.SEPARATRIX and session.body.D == 2.0
    readout = page.page.get_by_text("on the separatrix (unstable)")
    assert wait_until(lambda: readout.count() == 1, 10)
    assert page.errors == []


# -- 6. what a symmetric body or a sphere leaves out -----------------------------------------
def test_a_symmetric_body_offers_no_separatrix_and_the_sphere_no_k2(pages):
    page, session = pages.get(1280, 800)
    started(session)
    assert page.control_count("Side of separatrix") == 1
    for key in ("oblate", "prolate"):
        page.choose("Preset", preset_by_key(key).label)
        assert wait_until(lambda k=key: session.preset.key == k, 10)
        assert wait_until(lambda: page.control_count("Side of separatrix") == 0, 10), key
        assert page.control_count("Polhode") == 1  # which of the two polhodes: still a choice
        labels = [label for _, label in slider_marks(page)["marks"]]
        assert "I₂" not in labels, labels
    page.choose("Preset", preset_by_key("sphere").label)
    assert wait_until(lambda: session.preset.key == "sphere" and session.body is not None, 10)
    column = page.page.locator("table").first
    assert wait_until(lambda: "sphere: ω constant" in column.inner_text(), 10)
    assert "k²" not in column.inner_text()
    assert page.errors == []


def test_the_sphere_shows_omega_and_L_apart(pages):
    """ω is parallel to L: the thicker ω arrow shows up to the plane round the thinner L, L
    goes on above it, and their labels stand apart."""
    page, session = pages.get(1280, 800)
    page.set_live_view(True)
    started(session)
    page.choose("Preset", preset_by_key("sphere").label)
    assert wait_until(lambda: session.preset.key == "sphere" and session.body is not None, 10)
    pause(page, session)
    box = page.canvas_box()
    drawn = [e for e in Element if session.scene.is_visible(e)]
    # Each arrow's pixels: a picture with it alone against one with nothing (the lit arrow's
    # shades stray from its colour's hue; the sphere's amber and an axis are near L's).
    pictures = {
        shown: alone_in_the_view(session, drawn, shown, box["width"], box["height"])
        for shown in (None, Element.OMEGA, Element.L)
    }
    for element in drawn:
        session.set_visible(element, True)
    nothing = pictures[None].astype(int)
    omega, momentum = (
        in_patches(np.abs(pictures[e].astype(int) - nothing).max(axis=2) > 40, 50)
        for e in (Element.OMEGA, Element.L)
    )
    assert omega.sum() > 150 and momentum.sum() > 150, (omega.sum(), momentum.sum())
    # L reaches higher on screen than ω (L goes on above the plane).
    assert bounding_box(momentum)[1] < bounding_box(omega)[1] - 20
    assert wait_until(lambda: all(session.scene.is_visible(e) for e in drawn), 10)
    placed = lay_out_on_the_frame_thread(session)
    assert {"omega", "L"} <= placed.keys()
    assert not boxes_overlap(placed["omega"].box, placed["L"].box)
    assert page.errors == []


def alone_in_the_view(session, drawn, shown: Element | None, width: float, height: float):
    """The 3D view rendered with ``shown`` the only one of the ``drawn`` elements (None: none
    of them). Only these are touched: hiding an element the preset does not draw would keep it
    hidden in the presets after, and in the module's later tests on this page."""
    for element in drawn:
        session.set_visible(element, element is shown)
    assert wait_until(lambda: all(session.scene.is_visible(e) == (e is shown) for e in drawn), 10)
    return scene_only(session, width, height)


def boxes_overlap(a, b) -> bool:
    return min(a[2], b[2]) > max(a[0], b[0]) and min(a[3], b[3]) > max(a[1], b[1])


# -- 8. labels do not pile up ----------------------------------------------------------------
LABEL_ELEMENTS = (Element.L, Element.OMEGA, Element.AXES, Element.POLHODE, Element.HERPOLHODE)


def lay_out_on_the_frame_thread(session) -> dict:
    """Lay the labels out now, on the session's own frame thread: the frame loop lays them out
    too, and two layouts at once could mix one's anchor with the other's position."""
    import threading

    done, placed = threading.Event(), {}

    def lay_out() -> None:
        placed.update(session.lecture.display.lay_out_labels())
        done.set()

    session.post(lay_out)
    assert done.wait(20), "the session never laid the labels out"
    return placed


def label_handles(session):
    drawings = session.scene._drawings
    handles = []
    for element in LABEL_ELEMENTS:
        for handle in drawings[element].handles:
            if type(handle).__name__ == "LabelHandle":
                handles.append(handle)
    return handles


# -- 9. the light theme is readable ----------------------------------------------------------
@pytest.mark.parametrize("theme", THEMES)
def test_plot_ticks_and_button_text_are_readable(pages, theme):
    from PIL import Image

    page, session = pages.get(1280, 800)
    started(session)
    set_theme(page, session, theme)
    # The outlined buttons of a button group: their text against the panel.
    style = page.page.get_by_role("button", name="minor axis", exact=True).evaluate(
        "b => { const s = getComputedStyle(b); let e = b, bg = 'rgba(0, 0, 0, 0)';"
        " while (e && (bg === 'rgba(0, 0, 0, 0)' || bg === 'transparent'))"
        " { bg = getComputedStyle(e).backgroundColor; e = e.parentElement; }"
        " return [s.color, bg]; }"
    )
    text, ground = css_rgb(style[0]), css_rgb(style[1])
    assert contrast(text, ground) >= 4.5, (theme, style)
    # The plot's y tick labels (drawn on its canvas, in the column left of the curves): their
    # ink stands out from the plot's background by 4.5 : 1 at least.
    plot = page.page.locator(".uplot-container").first
    plot.wait_for(state="visible", timeout=20000)
    page.page.wait_for_timeout(1500)
    import io

    image = np.asarray(Image.open(io.BytesIO(plot.screenshot())).convert("RGB")).astype(float)
    height, width = image.shape[:2]
    background = tuple(np.median(image.reshape(-1, 3), axis=0))
    ticks = image[int(0.15 * height) : int(0.7 * height), : int(0.15 * width)].reshape(-1, 3)
    inked = [px for px in ticks if contrast(tuple(px), background) >= 4.5]
    assert len(inked) >= 15, (theme, len(inked), background)
    assert page.errors == []


# -- 10. no console error when widgets come and go --------------------------------------------
STALL_JS = "(ms) => { const t = Date.now(); while (Date.now() - t < ms) {} }"


def test_sphere_and_custom_alternate_without_console_errors(pages):
    """Switched back and forth by the dropdown, some switches made by the server while the
    browser's main thread is blocked (as software WebGL compiling a new scene's shaders blocks
    it), so that all of a switch's messages wait for one drain: no update ever reaches a
    widget the browser no longer has."""
    import threading

    page, session = pages.get(1280, 800)
    started(session)
    sphere = preset_by_key("sphere")
    for n in range(4):  # two rounds of switches by the dropdown, two by the server
        for preset in (sphere, CUSTOM):
            if n % 2:  # the server switches while the page is frozen
                timer = threading.Timer(0.3, lambda p=preset: session.choose_preset(p))
                timer.start()
                page.page.evaluate(STALL_JS, 1500)  # the switch begins 0.3 s into it
                timer.join()
            else:
                page.choose("Preset", preset.label)
            assert wait_until(lambda p=preset: session.preset is p, 10)
            page.page.wait_for_timeout(300)  # the next switch while this one is under way
    page.drawn_after(session.client)  # every switch's messages applied (an error is logged)
    assert page.errors == []
    assert session.stats.errors == 0, session.stats.last_error


# -- projector mode and the two views ---------------------------------------------------------
def test_two_views_show_the_body_frame_beside_the_space_frame(pages):
    """The space frame (left: the herpolhode on the plane) and the body frame (right: the
    ellipsoid with its polhode, no herpolhode), side by side."""
    page, session = pages.get(1280, 800)
    page.set_live_view(True)
    # A third of ω's period played (a fresh page's first frames, or the first screen's preset
    # chosen again, leave a herpolhode too short to count): a ring of a few hundred pixels.
    session.set_speed(4.0)
    assert wait_until(lambda: session.frame is not None and session.frame.t > 3.0, 30)
    page.set_checkbox("Two views: space | body", True)
    assert wait_until(lambda: session.lecture.display.body_view is not None, 10)
    pause(page, session)
    look = session.scene.look
    traces = (Element.POLHODE, Element.HERPOLHODE)
    assert all(session.scene.is_visible(e) for e in traces), "an earlier test left one hidden"

    def halves() -> tuple[int, int, int, int, int]:
        """Herpolhode left and right, polhode left and right, ellipsoid right [pixels]."""
        rgb, box = canvas_slice(page)
        x0, x1 = int(box["x"]), int(box["x"] + box["width"])
        left, right = slice(x0, (x0 + x1) // 2), slice((x0 + x1) // 2, x1)
        # Where the body frame's axes cross, their blended pixels can take the herpolhode's
        # hue: only patches of a line count.
        herpolhode = in_patches(hue_mask(rgb, look.herpolhode), 30)
        polhode = hue_mask(rgb, look.polhode)
        # The translucent ellipsoid comes out a dim amber on the dark background.
        ellipsoid = hue_mask(rgb, look.ellipsoid, tolerance=12.0, saturation=0.4, brightness=0.12)
        return (
            int(herpolhode[:, left].sum()),
            int(herpolhode[:, right].sum()),
            int(polhode[:, left].sum()),
            int(polhode[:, right].sum()),
            int(ellipsoid[:, right].sum()),
        )

    def both_drawn(h: tuple[int, int, int, int, int]) -> bool:
        """The herpolhode in the space frame only (on the body side no more than stray pixels
        of a like hue: a quarter of the space side's), the body frame's polhode and ellipsoid on
        the right (the space frame's polhode is found below). While the single view gives way
        to the two, the herpolhode crosses the middle."""
        return h[0] > 100 and h[1] < 0.25 * h[0] and h[3] > 50 and h[4] > 2000

    # A software-WebGL browser under load takes its time to draw the second view: poll.
    seen = halves()
    for _ in range(40):
        if both_drawn(seen):
            break
        page.page.wait_for_timeout(500)
        seen = halves()
    assert both_drawn(seen), seen
    # The space frame's polhode: a picture with it against one without (seen through the
    # plane and on the amber body, its hue strays; at some attitudes no pixel kept it).
    rgb, box = drawn_screenshot(page, session.client), page.canvas_box()
    session.set_visible(Element.POLHODE, False)
    assert wait_until(lambda: not session.scene.is_visible(Element.POLHODE), 10)
    without = drawn_screenshot(page, session.client)
    session.set_visible(Element.POLHODE, True)
    x0, x1 = int(box["x"]), int(box["x"] + box["width"])
    space_side = np.abs(rgb - without)[:, x0 : (x0 + x1) // 2].max(axis=2) > 40
    assert in_patches(space_side, 30).sum() > 50, (seen, int(space_side.sum()))
    assert wait_until(lambda: session.scene.is_visible(Element.POLHODE), 10)
    # The pictures' titles say which frame is which.
    assert session.lecture.display.body_view.titles[1].text.startswith("body frame")
    page.page.keyboard.press("v")  # key V: back to one view
    assert wait_until(lambda: session.lecture.display.body_view is None, 10)
    assert page.errors == []


def test_projector_mode_folds_the_control_panel_and_thickens_the_picture(pages):
    """On the labels' page (a fixed pixel ratio), before them."""
    # Two pictures' pixels compared: the canvas's pixel ratio held (viser lowers it while a
    # page draws few frames a second, as the suite's pages do).
    page, session = pages.get(1280, 800, "?fixedDpr=1")
    page.set_live_view(True)
    # Two thirds of ω's period played: the herpolhode's ring, a thousand pixels of it.
    session.set_speed(4.0)
    assert wait_until(lambda: session.frame is not None and session.frame.t > 6.0, 30)
    pause(page, session)
    page.drawn_after(session.client)
    # The page has laid its control panel out (the canvas is first as wide as the page).
    assert wait_until(lambda: page.canvas_box()["width"] < 0.6 * 1280, 20), page.canvas_box()
    before_box = page.canvas_box()
    thin = session.scene.look.trace_width
    # The herpolhode alone is measured: the plane's grid and the compact legend's swatch share
    # its hue (darker, thinner), which made a measure of the whole page read 2 px either way.
    others = [e for e in Element if e is not Element.HERPOLHODE]
    for element in others:
        session.set_visible(element, False)
    assert wait_until(lambda: not any(session.scene.is_visible(e) for e in others), 10)
    thin_px = trace_thickness(page, session)
    root = "parseFloat(getComputedStyle(document.documentElement).fontSize)"
    base_font = page.page.evaluate(root)
    page.set_checkbox("Projector mode", True)
    assert wait_until(lambda: session.lecture.display.style.projector, 10)
    # The flag is set before the scene is recoloured: wait for the projector's colours.
    projector_look = palette.look(True, projector=True)
    assert wait_until(lambda: session.scene.look is projector_look, 20), session.scene.look
    look = session.scene.look
    # The control panel folds to its strip; the left column stays, a compact legend and t.
    wider = before_box["width"] + 100
    assert wait_until(lambda: page.canvas_box()["width"] > wider, 10), page.canvas_box()
    # The lines are drawn twice as thick (3.5 to 7 px), and the picture shows it: the trace's
    # pixels of its own colour (its anti-aliased edge left out) are thicker by more than 1.4.
    assert look.trace_width >= 1.9 * thin, (thin, look.trace_width)
    thick_px = trace_thickness(page, session)
    assert thick_px >= 1.4 * thin_px, (thin_px, thick_px)
    for element in others:
        session.set_visible(element, True)
    # A column opened from its strip shows its text large.
    session.client.gui.main_panel.expand()
    assert wait_until(lambda: page.page.evaluate(root) >= base_font * 1.45, 10)
    session.client.gui.main_panel.minimize()
    # Key P switches it off again: the columns are back.
    page.page.mouse.click(640, 790)
    page.page.keyboard.press("p")
    assert wait_until(lambda: not session.lecture.display.style.projector, 10)
    assert wait_until(lambda: page.canvas_box()["width"] < 0.6 * 1280, 10), page.canvas_box()
    assert PROJECTOR_TEXT_PERCENT >= 140
    assert page.errors == []


# -- 8. (continued) the labels, on a page of a fixed pixel ratio (the module's last) -------
@pytest.mark.parametrize("view", ["default", "along-L", "side"])
def test_labels_stand_apart_and_off_the_contact_point(pages, view):
    """The labels' pixels (a picture with them against one without) fall into one patch per
    label, none of them on the contact point's marker."""
    # Two pictures compared pixel by pixel: the canvas's pixel ratio must not change between
    # them (viser lowers it while frames are slow; a URL option of its client holds it).
    page, session = pages.get(1280, 800, "?fixedDpr=1")
    page.set_live_view(True)
    started(session, frames=40)
    pause(page, session)
    session.lecture.set_camera(view)  # (the views are pressed from the keyboard in another test)
    # The layout is for the camera the browser reports: wait until the view has settled there
    # (under load the animation to it outlasts any fixed wait).
    # (the side and along-L views framed for this page's view: the view the lecture sent)
    target, camera_handle = session.lecture.view(view), session.client.camera
    assert wait_until(
        lambda: (
            np.allclose(camera_handle.position, target.position, atol=1e-3)
            and np.allclose(camera_handle.look_at, target.look_at, atol=1e-3)
        ),
        20,
    ), (view, camera_handle.position, camera_handle.look_at)
    # ... and reports the canvas's size (a page just opened reports it again as its columns
    # dock): the layout's pixels are those of the camera reported.
    page.settled_canvas(session.client)
    lay_out_on_the_frame_thread(session)
    shown = drawn_screenshot(page, session.client)
    handles = label_handles(session)
    assert len(handles) == 7
    for handle in handles:
        handle.visible = False
    hidden = drawn_screenshot(page, session.client)
    for handle in handles:
        handle.visible = True
    box = page.canvas_box()
    mask = np.abs(shown - hidden).sum(axis=2) > 60
    mask[:, : int(box["x"])] = mask[:, int(box["x"] + box["width"]) :] = False
    patches, count = ndimage.label(mask)  # a label's box is solid: one patch per box
    sizes = ndimage.sum(mask, patches, range(1, count + 1))
    patches_seen = int(np.sum(sizes > 40))
    camera = browser_camera(session.client)
    on_screen = 0
    for handle in handles:
        xy, depth = camera.project(np.asarray(handle_world(session, handle)))
        x, y = xy[0]
        on_screen += int(depth[0] > 0 and 0 <= x < camera.width and 0 <= y < camera.height)
    assert patches_seen >= on_screen, (patches_seen, on_screen)
    # The contact point's marker is not under a label. The camera's pixels are the canvas's
    # drawing buffer: CSS pixels times the device-pixel ratio viser adapts (0.75 to 1 of the
    # screen's, lower while rendering is slow, as software WebGL often is).
    xy, _ = camera.project(np.asarray(session.frame.contact))
    css_per_pixel = box["width"] / camera.width
    cx, cy = xy[0] * css_per_pixel
    cx, cy = int(round(cx + box["x"])), int(round(cy + box["y"]))
    # A label is one solid patch; single pixels where the two renders differ (the plane's
    # grid seen edge-on) are no label.
    labels = np.isin(patches, 1 + np.flatnonzero(sizes > 40))
    assert not labels[cy - 4 : cy + 5, cx - 4 : cx + 5].any(), "a label covers the contact point"
    assert page.errors == []


def trace_thickness(page, session) -> float:
    """The herpolhode's mean thickness in the 3D view, once the page has drawn what was sent
    [pixels]: the pixels of its colour, in patches of a trace's size."""
    rgb, box = drawn_screenshot(page, session.client), page.canvas_box()
    x, y = int(box["x"]), int(box["y"])
    view = rgb[y : y + int(box["height"]), x : x + int(box["width"])]
    mask = in_patches(near(view, session.scene.look.herpolhode), 200)
    assert mask.sum() > 500, f"only {mask.sum()} pixels of the herpolhode"
    return line_thickness(mask)


def drawn_screenshot(page, client) -> np.ndarray:
    """The page's pixels, as ints, once it has drawn what was sent to ``client`` before."""
    page.drawn_after(client)
    return page.screenshot_rgb().astype(int)


def handle_world(session, handle) -> np.ndarray:
    """A label's point in world coordinates (its parent frame's pose applied)."""
    from poinsot.app.construction.sampled.frames import rotation_from_wxyz

    position = np.asarray(handle.position, float)
    if "/body/" in handle.name:
        return rotation_from_wxyz(session.frame.wxyz).apply(position)
    if "/tip/" in handle.name:
        return np.asarray(session.frame.contact) + position
    return position
