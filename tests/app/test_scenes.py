"""The scenes (app/lessons) in the live server, observed through websocket probes: each creates
exactly the nodes and widgets it declares, the menu switches between scenes and presets
creating and removing exactly, bad input leaves a message and the last valid scene, and per
frame only poses and trail increments are sent."""

from __future__ import annotations

import logging
import os

import pytest
from conftest import after_frames, session_of, wait_until
from scene_probing import (
    ALWAYS,
    CONSTRUCTION_TRAILS,
    construction_nodes,
    plot_titles,
    scene_node_names,
    start,
    visible_labels,
)

from poinsot.app.lessons import SCENES, scene_by_name
from poinsot.app.lessons.support.spec import SceneSpec
from poinsot.app.live.panel.panel import ELEMENT_LABELS
from poinsot.app.model.elements import Control, Element
from poinsot.app.model.presets import preset_by_key

#: The panel's shared groups: their widgets' labels and the folder they go in.
SHARED_LABELS: dict[Control, set[str]] = {
    Control.SPEED: {"Speed", "Playback"},
    Control.PLAYBACK: {"Pause", "Step", "Reset", "Playback"},
    Control.TRAIL: {"Trail length", "Playback"},
    Control.VISIBILITY: {"Show"},
}
IDS = [s.name for s in SCENES]


@pytest.fixture(scope="module")
def element_nodes() -> dict[Element, set[str]]:
    """The nodes each element of the construction creates (read off the construction)."""
    return construction_nodes()


def expected_nodes(spec: SceneSpec, element_nodes: dict[Element, set[str]]) -> set[str]:
    names = set(ALWAYS) | set(spec.node_names())
    for element in spec.elements:
        names |= element_nodes[element]
    return names


def trails_of(spec: SceneSpec) -> tuple[str, ...]:
    return CONSTRUCTION_TRAILS + tuple(t for p in spec.parts for t in p.trails)


def expected_labels(spec: SceneSpec) -> set[str]:
    labels = set(spec.control_labels()) | {spec.label.removeprefix("Scene: ")}
    for control in spec.shared:
        labels |= SHARED_LABELS[control]
    if Control.VISIBILITY in spec.shared:
        labels |= {ELEMENT_LABELS[e] for e in spec.elements}
    return labels


def common_labels(make_app, make_probe) -> set[str]:
    """What every session shows whatever it plays: the menu, the lecture and ghost folders
    (read off a session on the sphere preset, minus the sphere's own groups)."""
    sphere = preset_by_key("sphere")
    app = make_app(sphere)
    probe = make_probe(app)
    session = session_of(app)
    assert wait_until(lambda: session.stats.frames > 3, 30)
    received = len(probe.batches)
    after_frames(session)  # the panel was built before the first frame; these reached the probe
    assert probe.wait_for(lambda p: len(p.batches) >= received + 5, 30)
    own = {ELEMENT_LABELS[e] for e in sphere.elements}
    for control in sphere.controls:
        own |= SHARED_LABELS.get(control, set())
    own |= {"I₁", "I₂", "I₃", "|ω₀|", "Body: principal moments", "Motion"}
    return visible_labels(probe) - own


@pytest.mark.parametrize("spec", SCENES, ids=IDS)
def test_each_scene_creates_only_what_it_declares(spec, make_app, make_probe, element_nodes):
    common = common_labels(make_app, make_probe)
    _, session, probe = start(make_app, make_probe, spec)
    expected = expected_nodes(spec, element_nodes)
    trails = trails_of(spec)
    assert probe.wait_for(lambda p: scene_node_names(p, trails) == expected, 30), (
        scene_node_names(probe, trails) ^ expected
    )
    labels = expected_labels(spec)
    assert probe.wait_for(lambda p: labels <= visible_labels(p), 30), labels - visible_labels(probe)
    extra = visible_labels(probe) - labels - common
    assert extra == set(), f"undeclared widgets: {extra}"
    assert plot_titles(probe) == {p.title for p in spec.plots}
    assert session.stats.errors == 0, session.stats.last_error


def viser_warnings(recwarn: pytest.WarningsRecorder, caplog: pytest.LogCaptureFixture) -> list:
    """What viser warned about (a warning raised in viser's code, or logged by viser)."""
    raised = [str(w.message) for w in recwarn if f"{os.sep}viser{os.sep}" in w.filename]
    logged = [
        r.getMessage()
        for r in caplog.records
        if r.name.startswith("viser") and r.levelno >= logging.WARNING
    ]
    return raised + logged


