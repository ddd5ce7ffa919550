"""The page's layout at the sizes a lecture and a class meet, in Chromium
(app/live/lecture/display.py, app/live/lecture/layout.py):

- Large text at 1920 x 1080: no text of the panels is cut or spills (``scrollWidth >
  clientWidth`` on every element that holds text), no horizontal scrollbar, slider tracks a
  finger's width and more, the scene's labels grown with the text;
- the projector mode keeps a compact legend and t;
- a phone held upright: the bottom sheet the screen's width, t and the regime in its header,
  every touch target (buttons, menu rows, fields, sliders, check boxes) at least 44 px tall.
"""

from __future__ import annotations

import re

import pytest
from conftest import after_frames, session_of, wait_until
from test_picture_page import label_handles
from test_touch_page import open_device

from poinsot.app.live.lecture.display import LARGE_TEXT_PERCENT
from poinsot.app.live.lecture.layout import TOUCH_TARGET_PX

pytestmark = pytest.mark.browser

#: Every element of the panels (not the 3D view) that holds text of its own, measured on the
#: nearest box that is not inline (an inline element has no client width): those whose text is
#: wider than their box (cut by an ellipsis or hidden, or spilling over its neighbours), with
#: their text and widths; and the panels' scroll boxes that scroll sideways.
CLIPPED_JS = """() => {
  const boxOf = (e) => {
    while (e && getComputedStyle(e).display === 'inline') e = e.parentElement;
    return e;
  };
  const shown = (e) => {
    const r = e.getBoundingClientRect();
    if (r.width === 0 || r.height === 0) return false;
    for (let a = e; a; a = a.parentElement) {
      const s = getComputedStyle(a);
      if (s.display === 'none' || s.visibility === 'hidden') return false;
      if (a !== e && s.overflow === 'hidden' && a.getBoundingClientRect().height < 2) return false;
    }
    return true;
  };
  const cut = [], seen = new Set();
  for (const e of document.querySelectorAll('body *')) {
    if (e.closest('canvas') || e.tagName === 'SCRIPT' || e.tagName === 'STYLE') continue;
    const own = [...e.childNodes].some((n) => n.nodeType === 3 && n.textContent.trim());
    if (!own) continue;
    const box = boxOf(e);
    if (!box || seen.has(box) || !shown(box)) continue;
    seen.add(box);
    if (box.scrollWidth > box.clientWidth + 1) {
      cut.push([box.innerText.slice(0, 40), box.scrollWidth, box.clientWidth]);
    }
  }
  const sideways = [...document.querySelectorAll('body *')].filter((e) => {
    const s = getComputedStyle(e);
    return (s.overflowX === 'auto' || s.overflowX === 'scroll') && shown(e)
      && e.scrollWidth > e.clientWidth + 1;
  }).map((e) => [e.className.toString().slice(0, 40), e.scrollWidth, e.clientWidth]);
  return {cut, sideways};
}"""

#: The widths of the slider tracks shown [CSS px].
TRACKS_JS = """() => [...document.querySelectorAll('.mantine-Slider-track')]
  .map((e) => e.getBoundingClientRect().width).filter((w) => w > 0)"""


def test_large_text_at_1920_cuts_no_text_and_grows_the_labels(poinsot_app, open_page):
    page = open_page(poinsot_app.url, 1920, 1080, live_view=False)
    session = session_of(poinsot_app, timeout=60)
    assert wait_until(lambda: session.running and session.lecture is not None, 30)
    labels = label_handles(session)
    normal = [handle.font_screen_scale for handle in labels]
    assert page.page.evaluate(CLIPPED_JS) == {"cut": [], "sideways": []}
    page.set_checkbox("Large text", True)
    display = session.lecture.display
    assert wait_until(lambda: display.style.large_text, 20)
    root = "parseFloat(getComputedStyle(document.documentElement).fontSize)"
    assert wait_until(lambda: page.page.evaluate(root) == 16 * LARGE_TEXT_PERCENT / 100, 20)
    # The columns widen with the text (viser docks them in one layout pass after the message).
    after_frames(session, 10)
    assert wait_until(lambda: page.page.evaluate(CLIPPED_JS) == {"cut": [], "sideways": []}, 20), (
        page.page.evaluate(CLIPPED_JS)
    )
    tracks = page.page.evaluate(TRACKS_JS)
    assert len(tracks) >= 6 and min(tracks) >= 100, tracks
    assert len(labels) == 7
    for handle, scale in zip(labels, normal, strict=True):
        assert handle.font_screen_scale == pytest.approx(scale * LARGE_TEXT_PERCENT / 100)
    assert page.errors == []


