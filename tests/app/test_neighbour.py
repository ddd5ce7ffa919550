"""Compare with a neighbour: any preset gets a second body started ε′ away, posed each frame
at its own exact attitude; near the middle axis the lag of the flips, theory against the two
motions, is read out."""

from __future__ import annotations

import math
import re

import numpy as np
from conftest import session_of, wait_until

from poinsot.app.lessons.twins import TWIN_STEP
from poinsot.app.live.lecture import neighbour
from poinsot.app.model.presets import preset_by_key
from poinsot.physics.core.rotations import geodesic_angle


def _choose(probe, option: str) -> None:
    assert probe.wait_for(lambda p: neighbour.LABEL in p.labels(), 15)
    probe.set_value(probe.widget(neighbour.LABEL)[0], option)


def test_a_neighbour_of_a_stable_preset_is_drawn_at_its_exact_attitude(poinsot_app, probe):
    session = session_of(poinsot_app)
    folder = session.lecture.neighbour
    _choose(probe, "1e-2 rad")
    assert wait_until(lambda: folder.body is not None, 10)
    assert probe.wait_for(lambda p: f"{neighbour.NODE}/solid" in p.nodes, 10)
    # The readout is written after the body is set: wait for it.
    assert wait_until(lambda: "stays close" in folder.readout.content, 30), folder.readout.content
    body = folder.body
    w0, w1 = session.body.omega0, body.omega0
    between = math.atan2(np.linalg.norm(np.cross(w0, w1)), float(w0 @ w1))
    assert abs(between / 1e-2 - 1.0) < 1e-9
    # posed at its own attitude: the node's pose is the body's at a grid time near the frame
    session.clock.paused = True
    frames = session.stats.frames
    assert wait_until(lambda: session.stats.frames > frames + 5, 30)
    t = session.frame.t
    grid = math.floor(t / TWIN_STEP + 1e-9) * TWIN_STEP
    x, y, z, w = body.attitude(grid).as_quat()
    assert folder.frame is not None
    shown_w, *shown_xyz = np.asarray(folder.frame.wxyz)
    # The geodesic angle (2 acos |p.q| would give 3e-8 for two equal quaternions' rounding).
    assert float(geodesic_angle([*shown_xyz, shown_w], [x, y, z, w])) < 1e-9
    _choose(probe, neighbour.OPTIONS[0])
    assert wait_until(lambda: folder.body is None and folder.frame is None, 10)
    assert probe.wait_for(lambda p: f"{neighbour.NODE}/solid" not in p.nodes, 10)
    assert session.stats.errors == 0, session.stats.last_error


def test_the_lag_of_a_neighbour_near_the_middle_axis(poinsot_app, probe):
    session = session_of(poinsot_app)
    session.choose_preset(preset_by_key("t_handle"))
    assert wait_until(lambda: session.preset.key == "t_handle" and session.body is not None, 10)
    _choose(probe, "1e-4 rad")
    folder = session.lecture.neighbour
    assert wait_until(lambda: "| lag |" in folder.readout.content, 15)
    row = re.search(r"\| lag \| ([^|]+) \| ([^|]+) \|", folder.readout.content)
    assert row is not None
    theory, measured = float(row.group(1)), float(row.group(2))
    assert abs(measured / theory - 1.0) < 2e-6  # both printed to 6 digits
    assert session.stats.errors == 0, session.stats.last_error
