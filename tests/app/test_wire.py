"""Nothing from the wire is trusted: origins, raw widget values, floods, pending uploads."""

from __future__ import annotations

import collections
import logging
import math
import socket
import threading
import time
from typing import Any

import numpy as np
import pytest
import websockets
from conftest import TEST_MAX_FPS, after_frames, session_of, wait_until
from uploading import MESH

from poinsot.app import viser_private
from poinsot.app.devtools.load import crafted
from poinsot.app.devtools.probe import Probe
from poinsot.app.live.hardening import guard
from poinsot.app.live.hardening import transfers as transfers_module
from poinsot.app.live.hardening.budget import MessageBudget
from poinsot.app.live.hardening.guard import POLICY_VIOLATION, origin_allowed
from poinsot.app.live.hardening.transfers import handle_id
from poinsot.app.live.panel.motion_window import PLOT_SAMPLES, MotionWindow
from poinsot.app.live.panel.widgets import checked
from poinsot.app.model.parameters import TRAIL_RANGE, Parameters
from poinsot.app.model.presets import DEFAULT_PRESET, MESH_BODY

# -- origins ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("origin", "host", "allowed", "expected"),
    [
        (None, "127.0.0.1:8080", (), True),  # not a browser
        ("http://127.0.0.1:8080", "127.0.0.1:8080", (), True),
        ("https://Room.Example:8443/", "room.example:8443", (), True),
        ("http://evil.example", "127.0.0.1:8080", (), False),
        ("http://127.0.0.1:8081", "127.0.0.1:8080", (), False),  # another port is another site
        ("null", "127.0.0.1:8080", (), False),  # a local file, a sandboxed frame
        ("http://127.0.0.1:8080", None, (), False),
        ("http://slides.example", "127.0.0.1:8080", ("http://slides.example/",), True),
        ("file://", "127.0.0.1:8080", (), False),
    ],
)
def test_which_origins_may_connect(origin, host, allowed, expected):
    assert origin_allowed(origin, host, allowed) is expected


def _session_built(app, probe: Probe) -> bool:
    return wait_until(lambda: probe.closed or len(app.sessions()) == 1, 15) and not probe.closed


@pytest.mark.parametrize(
    ("origin", "served"),
    [
        ("http://evil.example", False),
        ("same", True),
        ("http://slides.example", True),  # given to --allow-origin
        (None, True),  # the probe, curl, the load test: no Origin header
    ],
)
def test_a_page_from_another_origin_gets_no_session(make_app, make_probe, origin, served):
    app = make_app(allow_origins=["http://slides.example"])
    if origin == "same":
        origin = f"http://127.0.0.1:{app.port}"
    if served:
        probe = make_probe(app, origin=origin)
        assert _session_built(app, probe)
        assert app.guard.refused == 0
    else:  # refused at the HTTP upgrade: no connection, no client id, no state in viser
        with pytest.raises(websockets.InvalidStatus) as refused:
            make_probe(app, origin=origin)
        assert refused.value.response.status_code == 403
        assert app.guard.refused == 1
        assert not viser_private.connection_count(app.server)
        assert len(app.sessions()) == 0


# -- raw values --------------------------------------------------------------------------------
def _non_finite(value: Any) -> bool:
    if isinstance(value, float):
        return not math.isfinite(value)
    if isinstance(value, np.ndarray):
        return value.dtype.kind == "f" and not bool(np.isfinite(value).all())
    if isinstance(value, dict):
        return any(_non_finite(v) for v in value.values())
    if isinstance(value, list | tuple):
        return any(_non_finite(v) for v in value)
    return False


JUNK = [math.nan, math.inf, -math.inf, 1e300, -1e300, 99_999_999, "abc", None, [1, 2], "Nope"]
INPUTS = ("GuiSliderMessage", "GuiNumberMessage", "GuiDropdownMessage", "GuiButtonGroupMessage")


def _values(options: list[Any]) -> list[Any]:
    """A dropdown's values, its options plain or in groups ({group, items: [{value, label}]})."""
    values: list[Any] = []
    for option in options:
        if isinstance(option, dict) and "items" in option:
            values += [
                item["value"] if isinstance(item, dict) else item for item in option["items"]
            ]
        else:
            values.append(option)
    return values


def _inputs(probe: Probe) -> dict[str, Any]:
    _, widgets = probe.snapshot()
    return {uuid: w for uuid, w in widgets.items() if w.type in INPUTS}


