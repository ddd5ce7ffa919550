"""Server-side behaviour on a real ViserServer(port=0), observed through websocket probes that
speak viser's protocol like a browser (app/devtools/probe.py): what is created, what is sent
per frame, the frame rate, sessions, invalid input, and robustness."""

from __future__ import annotations

import random
import re
import time
import warnings

import numpy as np
import pytest
from conftest import after_frames, record_frame_times, session_of, wait_until
from test_scene_geometry import check_finite

from poinsot.app import viser_private
from poinsot.app.construction.trail import CHUNK_SEGMENTS
from poinsot.app.live.classroom import links
from poinsot.app.live.lecture.display import LABEL_MIN_FRAMES
from poinsot.app.live.panel.panel import ELEMENT_LABELS
from poinsot.app.live.server import built_session
from poinsot.app.live.session.session import MAX_FPS, STEP_SECONDS, SessionOptions
from poinsot.app.model.elements import Control, Element, Plot
from poinsot.app.model.parameters import Parameters
from poinsot.app.model.presets import CUSTOM, DEFAULT_PRESET, PRESETS, preset_by_key

#: Nodes each element creates (trail chunks "…/g<layer>/c<n>" come and go under their group).
ELEMENT_NODES: dict[Element, set[str]] = {
    Element.ELLIPSOID: {"/space/body/ellipsoid"},
    Element.AXES: {f"/space/body/axis{i}" for i in (1, 2, 3)}
    | {f"/space/body/axis{i}/label" for i in (1, 2, 3)}
    | {"/space/origin"},
    Element.PLANE: {"/space/plane", "/space/plane/disc", "/space/plane/grid", "/space/plane/rim"},
    Element.CONTACT: {"/space/tip/contact"},
    Element.OMEGA: {"/space/omega", "/space/tip/omega_label"},
    Element.L: {"/space/L", "/space/L_label"},
    Element.POLHODE: {"/space/body/polhode", "/space/body/polhode_label"},
    Element.POLHODE_FULL: {"/space/body/polhode_full"},
    Element.HERPOLHODE: {"/space/herpolhode", "/space/herpolhode_label"},
    Element.SOLID: {"/space/body/solid"},
}
ALWAYS = {"/WorldAxes", "/space", "/space/body", "/space/tip", "/lights", "/lights/fill"}
TRAIL_GROUPS = ("/space/body/polhode/", "/space/herpolhode/")

#: Widget labels per control group.
CONTROL_LABELS: dict[Control, set[str]] = {
    Control.INERTIA: {"I₁", "I₂", "I₃"},
    Control.ENERGY: {"D = |L|²/2T"},
    Control.SIDE: {"Polhode"},  # and "Side of separatrix" where the body has a separatrix
    Control.OMEGA_NORM: {"|ω₀|"},
    Control.SPEED: {"Speed"},
    Control.PLAYBACK: {"Pause", "Step", "Reset"},
    Control.TRAIL: {"Trail length"},
}


def scene_names(probe) -> set[str]:
    nodes, _ = probe.snapshot()
    return {n for n in nodes if not any(n.startswith(g) for g in TRAIL_GROUPS)}


def visible_labels(probe) -> set[str]:
    _, widgets = probe.snapshot()
    return {
        w.props["label"]
        for w in widgets.values()
        if w.props.get("label") and w.props.get("visible", True)
    }


def has_plot(probe) -> bool:
    _, widgets = probe.snapshot()
    return any(
        w.type == "GuiUplotMessage" and w.props.get("visible", True) for w in widgets.values()
    )


def markdown_texts(probe) -> list[str]:
    """The markdown the browser shows (the probe's model is read under its lock)."""
    return [
        str(w.props.get("_markdown", ""))
        for w in probe.widgets.values()
        if w.type == "GuiMarkdownMessage"
    ]


def expected_nodes(preset) -> set[str]:
    names = set(ALWAYS)
    for element in preset.elements:
        names |= ELEMENT_NODES[element]  # a preset without a solid gets the physics box
    return names


