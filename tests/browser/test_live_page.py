"""The app in a real browser: Debian's Chromium, driven through playwright, rendering viser's
WebGL client with SwiftShader. Each test drives the page like a user (keyboard on a slider
thumb, clicks on the dropdown, the buttons and the checkboxes) and checks both what the server
now holds and what the canvas shows.

The tests share one app and one page, in this order (each leaves the page as it needs the next
to find it, or says what it changed): a page load and a software-WebGL page's every
interaction cost seconds, and an open page that animates takes a core."""

from __future__ import annotations

import colorsys

import numpy as np
import pytest
from conftest import session_of, wait_until

from poinsot.app.construction import palette
from poinsot.app.devtools.probe import Probe
from poinsot.app.live.classroom import links
from poinsot.app.model.elements import Element
from poinsot.app.model.presets import DEFAULT_PRESET, preset_by_key
from tests.app.test_follow import _lead, _ready, _set

pytestmark = pytest.mark.browser

#: What Chromium logs when a mouse press lands on a node that viser binds for dragging.
DRAG_BINDING = "Unable to preventDefault inside passive event listener invocation."


def amber_fraction(rgb: np.ndarray) -> float:
    """Fraction of pixels with the ellipsoid's hue (amber, 22-45 degrees), saturated and not
    dark (every other pixel sampled)."""
    small = rgb[::2, ::2].reshape(-1, 3).astype(np.float64) / 255.0
    hsv = np.array([colorsys.rgb_to_hsv(*px) for px in small[small.max(axis=1) > 0.15]])
    if len(hsv) == 0:
        return 0.0
    hue = hsv[:, 0] * 360.0
    amber = (hue > 22) & (hue < 45) & (hsv[:, 1] > 0.3) & (hsv[:, 2] > 0.18)
    return float(np.sum(amber)) / len(small)


#: The ellipsoid's scale in viser's client (its scene tree, as the page holds it).
ELLIPSOID_SCALE_JS = """() => {
  const node = window.__viserSceneTree.getState()['/space/body/ellipsoid'];
  return node ? node.message.props.scale : null;
}"""


def canvas_pixels(page) -> np.ndarray:
    """The 3D view (left of the control panel) of a screenshot."""
    rgb = page.screenshot_rgb()
    return rgb[:, : int(rgb.shape[1] * 0.7)]


def started(app, frames: int = 20):
    session = session_of(app, timeout=60)  # a loaded machine: the page's session comes late
    assert wait_until(lambda: session.stats.frames >= frames, 20), "the scene is not animating"
    return session


def pause(page, session) -> None:
    page.click_button("Pause")
    assert wait_until(lambda: session.clock.paused, 30)


@pytest.fixture(scope="module")
def shared(make_module_app, open_module_page):
    """(app, page, its session): one page on one app for the whole module, drawing no live
    frames until the first test that reads the 3D view's pixels switches them on."""
    app = make_module_app()
    page = open_module_page(app.url, live_view=False)
    return app, page, started(app)


def test_page_loads_without_console_errors(shared):
    app, page, session = shared
    started(app, frames=60)
    page.drawn_after(session.client)
    assert page.errors == []
    assert session.stats.errors == 0, session.stats.last_error
    assert page.page.get_by_text("Stable about the major axis").count() >= 1


def test_the_browser_runs_no_web_page_of_its_own_beside_ours(shared):
    """Chromium's flags leave out its own web pages (the address bar's popup, preloaded for
    every new page: a renderer and its CPU each)."""
    _, page, _ = shared
    browser = page.page.context.browser
    assert browser is not None
    targets = browser.new_browser_cdp_session().send("Target.getTargets")["targetInfos"]
    assert any(t["url"].startswith("http://127.0.0.1") for t in targets), targets
    assert [t["url"] for t in targets if t["url"].startswith("chrome")] == []


def test_the_omega_plot_draws_its_three_components(shared):
    """The live uPlot of omega_1, omega_2, omega_3 (numeric time axis) shows three curves."""
    from PIL import Image

    app, page, _ = shared
    started(app, frames=30)
    plot = page.page.locator(".uplot-container").first
    plot.wait_for(state="visible", timeout=20000)
    import io

    colors = [np.array([int(c[i : i + 2], 16) for i in (1, 3, 5)]) for c in palette.PLOT_SERIES]
    near: list[int] = []

    def three_curves() -> bool:
        # The event: the plot shows its samples (as many as a loaded machine has drawn by then).
        rgb = np.asarray(Image.open(io.BytesIO(plot.screenshot())).convert("RGB")).astype(int)
        near[:] = [int(np.sum(np.abs(rgb - color).sum(axis=2) < 60)) for color in colors]
        return all(n > 40 for n in near)

    assert wait_until(three_curves, 30, poll=0.5), dict(zip(palette.PLOT_SERIES, near, strict=True))
    assert page.errors == []


