"""The labels' layout as a frame carries it (app/construction/labels/layout.py,
app/live/lecture/display.py): its shortcuts choose what the plain sums choose, it runs in steps that
send only at their end, and a frame takes at most one step, never on a frame that sends the traces
or the plot. Counts and events only, never wall-clock bounds."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import viser
from conftest import after_frames, record_messages, session_of, wait_until

from poinsot.app.construction.construction import TRAIL_EVERY, PoinsotScene
from poinsot.app.construction.labels import layout as labels
from poinsot.app.construction.labels.layout import Camera, finish
from poinsot.app.live.lecture import display
from poinsot.app.live.session.builder import MAX_FPS
from poinsot.app.live.session.session import PLOT_MIN_FRAMES
from poinsot.app.model.parameters import Parameters
from poinsot.app.model.presets import DEFAULT_PRESET

#: The most frames a plot's sending waits past its first possible frame: a layout step every
#: other frame and the traces every TRAIL_EVERY frames, never together, leave a free frame
#: within three (at most 3 measured, alone and beside three busy loops).
PLOT_WAIT = 4


def _reference_choice(boxes: np.ndarray, reach: np.ndarray) -> tuple[list[int], list[float]]:
    """The choice as arrays give it: each label's costs in full (reach plus overlap with the
    boxes chosen before), the first zero, else the least."""
    chosen: list[int] = []
    costs: list[float] = []
    for i in range(len(boxes)):
        cost = reach[i].copy()
        if chosen:
            placed = np.array([boxes[j, k] for j, k in enumerate(chosen)])
            cost = cost + labels._overlap_costs(boxes[i], placed)
        free = np.flatnonzero(cost == 0.0)
        k = int(free[0]) if len(free) else int(np.argmin(cost))
        chosen.append(k)
        costs.append(float(cost[k]))
    return chosen, costs


def test_the_float_shortcut_chooses_what_the_full_costs_choose():
    """Crowded random screens (boxes on top of each other, reach zero, positive or barred):
    :func:`labels._choose`, which checks candidates one by one in plain floats and costs a
    whole row only when none is free, picks the same candidate at the same cost."""
    rng = np.random.default_rng(7)
    fallbacks = 0
    for _ in range(300):
        n, k = int(rng.integers(1, 9)), int(rng.integers(1, 33))
        corner = rng.uniform(0.0, 120.0, (n, k, 2))
        boxes = np.concatenate([corner, corner + rng.uniform(5.0, 40.0, (n, k, 2))], axis=2)
        reach = np.where(rng.random((n, k)) < 0.6, 0.0, rng.uniform(0.0, 50.0, (n, k)))
        reach[:, : k // 2] += np.where(rng.random((n, 1)) < 0.2, np.inf, 0.0)
        chosen, costs = labels._choose(boxes, reach)
        assert (chosen, costs) == _reference_choice(boxes, reach)
        fallbacks += sum(cost > 0.0 for cost in costs)
    assert fallbacks > 50  # the row-costing path ran too, not only the shortcut


def test_the_reach_into_discs_is_the_sum_over_each_pair():
    """:func:`labels._disc_costs` (a root only for pairs that touch) against the plain double
    sum of weight x (radius + gap - distance)^2 over every box and disc."""
    rng = np.random.default_rng(11)
    corner = rng.uniform(0.0, 300.0, (400, 2))
    boxes = np.concatenate([corner, corner + rng.uniform(5.0, 60.0, (400, 2))], axis=1)
    centres = rng.uniform(0.0, 350.0, (30, 2))
    radii, weights = rng.uniform(1.0, 20.0, 30), rng.choice([1.0, labels.MARKER_WEIGHT], 30)
    expected = np.zeros(len(boxes))
    for b, (x0, y0, x1, y1) in enumerate(boxes):
        for (cx, cy), r, w in zip(centres, radii, weights, strict=True):
            distance = math.hypot(min(max(cx, x0), x1) - cx, min(max(cy, y0), y1) - cy)
            expected[b] += w * max(r + labels.GAP_PX - distance, 0.0) ** 2
    got = labels._disc_costs(boxes, centres, radii, weights)
    assert np.count_nonzero(expected) > 50
    np.testing.assert_array_equal(got == 0.0, expected == 0.0)
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-9)
    assert not labels._disc_costs(boxes, np.zeros((0, 2)), np.zeros(0), np.zeros(0)).any()


@pytest.fixture
def scene_and_sent():
    """A default scene on a server of its own, its body turning, and the messages it sends."""
    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    try:
        scene = PoinsotScene(server.scene, DEFAULT_PRESET.elements, 48, atomic=server.atomic)
        body = Parameters.from_preset(DEFAULT_PRESET).build()
        scene.load(body, DEFAULT_PRESET.solid, frame_time=DEFAULT_PRESET.speed / 60.0)
        scene.advance(1.7)
        yield scene, record_messages(server)
    finally:
        server.stop()


def _camera() -> Camera:
    return Camera(
        np.array([3.5, -4.0, 2.5]), np.zeros(3), np.array([0.0, 0.0, 1.0]), 0.9, 900.0, 700.0
    )


def _label_messages(sent: list) -> list[str]:
    return [str(getattr(m, "name", "")) for m in sent if "label" in str(getattr(m, "name", ""))]


def test_a_layout_in_steps_sends_only_at_its_end_what_a_layout_at_once_sends(scene_and_sent):
    scene, sent = scene_and_sent
    steps = scene.label_steps(_camera())
    taken = 0
    for _ in steps:
        taken += 1
        assert _label_messages(sent) == []  # nothing before the last step
    assert taken == 4  # five steps: four yields, then the end
    stepped = {name for name in _label_messages(sent)}
    assert {"/space/body/axis1/label", "/space/tip/omega_label"} <= stepped
    at_once = scene.lay_out_labels(_camera())  # the same camera and time: the same choice
    del sent[:]
    again = finish(scene.label_steps(_camera()))
    assert {k: (p.anchor, p.box) for k, p in at_once.items()} == {
        k: (p.anchor, p.box) for k, p in again.items()
    }
    assert _label_messages(sent) == []  # unchanged: nothing resent


def test_a_layout_outdated_by_a_new_body_sends_nothing(scene_and_sent):
    """A layout begun before the body changes would place its labels for the old sizes: it
    ends without a message (the next layout places them)."""
    scene, sent = scene_and_sent
    steps = scene.label_steps(_camera())
    next(steps)
    next(steps)
    other = Parameters.from_preset(DEFAULT_PRESET).build()
    scene.load(other, DEFAULT_PRESET.solid, frame_time=0.01)
    del sent[:]
    assert finish(steps) == {}
    assert _label_messages(sent) == []
    assert scene.lay_out_labels(_camera())  # a new layout does place them


def test_a_frame_carries_at_most_one_of_traces_plot_and_a_layout_step(make_app, make_probe):
    """In a live session, per frame drawn: at most one step of the labels' layout, and never
    with the traces or the plot on the same frame; layouts still complete, in five steps, the
    traces keep their share of the frames, and the plot is sent within a few frames of each
    sample (all counted in frames: what the clock brings a frame is the machine's)."""
    app = make_app(max_fps=MAX_FPS)
    make_probe(app)
    session = session_of(app)
    # Counted from its 30th frame on: its first frames restart the traces (sent at once, out of
    # their cadence) while its first layout is taken, and a plot could wait a frame more.
    after_frames(session, 30)
    display, motion = session.lecture.display, session.panel.motion
    frames: list[set[str]] = []
    current: set[str] = set()
    begun = [0]

    def wrap(owner, name, tag, count=None):
        original = getattr(owner, name)

        def wrapper(*args, **kwargs):
            current.add(tag) if tag not in current else current.add(tag + "+")
            if count is not None:
                count[0] += 1
            return original(*args, **kwargs)

        setattr(owner, name, wrapper)

    original_frame = session.frames.draw

    def frame(now: float) -> bool:
        current.clear()
        drawn = original_frame(now)
        if drawn:
            frames.append(set(current) | ({"traces"} if session.scene.sent_traces else set()))
        return drawn

    wrap(display, "_step", "step")
    wrap(motion, "send_plot", "plot")
    wrap(motion, "record_plot", "sample")
    wrap(session.scene, "label_steps", "begin", begun)
    session.frames.draw = frame  # type: ignore[method-assign]
    assert wait_until(lambda: len(frames) > 240, 30)
    kinds = list(frames)
    assert all("step+" not in f for f in kinds)  # one step a frame at most
    assert not [f for f in kinds if len(f & {"step", "traces", "plot"}) > 1]
    steps = sum("step" in f for f in kinds)
    assert begun[0] >= 3, begun  # ~2 layouts a second under a still camera
    assert steps >= 5 * (begun[0] - 1)
    assert sum("traces" in f for f in kinds) >= len(kinds) // TRAIL_EVERY - 2
    # The plot waits a frame or two, not a sample (a step every other frame leaves it room).
    waits = plot_waits(kinds)
    assert len(waits) >= 3 and max(waits) <= PLOT_WAIT, waits


def plot_waits(kinds: list[set[str]]) -> list[int]:
    """For each sending of the plot, the frames it waited past the first frame that could
    carry its samples (the later of the first sample's frame and PLOT_MIN_FRAMES after the last
    sending). In frames: the samples come by the clock, and how many come a frame is the
    machine's. From the second sending counted on: the first's last sending was before the
    count (a busy run read a first "wait" of 6 frames, the sending before it unseen)."""
    waits: list[int] = []
    last_sent: int | None = None
    pending: int | None = None
    for i, kind in enumerate(kinds):
        if "sample" in kind and pending is None:
            pending = i
        if "plot" in kind:
            if last_sent is not None and pending is not None:
                waits.append(i - max(pending, last_sent + PLOT_MIN_FRAMES))
            last_sent, pending = i, None
    return waits


def test_a_view_of_another_height_is_laid_out_again():
    """A still camera is laid out again only when what a layout depends on changes: the
    view's height too (a phone's sheet folding leaves its width as it was)."""
    camera = _camera()
    taller = dataclasses.replace(camera, height=camera.height + 300.0)
    assert display._camera_key(taller) != display._camera_key(camera)
    assert display._camera_key(dataclasses.replace(camera)) == display._camera_key(camera)