@pytest.mark.parametrize("preset", PRESETS, ids=[p.key for p in PRESETS])
def test_only_what_the_preset_declares_is_created(preset, make_app, make_probe):
    app = make_app(preset)
    probe = make_probe(app)
    session = session_of(app)
    assert wait_until(lambda: session.stats.frames > 3, 30)
    assert probe.wait_for(lambda p: scene_names(p) == expected_nodes(preset), 10), scene_names(
        probe
    ) ^ expected_nodes(preset)
    labels = visible_labels(probe)
    for control, names in CONTROL_LABELS.items():
        assert (names <= labels) == (control in preset.controls), control
        assert (names & labels == set()) == (control not in preset.controls), control
    # A symmetric body (or a sphere) has no separatrix: no side of it to choose.
    separatrix = Parameters.from_preset(preset).has_separatrix
    assert ("Side of separatrix" in labels) == (Control.SIDE in preset.controls and separatrix)
    shown = {ELEMENT_LABELS[e] for e in preset.elements}
    hidden = {ELEMENT_LABELS[e] for e in Element if e not in preset.elements}
    assert shown <= labels and not hidden & labels
    assert has_plot(probe) == (Plot.OMEGA in preset.plots)


def test_switching_preset_creates_and_removes_exactly(poinsot_app, probe):
    session = session_of(poinsot_app)
    uuid, _ = probe.widget("Preset")
    for key in ("sphere", "t_handle", "sphere", "oblate"):
        preset = preset_by_key(key)
        probe.set_value(uuid, preset.label)
        assert wait_until(
            lambda p=preset: session.preset is p and session.params.inertia == p.inertia, 10
        )
        expected = expected_nodes(preset)
        assert probe.wait_for(lambda p, e=expected: scene_names(p) == e, 10)
        assert probe.wait_for(lambda p, pr=preset: has_plot(p) == (Plot.OMEGA in pr.plots), 10)
    assert session.stats.errors == 0, session.stats.last_error