def test_canvas_shows_the_ellipsoid(shared):
    app, page, _ = shared
    session = started(app)
    pause(page, session)
    page.set_live_view(True)  # and so it stays for the module's later tests
    page.drawn_after(session.client)
    shown = canvas_pixels(page)
    page.open_folder("Show")  # collapsed by default
    page.set_checkbox("energy ellipsoid", False)
    assert wait_until(lambda: not session.scene.is_visible(Element.ELLIPSOID), 30)
    page.drawn_after(session.client)
    hidden = canvas_pixels(page)
    # The semi-transparent amber ellipsoid covers a good part of the view; only it is amber.
    assert amber_fraction(shown) > 0.02, amber_fraction(shown)
    assert amber_fraction(hidden) < amber_fraction(shown) / 10, amber_fraction(hidden)
    assert page.errors == []
    # As the next test finds a new page: the ellipsoid shown, "Show" collapsed, playing.
    page.set_checkbox("energy ellipsoid", True)
    assert wait_until(lambda: session.scene.is_visible(Element.ELLIPSOID), 20)
    page.open_folder("Show")
    page.click_button("Play")
    assert wait_until(lambda: not session.clock.paused, 20)


def test_moving_a_slider_changes_the_scene(shared):
    app, page, _ = shared
    session = started(app)
    pause(page, session)
    page.drawn_after(session.client)
    before_pixels = canvas_pixels(page)
    before_axes = session.scene.geometry.semi_axes.copy()
    generation = session.generation
    # I1: 1.00 -> 1.15, 15 steps of 0.01 (and the steps an answer of the server took back)
    page.press_slider_to("I₁", 1.15, 0.01, lambda: session.params.inertia[0])
    assert wait_until(lambda: abs(session.params.inertia[0] - 1.15) < 1e-9, 10), session.params
    assert session.generation > generation
    assert page.slider_value("I₁") == pytest.approx(1.15)
    assert session.preset.key == "custom"  # a hand edit leaves the preset
    # the menu's new label is a message of its own, after the session's change
    assert wait_until(lambda: page.dropdown_value("Preset") == "Custom (edited)", 10)
    assert not np.allclose(session.scene.geometry.semi_axes, before_axes)
    page.drawn_after(session.client)
    after_pixels = canvas_pixels(page)
    changed = np.mean(np.any(np.abs(after_pixels.astype(int) - before_pixels) > 24, axis=2))
    assert changed > 0.01, f"only {changed:.4f} of the view changed"
    assert page.errors == []


def test_choosing_a_preset_changes_the_scene(shared):
    """After the slider's test: from the edited body (paused) to the sphere."""
    app, page, _ = shared
    session = started(app)
    page.drawn_after(session.client)
    before = canvas_pixels(page)
    sphere = preset_by_key("sphere")
    page.choose("Preset", sphere.label)
    assert wait_until(
        lambda: (
            session.preset.key == "sphere"
            and session.body is not None
            and session.params.inertia == sphere.inertia
        ),
        10,
    )
    # The sphere declares no traces and no energy control: they are gone from scene and panel.
    assert session.scene.elements == sphere.elements
    for gone in ("polhode (live)", "D = |L|²/2T", "Trail length"):
        assert wait_until(lambda g=gone: page.control_count(g) == 0, 15), gone
    assert page.control_count("|ω₀|") == 1  # declared by the sphere: still there
    assert np.allclose(session.scene.geometry.semi_axes, 1.0)
    page.drawn_after(session.client)
    after = canvas_pixels(page)
    changed = np.mean(np.any(np.abs(after.astype(int) - before) > 24, axis=2))
    assert changed > 0.01, f"only {changed:.4f} of the view changed"
    assert page.errors == []


def test_two_browsers_have_independent_sessions(shared, open_page):
    """The module's page is the first browser (it chooses a preset: any it showed before is
    replaced whole); a new page is the second, on the default preset."""
    app, first, a = shared
    second = open_page(app.url, live_view=False)
    assert wait_until(lambda: len(app.sessions()) == 2, 10)
    b = session_of(app, 2)
    assert a is not b
    assert wait_until(lambda: b.stats.frames > 10, 30)
    first.choose("Preset", preset_by_key("oblate").label)
    assert wait_until(lambda: a.preset.key == "oblate", 10)
    second.press_slider_to("|ω₀|", 1.4, 0.05, lambda: b.params.omega_norm)  # 4 steps up
    assert wait_until(lambda: b.params.omega_norm == pytest.approx(1.4), 10)
    # Each change stayed in its own session, scene and panel.
    assert b.preset.key == "custom" and a.params.omega_norm == preset_by_key("oblate").omega_norm
    assert a.params.inertia == preset_by_key("oblate").inertia
    assert b.params.inertia == DEFAULT_PRESET.inertia
    # the menus' labels are messages of their own, after the sessions' changes
    assert wait_until(lambda: second.dropdown_value("Preset") == "Custom (edited)", 10)
    assert wait_until(lambda: first.dropdown_value("Preset") == preset_by_key("oblate").label, 10)
    assert a.scene.api is not b.scene.api
    assert first.errors == [] and second.errors == []
    second.page.context.close()  # the next test counts one session