def test_junk_values_are_clamped_or_refused_and_the_session_keeps_running(
    poinsot_app, probe, caplog
):
    """Every value input of the panel gets what no browser sends: numbers are clamped into the
    widget's range, the rest refused (the widget shows its last value again); no frame fails,
    no NaN is sent, and a valid edit afterwards still works."""
    session = session_of(poinsot_app)
    sent_nan: list[str] = []
    probe.add_listener(lambda m, _: _non_finite(m) and sent_nan.append(m["type"]))
    inputs = _inputs(probe)
    assert {"I₁", "D = |L|²/2T", "|ω₀|", "Speed", "Trail length", "Preset"} <= {
        w.props.get("label") for w in inputs.values()
    }
    for uuid in inputs:
        for junk in JUNK:
            probe.set_value(uuid, junk)
    # a valid value after the junk: once it has arrived, so have the junk's callbacks
    trail_uuid, _ = probe.widget("Trail length")
    probe.set_value(trail_uuid, 1234)
    assert wait_until(lambda: session.scene.trail_points == 1234, 15)
    for handle in (session.panel.preset, session.panel.widgets.speed):
        assert handle.value == checked(handle, handle.value)
    # ... and the body they asked for is shown (the rebuild runs after the callbacks: until it
    # is done, the parameters and the D slider's range are still the first preset's, so the
    # checks below would pass at once, and the D sent would meet the junk body's range).
    build = session.choice.build
    assert wait_until(lambda: session.params == build.desired and not build.dirty, 15)
    after_frames(session, 2)
    # then valid edits: a preset (the junk made a sphere of the moments), and D
    preset_uuid, _ = probe.widget("Preset")
    probe.set_value(preset_uuid, DEFAULT_PRESET.label)
    assert wait_until(lambda: session.params == Parameters.from_preset(DEFAULT_PRESET), 15)
    energy = session.panel.widgets.energy  # the one shown (others are kept hidden)
    d_uuid = handle_id(energy)
    # The slider's range is the preset's once the panel has mirrored the new body (just after
    # the body itself): a value that arrives before is clamped into the junk's range.
    d_range = pytest.approx(Parameters.from_preset(DEFAULT_PRESET).D_range)
    assert wait_until(lambda: (energy.min, energy.max) == d_range, 15), (energy.min, energy.max)
    # ... and the probe's once that range has reached it (the target is computed from it: from
    # a range not yet updated, the target could lie outside the new one and be clamped).
    assert probe.wait_for(
        lambda p: (p.widgets[d_uuid].props["min"], p.widgets[d_uuid].props["max"]) == d_range
    ), (probe.widgets[d_uuid].props["min"], probe.widgets[d_uuid].props["max"])
    d = probe.widgets[d_uuid]
    target = round(0.3 * d.props["min"] + 0.7 * d.props["max"], 2)
    probe.set_value(d_uuid, target)
    assert wait_until(lambda: abs(session.params.D - target) < 0.02, 15), (
        poinsot_app.guard.dropped,
        poinsot_app.guard.malformed,
        len(inputs),
        session.params,
        target,
    )
    frames = session.stats.frames
    assert wait_until(lambda: session.stats.frames > frames + 10, 30), "the frames stopped"
    assert session.stats.errors == 0, session.stats.last_error
    assert not sent_nan
    # a value viser could not even convert (a text for a slider) never reaches it
    assert poinsot_app.guard.malformed > 0
    assert not [r for r in caplog.records if r.levelname == "ERROR"], caplog.text[:2000]
    assert math.isfinite(session.clock.speed) and math.isfinite(session.clock.now())

    def in_range(widget: Any) -> bool:
        if "min" in widget.props and widget.value is not None:
            return bool(widget.props["min"] <= widget.value <= widget.props["max"])
        return "options" not in widget.props or widget.value in _values(widget.props["options"])

    # A widget's new range and its new value are two messages: wait for both to arrive.
    def all_in_range(p: Probe) -> bool:
        return all(in_range(w) for w in p.widgets.values() if w.type in INPUTS)

    assert probe.wait_for(all_in_range, 15), [
        w.props for w in _inputs(probe).values() if not in_range(w)
    ]


def test_a_number_beyond_the_range_is_clamped_and_shown_clamped(poinsot_app, probe):
    session = session_of(poinsot_app)
    uuid, widget = probe.widget("|ω₀|")
    top = widget.props["max"]
    probe.set_value(uuid, 99_999_999.0)
    assert probe.wait_for(lambda p: p.widgets[uuid].value == top, 10)
    assert wait_until(lambda: abs(session.params.omega_norm - top) < 1e-9, 10)
    uuid, widget = probe.widget("Speed")
    before = session.clock.speed
    probe.set_value(uuid, math.nan)
    assert probe.wait_for(lambda p: p.widgets[uuid].value == before, 10)  # set back
    probe.set_value(uuid, -1e300)
    assert probe.wait_for(lambda p: p.widgets[uuid].value == widget.props["min"], 10)
    assert wait_until(lambda: session.clock.speed == widget.props["min"], 10)
    assert session.stats.errors == 0, session.stats.last_error


