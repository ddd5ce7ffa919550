"""A body of one's own, through the wire: recordings and meshes uploaded by a probe that speaks
viser's protocol like the browser (announce, then parts), and what the session then sends.

Good uploads become the body on screen (moments in the sliders, the measured ω in the plot,
the mesh as the solid); bad ones (junk, too large, open meshes, NaN rows, no flight) leave a
message in the folder and the scene as it was, with nothing non-finite sent."""

from __future__ import annotations

import threading

import numpy as np
import pytest
from conftest import after_frames, session_of, wait_until
from test_scene_geometry import check_finite
from test_server import markdown_texts
from uploading import (
    MESH,
    PART,
    RECORDING,
    box_stl,
    expected_moments,
    open_bowl_stl,
    phyphox_csv,
    toss_recording,
    upload,
)

from poinsot.app import viser_private
from poinsot.app.model import own_bodies
from poinsot.app.model.bodies import bundled_body, load_mesh_body
from poinsot.app.model.elements import Control, Plot
from poinsot.app.model.presets import DEFAULT_PRESET, FITTED_TOSS, MESH_BODY, preset_by_key

SLIDERS = ("I₁", "I₂", "I₃")


def choose(probe, session, label: str) -> None:
    uuid, _ = probe.widget("Preset")
    probe.set_value(uuid, label)
    assert wait_until(lambda: session.preset.label == label, 10), session.preset.label


def finished(session, count: int) -> None:
    assert wait_until(lambda: session.uploads.finished >= count, 30), "the upload never finished"


def shown_labels(probe) -> set[str]:
    """Labels of the widgets the browser shows: each visible, and every folder around it."""
    _, widgets = probe.snapshot()

    def shown(widget) -> bool:
        while widget is not None:
            if not widget.props.get("visible", True):
                return False
            widget = widgets.get(widget.container)
        return True

    return {str(w.props["label"]) for w in widgets.values() if w.props.get("label") and shown(w)}


def ellipsoid_scale(probe) -> np.ndarray:
    return np.asarray(probe.snapshot()[0]["/space/body/ellipsoid"].props["scale"], dtype=float)


def slider_values(probe) -> np.ndarray:
    return np.array([probe.widget(label)[1].value for label in SLIDERS], dtype=float)


def the_plot(probe):
    _, widgets = probe.snapshot()
    plots = [
        w for w in widgets.values() if w.type == "GuiUplotMessage" and w.props.get("visible", True)
    ]
    assert len(plots) == 1, len(plots)
    return plots[0]


def scene_shown(session, probe):
    """What must stay as it was after a refused upload."""
    return session.body, session.preset, ellipsoid_scale(probe)


def assert_kept(session, probe, before) -> None:
    body, preset, scale = before
    received = len(probe.batches)
    after_frames(session)  # anything the refusal would have sent went out before these frames
    assert probe.wait_for(lambda p: len(p.batches) >= received + 5, 15)
    assert session.body is body and session.preset is preset
    assert np.allclose(ellipsoid_scale(probe), scale)
    assert session.stats.errors == 0, session.stats.last_error
    check_finite(probe)


def settled(session, probe) -> None:
    """The chosen entry's body is on screen (its rebuild done and sent)."""
    assert wait_until(lambda: session.params.inertia == session.preset.inertia, 10)
    scale = session.scene.geometry.semi_axes
    assert probe.wait_for(lambda p: np.allclose(ellipsoid_scale(p), scale), 10)


@pytest.fixture
def toss_page(poinsot_app, probe):
    """The session on "Fitted toss", its upload folder built."""
    session = session_of(poinsot_app)
    choose(probe, session, FITTED_TOSS.label)
    assert probe.wait_for(lambda p: RECORDING in p.labels(), 10)
    settled(session, probe)
    return session


@pytest.fixture
def mesh_page(poinsot_app, probe):
    session = session_of(poinsot_app)
    choose(probe, session, MESH_BODY.label)
    assert probe.wait_for(lambda p: MESH in p.labels(), 10)
    settled(session, probe)
    return session


