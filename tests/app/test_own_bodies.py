"""A body of one's own, without a server: an upload's bytes become a preset (the fitted toss, the
measured mesh), and the measured ω is merged with the live exact one for the plot."""

from __future__ import annotations

import numpy as np
import pytest
from test_recordings import I_TRUE, three_throws
from uploading import box_stl, phyphox_csv, toss_recording

from poinsot.app.live.panel.overlay import Measured, merge
from poinsot.app.model import own_bodies
from poinsot.app.model.bodies import bundled_body, load_mesh_body
from poinsot.app.model.elements import Plot
from poinsot.app.model.parameters import SPEED_RANGE, Parameters
from poinsot.app.model.presets import FITTED_TOSS, MENU, MESH_BODY, preset_by_key, preset_by_label


@pytest.mark.parametrize(
    ("name", "shown"),
    [
        ("../../etc/toss.csv", "toss.csv"),
        ("C:\\Users\\me\\toss.zip", "toss.zip"),
        ("a<b>|c.csv", "a_b__c.csv"),
        ("", "upload"),
    ],
)
def test_an_uploaded_name_is_a_plain_file_name(name, shown):
    assert own_bodies.display_name(name) == shown


def test_the_size_is_checked_first():
    own_bodies.check_size(10, 10, "x.csv", "toss")
    with pytest.raises(ValueError, match=r"x.csv is 2 MB; files up to 1 MB .*time range"):
        own_bodies.check_size(2 * 2**20, 2**20, "x.csv", "toss")
    with pytest.raises(ValueError, match="simplify the mesh"):
        own_bodies.load_mesh(b"0" * (own_bodies.MAX_MESH_BYTES + 1), "x.stl")
    with pytest.raises(ValueError, match="cut the recording"):
        own_bodies.fit_recording(b"0" * (own_bodies.MAX_RECORDING_BYTES + 1), "x.csv")


def test_the_best_of_three_tosses_is_shown():
    t, w, truth = three_throws(0)
    toss = own_bodies.fit_recording(phyphox_csv(t, w), "three.csv")
    assert toss.count == 3 and 1 <= toss.index <= 3
    assert toss.fit.explained
    segment = toss.result.segment
    start, end = truth[toss.index - 1]
    assert start - 0.05 <= segment.start < segment.end <= end + 0.05
    np.testing.assert_allclose(toss.fit.inertia, I_TRUE / I_TRUE.max(), atol=0.03)


def test_a_fitted_toss_is_a_preset_that_builds():
    toss = own_bodies.fit_recording(toss_recording(), "toss.csv")
    preset = own_bodies.toss_preset(toss)
    assert preset.label == FITTED_TOSS.label and preset.plots == frozenset({Plot.MEASURED})
    assert preset.controls == FITTED_TOSS.controls
    params = Parameters.from_preset(preset)
    body = params.build()
    np.testing.assert_allclose(body.omega(0.0), toss.fit.omega0, rtol=1e-12)
    np.testing.assert_allclose(body.omega(toss.tau), toss.exact, atol=1e-9)
    assert SPEED_RANGE[0] <= preset.speed <= 1.0
    assert max(preset.inertia) == 1.0
    assert toss.bound >= np.max(np.abs(toss.exact)) and toss.bound >= np.max(np.abs(toss.measured))
    text = own_bodies.toss_markdown(toss)
    for row in ("I₁ (x)", "I₂ (y)", "I₃ (z)", "rms residual", "flip period, predicted"):
        assert row in text


def test_a_mesh_is_a_preset_drawn_as_itself():
    body = load_mesh_body(box_stl((3.0, 2.0, 1.0)), "box.stl")
    preset = own_bodies.mesh_preset(body)
    assert preset.label == MESH_BODY.label
    assert preset.solid is not None and preset.solid.kind == "mesh"
    shape = preset.solid.mesh
    assert shape is not None and len(shape.vertices) == len(body.mesh.vertices)
    assert not shape.vertices.flags.writeable
    i1, i2, i3 = preset.inertia
    assert i1 < i2 < preset.D < i3 == 1.0  # just past the separatrix: it flips
    Parameters.from_preset(preset).build()
    repaired = own_bodies.mesh_preset(load_mesh_body(box_stl(drop_faces=1), "holed.stl"))
    assert "repaired" in repaired.source
    assert own_bodies.repair_note(load_mesh_body(box_stl(drop_faces=1), "h.stl")).startswith(
        "Repaired: h.stl was not closed"
    )
    assert own_bodies.repair_note(body) == ""


@pytest.mark.parametrize("key", ["book", "phone", "racquet", "t_handle"])
def test_every_bundled_body_builds(key):
    Parameters.from_preset(own_bodies.mesh_preset(bundled_body(key))).build()


def test_the_menu_has_the_own_body_entries():
    labels = [p.label for p in MENU]
    assert len(set(labels)) == len(labels)
    for template in (FITTED_TOSS, MESH_BODY):
        assert preset_by_key(template.key) is template
        assert preset_by_label(template.label) is template
        Parameters.from_preset(template).build()


# -- the plot's columns -----------------------------------------------------------------------
def _measured() -> Measured:
    tau = np.array([0.0, 0.1, 0.2, 0.3])
    omega = np.arange(12.0).reshape(4, 3)
    return Measured(tau, omega, omega + 0.5, bound=20.0)


def test_measured_samples_merge_with_live_ones_in_time():
    t = np.array([0.05, 0.15, 0.4])
    live = -np.ones((3, 3))
    x, *columns = merge(t, live, _measured())
    exact, seen = np.stack(columns[:3], 1), np.stack(columns[3:], 1)
    np.testing.assert_array_equal(x, [0.05, 0.1, 0.15, 0.2, 0.3, 0.4])  # 0.0 is before t[0]
    assert np.all(np.isfinite(exact))
    np.testing.assert_array_equal(np.isfinite(seen).all(1), [0, 1, 0, 1, 1, 0])
    np.testing.assert_array_equal(exact[1], [3.5, 4.5, 5.5])
    np.testing.assert_array_equal(seen[1], [3.0, 4.0, 5.0])
    assert np.all(np.isnan(seen[[0, 2, 5]])) and np.all(exact[[0, 2, 5]] == -1.0)


def test_before_any_live_sample_every_measured_one_shows():
    x, *_ = merge(np.zeros(0), np.zeros((0, 3)), _measured())
    np.testing.assert_array_equal(x, [0.0, 0.1, 0.2, 0.3])


def test_measured_samples_are_checked_and_fix_the_axis():
    scales = _measured().scales()
    low, high = scales["y"]["range"]
    assert scales["y"]["auto"] is False and low == -high and high > 20.0
    tau = np.zeros(2)
    with pytest.raises(ValueError, match="finite"):
        Measured(tau, np.full((2, 3), np.nan), np.zeros((2, 3)))
    with pytest.raises(ValueError, match="tau"):
        Measured(tau, np.zeros((3, 3)), np.zeros((2, 3)))
    with pytest.raises(ValueError, match="bound"):
        Measured(tau, np.zeros((2, 3)), np.zeros((2, 3)), bound=0.0)
