"""Cheap frames: the messages a frame sends, and each client's frame rate following what it
takes (app/live/hardening/pacing.py). Counts and events only, never wall-clock bounds."""

from __future__ import annotations

import collections
import warnings

import viser
from conftest import record_messages, session_of, wait_until

from poinsot.app.construction.construction import TRAIL_EVERY, PoinsotScene
from poinsot.app.live.hardening.pacing import (
    MAX_IN_FLIGHT,
    MAX_UNACKED,
    MIN_FPS,
    Pacer,
    next_due,
)
from poinsot.app.live.session.builder import MAX_FPS
from poinsot.app.model.parameters import Parameters
from poinsot.app.model.presets import DEFAULT_PRESET


class FakeOutbox:
    """A client's queue as the pacer sees it: ids of messages queued, and taken."""

    def __init__(self) -> None:
        self.queued = -1
        self.taken = -1

    def last_queued(self) -> int:
        return self.queued

    def last_taken(self) -> int:
        return self.taken

    unacked = 0

    def unacknowledged(self) -> int:
        return self.unacked

    left = False

    def closed(self) -> bool:
        return self.left

    def frame(self, pacer: Pacer, messages: int = 4) -> bool:
        """One pass of the frame loop: draw (queue messages) if the pacer allows it."""
        if not pacer.may_draw():
            return False
        self.queued += messages
        pacer.sent()
        return True


def test_a_client_that_takes_nothing_gets_no_backlog_and_a_lower_rate():
    outbox = FakeOutbox()
    pacer = Pacer(outbox, max_fps=60.0)  # type: ignore[arg-type]
    drawn = [outbox.frame(pacer) for _ in range(50)]
    assert drawn.count(True) == MAX_IN_FLIGHT + 1  # then nothing more is queued
    assert pacer.in_flight() == MAX_IN_FLIGHT + 1
    assert pacer.stats.skipped == 50 - (MAX_IN_FLIGHT + 1)
    assert pacer.fps == MIN_FPS  # polled at the slowest rate
    outbox.taken = outbox.queued  # the client catches up
    assert all(outbox.frame(pacer) for _ in range(MAX_IN_FLIGHT + 1))
    outbox.taken = outbox.queued
    for _ in range(40):  # and keeps up: each frame is taken before the next
        assert outbox.frame(pacer)
        outbox.taken = outbox.queued
    assert pacer.fps == 60.0


def test_a_client_that_acknowledges_nothing_gets_no_new_frame():
    """The frames were taken from the queue, but the bytes wait unacknowledged in the socket
    (a client that stopped reading): no frame until they are acknowledged."""
    outbox = FakeOutbox()
    pacer = Pacer(outbox, max_fps=60.0)  # type: ignore[arg-type]
    outbox.unacked = MAX_UNACKED + 1
    for _ in range(20):
        assert not outbox.frame(pacer)
        outbox.taken = outbox.queued
    assert pacer.stats.drawn == 0 and pacer.fps == MIN_FPS
    outbox.unacked = 0
    assert outbox.frame(pacer)


def test_a_client_that_left_gets_no_frame():
    outbox = FakeOutbox()
    pacer = Pacer(outbox, max_fps=60.0)  # type: ignore[arg-type]
    assert outbox.frame(pacer)
    outbox.taken = outbox.queued
    outbox.left = True
    assert not any(outbox.frame(pacer) for _ in range(10))
    assert pacer.stats.drawn == 1


def test_a_session_whose_client_left_queues_nothing_before_it_is_closed(poinsot_app, probe):
    """Between viser's closing a departed client's queue and the server's closing its
    session, the frame thread goes on: it draws nothing and rebuilds nothing for nobody, and
    viser has nothing to warn about in the server's terminal (nor for a frame begun just
    before the client left)."""
    session = session_of(poinsot_app)
    close, held = session.close, []
    session.close = lambda timeout=None: held.append(timeout)  # type: ignore[method-assign]
    passes = [0]
    may_draw = session.pacer.may_draw

    def counted() -> bool:
        passes[0] += 1
        return may_draw()

    session.pacer.may_draw = counted  # type: ignore[method-assign]
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            probe.close()
            assert wait_until(lambda: held and session.pacer.outbox.closed(), 20)
            seen = passes[0]  # a whole pass of the frame thread since, its queue drained
            assert wait_until(lambda: passes[0] >= seen + 2, 20), "the frame thread stopped"
            frames, rebuilds, seen = session.stats.frames, session.stats.rebuilds, passes[0]
            session.edit(lambda p: p.with_omega_norm(2.0))  # a last slider move, unsent
            assert wait_until(lambda: passes[0] >= seen + 10, 20), "the frame thread stopped"
            assert (session.stats.frames, session.stats.rebuilds) == (frames, rebuilds)
        assert [str(w.message) for w in caught if "closed connection" in str(w.message)] == []
        # A frame begun just before the client left: its messages are dropped quietly; the
        # same message outside that block is what viser warns of.
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            with session.pacer.outbox.quiet_if_left():
                session.client.gui.add_markdown("for nobody")
            assert not [w for w in caught if "closed connection" in str(w.message)]
            session.client.gui.add_markdown("for nobody, and said")
            assert [w for w in caught if "closed connection" in str(w.message)]
    finally:
        close(timeout=5.0)


