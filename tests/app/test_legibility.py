"""What the picture promises, checked without a browser: the user's D survives an impossible
body, D at I₂ on the slider is the exact separatrix, a stalled frame loop draws no chord
through the body, symmetric bodies offer no separatrix, the panel never deletes its widgets,
the labels' layout keeps boxes apart."""

from __future__ import annotations

import threading

import numpy as np
import pytest
from conftest import session_of, wait_until

from poinsot.app import viser_private
from poinsot.app.live.panel.panel import D_STEP
from poinsot.app.live.panel.widgets import Shelf
from poinsot.app.model.parameters import Parameters
from poinsot.app.model.presets import preset_by_key
from poinsot.physics import Regime


# -- the user's D (an impossible body on the way) -----------------------------------------
def test_passing_through_an_impossible_body_keeps_the_users_D():
    major = Parameters.from_preset(preset_by_key("major"))
    assert major.D == 2.45
    impossible = major.with_inertia(2, 0.1)  # I = (1, 2, 0.1): no real body
    with pytest.raises(ValueError, match="no real body"):
        impossible.check()
    back = impossible.with_inertia(2, 2.6)
    assert back.D == 2.45 and back.D_asked is None
    assert back.build().D == pytest.approx(2.45, rel=1e-12)
    # A range that still holds D leaves it alone; one that does not clamps it, for a while.
    assert major.with_inertia(2, 2.5).D == 2.45
    narrow = major.with_inertia(2, 2.2)
    assert narrow.D == 2.2 and narrow.D_asked == 2.45
    assert narrow.with_inertia(2, 2.6).D == 2.45
    # A D the user sets while the range is narrow is the user's new D.
    assert narrow.with_D(2.1).with_inertia(2, 2.6).D == 2.1


def test_the_session_keeps_D_through_an_impossible_body(poinsot_app, probe):
    """Major preset (D = 2.45), I₃ -> 0.1 (refused), back to 2.6: D is 2.45 again."""
    session = session_of(poinsot_app)
    uuid, _ = probe.widget("I₃")
    probe.set_value(uuid, 0.1)
    assert wait_until(lambda: "no real body" in session.status.lower(), 10), session.status
    probe.set_value(uuid, 2.6)
    assert wait_until(lambda: session.params.inertia[2] == 2.6 and not session.status, 10)
    assert session.params.D == 2.45
    assert session.body is not None and session.body.D == pytest.approx(2.45, rel=1e-12)


# -- D = I₂ is the separatrix ---------------------------------------------------------------
@pytest.mark.parametrize(
    "inertia", [(1.0, 2.0, 2.6), (1.0, 2.2782, 3.1839), (2.6, 1.37, 1.4), (0.3, 0.7, 0.95)]
)
def test_D_within_half_a_step_of_I2_is_the_exact_separatrix(inertia):
    p = Parameters(inertia, sorted(inertia)[0])
    mid = sorted(inertia)[1]
    for near in (mid, mid - 0.4 * D_STEP, mid + 0.49 * D_STEP, np.nextafter(mid, 0.0)):
        q = p.with_D(float(near), snap=D_STEP / 2)
        assert q.D == mid
        body = q.build()
        assert body.regime is Regime.SEPARATRIX and body.D == mid
    assert p.with_D(mid + D_STEP, snap=D_STEP / 2).build().regime is not Regime.SEPARATRIX


def test_a_symmetric_body_has_no_separatrix_to_snap_to():
    disc = Parameters((1.0, 1.0, 1.9592), 1.45)
    assert not disc.has_separatrix
    assert disc.with_D(1.0004, snap=D_STEP / 2).D == 1.0004


def test_the_D_slider_at_I2_gives_the_separatrix(poinsot_app, probe):
    """I = (1, 2, 2.6) and the slider's value 2.000 as the browser sends it: the readout says
    separatrix."""
    session = session_of(poinsot_app)
    uuid, _ = probe.widget("D = |L|²/2T")
    probe.set_value(uuid, 1.9999999999999996)
    assert wait_until(lambda: session.body is not None and session.params.D == 2.0, 10)
    assert session.body.regime is Regime.SEPARATRIX
    assert probe.wait_for(lambda p: any("separatrix" in t for t in _markdown(p)), 10)


