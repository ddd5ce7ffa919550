"""The per-client bounds: what a client leaves untaken (app/live/hardening/backlog.py) and the
actions a session has queued (app/live/session/actions.py). Counts and events only, never wall-clock
bounds."""

from __future__ import annotations

import collections
import logging
import threading
import types

from conftest import session_of, wait_until

from poinsot.app.devtools.probe import Probe
from poinsot.app.live.hardening.backlog import BacklogLimit, BacklogWatch
from poinsot.app.live.server import PoinsotApp
from poinsot.app.live.session.builder import MAX_FPS
from poinsot.app.live.session.session import Session

FAST = 0.05  # the watch's poll in these tests [s]: sooner events, same rules


def _stalled(app: PoinsotApp, make_probe, skips: int = 20) -> tuple[Probe, Session, Probe, Session]:
    """Two clients; the first stops reading, with a small socket buffer that fills sooner,
    until its session skips ``skips`` frames (its socket is full). ``app`` runs at the
    server's own frame rate: the socket fills in as many frames, a third of the time."""
    slow = make_probe(app, receive_buffer=4096)
    slow_session = session_of(app, 1)
    fast = make_probe(app)
    fast_session = session_of(app, 2)
    assert wait_until(lambda: fast_session.stats.frames > 10, 30)
    slow.stall()
    assert wait_until(lambda: slow_session.pacer.stats.skipped >= skips, 120)
    return slow, slow_session, fast, fast_session


def test_a_stalled_client_within_the_bounds_keeps_a_small_queue_and_its_connection(
    make_app, make_probe
):
    """Frames are paced: while another client draws 200 frames, the stalled client's queue
    and unacknowledged bytes stay far below the default bounds, and it is not disconnected."""
    app = make_app(backlog=BacklogLimit(poll=FAST), max_fps=MAX_FPS)
    limit = app.backlog.limit
    slow, slow_session, _fast, fast_session = _stalled(app, make_probe)
    slow_id = slow_session.client.client_id
    frames = fast_session.stats.frames
    assert wait_until(lambda: fast_session.stats.frames - frames > 200, 120)
    assert app.backlog.wait_checks(3)
    stats = app.backlog.stats
    assert stats.closed == 0 and slow_id in app.sessions()
    assert 0 < stats.most_unacked[slow_id] <= limit.max_unacked  # it was watched, and held
    # Connecting queues the panel at once; then a frame's messages at most, never a backlog.
    assert stats.most_pending[slow_id] <= limit.max_pending
    slow.stall(False)  # reads again: gets frames again
    assert slow.wait_frames(3)


def test_a_client_over_its_unacknowledged_bound_past_the_grace_is_disconnected(
    make_app, make_probe, caplog
):
    """A bound below what a stalled client holds (the pacer allows 32 kB in flight): after
    the grace it is disconnected, once, with one log line; its session is closed and gone,
    and the other client goes on."""
    app = make_app(
        backlog=BacklogLimit(max_unacked=8 * 1024, grace=0.5, poll=FAST), max_fps=MAX_FPS
    )
    with caplog.at_level(logging.WARNING, logger="poinsot.app.live.hardening.backlog"):
        slow, slow_session, fast, fast_session = _stalled(app, make_probe, skips=0)
        slow_id = slow_session.client.client_id
        assert wait_until(lambda: slow_id not in app.sessions(), 60)
    assert app.backlog.stats.closed == 1
    assert wait_until(lambda: not slow_session.running, 30)  # its frame thread stopped
    assert list(app.sessions()) == [fast_session.client.client_id]
    lines = [r for r in caplog.records if r.name == "poinsot.app.live.hardening.backlog"]
    assert len(lines) == 1 and f"client {slow_id} closed" in lines[0].getMessage()
    slow.stall(False)
    assert wait_until(lambda: slow.closed, 30)  # it sees its connection closed
    assert fast.wait_frames(5)  # the other client still gets frames
    assert fast_session.client.client_id in app.sessions()


class _Outbox:
    """A client's queue as the watch sees it."""

    def __init__(self, client_id: int) -> None:
        self.client = client_id
        self.queued = self.unacked = 0

    def pending(self) -> int:
        return self.queued

    def unacknowledged(self) -> int:
        return self.unacked


def test_a_client_over_the_message_cap_past_the_grace_is_closed_once():
    """The watch's rule on its own, with explicit times: over the cap for less than the grace
    is forgiven (a dip below restarts the count), past the grace the client is closed once.
    (Through a real socket, a client that reads nothing holds its backlog as unacknowledged
    bytes rather than queued messages: viser's sender hands every window to the transport.)"""
    limit = BacklogLimit(max_pending=100, max_unacked=1000, grace=2.0)
    outboxes = {0: _Outbox(0), 1: _Outbox(1)}
    sessions = {
        k: types.SimpleNamespace(pacer=types.SimpleNamespace(outbox=o)) for k, o in outboxes.items()
    }
    closed: list[int] = []
    watch = BacklogWatch(lambda: sessions, limit, close=lambda c: closed.append(c) or True)
    outboxes[0].queued = 101  # client 0 over the message cap, client 1 over the bytes bound
    outboxes[1].unacked = 1001
    assert watch.check(0.0) == [] and watch.check(1.9) == []
    outboxes[1].unacked = 1000  # back within: its count restarts
    assert watch.check(2.0) == [0] and closed == [0]
    outboxes[1].unacked = 5000
    assert watch.check(3.0) == [] and watch.check(4.9) == []
    assert watch.check(5.0) == [1] and closed == [0, 1]
    assert watch.check(9.0) == [] and watch.stats.closed == 2  # closed once each
    assert watch.stats.most_pending == {0: 101, 1: 0}
    assert watch.stats.most_unacked == {0: 0, 1: 5000}
    del sessions[0], sessions[1]  # their disconnects arrived
    assert watch.check(10.0) == [] and watch.stats.checks == 8


def test_the_action_queue_holds_its_cap_under_a_burst_and_later_edits_work(probe, poinsot_app):
    del probe  # connected, the scene drawn
    """While the frame thread is busy, 8 threads post 200 actions each: the queue never holds
    more than its cap, repeated settings of one control coalesce into one, the refused ones are
    counted and the user is told; afterwards an edit is applied as usual."""
    session = session_of(poinsot_app)
    actions = session.actions
    actions.maxsize = 64
    busy, release = threading.Event(), threading.Event()
    session.post(lambda: (busy.set(), release.wait(60)))
    assert busy.wait(30)  # the frame thread now waits inside that action
    ran = collections.Counter()

    def burst(thread: int) -> None:
        for i in range(200):
            session.set_speed(0.5 + 0.001 * i)  # one queued speed, however many are posted
            session.post(lambda thread=thread: ran.update([thread]))

    threads = [threading.Thread(target=burst, args=(t,)) for t in range(8)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(60)
    assert len(actions) == 64 == actions.most  # full, never more
    refused = actions.refused_total
    assert refused == 8 * 200 - (64 - 1)  # all but what fitted beside the one speed
    release.set()
    assert wait_until(lambda: len(actions) == 0 and session.status.startswith("Too many"), 30)
    assert f"{refused} were ignored" in session.status
    assert sum(ran.values()) == 63 and actions.most == 64
    generation = session.generation
    session.edit(lambda p: p.with_omega_norm(1.7))
    assert session.wait_applied(generation, 30) > generation
    assert session.params.omega_norm == 1.7 and session.status == ""