def test_a_slow_client_gets_the_frames_it_takes():
    """A client that takes its queue every fourth pass of the loop gets MAX_IN_FLIGHT + 1
    frames per four passes, at a lowered rate, and never more queued."""
    outbox = FakeOutbox()
    pacer = Pacer(outbox, max_fps=60.0)  # type: ignore[arg-type]
    drawn = 0
    for i in range(200):
        drawn += outbox.frame(pacer)
        if i % 4 == 3:
            outbox.taken = outbox.queued
    assert drawn == 50 * (MAX_IN_FLIGHT + 1)
    assert pacer.stats.max_in_flight <= MAX_IN_FLIGHT + 1
    assert pacer.fps < 60.0


def _target(message) -> tuple[str, str]:
    return type(message).__name__, str(getattr(message, "name", ""))


def test_a_frame_of_the_default_preset_sends_three_messages_and_traces_every_fourth():
    """Everything that turns with the body rides on /space/body: a frame sends its wxyz, the
    contact point's frame and omega's arrow, nothing else; every TRAIL_EVERY-th frame adds the
    traces' increments, updates of existing nodes only once the trails are full."""
    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    try:
        scene = PoinsotScene(server.scene, DEFAULT_PRESET.elements, 48, atomic=server.atomic)
        body = Parameters.from_preset(DEFAULT_PRESET).build()
        dt = DEFAULT_PRESET.speed / 60.0
        scene.load(body, DEFAULT_PRESET.solid, frame_time=dt)
        t = 0.0
        for _ in range(400):  # past the trails' first fill: 48 points each
            t += dt
            scene.advance(t)
        sent = record_messages(server)
        per_frame = []
        for _ in range(10 * TRAIL_EVERY):
            t += dt
            del sent[:]
            scene.advance(t)
            per_frame.append([_target(m) for m in sent])
    finally:
        server.stop()
    poses = [
        ("SetOrientationMessage", "/space/body"),
        ("SetPositionMessage", "/space/tip"),
        ("SceneNodeUpdateMessage", "/space/omega"),
    ]
    with_traces = [i for i, frame in enumerate(per_frame) if len(frame) > len(poses)]
    assert len(with_traces) == 10
    assert all(b - a == TRAIL_EVERY for a, b in zip(with_traces, with_traces[1:], strict=False))
    for i, frame in enumerate(per_frame):
        assert frame[:3] == poses
        if i not in with_traces:
            assert len(frame) == 3
            continue
        traces = collections.Counter(name.split("/g")[0] for _, name in frame[3:])
        assert set(traces) == {"/space/herpolhode", "/space/body/polhode"}
        # One points update each; where the head fills, also the chunk dropped and reused.
        assert all(1 <= n <= 3 for n in traces.values()), frame
        assert {kind for kind, _ in frame[3:]} == {"SceneNodeUpdateMessage"}


def test_a_stalled_client_gets_fewer_frames_and_a_bounded_queue(make_app, make_probe):
    """A client that stops reading: once its socket is full its session skips frames at a
    lowered rate and its queue stays within a few frames' messages, while another client
    keeps getting frames (at the server's own frame rate: the socket fills in as many frames,
    in a third of the time)."""
    poinsot_app = make_app(max_fps=MAX_FPS)
    slow = make_probe(poinsot_app, receive_buffer=4096)  # fills sooner
    slow_session = session_of(poinsot_app, 1)
    fast = make_probe(poinsot_app)
    fast_session = session_of(poinsot_app, 2)
    assert wait_until(lambda: fast_session.stats.frames > 10, 30)
    slow.stall()
    assert wait_until(lambda: slow_session.pacer.stats.skipped > 20, 120)  # the socket filled
    outbox = slow_session.pacer.outbox
    skipped, f_slow, f_fast = (
        slow_session.pacer.stats.skipped,
        slow_session.stats.frames,
        fast_session.stats.frames,
    )
    n_fast = len(fast.batches)
    most_pending = 0

    def measured() -> bool:
        nonlocal most_pending
        most_pending = max(most_pending, outbox.pending())
        return fast_session.stats.frames - f_fast > 120 and len(fast.batches) - n_fast > 60

    assert wait_until(measured, 120, poll=0.005)
    assert slow_session.stats.frames - f_slow < 20  # fewer than a sixth of the other's
    assert slow_session.pacer.stats.skipped > skipped  # its loop goes on, skipping
    assert slow_session.pacer.fps < slow_session.max_fps
    assert most_pending <= 16 * (MAX_IN_FLIGHT + 1)  # a few frames' messages, never more


def test_frames_are_due_on_a_cadence_and_never_in_a_burst():
    step = 0.03
    assert next_due(1.0, 1.0, step) == 1.0 + step  # on time
    assert next_due(1.0, 1.01, step) == 1.0 + step  # late: the next one is sooner
    assert next_due(1.0, 1.02, step) == 1.02 + 0.5 * step  # but half a step after it
    assert next_due(1.0, 1.05, step) == 1.05 + step  # a whole step late: from now
    due, drawn = 0.0, []
    for now in (0.0, 0.041, 0.061, 0.09, 0.12):  # the second frame 11 ms late
        if now >= due:
            drawn.append(now)
            due = next_due(due, now, step)
    assert drawn == [0.0, 0.041, 0.061, 0.09, 0.12]  # five frames in 0.12 s, as at 1/step