def test_a_gui_update_naming_another_property_is_dropped(poinsot_app, probe):
    """A browser sends only values; viser would set any attribute named (the callbacks)."""
    session = session_of(poinsot_app)
    after_frames(session, 30)  # settled: the panel's playback values are not shown again
    uuid, widget = probe.widget("Speed")
    probe.send(
        viser_private.wire_message("GuiUpdateMessage", uuid, {"max": 1e300, "update_cb": []})
    )
    assert wait_until(lambda: poinsot_app.guard.malformed == 1, 10)
    probe.set_value(uuid, 1e300)
    assert wait_until(lambda: session.clock.speed == widget.props["max"], 10)


# -- floods ------------------------------------------------------------------------------------
FLOOD_RATE = 10_000.0
#: The flood's length [s]: longer than the server's patience (guard.EXCESS_SECONDS over budget,
#: then a second to answer the close).
FLOOD_SECONDS = 6.0
#: Frames the other client's session draws at least while the flooder is over its budget and
#: still connected: a quarter of the test server's rate over guard.EXCESS_SECONDS (a server that
#: the flood held would draw none). The share of its quiet rate is a timing: the load test's
#: flood phase measures it (``make load``).
FLOODED_FRAMES = int(0.25 * TEST_MAX_FPS * guard.EXCESS_SECONDS)


@pytest.mark.slow
def test_a_flooding_client_is_cut_off_and_the_others_keep_their_frames(make_app, make_probe):
    """A raw client (its own process) sends 10k camera messages a second: beyond its budget
    they are dropped unread by viser, then it is disconnected; the other client's session
    draws its frames meanwhile (counted from the flood's start to the cut-off)."""
    from poinsot.app.devtools.load.workloads.flood import Flooder

    app = make_app()
    make_probe(app)
    quiet_session = session_of(app)
    assert wait_until(lambda: quiet_session.stats.frames > 30, 30)
    with Flooder(app.port, FLOOD_RATE, FLOOD_SECONDS, lifetime=120.0) as flooder:
        assert len(app.sessions()) == 2
        before = quiet_session.stats.frames
        flooder.begin()
        assert wait_until(lambda: app.guard.disconnected == 1, 30)
        flooded = quiet_session.stats.frames - before
        sent = flooder.end()
    assert sent["sent"] > 2 * guard.MESSAGE_BURST
    # Over its budget, the guard reads one message each 1/MESSAGE_RATE s and drops it, until
    # the excess has lasted EXCESS_SECONDS: how many is the pace of the machine's sleeps (400,
    # once, on a busy machine), not the guard's choice.
    assert app.guard.dropped > 0, (app.guard.dropped, sent)
    assert app.guard.disconnected == 1 and sent["closed_by_server"], sent
    assert wait_until(lambda: len(app.sessions()) == 1, 10)
    assert quiet_session.stats.errors == 0
    assert flooded >= FLOODED_FRAMES, (flooded, sent)


# -- bounded: uploads --------------------------------------------------------------------------
MB = 1_000_000


def _peak_while(measure, action) -> int:
    """The largest ``measure()`` seen while ``action()`` runs (polled from another thread)."""
    peak, done = [0], threading.Event()

    def poll() -> None:
        while not done.is_set():
            peak[0] = max(peak[0], measure())
            time.sleep(0.005)

    poller = threading.Thread(target=poll, daemon=True)
    poller.start()
    try:
        action()
    finally:
        done.set()
        poller.join()
    return max(peak[0], measure())