# -- declared like every control ------------------------------------------------------------
def test_only_the_own_body_entries_have_the_upload_folders(poinsot_app, probe):
    session = session_of(poinsot_app)
    assert not ({RECORDING, MESH, "Bundled body"} & set(probe.labels()))  # never made
    assert Control.TOSS not in DEFAULT_PRESET.controls
    for key in ("fitted_toss", "mesh_body"):
        choose(probe, session, preset_by_key(key).label)
        assert probe.wait_for(lambda p: {RECORDING, MESH} <= shown_labels(p), 10), key
    choose(probe, session, preset_by_key("t_handle").label)
    assert probe.wait_for(lambda p: not ({RECORDING, MESH} & shown_labels(p)), 10)
    # a body edited by hand (a slider, a click) keeps the folders it had, and adds none
    session.edit(lambda p: p.with_inertia(0, 1.1))
    assert wait_until(lambda: session.preset.key == "custom" and not session.build.dirty, 10)
    assert not ({Control.TOSS, Control.MESH} & session.panel.groups)
    choose(probe, session, preset_by_key("custom").label)
    assert not ({Control.TOSS, Control.MESH} & session.panel.groups)


# -- a recording ----------------------------------------------------------------------------
def test_a_recording_is_fitted_and_plays_like_a_preset(toss_page, probe):
    session = toss_page
    upload(probe, RECORDING, "my toss.csv", toss_recording())
    finished(session, 1)
    assert wait_until(lambda: session.preset.key == "fitted_toss" and session.params.omega0, 10)
    moments = np.asarray(session.params.inertia)
    np.testing.assert_allclose(moments, expected_moments(), atol=5e-3)
    assert probe.wait_for(lambda p: np.allclose(slider_values(p), moments), 10)
    _, omega_slider = probe.widget("|ω₀|")
    assert omega_slider.value == pytest.approx(np.linalg.norm(session.params.omega0))
    assert omega_slider.props["max"] >= omega_slider.value  # widened past 4 rad/s
    assert probe.wait_for(lambda p: any("| rms residual |" in t for t in markdown_texts(p)), 10)
    readout = next(t for t in markdown_texts(probe) if "| rms residual |" in t)
    assert "my toss.csv" in readout
    fit = session.uploads.toss.fit
    for k in range(3):
        assert own_bodies.plus_minus(fit.inertia[k], fit.inertia_sigma[k]) in readout
    assert "explained" in readout and "not explained" not in readout
    assert "flip period, predicted" in readout and "flip period, measured" in readout
    assert session.status == "" and session.stats.errors == 0, session.stats.last_error
    check_finite(probe)


def test_the_plot_draws_the_measured_omega_over_the_exact_one(toss_page, probe):
    session = toss_page
    upload(probe, RECORDING, "toss.csv", toss_recording())
    finished(session, 1)
    toss = session.uploads.toss
    assert Plot.MEASURED in session.preset.plots

    def overlaid(p) -> bool:
        plots = [w for w in p.widgets.values() if w.type == "GuiUplotMessage"]
        return any(len(w.props["series"]) == 7 and len(w.props["data"][0]) > 50 for w in plots)

    assert probe.wait_for(overlaid, 10)
    plot = the_plot(probe)
    labels = [s["label"] for s in plot.props["series"]]
    assert labels[4:] == ["ω₁ measured", "ω₂ measured", "ω₃ measured"]
    x, *columns = (np.asarray(c, dtype=float) for c in plot.props["data"])
    exact, measured = np.stack(columns[:3], 1), np.stack(columns[3:], 1)
    assert np.all(np.isfinite(x)) and np.all(np.isfinite(exact)) and np.all(np.diff(x) >= 0)
    seen = np.all(np.isfinite(measured), axis=1)
    assert np.all(np.isfinite(measured[seen])) and not np.any(np.isfinite(measured[~seen]))
    # every kept sample of the recording is there, at its time, with the fit beside it
    assert seen.sum() == toss.tau.size
    np.testing.assert_allclose(x[seen], toss.tau)
    np.testing.assert_allclose(measured[seen], toss.measured)
    assert np.sqrt(np.mean((measured[seen] - exact[seen]) ** 2)) < 0.05  # the noise: 0.02
    # uPlot cannot range an axis over NaN: the ω axis is fixed, and holds every value
    y = plot.props["scales"]["y"]
    assert y["auto"] is False and y["range"][0] == -y["range"][1]
    assert np.max(np.abs(exact)) < y["range"][1] and np.max(np.abs(measured[seen])) < y["range"][1]
    assert y["range"][1] < 2.0 * np.linalg.norm(session.params.omega0)  # and is not far off
    # the exact solution goes on past the recording
    session.set_speed(4.0)
    assert probe.wait_for(lambda p: float(the_plot(p).props["data"][0][-1]) > toss.tau[-1], 20)


