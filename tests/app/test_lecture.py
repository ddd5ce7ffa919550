"""The lecture panel of a live session, driven by a headless websocket client
(app/devtools/probe.py): the CSV and GLB buttons hand files to the browser that parse back to
the session's body and time, and a screenshot that the client never renders ends in a message in the
panel, not a hang. (The real-browser side is in browser/test_exports_page.py.)"""

from __future__ import annotations

import io
import threading

import numpy as np
import pytest
import trimesh
from conftest import lecture_of, session_of, wait_until

from poinsot.app.exports import glb, run_csv


class Downloads:
    """Reassembles the files the server hands to the probe (send_file_download)."""

    def __init__(self, probe) -> None:
        self._lock = threading.Lock()
        self._starts: dict[str, dict] = {}
        self._parts: dict[str, dict[int, bytes]] = {}
        probe.add_listener(self._on_message)

    def _on_message(self, message: dict, _arrival: float) -> None:
        with self._lock:
            if message["type"] == "FileTransferStartDownload":
                self._starts[message["transfer_uuid"]] = message
                self._parts.setdefault(message["transfer_uuid"], {})
            elif message["type"] == "FileTransferPart":
                content = message["content"]
                self._parts.setdefault(message["transfer_uuid"], {})[message["part_index"]] = bytes(
                    content
                )

    def complete(self) -> dict[str, bytes]:
        """filename -> bytes of every download whose parts have all arrived."""
        out = {}
        with self._lock:
            for uuid, start in self._starts.items():
                parts = self._parts.get(uuid, {})
                if len(parts) == start["part_count"]:
                    data = b"".join(parts[i] for i in range(start["part_count"]))
                    assert len(data) == start["size_bytes"]
                    out[start["filename"]] = data
        return out


@pytest.fixture
def live(poinsot_app, make_probe):
    probe = make_probe(poinsot_app)
    downloads = Downloads(probe)
    assert probe.wait_for(lambda p: p.has_widget("Screenshot (PNG)"), 15), probe.labels()
    session = session_of(poinsot_app)
    assert wait_until(lambda: session.stats.frames > 5 and session.clock.now() > 0.1, 30)
    return probe, downloads, session


def click(probe, label: str) -> None:
    uuid, _ = probe.widget(label)
    probe.set_value(uuid, True)


def test_csv_button_downloads_the_run_so_far(live):
    probe, downloads, session = live
    t_click = session.clock.now()
    click(probe, "Data: t, ω, q (CSV)")
    assert wait_until(lambda: any(n.endswith(".csv") for n in downloads.complete()), 10)
    name, data = next((n, d) for n, d in downloads.complete().items() if n.endswith(".csv"))
    assert name.startswith(f"poinsot_{session.preset.key}_t")
    run = run_csv.read_run_csv(data.decode("utf-8"))
    # The run up to the click: t from 0 to the session's time then, from the session's body.
    assert run.t[0] == 0.0
    assert t_click <= run.t[-1] <= session.clock.now()
    assert float(name.removesuffix(".csv").rsplit("_t", 1)[1]) == pytest.approx(run.t[-1], abs=0.01)
    omega, _ = session.body.state(run.t)
    assert np.array_equal(run.omega, omega)
    assert run.meta["scene"] == session.preset.key
    # The message is written just after the download is sent: wait for it.
    message = lecture_of(session).message
    assert wait_until(lambda: "Saved" in message.content, 30), message.content


def test_glb_button_downloads_the_current_construction(live):
    probe, downloads, session = live
    click(probe, "Mesh: ellipsoid, plane, curves (GLB)")
    assert wait_until(lambda: any(n.endswith(".glb") for n in downloads.complete()), 10)
    data = next(d for n, d in downloads.complete().items() if n.endswith(".glb"))
    scene = trimesh.load(io.BytesIO(data), file_type="glb", force="scene")
    assert set(glb.GLB_NAMES) <= set(scene.geometry)
    # The same sizes as the scene the session draws.
    transform, geometry = scene.graph.get("plane")
    plane_y = trimesh.transform_points(scene.geometry[geometry].vertices, transform)[:, 1]
    assert np.allclose(plane_y, session.scene.geometry.plane_height, atol=1e-6)