def test_pending_uploads_stay_bounded_and_are_freed_when_the_client_leaves(poinsot_app, probe):
    """A raw client sends 200 MB of upload parts: ten transfers of 19 MB announced at once to
    the mesh button, parts sent round robin, and parts "uploaded" to a slider. The parts held
    stay within one client's pending cap (plus a part), and are freed when it leaves."""
    session = session_of(poinsot_app)
    probe.set_value(probe.widget("Preset")[0], MESH_BODY.label)
    assert probe.wait_for(lambda p: MESH in p.labels(), 10)
    guard_ = session.uploads.guard
    button, _ = probe.widget(MESH)
    slider, _ = probe.widget("Speed")
    part = b"\0" * MB

    def send_200_mb() -> None:
        transfers = [f"t{k}" for k in range(10)]
        for t in transfers:
            probe.send(
                viser_private.wire_message(
                    "FileTransferStartUpload", button, t, f"{t}.stl", "x", 19, 19 * MB
                )
            )
        probe.send(
            viser_private.wire_message(
                "FileTransferStartUpload", slider, "s", "s.stl", "x", 10, 10 * MB
            )
        )
        for k in range(19):
            for t in transfers:
                probe.send(viser_private.wire_message("FileTransferPart", button, t, k, part))
        for k in range(9):  # the slider's, and the first transfer's last part, never come
            probe.send(viser_private.wire_message("FileTransferPart", slider, "s", k, part))
        probe.widget(MESH)  # the probe's own model: nothing to wait for on the server

    peak = _peak_while(guard_.pending_bytes, send_200_mb)
    states = viser_private.upload_states(session.client.gui)
    assert wait_until(lambda: guard_.pending_bytes() == 19 * MB or not states, 20)
    assert peak <= transfers_module.MAX_PENDING_BYTES + MB, peak
    assert set(states) <= {"t0"}  # one transfer in progress at most, the first
    assert poinsot_app.guard.dropped == 0  # within the message budget: the caps held it
    probe.close()
    assert wait_until(lambda: guard_.pending_bytes() == 0 and not states, 10)


# -- bounded: trails, the plot, what a client may queue -----------------------------------------
def test_a_client_cannot_lengthen_the_trails_beyond_their_cap(poinsot_app, probe):
    """The trail length a client sends is clamped to the slider's top (the ring of chunks
    itself holds its length: tests/app/test_parts.py)."""
    session = session_of(poinsot_app)
    # Once the new session has settled: a value that comes while the server shows the panel's
    # playback values again (at start) was overwritten by them before its callback read it.
    after_frames(session, 30)
    probe.set_value(probe.widget("Trail length")[0], 10**12)
    # The scene's length is set first, then each trail's (on the frame thread): wait for all.
    assert wait_until(lambda: session.scene.trail_points == TRAIL_RANGE[1], 30)
    assert wait_until(
        lambda: all(t.max_points == TRAIL_RANGE[1] for t in session.scene._trails.values()), 30
    ), {e: t.max_points for e, t in session.scene._trails.items()}


def test_the_plot_keeps_a_window_of_samples(poinsot_app):
    motion = MotionWindow(poinsot_app.server.gui, order=0.0)
    motion.add_plot()
    for k in range(3 * PLOT_SAMPLES):
        motion.record_plot(0.01 * k, np.array([1.0, 2.0, 3.0]))
    assert motion.send_plot()
    assert motion.plot is not None
    assert all(len(series) == PLOT_SAMPLES for series in motion.plot.data)


def test_what_a_client_gets_through_is_bounded_by_its_budget():
    """The budget admits at most its burst at once and its rate after; a second within the
    budget ends a streak of excess."""
    budget = MessageBudget(rate=100.0, burst=50.0, excess_seconds=2.0)
    t = time.monotonic()
    admitted = sum(budget.admit(t) for _ in range(1000))  # 1000 at once
    assert admitted == 50 and budget.dropped == 950 and not budget.sustained(t)
    flood = [t + 0.001 * k for k in range(1, 3001)]  # 3 s at 1000 messages a second
    admitted = sum(budget.admit(now) for now in flood)
    assert admitted <= 100.0 * 3.0 + 1 and budget.sustained(flood[-1])
    assert not budget.sustained(flood[-1] + 1.5)  # it paused


# -- the allow-list: only what viser's client sends --------------------------------------------
def _quiet(caplog, capfd) -> tuple[list[str], str]:
    """The guard's log lines, and whatever else reached the terminal (tracebacks, rich)."""
    lines = [r.getMessage() for r in caplog.records if r.name == guard.__name__]
    assert not [r for r in caplog.records if r.exc_info or r.levelno >= logging.ERROR]
    out, err = capfd.readouterr()
    return lines, out + err


@pytest.mark.parametrize("name", list(crafted.MESSAGES))
def test_a_message_viser_s_client_never_sends_closes_its_sender_with_one_line(
    poinsot_app, make_probe, caplog, capfd, name
):
    """Valid msgpack that is wrong for viser, or no msgpack at all: the sender is closed with
    1008 and one log line naming the type and the client, never a traceback; the share
    tunnel is never asked for; another client plays on."""
    caplog.set_level(logging.WARNING)
    other = make_probe(poinsot_app)
    assert other.wait_frames(3)
    probe = make_probe(poinsot_app)
    capfd.readouterr()
    probe.send_raw(crafted.MESSAGES[name])
    assert wait_until(lambda: probe.closed, 10)
    assert probe.close_code == POLICY_VIOLATION
    assert poinsot_app.guard.closed_for_message == 1
    lines, terminal = _quiet(caplog, capfd)
    assert len(lines) == 1 and "127.0.0.1:" in lines[0], lines
    assert "Traceback" not in terminal and "Share URL" not in terminal, terminal[-2000:]
    assert other.wait_frames(3) and not other.closed


