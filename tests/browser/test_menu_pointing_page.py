"""The menu in groups and pointing that shows itself, in Chromium at 1280×800.

* The Preset menu lists its entries under headings (presets, textbook scenes, your own body, the
  challenges), a scene by its name without "Scene: ", chosen from the keyboard too; the chosen
  scene's whole name is on the page, uncut; the T-handle preset says Dzhanibekov.
* The Scene folder says that the ellipsoid can be clicked; a click beside the body says it
  missed; a click on the ellipsoid starts there and the sliders do not move (no folder comes
  above them).
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import css_pixel, session_of, wait_until

from poinsot.app.lessons import scene_by_name
from poinsot.app.live.lecture import challenges
from poinsot.app.live.panel.panel import MENU_OWN, MENU_PRESETS, MENU_SCENES, shown_label
from poinsot.app.live.pointing.pointer import MISSED
from poinsot.app.model.presets import preset_by_key

pytestmark = pytest.mark.browser

#: viser's drag binding on the ellipsoid answers a mouse press so.
DRAG_BINDING = "Unable to preventDefault inside passive event listener invocation."


def test_the_menu_shows_its_groups_and_a_scene_whole(make_app, open_page) -> None:
    app = make_app()
    page = open_page(app.url, width=1280, height=800, live_view=False)
    session = session_of(app)
    menu = page.page.locator(f"[id='{page.widget_id('Preset')}']")
    menu.click()
    listbox = page.page.get_by_role("listbox")
    for heading in (MENU_PRESETS, MENU_SCENES, MENU_OWN, challenges.MENU_GROUP):
        listbox.get_by_text(heading, exact=True).wait_for(timeout=15000)
    handle = preset_by_key("t_handle").label
    assert "Dzhanibekov" in handle
    listbox.get_by_role("option", name=handle, exact=True).wait_for(timeout=15000)
    groups = listbox.get_by_role("group")
    assert groups.count() == 4
    scenes = groups.nth(1).get_by_role("option")
    assert groups.nth(1).get_attribute("aria-labelledby")  # named by its heading
    assert scenes.count() == 8 and not any("Scene:" in t for t in scenes.all_inner_texts())
    page.page.keyboard.press("Escape")
    # from the keyboard: type part of a scene's name, then Enter
    spec = scene_by_name("dzhanibekov")
    menu.focus()
    page.page.keyboard.press("Control+a")
    page.page.keyboard.type("theory vs")  # the menu filters as one types
    page.page.get_by_role("option", name=shown_label(spec.label)).wait_for(timeout=15000)
    page.page.keyboard.press("ArrowDown")
    page.page.keyboard.press("Enter")
    assert wait_until(lambda: session.preset.label == spec.label, 30), session.preset.label
    name = page.page.get_by_text(shown_label(spec.label), exact=True).first
    name.wait_for(timeout=15000)
    assert name.evaluate("e => e.scrollWidth <= e.clientWidth")  # the whole name, uncut
    assert page.errors == [], page.errors


def test_a_click_beside_the_body_says_so_and_one_on_it_moves_no_slider(make_app, open_page):
    app = make_app()
    page = open_page(app.url, width=1280, height=800)
    session = session_of(app)
    pointer = session.pointer
    page.page.get_by_text("Click the ellipsoid to start ω there.").wait_for(timeout=20000)
    box = page.settled_canvas(session.client)
    camera = session.client.camera
    # beside the body: a corner of the view, far from the ellipsoid
    corner = css_pixel(camera, box, np.asarray(camera.look_at, float))
    page.page.mouse.click(corner[0] - 0.45 * box["width"] / 2, box["y"] + 0.1 * box["height"])
    missed = MISSED.format(verb="click").replace("**", "")
    page.page.get_by_text(missed).wait_for(timeout=20000)
    assert pointer.misses >= 1 and pointer.starts == 0
    slider = page.page.locator(f"[id='{page.widget_id('I₁')}']")
    before = slider.bounding_box()
    body = session.body
    assert body is not None and before is not None
    x, y = css_pixel(camera, page.settled_canvas(session.client), np.zeros(3))
    page.page.mouse.click(x, y)
    assert wait_until(lambda: pointer.starts == 1 and session.body is not body, 20)
    assert wait_until(lambda: session.preset.key == "custom" and not session.build.dirty, 20)
    page.page.get_by_text("Click the ellipsoid to start ω there.").wait_for(timeout=20000)
    after_frames = page.frames_drawn()
    assert wait_until(lambda: page.frames_drawn() >= after_frames + 2, 30)
    assert slider.bounding_box() == before  # no folder came above the sliders
    assert set(page.errors) <= {DRAG_BINDING}, page.errors
    assert session.stats.errors == 0, session.stats.last_error
