"""The strobe's pieces without a browser: its default interval is one flip (checked on the
exact ω, sampled densely: the interval's middle is where ω2 changes sign and its ends are where
|ω2| is largest, one each way), its arguments are checked, and its row of copies stands below
the construction as the camera sees it, the copies apart, the camera centred on both."""

from __future__ import annotations

import math

import numpy as np
import pytest

from poinsot.app.construction.cameras import space_view
from poinsot.app.exports.strobe import (
    DEFAULT_SPAN,
    Strobe,
    StrobeError,
    default_interval,
    row_below,
)
from poinsot.app.model.parameters import Parameters
from poinsot.app.model.presets import preset_by_key


def body(key: str):
    return Parameters.from_preset(preset_by_key(key)).build()


def test_the_default_interval_of_the_t_handle_is_one_flip():
    b = body("t_handle")
    t0, t1 = default_interval(b)
    assert t1 - t0 == pytest.approx(b.period / 2.0, rel=1e-12)  # flip to flip
    grid = np.linspace(0.0, b.period, 20001)
    w2 = b.omega(grid)[:, 1]
    biggest = np.abs(w2).max()
    start, end = b.omega(np.array([t0, t1]))[:, 1]
    assert np.sign(start) == -np.sign(end)  # turned over
    assert min(abs(start), abs(end)) > 0.999 * biggest  # calm at both ends
    middle = (t0 + t1) / 2.0
    near = np.linspace(middle - 1e-3, middle + 1e-3, 3)
    w_mid = b.omega(near)[:, 1]
    assert w_mid[0] * w_mid[2] < 0.0  # the flip itself in the middle


def test_a_body_without_a_period_gets_the_default_span():
    assert default_interval(body("sphere")) == (0.0, DEFAULT_SPAN)
    assert default_interval(None) == (0.0, DEFAULT_SPAN)


def test_the_strobe_s_times_and_its_bad_arguments():
    b = body("t_handle")
    times = Strobe(5, 2.0, 6.0).times(b)
    assert times.tolist() == [2.0, 3.0, 4.0, 5.0, 6.0]
    t0, t1 = default_interval(b)
    assert Strobe(3, t0=1.0).interval(b) == pytest.approx((1.0, 1.0 + t1 - t0))
    for bad in (dict(copies=1), dict(copies=25), dict(copies=3, t0=4.0, t1=4.0)):
        with pytest.raises(StrobeError):
            Strobe(**bad)
    with pytest.raises(StrobeError):
        Strobe(3, t0=math.nan)


@pytest.mark.parametrize("view", ["default", "along-L", "side"])
@pytest.mark.parametrize("copies", [2, 8, 24])
def test_the_row_stands_below_the_construction_with_the_copies_apart(view, copies):
    camera = space_view(view)
    rng = np.random.default_rng(3)
    points = rng.uniform(-1.5, 1.5, (200, 3))
    row = row_below(camera, points, copies, mesh_radius=1.0)
    position, target = np.asarray(row.camera.position), np.asarray(row.camera.look_at)
    forward = (target - position) / np.linalg.norm(target - position)
    right = np.cross(forward, row.camera.up)
    right /= np.linalg.norm(right)
    down = np.cross(forward, right)

    def screen(p):
        rel = np.atleast_2d(p) - position
        depth = rel @ forward
        return np.column_stack([rel @ right / depth, rel @ down / depth])

    construction, centres = screen(points), screen(row.centres)
    radius = row.scale * 1.0  # the copies' radius in display units
    depth = (row.centres - position) @ forward
    assert np.all(centres[:, 1] - radius / depth > construction[:, 1].max())  # below it
    gaps = np.diff(centres[:, 0])
    assert np.all(gaps > 0) and np.all(gaps * depth[:-1] > 2.0 * radius)  # apart
    top, bottom = construction[:, 1].min(), (centres[:, 1] + radius / depth).max()
    # Centred: the camera's sideways move is exact at its target's depth; nearer and farther
    # points move a little more or less (parallax), within a tenth of the picture's height.
    assert abs(top + bottom) < 0.1 * (bottom - top)