def test_the_share_tunnel_is_off_on_the_server_side_too(poinsot_app):
    assert not viser_private.share_enabled(poinsot_app.server)
    assert "ShareUrlRequest" not in viser_private.ALLOWED


def test_many_bad_messages_give_few_lines(poinsot_app, caplog, capfd):
    """50 refused messages, from 50 clients: the lines are rate-limited (one a second, the
    rest counted in the next), and none is a traceback."""
    caplog.set_level(logging.WARNING)
    payloads = list(crafted.MESSAGES.values())
    outcomes = collections.Counter(
        crafted.send_message(poinsot_app.port, payloads[k % len(payloads)]) for k in range(50)
    )
    assert outcomes == {"closed 1008": 50}
    lines, terminal = _quiet(caplog, capfd)
    assert 1 <= len(lines) < 15 and "Traceback" not in terminal, (lines, terminal[-2000:])


# -- handshakes --------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("host", "listen", "allowed", "expected"),
    [
        ("127.0.0.1:8080", "127.0.0.1", (), True),
        ("localhost:8080", "127.0.0.1", (), True),
        ("127.0.0.1:80", "127.0.0.1", (), True),  # nginx in front forwards the page's own Host
        ("evil.example:8080", "0.0.0.0", (), False),  # DNS rebinding
        ("evil.example:8080", "127.0.0.1", (), False),
        ("192.0.2.7:8080", "0.0.0.0", (), False),  # not an address of this machine
        ("room.example", "0.0.0.0", ("https://room.example",), True),
        ("room.example:8080", "room.example", (), True),
        ("[::1]:8080", "0.0.0.0", (), True),
        ("", "0.0.0.0", (), False),
        (None, "0.0.0.0", (), False),
    ],
)
def test_which_hosts_may_connect(host, listen, allowed, expected):
    assert guard.host_allowed(host, listen, allowed) is expected


def _rss() -> int:
    with open("/proc/self/status") as f:
        return next(int(line.split()[1]) * 1024 for line in f if line.startswith("VmRSS:"))


@pytest.mark.slow
def test_two_thousand_bad_handshakes_leave_nothing_behind(poinsot_app, caplog, capfd):
    """Duplicate and missing Host, DNS rebinding, foreign and null origins: each is answered
    403 at the upgrade; memory stays within 5 % (after a warm-up), viser holds no connection
    state, no traceback is printed."""
    caplog.set_level(logging.WARNING)
    port = poinsot_app.port
    assert crafted.bad_handshakes(port, 200) == {"403": 200}  # warm-up: caches, allocator
    before = _rss()
    assert crafted.bad_handshakes(port, 2000) == {"403": 2000}
    after = _rss()
    assert not viser_private.connection_count(poinsot_app.server)
    assert not viser_private.live_connection_ids(poinsot_app.server)
    assert poinsot_app.guard.refused == 2200 and not poinsot_app.sessions()
    assert after <= 1.05 * before, (before, after)
    _, terminal = _quiet(caplog, capfd)
    assert "Traceback" not in terminal, terminal[-2000:]


def test_a_rebinding_page_is_refused_and_the_own_page_is_not(poinsot_app, make_probe):
    port = poinsot_app.port
    rebinding = crafted.HANDSHAKES["DNS rebinding (Host and Origin evil.example)"](port)
    assert crafted.exchange(port, rebinding) == "403"
    probe = make_probe(poinsot_app, origin=f"http://127.0.0.1:{port}")
    assert _session_built(poinsot_app, probe)


@pytest.mark.parametrize("name", list(crafted.HTTP10))
def test_an_http_1_0_get_gets_the_page(poinsot_app, caplog, capfd, name):
    caplog.set_level(logging.WARNING)
    with socket.create_connection(("127.0.0.1", poinsot_app.port), timeout=10) as sock:
        sock.sendall(crafted.HTTP10[name])
        answer = b"".join(iter(lambda: sock.recv(1 << 16), b""))
    head, _, body = answer.partition(b"\r\n\r\n")
    assert head.startswith(b"HTTP/1.1 200"), head[:200]
    assert b"<html" in body.lower()
    _, terminal = _quiet(caplog, capfd)
    assert "Traceback" not in terminal