def _markdown(probe) -> list[str]:
    _, widgets = probe.snapshot()
    return [str(w.props.get("_markdown", "")) for w in widgets.values()]


# -- the panel puts widgets away, it never deletes them -------------------------------------
class FakeHandle:
    def __init__(self) -> None:
        self.visible = True
        self.removed = False

    def remove(self) -> None:
        self.removed = True


def test_the_shelf_hides_keeps_and_gives_back():
    shelf, handles = Shelf(), [FakeHandle(), FakeHandle()]
    shelf.stow("energy", handles)
    assert "energy" in shelf and all(not h.visible and not h.removed for h in handles)
    assert shelf.take("energy") == handles and all(h.visible for h in handles)
    assert shelf.take("energy") is None and "energy" not in shelf


def test_switching_sphere_and_custom_deletes_no_panel_widget(poinsot_app, probe):
    """The browser logs an error for an update that reaches a deleted widget; the panel's
    widgets are only hidden and shown, so the widgets it ever made are all still there."""
    from poinsot.app.model.presets import CUSTOM

    session = session_of(poinsot_app)
    removed: list[str] = []
    probe.add_listener(
        lambda m, _t: removed.append(m["uuid"]) if m["type"] == "GuiRemoveMessage" else None
    )
    uuid, _ = probe.widget("Preset")
    for _ in range(4):
        for preset in (preset_by_key("sphere"), CUSTOM):
            probe.set_value(uuid, preset.label)
            shown = (session.preset.key, session.panel.preset.value)
            assert wait_until(lambda p=preset: session.preset is p, 10), shown
    assert probe.wait_for(lambda p: "D = |L|²/2T" in p.labels(), 10)
    assert removed == []
    assert session.stats.errors == 0, session.stats.last_error


def test_a_callback_reads_the_users_value_not_a_later_server_write(make_probe):
    """viser runs a widget's callback on a worker thread, after the browser's message has set
    the value. If the server writes the widget in between (a preset being shown), the callback
    must still act on what the user chose; reading ``handle.value`` it chose the stale preset
    again, and the session never reached the user's."""
    import threading

    import viser

    from poinsot.app.devtools.probe import Probe
    from poinsot.app.live.panel.widgets import on_user

    server = viser.ViserServer("127.0.0.1", 0, verbose=False)
    try:
        dropdown = server.gui.add_dropdown("Preset", ("Sphere", "Custom"), initial_value="Sphere")
        release, seen, errors = threading.Event(), [], []

        def callback(sent) -> None:
            release.wait(10)
            seen.append(sent.value)

        on_user(dropdown, callback, errors.append)
        with Probe(server.get_port()) as probe:
            assert probe.wait_for(lambda p: "Preset" in p.labels(), 10)
            uuid, _ = probe.widget("Preset")
            probe.set_value(uuid, "Custom")
            assert wait_until(lambda: dropdown.value == "Custom", 10)
            dropdown.value = "Sphere"  # the server shows the preset it is still applying
            release.set()
            assert wait_until(lambda: seen != [], 10)
        assert seen == ["Custom"] and errors == []
    finally:
        server.stop()