def test_reset_speed_and_the_menu_entry_bring_the_toss_back(toss_page, probe):
    session = toss_page
    upload(probe, RECORDING, "toss.csv", toss_recording())
    finished(session, 1)
    fitted = session.preset
    assert wait_until(lambda: session.frame is not None and session.frame.t > 0.05, 10)
    for button in ("Pause", "Reset"):
        uuid, _ = probe.widget(button)
        probe.set_value(uuid, True)
    assert wait_until(lambda: session.frame is not None and session.frame.t == 0.0, 10)
    uuid, _ = probe.widget("Speed")
    probe.set_value(uuid, 0.5)
    assert wait_until(lambda: session.clock.speed == 0.5, 10)
    choose(probe, session, preset_by_key("major").label)
    choose(probe, session, FITTED_TOSS.label)
    assert wait_until(lambda: session.preset is fitted and session.params.inertia == fitted.inertia)
    assert session.stats.errors == 0, session.stats.last_error


def test_the_work_runs_on_the_upload_workers(toss_page, probe, monkeypatch):
    names: list[str] = []
    fit = own_bodies.fit_recording

    def spy(data: bytes, name: str):
        names.append(threading.current_thread().name)
        return fit(data, name)

    monkeypatch.setattr(own_bodies, "fit_recording", spy)
    upload(probe, RECORDING, "toss.csv", toss_recording())
    finished(toss_page, 1)
    assert names and names[0].startswith("poinsot-upload")


def test_an_upload_that_finishes_after_its_folder_is_gone(toss_page, probe, monkeypatch):
    """The student leaves for another preset while the fit runs; the folder goes (put away or
    deleted). The result still comes and brings the folder back, with its readout, and no
    update reaches a widget that is gone."""
    session = toss_page
    release = threading.Event()
    fit = own_bodies.fit_recording

    def slow(data: bytes, name: str):
        release.wait(20)
        return fit(data, name)

    monkeypatch.setattr(own_bodies, "fit_recording", slow)
    upload(probe, RECORDING, "toss.csv", toss_recording())
    assert wait_until(lambda: "Fitting toss.csv" in session.uploads.toss_lines.status, 10)
    choose(probe, session, preset_by_key("major").label)
    assert probe.wait_for(lambda p: RECORDING not in shown_labels(p), 10)
    assert wait_until(lambda: session.preset.key == "major", 10)
    after_frames(session)  # the switch is drawn while the fit is still held
    release.set()
    finished(session, 1)
    assert wait_until(lambda: session.preset.key == "fitted_toss", 10)
    assert probe.wait_for(lambda p: RECORDING in shown_labels(p), 10)
    assert probe.wait_for(lambda p: any("| rms residual |" in t for t in markdown_texts(p)), 10)
    assert session.stats.errors == 0, session.stats.last_error


def _nan_rows() -> bytes:
    lines = toss_recording().decode().splitlines()
    lines[40] = "0.3966,nan,nan,nan,nan"
    return ("\n".join(lines) + "\n").encode()


def _slow_spin() -> bytes:
    t = np.arange(0.0, 2.0, 0.01)
    return phyphox_csv(t, np.column_stack([np.full_like(t, 0.5), 0 * t, 0 * t]))


BAD_RECORDINGS = {
    "junk": ("toss.csv", b"\x00\xff\xfe junk \x89PNG", "is not a text (CSV) file"),
    "nan rows": ("toss.csv", _nan_rows(), "line 41: a value is not a number"),
    "no flight": ("toss.csv", _slow_spin(), "No free flight found in toss.csv"),
    "empty": ("toss.csv", b"", "toss.csv is empty"),
    "not a recording": ("toss.mp4", b"\x00\x00\x00\x18ftypmp42", "is not a recording Poinsot"),
    "another sensor": (
        "toss.csv",
        b'"Time (s)","Acceleration x (m/s^2)","Acceleration y (m/s^2)","Acceleration z (m/s^2)"'
        b"\n0,1,2,3\n0.01,1,2,3\n",
        "is not a gyroscope recording",
    ),
}


