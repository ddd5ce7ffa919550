"""The page for everyone (WCAG 2.1 AA), in Chromium: axe-core (through axe-playwright-python)
finds no serious or critical violation on the default page and on every textbook scene, on a
laptop and on a phone, in the dark and the light theme, with every folder open; every slider
and number box has a name; every folder opens from the keyboard; the paired buttons show
which one is on; a drag on the scene logs no error. What viser's own client leaves out is added
from the page (app/viser_private/page.py, :func:`make_accessible`)."""

from __future__ import annotations

import re

import numpy as np
import pytest
from conftest import BrowserPage, lecture_of, wait_until
from test_touch_page import IPHONE, screen_point

from poinsot.app.lessons import scene_by_name, scene_names
from poinsot.app.model.presets import DEFAULT_PRESET

pytestmark = pytest.mark.browser

#: axe-core's rules of WCAG 2.0 and 2.1, levels A and AA.
WCAG_TAGS = ["wcag2a", "wcag2aa", "wcag21a", "wcag21aa"]
#: axe-core's rules that read colours (the rest read the page's structure, the same in either
#: theme).
COLOUR_RULES = ["color-contrast", "link-in-text-block"]
#: The impacts that fail: a blind or keyboard user cannot use the control, or cannot read it.
FAILING = ("serious", "critical")
#: A laptop, and a phone held upright (touch, its browser's User-Agent: the compact page).
SIZES = {"laptop": (1280, 800, None), "phone": (390, 844, IPHONE)}
#: The sliders of the default page, by name: a screen reader says "I₁ slider", not "slider".
SLIDERS = ("I₁", "I₂", "I₃", "D = |L|²/2T", "|ω₀|", "Speed", "Trail length", "Video length [s]")

#: Opens every folder of the panel (a header whose chevron points down; an empty folder's
#: chevron is hidden), as many times as new ones appear; returns how many it opened.
_OPEN_FOLDERS_JS = """() => {
  let opened = 0;
  for (const icon of document.querySelectorAll("svg.tabler-icon-chevron-down")) {
    const header = icon.parentElement;
    if (icon.style.display === "none" || !header.parentElement.classList.contains(
        "mantine-Paper-root")) continue;
    header.click();
    opened++;
  }
  return opened;
}"""

_FOLDERS_JS = """() => [...document.querySelectorAll("[data-poinsot-folder][role=button]")]
  .map((e) => [e.textContent.trim(), e.getAttribute("aria-expanded")])"""


#: The folder header that has the focus: [its title, aria-expanded], or null.
_FOCUSED_FOLDER_JS = """() => {
  const e = document.activeElement;
  if (!e || !e.hasAttribute("data-poinsot-folder")) return null;
  return [e.textContent.trim(), e.getAttribute("aria-expanded")];
}"""
_BUTTONS = "[...document.querySelectorAll('button')].filter((b) => b.textContent.trim() === name)"
#: The aria-pressed of the buttons named ``name``, and the background of the first.
_PRESSED_JS = f"(name) => {_BUTTONS}.map((b) => b.getAttribute('aria-pressed'))"
_BACKGROUND_JS = f"(name) => getComputedStyle({_BUTTONS}[0]).backgroundColor"