def test_a_preset_shown_late_does_not_overwrite_the_users_newer_choice():
    """The menu shows the preset being applied, unless the browser has chosen again: a choice
    recorded since the change was asked for (its count moved on), or one viser has stored in
    the handle whose callbacks have not yet recorded it. Overwriting the latter, the callback
    read the server's value, and viser dropped the user's next choice as "unchanged"."""
    import viser

    from poinsot.app.live.panel.widgets import Sent, on_user, write_unless_newer

    server = viser.ViserServer("127.0.0.1", 0, verbose=False)
    try:
        loop = server.get_event_loop()
        options = ("Sphere", "Custom", "Major")
        dropdown = server.gui.add_dropdown("Preset", options, initial_value="Sphere")
        menu, errors = Sent("Sphere"), []
        on_user(dropdown, lambda _sent: None, errors.append, menu)

        def written(value, count):
            write_unless_newer(dropdown, value, menu, count, loop)
            done = threading.Event()
            loop.call_soon_threadsafe(done.set)  # after the write, on the same loop
            assert done.wait(10)

        written("Custom", menu.count)  # nothing newer: shown
        assert dropdown.value == "Custom" and menu.value == "Custom"
        count = menu.count
        menu.count += 1  # the browser chose again since (recorded)
        written("Major", count)
        assert dropdown.value == "Custom"
        viser_private.store_value(
            dropdown, "Sphere"
        )  # stored by viser, not yet recorded by the callback
        written("Major", menu.count)
        assert viser_private.stored_value(dropdown) == "Sphere"
        assert errors == []
    finally:
        server.stop()


# -- a stalled frame loop -------------------------------------------------------------------
def _off_surface(segments: np.ndarray, semi_axes: np.ndarray) -> float:
    """Largest relative distance from the ellipsoid of a segment's end and midpoint points, as
    drawn (before the trail node's inflation)."""
    points = np.concatenate([segments[:, 0], segments[:, 1], segments.mean(axis=1)])
    radius = np.sqrt(np.sum((points / semi_axes) ** 2, axis=1))
    return float(np.max(np.abs(radius - 1.0)))


@pytest.mark.parametrize("stall", [2.0, 60.0])
def test_after_a_stall_no_trace_segment_cuts_through_the_body(stall):
    """60 frames a second for a second, then nothing for ``stall`` seconds (filled from the
    exact solution after 2 s, lifted after 60 s), then frames again: every polhode segment
    stays on the ellipsoid within the margin it is drawn off it, every herpolhode segment is a
    short chord."""
    from poinsot.app.construction.geometry import POLHODE_INFLATE
    from poinsot.app.construction.sampled.motion import MAX_CHORD
    from poinsot.app.model.elements import Element
    from poinsot.app.stage.served import Stage

    with Stage.from_preset(preset_by_key("major"), trail_points=6000) as stage:
        times = [k / 60.0 for k in range(61)]
        times += [times[-1] + stall + k / 60.0 for k in range(1, 30)]
        for t in times:
            stage.advance(t)
        stage.scene.flush_trails()
        semi = stage.scene.geometry.semi_axes
        polhode = stage.scene.trail(Element.POLHODE).segments()
        herpolhode = stage.scene.trail(Element.HERPOLHODE).segments()
    assert len(polhode) > 100
    assert _off_surface(polhode, semi) < POLHODE_INFLATE - 1.0
    chords = np.linalg.norm(herpolhode[:, 1] - herpolhode[:, 0], axis=1)
    assert chords.max() < 2 * MAX_CHORD


# -- labels laid out for a camera -----------------------------------------------------------
def _camera(position, look_at=(0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0)):
    from poinsot.app.construction.labels.layout import Camera

    return Camera(
        np.array(position, float),
        np.array(look_at, float),
        np.array(up, float),
        0.785,
        652.0,
        800.0,
    )


