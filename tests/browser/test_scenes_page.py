"""The scenes in a real browser (Debian's Chromium through playwright, WebGL through
SwiftShader): every scene renders a picture that is not blank and differs from the others; each
part it declares is on the picture (the colours of its lines are there, and hiding it from its
checkbox in the page changes the picture); its readouts and controls are in the page; the menu
takes the browser from a preset to a scene and back."""

from __future__ import annotations

import time

import numpy as np
import pytest
from conftest import TEST_MAX_FPS, session_of, wait_until
from test_live_page import amber_fraction

from poinsot.app.lessons import SCENES, scene_by_name
from poinsot.app.lessons.support.spec import SceneSpec
from poinsot.app.model.elements import Element
from poinsot.app.model.presets import preset_by_key

pytestmark = pytest.mark.browser

WIDTH, HEIGHT = 1280, 800
#: A pixel shows a line's colour when its RGB is this close (sum of absolute differences):
#: loose, because a line seen through a translucent surface (the ellipsoid, Landau's sphere, a
#: cone) is blended with it; the pixels must also change when the part is hidden (check_parts).
COLOUR_TOLERANCE = 90
#: Pixels of a line's colour that make it "on the picture".
MIN_COLOUR_PIXELS = 12
#: The fraction of the picture that hiding a part must change: 60 pixels (a paused scene
#: renders the same picture twice, pixel for pixel; a short trace, such as a path that has
#: played 60 frames, changes 150 to 250 pixels).
MIN_PART_CHANGE = 60 / (WIDTH * HEIGHT)
#: Scenes played from a fraction of their table's span: Explorer 1 half-way to its flat spin,
#: where ω stands apart from the satellite and from L (early on, ω lies along the satellite's
#: axis, inside the cylinder; in the flat spin, along L: hiding it changes almost no pixel).
PLAY_FROM = {"explorer-1": 0.5}


#: A scene plays what this many frames take at the test server's rate, in simulation time
#: (its clock runs on wall time: on a busy machine the frames come late, and a count of frames
#: would pause it further along the motion, where a part can be seen edge-on).
PLAYED_FRAMES = 60


def render_once(session) -> np.ndarray:
    """The browser's render of its 3D view (no panel, no notice), laid on black, (H, W, 3).
    It shows every change of the scene's state sent before it (viser applies the client's
    messages in order, the render request last)."""
    rgba = session.client.get_render(HEIGHT, WIDTH, transport_format="png", timeout=60.0)
    return (rgba[..., :3].astype(np.float64) * (rgba[..., 3:4] / 255.0)).astype(np.int16)


def render(session) -> np.ndarray:
    """:func:`render_once`, once two renders in a row agree (the browser decodes new nodes,
    a scene's meshes and labels, asynchronously)."""
    previous = render_once(session)
    for _ in range(10):
        current = render_once(session)
        if np.array_equal(current, previous):
            return current
        previous = current
    raise AssertionError("the picture did not settle")


def changed(a: np.ndarray, b: np.ndarray) -> float:
    """The fraction of pixels that differ visibly between two pictures."""
    return float(np.mean(np.abs(a - b).sum(axis=2) > 40))


def show(page, session, spec: SceneSpec, before: SceneSpec | None) -> None:
    """The scene on the page (chosen from the menu's session, after the first) once its
    controls and parts' checkboxes are there and those of the scene ``before`` are gone; played
    a moment (its traces grow), then paused (``render`` then waits until two pictures in a
    row agree: the pause has reached the page)."""
    if before is not None:
        session.choose_scene(spec)
    assert wait_until(
        lambda: (
            session.showcase is not None
            and session.showcase.spec is spec
            and session.showcase.loaded
        ),
        60,  # the first is loaded as the page's session starts: late on a loaded machine
    ), (spec.name, session.showcase and session.showcase.spec.name)
    labels = {c.label for c in spec.controls} | {p.label for p in spec.parts}
    old = set() if before is None else {c.label for c in before.controls}
    old |= set() if before is None else {p.label for p in before.parts}
    for label in labels:
        assert wait_until(lambda la=label: page.control_count(la) == 1, 20), (spec.name, label)
    for label in old - labels:
        assert wait_until(lambda la=label: page.control_count(la) == 0, 20), (spec.name, label)
    if spec.name in PLAY_FROM:
        session.clock.reset(
            PLAY_FROM[spec.name] * session.showcase.showcase.drawing.player.table.span
        )
    session.clock.paused = False
    start, frames = session.clock.now(), session.stats.frames
    span = PLAYED_FRAMES / TEST_MAX_FPS * session.clock.speed
    assert wait_until(
        lambda: session.clock.now() >= start + span and session.stats.frames > frames + 10, 30
    ), "not animating"
    session.clock.paused = True