@pytest.mark.parametrize("case", sorted(BAD_RECORDINGS))
def test_a_bad_recording_is_explained_and_the_scene_kept(toss_page, probe, case):
    session = toss_page
    name, content, message = BAD_RECORDINGS[case]
    before = scene_shown(session, probe)
    upload(probe, RECORDING, name, content)
    finished(session, 1)
    assert probe.wait_for(lambda p: any(message in t for t in markdown_texts(p)), 10), (
        session.uploads.toss_lines.status
    )
    assert "The body shown is kept" in session.uploads.toss_lines.status
    assert "/tmp" not in session.uploads.toss_lines.status  # the server's folders stay private
    assert session.uploads.toss is None
    assert_kept(session, probe, before)


# -- the size cap -----------------------------------------------------------------------------
CAP = 200_000


@pytest.fixture
def small_caps(monkeypatch):
    """Caps of 200 kB (0.191 MB) on both kinds of upload."""
    monkeypatch.setattr(own_bodies, "MAX_RECORDING_BYTES", CAP)
    monkeypatch.setattr(own_bodies, "MAX_MESH_BYTES", CAP)


def long_recording() -> bytes:
    """Two minutes of a spinning phone: more than two parts of an upload."""
    content = toss_recording(duration=120.0)
    assert len(content) > 2 * PART
    return content


def _acks(probe, transfer: str) -> list[int]:
    acks: list[int] = []
    probe.add_listener(
        lambda m, _: (
            acks.append(int(m["transferred_bytes"]))
            if m["type"] == "FileTransferPartAck" and m["transfer_uuid"] == transfer
            else None
        )
    )
    return acks


@pytest.mark.parametrize("declared", ["honest", "understated"])
def test_a_file_over_the_cap_is_dropped_while_it_arrives(
    small_caps, toss_page, probe, monkeypatch, declared
):
    session = toss_page
    before = scene_shown(session, probe)
    work: list[str] = []
    real = own_bodies.fit_recording
    monkeypatch.setattr(own_bodies, "fit_recording", lambda d, n: work.append(n) or real(d, n))
    content = long_recording()
    size = len(content) if declared == "honest" else 1000
    upload(probe, RECORDING, "long.csv", content, declared=size)
    finished(session, 1)
    assert "long.csv is" in session.uploads.toss_lines.status
    assert "files up to 0.191 MB are accepted" in session.uploads.toss_lines.status
    assert wait_until(lambda: session.uploads.guard.dropped == 0, 10)  # every part answered
    assert viser_private.upload_states(session.client.gui) == {}  # nothing kept in viser
    assert work == []  # never parsed
    assert_kept(session, probe, before)


def test_the_callback_refuses_a_file_over_the_cap_too(small_caps, toss_page, probe):
    """The guard answered for files that arrive in full: the callback checks again."""
    session = toss_page
    session.uploads.guard.caps.clear()  # the guard lets everything through
    before = scene_shown(session, probe)
    content = toss_recording(duration=30.0)
    assert CAP < len(content) < PART  # one part: the guard would have seen it whole
    upload(probe, RECORDING, "long.csv", content)
    finished(session, 1)
    assert "long.csv is" in session.uploads.toss_lines.status
    assert session.uploads.toss is None
    assert_kept(session, probe, before)


def test_the_browser_is_told_every_part_of_a_dropped_file_arrived(small_caps, toss_page, probe):
    content = long_recording()
    transfer = "dropped-transfer"
    acks = _acks(probe, transfer)
    button, _ = probe.widget(RECORDING)
    parts = [content[i : i + PART] for i in range(0, len(content), PART)]
    probe.send(
        viser_private.wire_message(
            "FileTransferStartUpload",
            button,
            transfer,
            "long.csv",
            "text/csv",
            len(parts),
            len(content),
        )
    )
    for k, part in enumerate(parts):
        probe.send(viser_private.wire_message("FileTransferPart", button, transfer, k, part))
    assert probe.wait_for(lambda p: len(acks) == len(parts), 10), acks
    assert acks[-1] == len(content)