def test_labels_whose_points_meet_on_screen_get_boxes_apart():
    """Seen along L, the tips of L and ω and the end of axis 3 fall on one spot: their boxes
    still do not overlap, nor cover the contact point's marker."""
    from poinsot.app.construction.labels.layout import Slot, lay_out, overlapping

    camera = _camera((0.0, -0.01, 5.4), up=(0.0, 1.0, 0.0))
    top, contact = np.array([0.0, 0.0, 1.3]), np.array([0.05, 0.0, 0.65])
    slots = [
        Slot("L", "L", 1.4, top + (0, 0, 0.05), top, np.zeros(3), movable=True, clearance=6),
        Slot("omega", "ω", 1.4, contact * 1.05, contact, np.zeros(3), True, 14.0),
        Slot(
            "axis3",
            "3",
            1.3,
            np.array([0.02, 0.01, 0.85]),
            np.array([0.02, 0.01, 0.8]),
            np.zeros(3),
            movable=True,
            clearance=10.0,
        ),
        Slot(
            "polhode",
            "polhode",
            1.1,
            np.array([0.3, 0.1, 0.6]),
            np.array([0.28, 0.1, 0.58]),
            np.zeros(3),
        ),
    ]
    placed = lay_out(slots, camera, markers=[(contact, 9.0)])
    assert set(placed) == {"L", "omega", "axis3", "polhode"}
    assert overlapping([p.box for p in placed.values()]) == []
    assert all(p.overlap == 0.0 for p in placed.values()), placed
    # The ω label was pushed off the marker, in the screen plane.
    assert np.linalg.norm(placed["omega"].offset) > 0.0


def test_a_label_goes_beyond_its_tip():
    """An axis pointing right on screen: its label's box lies right of its point."""
    from poinsot.app.construction.labels.layout import Slot, lay_out

    camera = _camera((0.0, -5.0, 0.0))
    tip = np.array([1.0, 0.0, 0.0])
    placed = lay_out([Slot("axis1", "1", 1.3, tip * 1.05, tip, np.zeros(3))], camera)
    (x0, _, x1, _), (px, _) = placed["axis1"].box, camera.project(tip * 1.05)[0][0]
    assert x0 >= px - 1e-6 and x1 > x0


def test_a_label_keeps_its_box_inside_the_picture():
    """An axis pointing right whose tip is near the picture's right edge: its box goes left
    of its point, wholly inside (beyond the tip it would be cut by the edge); and a movable
    label whose point is just above the top edge is pushed down into the picture."""
    from poinsot.app.construction.labels.layout import Slot, lay_out

    camera = _camera((0.0, -5.0, 0.0))
    edge = camera.width
    # the world x whose projection lies 3 px inside the right edge (at depth 5)
    x = (edge / 2 - 3.0) * float(camera.world_per_px(5.0))
    tip = np.array([x, 0.0, 0.0])
    placed = lay_out([Slot("axis1", "1", 1.3, tip * 1.001, tip, np.zeros(3))], camera)
    x0, y0, x1, y1 = placed["axis1"].box
    assert 0.0 <= x0 < x1 <= edge and 0.0 <= y0 < y1 <= camera.height, placed["axis1"]
    assert placed["axis1"].overlap == 0.0
    # L's tip 2 px above the top edge, the arrow pointing up: pushed, not drawn off the top.
    z = (camera.height / 2 + 2.0) * float(camera.world_per_px(5.0))
    top = np.array([0.0, 0.0, z])
    slot = Slot("L", "L", 1.4, top * 1.001, top, np.zeros(3), movable=True, clearance=6.0)
    placed = lay_out([slot], camera)
    x0, y0, x1, y1 = placed["L"].box
    assert 0.0 <= x0 < x1 <= edge and 0.0 <= y0 < y1 <= camera.height, placed["L"]
    assert np.linalg.norm(placed["L"].offset) > 0.0


def test_a_label_box_is_as_wide_as_the_browser_draws_it():
    """ω is wider than a Latin letter: Chromium draws ω's box at font scale 1.4 18-19 CSS px
    wide (the mean advance of a letter gave 13.3 px, and ω's box then touched the herpolhode's
    label beside it); a Latin letter's stays at the mean."""
    from poinsot.app.construction.labels.layout import box_size

    assert box_size("ω", 1.4)[0] >= 19.0
    assert box_size("L", 1.4)[0] == pytest.approx(13.272)
    assert box_size("Lω", 1.4)[0] > box_size("LL", 1.4)[0]