#: Every visible text on the page whose contrast with the background under it (its ancestors'
#: backgrounds composited) is below WCAG's 4.5:1 (3:1 for large text): "text: ratio". axe-core
#: leaves the phone's bottom sheet undecided ("overlapped by another element"); this decides it.
_LOW_CONTRAST_JS = r"""() => {
  const rgba = (s) => {
    const v = s.match(/[\d.]+/g).map(Number);
    return v.length === 3 ? [...v, 1] : v;
  };
  const over = (top, under) =>
    [0, 1, 2].map((i) => top[i] * top[3] + under[i] * (1 - top[3])).concat([1]);
  const lin = (c) => (c /= 255) <= 0.03928 ? c / 12.92 : ((c + 0.055) / 1.055) ** 2.4;
  const lum = (c) => 0.2126 * lin(c[0]) + 0.7152 * lin(c[1]) + 0.0722 * lin(c[2]);
  const background = (e) => {
    const layers = [];
    for (let a = e; a; a = a.parentElement) {
      const c = rgba(getComputedStyle(a).backgroundColor);
      if (c[3] > 0) layers.push(c);
      if (c[3] >= 1) break;
    }
    return layers.reverse().reduce((under, top) => over(top, under), [255, 255, 255, 1]);
  };
  const low = [], seen = new Set();
  const walker = document.createTreeWalker(document.body, NodeFilter.SHOW_TEXT);
  for (let n = walker.nextNode(); n; n = walker.nextNode()) {
    const e = n.parentElement;
    if (!n.textContent.trim() || seen.has(e) || e.closest("svg, canvas, script, style")) continue;
    seen.add(e);
    const box = e.getBoundingClientRect();
    const shown = e.checkVisibility({ opacityProperty: true, visibilityProperty: true });
    if (!box.width || !box.height || !shown) continue;
    const style = getComputedStyle(e);
    const bg = background(e), fg = over(rgba(style.color), bg);
    const ratio = (Math.max(lum(fg), lum(bg)) + 0.05) / (Math.min(lum(fg), lum(bg)) + 0.05);
    const size = parseFloat(style.fontSize), bold = parseInt(style.fontWeight) >= 700;
    const large = size >= 24 || (bold && size >= 18.66);
    const text = n.textContent.trim().slice(0, 30);
    if (ratio < (large ? 3 : 4.5)) low.push(`${text}: ${ratio.toFixed(2)}`);
  }
  return low;
}"""


def open_at(open_page, app, scene: str | None, size: str) -> tuple[BrowserPage, object]:
    """A page on ``app`` (``?scene=``), its session once its scene is loaded and the page's
    accessibility script runs."""
    width, height, agent = SIZES[size]
    options = {} if agent is None else {"has_touch": True, "is_mobile": True, "user_agent": agent}
    query = "" if scene is None else f"?scene={scene}"
    known = set(app.sessions())
    page = open_page(app.url + query, width, height, live_view=False, **options)
    assert wait_until(lambda: bool(set(app.sessions()) - known), 30), "no session"
    session = app.sessions()[max(set(app.sessions()) - known)]
    if scene is not None:
        assert wait_until(
            lambda: (
                session.showcase is not None
                and session.showcase.spec.name == scene
                and session.showcase.loaded
            ),
            30,
        ), scene
    assert wait_until(lambda: page.page.evaluate("() => !!window.poinsotA11y"), 30)
    return page, session


def open_sheet(page: BrowserPage, session) -> None:
    """On a phone, the bottom sheet opened (the page folds it once it is there: a tap then)."""
    if session.layout is None or not session.layout.compact:
        return
    assert wait_until(lambda: page.page.evaluate("() => window.poinsotSheetFolded === true"), 30)
    slider = page.page.get_by_role("slider").first
    if not slider.is_visible():
        # its header: t and the regime (the page's layout writes them there)
        page.page.get_by_text(re.compile(r"^t = \d+\.\d")).first.tap()
    assert wait_until(slider.is_visible, 15), "the sheet did not open"


def open_every_folder(page: BrowserPage) -> None:
    assert wait_until(lambda: page.page.evaluate(_OPEN_FOLDERS_JS) == 0, 15), "folders stay shut"


def axe_failures(page: BrowserPage, rules: list[str] | None = None) -> dict[str, list[str]]:
    """axe-core's serious and critical WCAG 2.1 A/AA violations on the page (of ``rules`` only,
    if given): rule -> the elements (their selectors), once the accessibility script has seen
    the page as it is.

    A widget still arriving when axe runs is named by the script's next pass (50 ms after the
    page changes): the page is scanned again until it is clean, for 30 s at most, and the last
    scan's violations are returned (a loaded machine once scanned two sliders in that gap)."""
    found: dict[str, list[str]] = {}

    def clean() -> bool:
        nonlocal found
        found = _axe_scan(page, rules)
        return not found

    wait_until(clean, 30, poll=0.5)
    return found


def _axe_scan(page: BrowserPage, rules: list[str] | None) -> dict[str, list[str]]:
    from axe_playwright_python.sync_playwright import Axe

    page.page.evaluate("() => window.poinsotA11y.apply()")
    only = (
        {"type": "tag", "values": WCAG_TAGS} if rules is None else {"type": "rule", "values": rules}
    )
    options = {"runOnly": only, "resultTypes": ["violations"]}
    results = Axe().run(page.page, options=options).response
    return {
        rule["id"]: [" ".join(map(str, node["target"])) for node in rule["nodes"]]
        for rule in results["violations"]
        if rule["impact"] in FAILING
    }