def test_screenshot_that_never_renders_gives_a_message_not_a_hang(live):
    """The probe has no WebGL and never answers a render request: the button must come back
    after the timeout with a message, and be usable again."""
    probe, downloads, session = live
    lecture = lecture_of(session)
    lecture.render_timeout = 1.0
    click(probe, "Screenshot (PNG)")
    assert wait_until(lambda: "Screenshot failed" in lecture.message.content, 30)
    assert "did not return the picture within 1 s" in lecture.message.content  # its timeout
    # The message is written before the button is enabled again: wait for the button.
    assert wait_until(lambda: not lecture.screenshot.disabled, 10)
    assert not any(n.endswith(".png") for n in downloads.complete())
    # The panel shows the message too (what the probe, i.e. the browser, received).
    assert probe.wait_for(
        lambda p: any("Screenshot failed" in str(w.props) for w in p.widgets.values()), 30
    )
    # A second attempt is not blocked by the first.
    lecture.message.content = ""
    click(probe, "Screenshot (PNG)")
    assert wait_until(lambda: "Screenshot failed" in lecture.message.content, 10)
    assert session.stats.errors == 0, session.stats.last_error


def test_hotkeys_and_views_are_registered(live):
    probe, _, session = live
    lecture = lecture_of(session)
    hotkeys = {c.hotkey: c.label for c in lecture.commands}
    assert hotkeys == {
        "space": "Play / pause",
        "1": "Camera: default",
        "2": "Camera: along-L",
        "3": "Camera: side",
        "4": "Camera: ride-along",
        "P": "Projector mode",
        "V": "Two views",
    }
    assert probe.has_widget("Camera") and probe.has_widget("Dark theme")


def test_a_view_chosen_during_a_ride_along_frame_is_the_last_camera_sent(live, monkeypatch):
    """Key 3 pressed (viser's thread) while the frame thread is between its ride-along check
    and sending that camera: the chosen view must still be the last camera the browser gets
    (it was not: the ride-along camera landed after it and the browser stayed on the ride)."""
    from poinsot.app.construction.cameras import space_view
    from poinsot.app.live.lecture import lecture as lecture_module

    _, _, session = live
    controls = lecture_of(session)
    sent: list = []
    apply = controls._apply
    monkeypatch.setattr(controls, "_apply", lambda view: (sent.append(view), apply(view)))
    inside, release = threading.Event(), threading.Event()
    ride_along = lecture_module.ride_along
    stepping: threading.Thread | None = None  # this test's frame step, once started

    def slow_ride_along(view, q):
        if threading.current_thread() is stepping:  # this test's frame step only
            inside.set()
            release.wait(10)
        return ride_along(view, q)

    monkeypatch.setattr(lecture_module, "ride_along", slow_ride_along)
    controls.set_camera("ride-along")
    frame = session.frame
    chooser = threading.Thread(target=controls.set_camera, args=("side",))

    def frame_step() -> None:
        controls.on_frame(frame)

    stepping = threading.Thread(target=frame_step)
    stepping.start()
    assert inside.wait(10)  # the frame step has checked the view and computes its camera
    chooser.start()
    chooser.join(0.5)  # bounded: with the lock it waits for the frame step
    release.set()
    stepping.join(10)
    chooser.join(10)
    assert controls.camera == "side"
    side = controls.view("side")  # the side view, framed for this browser's view
    assert np.allclose(_direction(side), _direction(space_view("side")))
    assert np.allclose(sent[-1].position, side.position), sent[-1]


def _direction(view) -> np.ndarray:
    d = np.subtract(view.look_at, view.position)
    return d / np.linalg.norm(d)