def test_the_projector_keeps_a_compact_legend_and_t(poinsot_app, open_page):
    page = open_page(poinsot_app.url, 1920, 1080, live_view=False)
    session = session_of(poinsot_app, timeout=60)
    assert wait_until(lambda: session.running and session.lecture is not None, 30)

    # The picture ends where the control panel begins (the page has laid the panel out: the
    # canvas is first as wide as the page), then at the folded panel's strip.
    def right() -> float:
        box = page.canvas_box()
        return box["x"] + box["width"]

    assert wait_until(lambda: right() < 1920 - 200, 20), page.canvas_box()
    page.set_checkbox("Projector mode", True)
    assert wait_until(lambda: session.lecture.display.style.projector, 20)
    assert wait_until(lambda: right() > 1920 - 60, 20), page.canvas_box()
    legend = page.page.locator('[data-legend="herpolhode (plane)"]').first
    assert wait_until(legend.is_visible, 20)
    time = page.page.locator("p").filter(has_text=re.compile(r"t = +\d")).first
    assert time.is_visible()
    # Compact: the caption, the readouts' table and the plot are not in it.
    assert wait_until(lambda: page.page.locator("table").count() == 0, 20)
    assert not session.panel.motion.readouts.visible
    assert page.page.evaluate(CLIPPED_JS)["cut"] == []
    assert page.errors == []


#: The phone's bottom sheet, and its box [CSS px] (null before the page has laid it out).
SHEET = '.mantine-Paper-root[style*="bottom: 0px"]'
SHEET_BOX_JS = f"""() => {{
  const e = document.querySelector('{SHEET}');
  if (!e) return null;
  const r = e.getBoundingClientRect();
  return {{x: r.x, width: r.width, height: r.height}};
}}"""

#: The touch targets of the page laid out (in the sheet, scrolled to or not) [CSS px high].
TARGETS_JS = """() => {
  const kinds = {
    button: 'button', option: '[role=option]', field: 'input.mantine-Input-input',
    slider: '.mantine-Slider-root', checkbox: '.mantine-Checkbox-root',
  };
  const out = {};
  for (const [kind, selector] of Object.entries(kinds)) {
    out[kind] = [...document.querySelectorAll(selector)].map((e) => e.getBoundingClientRect())
      .filter((r) => r.width > 0 && r.height > 0)
      .map((r) => r.height);
  }
  return out;
}"""


def test_a_phone_s_sheet_is_full_width_with_t_and_the_regime_and_44_px_targets(
    poinsot_app, open_page
):
    page = open_device(open_page, poinsot_app.url, "phone-portrait", live_view=False)
    session = session_of(poinsot_app, timeout=60)
    assert wait_until(lambda: session.layout is not None and session.layout.compact, 30)
    sheet = page.page.locator(SHEET).first
    box: dict[str, float] | None = None

    def full_width() -> bool:  # once the page has laid out the compact layout the server sent
        nonlocal box
        box = page.page.evaluate(SHEET_BOX_JS)
        return box is not None and box["x"] == 0 and box["width"] == 390

    assert wait_until(full_width, 20), box
    # The header: t and the regime, as the server last wrote them.
    header = re.compile(r"t = \d+\.\d · polhode around the major axis")
    assert wait_until(lambda: header.fullmatch(session.layout.header) is not None, 20)
    assert wait_until(lambda: header.search(sheet.inner_text()) is not None, 20)
    # The page folds the sheet once it is there (one tap on its bar): a tap before that fold
    # would fold it itself, and the page's fold would then find nothing to do.
    folded = "() => window.poinsotSheetFolded === true"
    assert wait_until(lambda: page.page.evaluate(folded), 30)
    assert wait_until(lambda: page.page.evaluate(SHEET_BOX_JS)["height"] < 100, 20)
    # Opened: every target a finger meets is 44 px tall, the Preset menu's rows too.
    page.page.get_by_text(header).first.click()
    assert wait_until(lambda: page.page.evaluate(SHEET_BOX_JS)["height"] > 200, 20)
    targets = page.page.evaluate(TARGETS_JS)
    assert targets["button"] and targets["slider"] and targets["field"], targets
    for kind, heights in targets.items():
        assert all(h >= TOUCH_TARGET_PX - 0.5 for h in heights), (kind, heights)
    page.page.locator(f"[id='{page.widget_id('Preset')}']").click()
    rows: list[float] = []

    def listed() -> bool:  # the menu's rows, once it has laid them out (it opens animated)
        nonlocal rows
        rows = page.page.evaluate(TARGETS_JS)["option"]  # one read of them all, none waited for
        return len(rows) >= 5

    assert wait_until(listed, 10), rows
    assert min(rows) >= TOUCH_TARGET_PX - 0.5, rows
    assert page.errors == []