def test_the_menu_switches_scenes_and_presets_exactly(
    make_app, make_probe, element_nodes, recwarn, caplog
):
    """... and viser warns about nothing meanwhile (a node removed twice, a handle used after
    its removal): the server's terminal stays quiet."""
    app = make_app()
    probe = make_probe(app)
    session = session_of(app)
    assert wait_until(lambda: session.stats.frames > 3, 30)
    uuid, _ = probe.widget("Preset")
    for name in ("polhode-family", "gyroscope-torque", "dzhanibekov", "explorer-1"):
        spec = scene_by_name(name)
        probe.set_value(uuid, spec.label)
        assert wait_until(
            lambda s=spec: (
                session.showcase is not None
                and session.showcase.spec is s
                and session.showcase.loaded
            ),
            30,
        )
        expected, trails = expected_nodes(spec, element_nodes), trails_of(spec)
        assert probe.wait_for(lambda p, e=expected, t=trails: scene_node_names(p, t) == e, 30), (
            scene_node_names(probe, trails) ^ expected
        )
        assert probe.wait_for(lambda p, s=spec: plot_titles(p) == {x.title for x in s.plots}, 30)
    preset = preset_by_key("t_handle")
    probe.set_value(uuid, preset.label)
    assert wait_until(lambda: session.showcase is None and session.preset is preset, 30)
    names = set(ALWAYS)
    for element in preset.elements:
        names |= element_nodes[element]
    assert probe.wait_for(lambda p: scene_node_names(p, CONSTRUCTION_TRAILS) == names, 30), (
        scene_node_names(probe, CONSTRUCTION_TRAILS) ^ names
    )
    assert probe.wait_for(lambda p: plot_titles(p) == {"ω in the body frame"}, 30)
    assert wait_until(lambda: session.body is not None and session.body.inertia[2] > 3.0, 30)
    assert session.stats.errors == 0, session.stats.last_error
    assert viser_warnings(recwarn, caplog) == []


def test_bad_input_keeps_the_last_scene_and_says_why(make_app, make_probe):
    spec = scene_by_name("gyroscope-torque")
    _, session, probe = start(make_app, make_probe, spec)
    showcase = session.showcase
    assert showcase is not None
    model = showcase.showcase.model
    generation = session.generation
    uuid, _ = probe.widget("spin ω₃")
    # From the wire, a value below the slider's range is clamped into it, as the browser would.
    probe.set_value(uuid, 0.0)
    assert wait_until(lambda: session.generation > generation, 30)
    assert session.status == "" and showcase.showcase.model is not model
    assert wait_until(lambda: showcase.showcase.settings["spin"] == 0.5, 30)
    model, generation = showcase.showcase.model, session.generation
    # A value the model refuses (here from the server's side) keeps the scene and says why.
    session.configure_scene("spin", 0.0)
    assert wait_until(lambda: session.generation > generation, 30)
    assert "a gyroscope must spin" in session.status
    assert showcase.showcase.model is model  # the last valid scene is kept
    said = "a gyroscope must spin"
    assert probe.wait_for(
        lambda p: any(said in str(w.props.get("_markdown", "")) for w in p.widgets.values()), 30
    )
    generation = session.generation
    probe.set_value(uuid, 2.0)
    assert wait_until(lambda: session.generation > generation and session.status == "", 30)
    assert showcase.showcase.model is not model
    assert session.stats.errors == 0, session.stats.last_error


#: What a frame may send (as in test_server): poses, node updates, trail chunks, GUI values.
PER_FRAME_TYPES = {
    "SetOrientationMessage",
    "SetPositionMessage",
    "SceneNodeUpdateMessage",
    "LineSegmentsMessage",
    "RemoveSceneNodeMessage",
    "SetSceneNodeVisibilityMessage",
    "GuiUpdateMessage",
}


@pytest.mark.parametrize("name", ["explorer-1", "symmetric-top"])
def test_per_frame_only_poses_and_trail_increments(name, make_app, make_probe):
    spec = scene_by_name(name)
    _, session, probe = start(make_app, make_probe, spec)
    trails = trails_of(spec)
    assert wait_until(lambda: session.stats.frames > 30, 30)
    start_batch, frames = len(probe.batches), session.stats.frames
    after_frames(session, 90)
    assert probe.wait_for(lambda p: len(p.batches) >= start_batch + 45, 30)
    assert session.stats.frames - frames >= 90
    for batch in probe.batches[start_batch:]:
        for kind, node in zip(batch.types, batch.names, strict=True):
            assert kind in PER_FRAME_TYPES, (kind, node)
            if kind in ("LineSegmentsMessage", "RemoveSceneNodeMessage"):
                assert node.startswith(tuple(t + "/g" for t in trails)), node
    assert session.stats.errors == 0, session.stats.last_error