# -- a mesh -------------------------------------------------------------------------------------
def test_a_mesh_upload_becomes_the_body(mesh_page, probe):
    session = mesh_page
    content = box_stl((3.0, 2.0, 1.0))
    measured = load_mesh_body(content, "box.stl")
    upload(probe, MESH, "box.stl", content)
    finished(session, 1)
    assert wait_until(lambda: session.preset.key == "mesh_body" and session.preset.solid, 10)
    ratios = np.asarray(measured.ratios)
    np.testing.assert_allclose(ratios, np.array([5.0, 10.0, 13.0]) / 13.0, rtol=1e-6)
    np.testing.assert_allclose(session.params.inertia, ratios)
    assert probe.wait_for(lambda p: np.allclose(slider_values(p), ratios), 10)

    def solid_vertices(p) -> int:
        node = p.nodes.get("/space/body/solid")
        return -1 if node is None else len(node.props["vertices"]) // 3

    assert probe.wait_for(lambda p: solid_vertices(p) == len(measured.mesh.vertices), 10)
    assert "box.stl" in session.uploads.mesh_lines.readout
    assert session.uploads.mesh_lines.status == ""  # nothing to repair
    assert session.stats.errors == 0, session.stats.last_error
    check_finite(probe)


def test_a_mesh_with_a_small_hole_is_repaired_and_says_so(mesh_page, probe):
    session = mesh_page
    upload(probe, MESH, "holed box.stl", box_stl(drop_faces=1))
    finished(session, 1)
    assert wait_until(lambda: session.preset.key == "mesh_body", 10)
    assert session.uploads.mesh_lines.status.startswith("Repaired: holed box.stl")
    assert probe.wait_for(lambda p: any("Repaired" in t for t in markdown_texts(p)), 10)
    assert "repaired" in session.preset.source


def test_a_bundled_body_with_a_moment_below_the_sliders_range(mesh_page, probe):
    session = mesh_page
    racquet = bundled_body("racquet")
    assert racquet.ratios[0] < 0.1  # below the usual range of the sliders
    uuid, _ = probe.widget("Bundled body")
    probe.set_value(uuid, racquet.name)
    finished(session, 1)
    assert wait_until(lambda: session.params.inertia == racquet.ratios, 10)
    assert probe.wait_for(lambda p: np.allclose(slider_values(p), racquet.ratios), 10)
    _, slider = probe.widget("I₁")
    assert slider.props["min"] <= racquet.ratios[0]
    assert session.stats.errors == 0, session.stats.last_error


BAD_MESHES = {
    "junk": ("body.stl", b"solid junk\n this is not an stl \x00\xff", "'body.stl'"),
    "open": ("bowl.stl", open_bowl_stl(), "is not a closed surface"),
    "not a mesh file": ("body.docx", box_stl(), "is not a mesh file Poinsot reads"),
    "empty": ("body.ply", b"", "is empty"),
}


@pytest.mark.parametrize("case", sorted(BAD_MESHES))
def test_a_bad_mesh_is_explained_and_the_scene_kept(mesh_page, probe, case):
    session = mesh_page
    name, content, message = BAD_MESHES[case]
    before = scene_shown(session, probe)
    upload(probe, MESH, name, content)
    finished(session, 1)
    assert probe.wait_for(lambda p: any(message in t for t in markdown_texts(p)), 10), (
        session.uploads.mesh_lines.status
    )
    assert session.uploads.mesh is None
    assert_kept(session, probe, before)


def test_a_mesh_over_the_cap_is_refused(small_caps, mesh_page, probe):
    session = mesh_page
    before = scene_shown(session, probe)
    upload(probe, MESH, "huge.stl", b"\x00" * 700_000)
    finished(session, 1)
    assert "huge.stl is" in session.uploads.mesh_lines.status
    assert "simplify the mesh" in session.uploads.mesh_lines.status
    assert_kept(session, probe, before)


def test_the_newest_upload_wins(mesh_page, probe):
    session = mesh_page
    upload(probe, MESH, "first.stl", box_stl((1.0, 1.5, 4.0)))
    upload(probe, MESH, "second.stl", box_stl((3.0, 2.0, 1.0)))
    finished(session, 2)
    assert wait_until(lambda: "second.stl" in session.preset.source, 10)
    assert session.uploads.mesh is not None and session.uploads.mesh.name == "second.stl"