# -- the legend and the caption --------------------------------------------------------------
def test_the_legend_lists_the_declared_elements_in_the_looks_colours():
    from poinsot.app.construction import palette
    from poinsot.app.live.panel.legend import entries, legend_html
    from poinsot.app.model.elements import ALL_ELEMENTS, TRACE_ELEMENTS

    for look in (palette.DARK, palette.LIGHT, palette.PROJECTOR_DARK):
        items = entries(ALL_ELEMENTS, look)
        names = [e.name for e in items]
        assert names[:2] == ["polhode (body)", "herpolhode (plane)"]
        assert items[1].colors == (look.herpolhode,)
        html = legend_html(items)
        assert palette.css(look.polhode) in html and "herpolhode" in html
    sphere = [e.name for e in entries(ALL_ELEMENTS - TRACE_ELEMENTS, palette.DARK)]
    assert not any("polhode" in name for name in sphere)


def test_every_preset_has_a_caption_and_a_scene_can_set_its_own():
    import dataclasses

    from poinsot.app.live.panel.legend import CAPTIONS, caption
    from poinsot.app.model.presets import MENU, PRESETS

    for preset in PRESETS:
        assert caption(preset) == CAPTIONS[preset.key]
    for preset in MENU:
        assert caption(preset)
    own = dataclasses.replace(PRESETS[0], key="scene", caption="What the scene shows.")
    assert caption(own) == "What the scene shows."


# -- one vocabulary for views; --help shows the defaults -----------------------------------
def test_the_views_have_one_name_in_the_browser_and_on_the_command_line():
    from poinsot.app.cli.main import build_parser
    from poinsot.app.construction.cameras import CAMERA_NAMES, canonical

    assert CAMERA_NAMES == ("default", "along-L", "side", "ride-along")
    parser = build_parser()
    for name in CAMERA_NAMES:
        assert parser.parse_args(["screenshot", "--out", "x.png", "--view", name]).view == name
    assert canonical("top") == "along-L" and canonical("body") == "ride-along"
    with pytest.raises(SystemExit):
        parser.parse_args(["export-html", "--out", "x.html", "--view", "ride-along"])


@pytest.mark.parametrize(
    "command", [[], ["serve"], ["report"], ["screenshot"], ["export-html"], ["benchmark"], ["fit"]]
)
def test_help_shows_the_defaults_and_no_backticks(command, capsys):
    from poinsot.app.cli.main import build_parser

    with pytest.raises(SystemExit):
        build_parser().parse_args([*command, "--help"])
    text = capsys.readouterr().out
    assert "`" not in text
    if command in ([], ["serve"]):
        assert "(default: 8080)" in text and "(default: major)" in text
    if command == ["screenshot"]:
        assert "(default: 1920x1080)" in text and "(default: default)" in text
        assert "Preset(" not in text


def test_an_inline_callback_sees_every_value_in_the_order_sent():
    """The panel's callbacks run on viser's event loop as each value arrives (they only post):
    a quick run of slider values reaches them all, in order, none read twice."""
    import viser

    from poinsot.app.devtools.probe import Probe
    from poinsot.app.live.panel.widgets import on_user

    server = viser.ViserServer("127.0.0.1", 0, verbose=False)
    try:
        slider = server.gui.add_slider("I₁", 0.0, 100.0, 1.0, 0.0)
        seen, threads, errors = [], set(), []

        def callback(sent) -> None:
            seen.append(sent.value)
            threads.add(threading.current_thread().name)

        on_user(slider, callback, errors.append, inline=True)
        values = [float(v) for v in range(1, 41)]
        with Probe(server.get_port()) as probe:
            assert probe.wait_for(lambda p: "I₁" in p.labels(), 10)
            uuid, _ = probe.widget("I₁")
            for value in values:
                probe.set_value(uuid, value)
            assert wait_until(lambda: len(seen) >= len(values), 10)
        assert seen == values and errors == []
        assert len(threads) == 1  # one thread: viser's event loop
    finally:
        server.stop()