def render_until(session, done, timeout: float = 60.0) -> np.ndarray:
    """The first render for which ``done(picture)`` holds, or the last one. A part shown or
    hidden is a visibility flag (nothing to decode): the first render after it normally
    shows it; the event waited for is the picture itself."""
    deadline = time.monotonic() + timeout
    picture = render_once(session)
    while not done(picture) and time.monotonic() < deadline:
        picture = render_once(session)  # each a round trip to the page: no sleep needed
    return picture


def check_parts(page, session, spec: SceneSpec, shown: np.ndarray) -> None:
    """Each part: hiding it from its checkbox changes the picture, and among the pixels that
    change are some in each of its lines' colours (so the colour on the picture is the part's,
    not another element's of a similar hue). A part is shown again before the next is hidden,
    and no render waits for that: the page applies the messages in order, so the next part's
    render shows it."""
    drawing = session.showcase.showcase.drawing
    for part in spec.parts:
        page.set_checkbox(part.label, False)
        assert wait_until(lambda p=part: not drawing.parts.is_visible(p.key), 10), part.key
        hidden = render_until(session, lambda picture: changed(shown, picture) > MIN_PART_CHANGE)
        assert changed(shown, hidden) > MIN_PART_CHANGE, (spec.name, part.key)
        gone = np.abs(shown - hidden).sum(axis=2) > 40
        for color in part.colors:
            near = np.abs(shown - np.asarray(color)).sum(axis=2) < COLOUR_TOLERANCE
            assert int(np.sum(gone & near)) >= MIN_COLOUR_PIXELS, (spec.name, part.key, color)
        page.set_checkbox(part.label, True)
        assert wait_until(lambda p=part: drawing.parts.is_visible(p.key), 10), part.key


def test_every_scene_draws_its_parts_distinctly(make_app, open_page):
    """Each scene in turn on one page, the first served as the page opens, the others chosen
    from the menu (each after the one before: nothing of it may remain)."""
    pictures: dict[str, np.ndarray] = {}
    app = make_app(scene=SCENES[0])
    page = open_page(app.url, width=WIDTH, height=HEIGHT, live_view=False)
    session = session_of(app)
    before: SceneSpec | None = None
    for spec in SCENES:
        show(page, session, spec, before)
        shown = render(session)
        drawn = np.abs(shown - shown[0, 0]).sum(axis=2) > 30
        assert drawn.mean() > 0.03, (spec.name, drawn.mean())  # not blank
        if Element.ELLIPSOID in spec.elements:
            assert amber_fraction(shown.astype(np.uint8)) > 0.005, spec.name
        check_parts(page, session, spec, shown)
        for quantity in spec.readouts:  # the readout table and the controls are in the page
            assert page.page.get_by_text(quantity.split(" ")[0], exact=False).count() >= 1
        for control in spec.controls:
            assert page.control_count(control.label) == 1, control.label
        assert page.errors == [], (spec.name, page.errors)
        assert session.stats.errors == 0, session.stats.last_error
        pictures[spec.name] = shown
        before = spec
    names = list(pictures)
    for i, a in enumerate(names):
        for b in names[i + 1 :]:
            assert changed(pictures[a], pictures[b]) > 0.03, (a, b)


def test_the_menu_takes_the_browser_to_a_scene_and_back(make_app, open_page):
    app = make_app()
    page = open_page(app.url, width=WIDTH, height=HEIGHT, live_view=False)
    session = session_of(app)
    assert wait_until(lambda: session.stats.frames > 20, 20)
    spec = scene_by_name("dzhanibekov")
    page.choose("Preset", spec.label)
    assert wait_until(lambda: session.showcase is not None and session.showcase.loaded, 20)
    assert wait_until(lambda: page.control_count("ε from the intermediate axis") == 1, 15)
    # The preset's energy slider is gone (hidden at once, deleted a moment later: its own
    # messages, which may reach the page after the scene's new control).
    assert wait_until(lambda: page.control_count("D = |L|²/2T") == 0, 15)
    page.choose("ε from the intermediate axis", "1e-12")
    assert wait_until(lambda: session.showcase.showcase.model.epsilon == 1e-12, 15)
    assert wait_until(lambda: page.page.get_by_text("1.058e-24").count() >= 1, 15)
    page.page.locator(".uplot-container").first.wait_for(state="visible", timeout=20000)
    preset = preset_by_key("oblate")
    page.choose("Preset", preset.label)
    assert wait_until(lambda: session.showcase is None and session.preset is preset, 15)
    assert wait_until(lambda: page.control_count("ε from the intermediate axis") == 0, 15)
    assert wait_until(lambda: page.control_count("D = |L|²/2T") == 1, 15)
    assert page.errors == []
    assert session.stats.errors == 0, session.stats.last_error