def test_a_real_browser_sends_only_what_the_wire_allows(shared):
    """Orbiting, a slider, a dropdown, a hotkey and a resize from Chromium's own viser client:
    every message passes the guard's allow-list, none is dropped, the session plays on. Last:
    it resizes the module's page. (I1 starts at 1: the default preset's, or the disc's that
    the test before chose.)"""
    app, page, session = shared
    assert wait_until(lambda: len(app.sessions()) == 1, 20), "another browser is still here"
    box = page.canvas_box()
    mouse = page.page.mouse
    mouse.move(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
    mouse.down()
    for k in range(20):  # an orbit: camera messages
        mouse.move(box["x"] + box["width"] / 2 + 8 * k, box["y"] + box["height"] / 2 + 3 * k)
    mouse.up()
    page.press_slider_to("I₁", 1.03, 0.01, lambda: session.params.inertia[0])  # 3 steps up
    assert wait_until(lambda: abs(session.params.inertia[0] - 1.03) < 1e-9, 10)
    page.choose("Preset", preset_by_key("minor").label)
    page.page.keyboard.press("Space")  # a command of the palette
    page.page.set_viewport_size({"width": 1001, "height": 777})
    frames = session.stats.frames
    assert wait_until(lambda: session.stats.frames > frames + 10, 30)
    guard = app.guard
    assert guard.closed_for_message == 0 and guard.malformed == 0 and guard.dropped == 0
    # A mouse press on the energy ellipsoid (its drag binding: a start is pointed at by hand)
    # makes Chromium note that viser's handler cannot cancel a passive event; nothing else may.
    errors = [e for e in page.errors if e != DRAG_BINDING]
    assert list(app.sessions().values()) == [session] and errors == []


def test_a_follower_s_body_turns_in_the_browser(shared):
    """Last: the page follows a lecturer (a probe; the page's panel is folded by the resize
    before, so its session follows as a link with ``follow=1`` makes it). Its poses then come
    from the process's cast, not its session's frames, and the view moves as the lecturer's
    body turns: a pose sent for another scope's node would be dropped by viser's client, the
    body standing still while only the traces grew."""
    app, page, session = shared
    page.page.set_viewport_size({"width": 1280, "height": 720})
    page.set_live_view(True)
    lead = _ready(Probe(app.port))
    try:
        _lead(lead, app.follow.code)
        links.apply(session, links.opening(f"{app.url}/?follow=1", session.preset, None))
        assert wait_until(lambda: session.shared.shared, 30), "the page never joined the cast"
        cast = app.follow.cast
        page.drawn_after(session.client)
        before, handed = canvas_pixels(page), cast.handed
        assert wait_until(lambda: cast.handed >= handed + 20, 30), "the cast sent no frames"
        page.drawn_after(session.client)
        after = canvas_pixels(page)
        changed = np.mean(np.any(np.abs(after.astype(int) - before) > 24, axis=2))
        assert changed > 0.01, f"only {changed:.4f} of the view changed"
        # The lecturer's move: the follower's new body goes to its browser through the cast
        # (held back from its own queue, encoded once for the process's followers): the page's
        # ellipsoid takes the size the session gave it.
        mesh = session.scene.drawing(Element.ELLIPSOID).mesh
        old_scale, fits = tuple(mesh.scale), cast.fits
        _set(lead, "I₂", 1.7)
        assert wait_until(lambda: cast.fits > fits and tuple(mesh.scale) != old_scale, 30)
        new_scale = np.array(mesh.scale)
        shown = lambda: page.page.evaluate(ELLIPSOID_SCALE_JS)  # noqa: E731
        assert wait_until(lambda: np.allclose(shown() or (0, 0, 0), new_scale, atol=1e-6), 30), (
            f"the page shows {shown()}, the session {new_scale} (was {old_scale})"
        )
        assert page.errors == [] and session.stats.errors == 0, session.stats.last_error
    finally:
        lead.close()