def frame_traffic(probe, session, frames: int) -> list:
    """What ``probe`` received while ``session`` drew ``frames`` more frames (and took them)."""
    start, first = len(probe.batches), session.stats.frames
    assert wait_until(lambda: session.stats.frames >= first + frames, 30)
    assert probe.wait_for(lambda p: len(p.batches) >= start + frames // 2, 10)
    return probe.batches[start:]


PER_FRAME_TYPES = {
    "SetOrientationMessage",
    "SetPositionMessage",
    "SceneNodeUpdateMessage",
    "LineSegmentsMessage",
    "RemoveSceneNodeMessage",
    "SetSceneNodeVisibilityMessage",
    "GuiUpdateMessage",
}


def test_per_frame_only_poses_and_trail_increments_are_sent(poinsot_app, probe):
    session = session_of(poinsot_app)
    assert wait_until(lambda: session.stats.frames > 30, 30)
    frames_before = session.stats.frames
    batches = frame_traffic(probe, session, 90)
    frames = session.stats.frames - frames_before
    assert frames >= 90
    labels = 0  # the labels' layout: an anchor or a push, a few times a second at most
    for batch in batches:
        for kind, name in zip(batch.types, batch.names, strict=True):
            assert kind in PER_FRAME_TYPES, (kind, name)
            if name.endswith("label") and kind in ("SetPositionMessage", "SceneNodeUpdateMessage"):
                labels += 1
            elif kind in ("LineSegmentsMessage", "RemoveSceneNodeMessage"):
                assert name.startswith(TRAIL_GROUPS), name  # trail chunks only
            elif kind == "SetOrientationMessage":
                assert name == "/space/body" or name.startswith(TRAIL_GROUPS), name
            elif kind == "SetPositionMessage":
                assert name == "/space/tip" or name.startswith(TRAIL_GROUPS), name
            elif kind == "SceneNodeUpdateMessage":
                assert name == "/space/omega" or name.startswith(TRAIL_GROUPS), name
    # a layout at most every LABEL_MIN_FRAMES frames (and LABEL_HZ), two messages per label
    assert labels <= 2 * 7 * (frames // LABEL_MIN_FRAMES + 1) + 7, labels
    # Bytes: poses plus at most a chunk of trail per trace per frame (the plot, at 10 Hz,
    # resends its 300-sample window; it is counted separately).
    scene_bytes = sum(b.nbytes for b in batches if "GuiUpdateMessage" not in b.types)
    per_frame = scene_bytes / frames
    assert per_frame < 400 + 2 * CHUNK_SEGMENTS * 24 + 600, per_frame


def test_the_loop_runs_at_most_60_hz(poinsot_app, probe):
    """Frames are due on a cadence of the pacer's interval (1/60 s at most), by the frame
    thread's own clock: 60 frames span more than 59 intervals, and a frame drawn late is
    followed by one at least half an interval later, never by a burst (a loaded machine only
    makes the gaps longer; the rate itself is ``poinsot benchmark``'s "frames per second per
    client"). And it animates: 60 more frames arrive."""
    session = session_of(poinsot_app)
    drawn_at = record_frame_times(session)
    assert wait_until(lambda: len(drawn_at) > 60, 30), len(drawn_at)
    assert session.pacer.interval >= 1.0 / MAX_FPS
    gaps = np.diff(drawn_at[:61])
    assert gaps.sum() > 59 / MAX_FPS, gaps.sum()
    assert gaps.min() >= (0.5 / MAX_FPS) * (1 - 1e-9), gaps.min()


def test_the_loop_stops_when_the_client_leaves(poinsot_app, make_probe):
    probe = make_probe(poinsot_app)
    session = session_of(poinsot_app)
    assert wait_until(lambda: session.running and session.stats.frames > 5, 30)
    probe.close()
    assert wait_until(lambda: not session.running, 30)
    assert poinsot_app.sessions() == {}
    assert wait_until(lambda: not session.running, 10)  # the frame thread ended
    frames = session.stats.frames
    assert not session.running and session.stats.frames == frames


#: Frames (about a second's worth at 60 Hz) the stalled client's session draws before the
#: measurement starts: the stalled socket's buffers fill meanwhile.
STALL_FILL_FRAMES = 60
#: Frames each session, and websocket messages the live client, must get past during the
#: measurement (about two seconds' worth at 60 Hz; a loaded machine just takes longer).
STALL_FRAMES = 120
#: Bounds a hang only: an unloaded machine needs about 3 s.
STALL_TIMEOUT = 120.0


def test_a_stalled_client_does_not_stall_the_others(poinsot_app, make_probe):
    slow = make_probe(poinsot_app)
    slow_session = session_of(poinsot_app, 1)
    fast = make_probe(poinsot_app)
    fast_session = session_of(poinsot_app, 2)
    assert fast_session is not slow_session
    assert wait_until(lambda: fast_session.stats.frames > 10, 30)
    slow.stall()
    f_slow = slow_session.stats.frames
    assert wait_until(lambda: slow_session.stats.frames > f_slow + STALL_FILL_FRAMES, 60)
    received = len(slow.batches)
    f_fast, f_slow = fast_session.stats.frames, slow_session.stats.frames
    n_fast = len(fast.batches)

    def all_moved_on() -> bool:
        return (
            fast_session.stats.frames - f_fast > STALL_FRAMES  # the other session animates
            and len(fast.batches) - n_fast > STALL_FRAMES  # and its browser keeps receiving
            and slow_session.stats.frames - f_slow > STALL_FRAMES  # the stalled one never blocks
        )

    assert wait_until(all_moved_on, STALL_TIMEOUT), (
        fast_session.stats.frames - f_fast,
        len(fast.batches) - n_fast,
        slow_session.stats.frames - f_slow,
    )
    assert len(slow.batches) == received  # while the stalled browser read nothing
    slow.stall(False)
    assert slow.wait_for(lambda p: len(p.batches) > received, 30)


def test_two_clients_have_independent_sessions(poinsot_app, make_probe):
    a = make_probe(poinsot_app)
    sa = session_of(poinsot_app, 1)
    b = make_probe(poinsot_app)
    sb = session_of(poinsot_app, 2)
    for p in (a, b):
        assert p.wait_for(lambda p: "/space/body/ellipsoid" in p.nodes and p.has_widget("I₂"), 15)
    uuid, _ = a.widget("I₂")
    a.set_value(uuid, 1.7)
    assert wait_until(lambda: sa.params.inertia[1] == 1.7, 10)
    assert a.wait_for(
        lambda p: np.allclose(
            p.nodes["/space/body/ellipsoid"].props["scale"], sa.scene.geometry.semi_axes
        ),
        10,
    )
    after_frames(sb)  # b's session has drained whatever reached it meanwhile
    assert b.wait_for(lambda p: len(p.batches) > 0, 30)
    assert sb.params.inertia == DEFAULT_PRESET.inertia and sb.preset is DEFAULT_PRESET
    a_scale = a.snapshot()[0]["/space/body/ellipsoid"].props["scale"]
    b_scale = b.snapshot()[0]["/space/body/ellipsoid"].props["scale"]
    assert not np.allclose(a_scale, b_scale)
    assert np.allclose(b_scale, sb.scene.geometry.semi_axes)


def test_an_impossible_body_is_refused_and_the_last_scene_kept(poinsot_app, probe):
    session = session_of(poinsot_app)
    scale_before = probe.snapshot()[0]["/space/body/ellipsoid"].props["scale"]
    body_before = session.body
    uuid, _ = probe.widget("I₃")
    generation = session.generation
    probe.set_value(uuid, 3.5)  # I1 = 1, I2 = 2: 3.5 > 1 + 2
    session.wait_applied(generation)
    assert "No real body has these moments" in session.status
    assert "I3 = 3.5 is larger than I1 + I2 = 3" in session.status
    assert probe.wait_for(lambda p: any("No real body" in t for t in markdown_texts(p)), 30)
    assert session.body is body_before
    received = len(probe.batches)
    after_frames(session)  # frames after the refusal reached the probe, no new ellipsoid
    assert probe.wait_for(lambda p: len(p.batches) >= received + 5, 10)
    assert np.allclose(probe.snapshot()[0]["/space/body/ellipsoid"].props["scale"], scale_before)
    assert session.stats.errors == 0
    check_finite(probe)
    generation = session.generation
    probe.set_value(uuid, 2.9)  # valid again
    session.wait_applied(generation)
    assert session.status == "" and session.body is not body_before
    assert probe.wait_for(lambda p: not any("No real body" in t for t in markdown_texts(p)), 30)
    assert probe.wait_for(
        lambda p: not np.allclose(p.nodes["/space/body/ellipsoid"].props["scale"], scale_before), 30
    )


def test_random_input_never_raises_nor_sends_nan(poinsot_app, probe):
    """A storm of user input, including extremes and impossible bodies: no callback raises,
    the frame thread reports no error, and nothing non-finite reaches the browser."""
    session = session_of(poinsot_app)
    rng = random.Random(1234)
    sliders = {
        "I₁": (0.1, 5.0),
        "I₂": (0.1, 5.0),
        "I₃": (0.1, 5.0),
        "|ω₀|": (0.2, 4.0),
        "Speed": (0.05, 4.0),
        "Trail length": (100, 6000),
    }
    presets = [p.label for p in (*PRESETS, CUSTOM)]
    for _ in range(150):
        choice = rng.random()
        if choice < 0.6:
            label, (lo, hi) = rng.choice(list(sliders.items()))
            if not probe.has_widget(label):
                continue
            value = rng.choice([lo, hi, rng.uniform(lo, hi)])
            uuid, _ = probe.widget(label)
            probe.set_value(uuid, int(value) if label == "Trail length" else round(value, 2))
        elif choice < 0.7 and probe.has_widget("D = |L|²/2T"):
            uuid, w = probe.widget("D = |L|²/2T")
            probe.set_value(uuid, rng.uniform(w.props["min"], w.props["max"]))
        elif choice < 0.8:
            uuid, _ = probe.widget("Preset")
            probe.set_value(uuid, rng.choice(presets))
        else:
            label = rng.choice(["Pause", "Step", "Reset", "Side of separatrix", "Polhode"])
            if probe.has_widget(label):
                uuid, w = probe.widget(label)
                value = rng.choice(w.props["options"]) if "options" in w.props else True
                probe.set_value(uuid, value)
        time.sleep(rng.choice([0.0, 0.0, 0.01, 0.05]))
    # One last change, then frames: the storm before it has been taken in.
    probe.set_value(probe.widget("Speed")[0], 1.25)
    assert wait_until(lambda: session.clock.speed == 1.25, 30)
    after_frames(session)
    assert session.stats.errors == 0, session.stats.last_error
    assert session.status in ("",) or "No real body" in session.status
    check_finite(probe)


def test_visibility_trail_length_and_time_controls(poinsot_app, probe):
    session = session_of(poinsot_app)
    assert wait_until(lambda: session.stats.frames > 10, 30)
    uuid, _ = probe.widget(ELEMENT_LABELS[Element.POLHODE_FULL])
    probe.set_value(uuid, False)
    assert probe.wait_for(lambda p: not p.nodes["/space/body/polhode_full"].visible, 30)
    uuid, _ = probe.widget("Trail length")
    probe.set_value(uuid, 100)
    assert wait_until(lambda: session.scene.trail_points == 100, 30)
    after_frames(session, 120)  # two seconds of trail at 60 Hz, more than 100 points
    for element in (Element.POLHODE, Element.HERPOLHODE):
        trail = session.scene.trail(element)
        assert trail.segment_count <= max(100, 2 * CHUNK_SEGMENTS) + CHUNK_SEGMENTS
    # On the wire too: the chunks the browser holds are bounded.
    chunks = [n for n in probe.snapshot()[0] if re.match(r"/space/herpolhode/g\d+/c", n)]
    assert len(chunks) <= max(100, 2 * CHUNK_SEGMENTS) // CHUNK_SEGMENTS + 2
    # Pause freezes time; Step advances it by STEP_SECONDS x speed; Reset goes back to 0.
    probe.set_value(probe.widget("Pause")[0], True)
    assert wait_until(lambda: session.clock.paused, 30)
    t = session.clock.now()
    after_frames(session)  # frames go on, time stands still
    assert session.clock.now() == t
    probe.set_value(probe.widget("Step")[0], True)
    assert wait_until(lambda: session.clock.now() > t, 30)
    assert session.clock.now() == pytest.approx(t + STEP_SECONDS * session.clock.speed)
    probe.set_value(probe.widget("Speed")[0], 2.0)
    assert wait_until(lambda: session.clock.speed == 2.0, 30)
    probe.set_value(probe.widget("Reset")[0], True)
    assert wait_until(lambda: session.clock.now() == 0.0, 30)
    probe.set_value(probe.widget("Play")[0], True)
    assert wait_until(lambda: not session.clock.paused and session.clock.now() > 0.2, 30)
    assert session.stats.errors == 0, session.stats.last_error


def test_a_slider_move_is_one_rebuild_and_one_new_ellipsoid(poinsot_app, probe):
    """Each slider value is rebuilt once and its ellipsoid reaches the client that moved it
    (how fast is ``poinsot benchmark``'s "slider-to-redraw" and "server rebuild alone")."""
    session = session_of(poinsot_app)
    uuid, _ = probe.widget("I₂")
    for value in (1.7, 1.8, 1.9):  # valid bodies: I3 = 2.6 <= I1 + I2
        rebuilds = session.stats.rebuilds
        probe.set_value(uuid, value)
        assert probe.wait_for(
            lambda p, v=value: (
                session.params.inertia[1] == v
                and np.allclose(
                    p.nodes["/space/body/ellipsoid"].props["scale"],
                    session.scene.geometry.semi_axes,
                )
            ),
            15,
        )
        # (counted just after the flush that the probe may already have read)
        assert wait_until(lambda r=rebuilds: session.stats.rebuilds > r, 15)
        assert session.stats.rebuilds == rebuilds + 1
    assert session.stats.errors == 0, session.stats.last_error


def _session_threads() -> list[str]:
    import threading

    return [t.name for t in threading.enumerate() if t.name.startswith("poinsot-session-")]


def test_clients_that_leave_during_connect_leave_no_session(poinsot_app):
    """Connect and drop at once, 100 times (some drops land while the session is being built,
    some after it started): afterwards no session, no frame thread and no pending departure."""
    from poinsot.app.devtools.probe import Probe

    before = len(_session_threads())
    for i in range(100):
        probe = Probe(poinsot_app.port)
        if i % 10 == 9:  # a few stay until their session runs, then leave
            wait_until(lambda: len(poinsot_app.sessions()) > 0, 5)
        probe.close()
    assert wait_until(
        lambda: (
            not poinsot_app.sessions()
            and poinsot_app.pending_departures() == 0
            and len(_session_threads()) <= before
        ),
        60,
    ), (len(poinsot_app.sessions()), poinsot_app.pending_departures(), _session_threads())
    assert poinsot_app.server.get_clients() == {}


def test_a_body_built_for_an_older_value_leaves_the_slider_where_the_browser_moved_it(
    poinsot_app, probe
):
    """Two values of |ω₀| from the browser, the second arriving while the body of the first is
    being built: the built body does not put the slider back to the first (the user's next
    key would step from there); the second is applied, and the slider keeps it."""
    import threading

    session = session_of(poinsot_app)
    uuid, widget = probe.widget("|ω₀|")
    first, second = float(widget.value) + 0.05, float(widget.value) + 0.1
    sent_back: list[float] = []

    def listen(message, _arrival) -> None:
        updates = message.get("updates", {})
        if message["type"] == "GuiUpdateMessage" and message["uuid"] == uuid:
            if "value" in updates:
                sent_back.append(float(updates["value"]))

    probe.add_listener(listen)
    panel = session.panel
    show = panel.show_parameters
    building, release = threading.Event(), threading.Event()
    shown: list[float] = []  # the slider's value once the first value's body is shown

    def held(params) -> None:  # the body of the first value, built: its sliders not yet shown
        building.set()
        release.wait(30)
        show(params)
        shown.append(float(panel.widgets.omega_norm.value))

    panel.show_parameters = held  # type: ignore[method-assign]
    probe.set_value(uuid, first)
    assert building.wait(20), "the first value's body was never built"
    panel.show_parameters = show  # type: ignore[method-assign]
    probe.set_value(uuid, second)
    slider = panel.widgets.omega_norm
    assert slider is not None
    assert wait_until(lambda: slider.value == pytest.approx(second), 10)  # it has arrived
    release.set()
    assert wait_until(lambda: session.params.omega_norm == pytest.approx(second), 10)
    after_frames(session, 5)
    assert slider.value == pytest.approx(second)
    assert shown == [pytest.approx(second)]
    assert not any(v == pytest.approx(first) for v in sent_back), sent_back


def test_a_slider_is_written_on_viser_s_loop_never_between_a_browser_s_value_and_its_callbacks(
    poinsot_app, probe
):
    """viser stores a browser's value in the handle on its event loop, then runs the callbacks
    that count it. The panel mirrors a built body into its sliders from the frame thread; were
    the write made there, it could land between the two and replace the user's value before it
    is counted. So the write waits for the loop: with the loop held, the slider keeps its
    value; released, the mirrored value is written (and sent)."""
    import threading

    session = session_of(poinsot_app)
    uuid, _ = probe.widget("|ω₀|")
    slider = session.panel.widgets.omega_norm
    assert slider is not None
    before = float(slider.value)
    mirrored = round(before + 0.3, 2)
    held, release = threading.Event(), threading.Event()

    def hold() -> None:
        held.set()
        release.wait(30)

    poinsot_app.server.get_event_loop().call_soon_threadsafe(hold)
    assert held.wait(10), "viser's loop never ran the hold"
    try:
        session.panel.show_parameters(session.params.with_omega_norm(mirrored))
        assert float(slider.value) == before  # not written from this thread
    finally:
        release.set()
    assert wait_until(lambda: float(slider.value) == pytest.approx(mirrored), 10)
    assert probe.wait_for(lambda p: p.widgets[uuid].value == pytest.approx(mirrored))


def test_a_session_still_being_built_when_the_server_stops_logs_no_error(
    make_app, make_probe, caplog, monkeypatch
):
    """A browser connects, and the server stops while its session is being built: the build
    meets viser's closed event loop, and nothing is logged as an error; no session starts."""
    import logging
    import threading

    from poinsot.app.live import server as server_module

    caplog.set_level(logging.DEBUG, logger=server_module.__name__)
    app = make_app()
    opening = server_module.links.opening
    building, release, done = threading.Event(), threading.Event(), threading.Event()

    def held(*args, **kwargs):
        building.set()
        release.wait(30)
        return opening(*args, **kwargs)

    log_failure = app._log_failure

    def logged(future) -> None:  # the build's end, on the pool's thread
        log_failure(future)
        done.set()

    monkeypatch.setattr(server_module.links, "opening", held)
    monkeypatch.setattr(app, "_log_failure", logged)
    make_probe(app)
    assert building.wait(20), "no session was being built"
    app.stop()
    release.set()
    assert done.wait(20), "the build never ended"
    errors = [r for r in caplog.records if r.levelno >= logging.ERROR]
    assert errors == [], [r.getMessage() for r in errors]
    assert app.sessions() == {}


def _closed_connection(caught: list[warnings.WarningMessage]) -> list[str]:
    return [str(w.message) for w in caught if "closed connection" in str(w.message)]


def test_a_session_built_for_a_browser_that_left_meanwhile_warns_of_nothing(poinsot_app, probe):
    """A browser may leave while its session is built: what the build sends then goes to
    nobody, silently (viser would warn of a write to a closed connection)."""
    client = session_of(poinsot_app).client
    buffer = viser_private.message_buffer(client)
    probe.close()
    assert wait_until(lambda: viser_private.closed(buffer) and not poinsot_app.sessions(), 30)
    link = links.opening(None, DEFAULT_PRESET, None)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        built_session(client, link, SessionOptions(follow=poinsot_app.follow)).close()
    assert _closed_connection(caught) == []