@pytest.fixture(scope="module")
def app(make_module_app):
    return make_module_app()


@pytest.fixture(scope="module")
def size_pages() -> dict[str, tuple[BrowserPage, object]]:
    """The page of each size that the scans walk through the scenes (:func:`scene_on`)."""
    return {}


def scene_on(pages, open_page, app, scene: str | None, size: str) -> tuple[BrowserPage, object]:
    """The page of ``size`` showing ``scene`` (None: the default preset), in the dark theme.
    The first of a size opens on it (``?scene=``); the others are chosen on that page, as from
    its menu, once the scene's controls are there (a page opens at 4 to 5 CPU-s of Chromium,
    and the scans read the panel, not how the page came to it)."""
    if size not in pages:
        pages[size] = open_at(open_page, app, scene, size)
        return pages[size]
    page, session = pages[size]
    page.errors.clear()  # the case before checked them
    spec = None if scene is None else scene_by_name(scene)
    shown = None if session.showcase is None else session.showcase.spec
    if shown is not spec:
        if spec is None:
            session.choose_preset(DEFAULT_PRESET)
        else:
            session.choose_scene(spec)
        assert wait_until(
            lambda: (
                session.showcase is None and session.preset is DEFAULT_PRESET
                if spec is None
                else session.showcase is not None
                and session.showcase.spec is spec
                and session.showcase.loaded
            ),
            60,
        ), scene
    labels = SLIDERS[:1] if spec is None else tuple(c.label for c in spec.controls)
    for label in labels:
        assert wait_until(lambda la=label: page.control_count(la) == 1, 30), (scene, label)
    lecture_of(session).set_theme(dark=True)
    dark = "() => document.documentElement.dataset.mantineColorScheme === 'dark'"
    assert wait_until(lambda: page.page.evaluate(dark), 30), "the dark theme never came"
    return page, session


@pytest.mark.parametrize("size", list(SIZES))
@pytest.mark.parametrize("scene", [None, *scene_names()])
def test_axe_finds_no_serious_violation(app, open_module_page, size_pages, scene, size) -> None:
    """Every folder open, in the dark theme (every rule), then the light one on the same page
    (the colours: the other rules read the same page in either theme). Paused once the page
    is laid out: a playing page's panel is the same, its readouts rewritten a few times a
    second (Chromium at 0.4 core against 0.05 paused, while axe reads the page)."""
    page, session = scene_on(size_pages, open_module_page, app, scene, size)
    open_sheet(page, session)
    open_every_folder(page)
    if not session.clock.paused:
        session.toggle_pause()
        assert wait_until(
            lambda: page.page.get_by_role("button", name="Play", exact=True).count() >= 1, 30
        )
    found = {"dark": axe_failures(page)}
    low = {"dark": page.page.evaluate(_LOW_CONTRAST_JS)}
    lecture_of(session).set_theme(dark=False)
    light = "() => document.documentElement.dataset.mantineColorScheme === 'light'"
    assert wait_until(lambda: page.page.evaluate(light), 30), "the light theme never came"
    found["light"] = axe_failures(page, COLOUR_RULES)
    low["light"] = page.page.evaluate(_LOW_CONTRAST_JS)
    counts = {
        theme: {rule: len(nodes) for rule, nodes in rules.items()} for theme, rules in found.items()
    }
    print(f"axe {scene or 'default'} {size}: {counts}; below 4.5:1: {low}")
    assert found == {"dark": {}, "light": {}}, found
    assert low == {"dark": [], "light": []}, low
    assert page.errors == []


def test_every_slider_and_number_box_has_a_name(app, open_page) -> None:
    page, _ = open_at(open_page, app, None, "laptop")
    sliders = page.page.get_by_role("slider", include_hidden=True)
    assert wait_until(lambda: sliders.count() == len(SLIDERS), 20), sliders.count()
    for name in SLIDERS:
        named = page.page.get_by_role("slider", name=name, exact=True, include_hidden=True)
        box = page.page.get_by_role(
            "textbox", name=f"{name} value", exact=True, include_hidden=True
        )
        assert wait_until(lambda: named.count() == 1 and box.count() == 1, 10), name  # noqa: B023
    for field in page.page.get_by_role("textbox", include_hidden=True).all():
        assert field.evaluate("e => !!(e.labels.length || e.getAttribute('aria-label'))")
    # The two icon buttons of the panel's header are named; one opens viser's configuration
    # view (the server's address, the scene tree), which axe finds clean too.
    header = page.page.locator(".mantine-ActionIcon-root")
    names = [b.get_attribute("aria-label") for b in header.all()]
    assert len(names) == 2 and all(names), names
    page.click_button("Configuration & diagnostics")
    server = page.page.get_by_role("textbox", name="Server URL", exact=True)
    assert wait_until(server.is_visible, 10)
    assert axe_failures(page) == {}
    page.click_button("Return to the controls")
    assert wait_until(page.page.get_by_role("slider", name="I₁").is_visible, 10)
    assert page.errors == []


def test_every_folder_opens_with_tab_and_enter(app, open_page) -> None:
    """From the top of the page, Tab to each shut folder's header, Enter: it opens."""
    page, _ = open_at(open_page, app, None, "laptop")

    def shut_folders() -> set[str]:
        return {name for name, open_ in page.page.evaluate(_FOLDERS_JS) if open_ == "false"}

    # The panel's folders arrive one by one (four were there, once, when five were read).
    assert wait_until(lambda: len(shut_folders()) >= 5, 30), page.page.evaluate(_FOLDERS_JS)
    shut = shut_folders()
    opened: set[str] = set()
    for _ in range(600):  # the panel's widgets: a few hundred stops at the most
        page.page.keyboard.press("Tab")
        header = page.page.evaluate(_FOCUSED_FOLDER_JS)
        if header is None or header[1] == "true":
            continue
        page.page.keyboard.press("Enter")
        name = header[0]
        now_open = [name, "true"]
        assert wait_until(lambda: page.page.evaluate(_FOCUSED_FOLDER_JS) == now_open, 10), name  # noqa: B023
        opened.add(name)
        if opened >= shut:
            break
    assert opened >= shut, shut - opened
    assert page.errors == []


def pressed(page: BrowserPage, pair: tuple[str, str]) -> str | None:
    """The one button of ``pair`` shown pressed (aria-pressed), or None if not exactly one."""
    states = {name: page.page.evaluate(_PRESSED_JS, name) for name in pair}
    on = [name for name, state in states.items() if state == ["true"]]
    off = [name for name, state in states.items() if state == ["false"]]
    return on[0] if len(on) == 1 and len(off) == 1 else None


def test_the_paired_buttons_show_which_one_is_on(app, open_page) -> None:
    """The default preset's: the default view, the major axis, + pole; a click on the other
    button of each pair presses it (and the server's state follows)."""
    page, session = open_at(open_page, app, None, "laptop")
    open_every_folder(page)
    pairs = (("default", "side"), ("major axis", "minor axis"), ("+ pole", "− pole"))
    for on, off in pairs:
        assert wait_until(lambda: pressed(page, (on, off)) == on, 20), on  # noqa: B023
        assert page.page.evaluate(_BACKGROUND_JS, on) != page.page.evaluate(_BACKGROUND_JS, off)
        page.click_button(off)
        assert wait_until(lambda: pressed(page, (on, off)) == off, 20), off  # noqa: B023
    assert lecture_of(session).camera == "side"
    assert session.params.side() == "minor" and session.params.pole_sign == -1
    assert page.errors == []


def test_a_drag_on_the_scene_logs_no_console_error(app, open_page) -> None:
    """A press and a drag on the energy ellipsoid (viser's drag binding on a node: a start
    pointed at by hand), released: the start is set, and the console holds no error."""
    page, session = open_at(open_page, app, None, "laptop")
    page.set_live_view(True)
    body = session.body
    x, y = screen_point(session, page, np.zeros(3))
    mouse = page.page.mouse
    mouse.move(x, y)
    mouse.down()
    for k in range(1, 8):
        mouse.move(x + 3 * k, y + 2 * k)
    mouse.up()
    assert wait_until(lambda: session.pointer.starts >= 1 and session.body is not body, 20)
    assert page.errors == []
