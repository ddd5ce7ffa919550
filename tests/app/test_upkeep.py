"""A server stays level through a storm: a fixed set of pool threads, memory trimmed after
departures (counted, never timed)."""

from __future__ import annotations

import gc
import threading
import weakref

from conftest import wait_until

from poinsot.app.live.hardening.upkeep import SETTLE_SESSIONS, MemoryTrim, fixed_pool


def _pool_threads(name: str) -> int:
    return sum(1 for t in threading.enumerate() if t.name.startswith(name))


def test_a_fixed_pool_has_all_its_threads_and_a_burst_adds_none():
    pool = fixed_pool(3, name="upkeep-test")
    try:
        assert _pool_threads("upkeep-test") == 3
        release = threading.Event()
        futures = [pool.submit(release.wait, 10) for _ in range(20)]  # more than it has
        assert _pool_threads("upkeep-test") == 3
        release.set()
        assert all(f.result(10) for f in futures)
        assert _pool_threads("upkeep-test") == 3
    finally:
        pool.shutdown(wait=True)
    assert _pool_threads("upkeep-test") == 0


def test_memory_is_trimmed_once_after_a_burst_of_departures():
    trim = MemoryTrim(quiet_seconds=0.2)
    try:
        for _ in range(50):
            trim.departed()
        assert wait_until(lambda: trim.trims == 1, 10)
        trim.departed()
        assert wait_until(lambda: trim.trims == 2, 10)
    finally:
        trim.stop()


class _Cycle:
    """An object in a reference cycle: only the cyclic collector frees it."""

    def __init__(self) -> None:
        self.me = self


def test_a_hall_s_heap_is_settled_after_an_arrival_and_scanned_again_after_a_departure():
    """A serving process with a hall of sessions: the quiet moment after one arrives freezes
    what is alive, so that a cycle among it that dies is left alone by the collector's scans;
    the quiet moment after a departure scans it again and frees it; once the hall is smaller
    than SETTLE_SESSIONS, the heap is no longer settled."""
    alive_sessions = [SETTLE_SESSIONS]
    trim = MemoryTrim(quiet_seconds=0.05, sessions=lambda: alive_sessions[0])
    try:
        cycle = _Cycle()
        alive = weakref.ref(cycle)
        trim.arrived()
        assert wait_until(lambda: trim.trims == 1, 10)
        assert trim.settled and gc.get_freeze_count() > 0
        del cycle
        gc.collect()
        assert alive() is not None  # frozen: not scanned
        trim.departed()
        assert wait_until(lambda: trim.trims == 2, 10)
        assert alive() is None
        assert trim.settled  # settled again: still a hall
        alive_sessions[0] = SETTLE_SESSIONS - 1
        trim.departed()
        assert wait_until(lambda: trim.trims == 3, 10)
        assert not trim.settled and gc.get_freeze_count() == 0
    finally:
        trim.stop()
    assert gc.get_freeze_count() == 0


def test_a_process_that_only_serves_a_test_never_settles_its_heap():
    """Without ``sessions`` (a test's or a notebook's process), arrivals trim nothing and a
    departure's trim freezes nothing."""
    trim = MemoryTrim(quiet_seconds=0.05)
    try:
        trim.arrived()
        trim.departed()
        assert wait_until(lambda: trim.trims == 1, 10)
        assert not trim.settled and gc.get_freeze_count() == 0
    finally:
        trim.stop()


def test_a_server_builds_sessions_on_its_fixed_pool(make_app, make_probe):
    """Twelve browsers connecting at once are served by the app's pool: its threads do not
    grow, and each browser gets its session."""
    app = make_app()
    before = _pool_threads("poinsot-pool")
    probes = [make_probe(app) for _ in range(12)]
    assert len(app.wait_for_sessions(12, 60)) == 12
    assert _pool_threads("poinsot-pool") == before
    for probe in probes:
        probe.close()
    assert wait_until(lambda: not app.sessions(), 30)
    assert wait_until(lambda: app.memory.trims >= 1, 30)


def test_a_process_shares_its_frames_among_its_browsers(make_app, make_probe):
    """Up to the cap each while few share a process, fewer as more join, never below the
    floor; a departure gives the others their share back."""
    from poinsot.app.live.hardening.pacing import PROCESS_FRAMES, SHARED_MIN_FPS, frame_share

    assert frame_share(60.0, 1) == 60.0
    assert frame_share(60.0, 9) == 60.0
    assert frame_share(60.0, 15) == PROCESS_FRAMES / 15 < 60.0
    assert frame_share(60.0, 100) == SHARED_MIN_FPS
    app = make_app()
    probes = [make_probe(app) for _ in range(12)]
    sessions = app.wait_for_sessions(12, 60)
    assert wait_until(lambda: len(app.sessions()) == 12, 30)
    assert {s.pacer.max_fps for s in sessions} == {frame_share(app.max_fps, 12)}
    for probe in probes[:6]:
        probe.close()
    assert wait_until(lambda: len(app.sessions()) == 6, 30)
    assert {s.pacer.max_fps for s in app.sessions().values()} == {app.max_fps}


def test_a_serving_server_runs_on_libuv_and_leaves_the_process_s_other_loops_to_asyncio(
    make_app, make_probe
):
    """``poinsot serve``'s server (and its workers', and the load test's) runs its browsers on
    libuv's event loop; the process's loops made after it, a test's other server's, are
    asyncio's (so is a browser driver's)."""
    import asyncio

    import uvloop

    from poinsot.app.live.hardening.eventloop import libuv_loops

    serving = make_app(serving=True)
    assert isinstance(serving.server.get_event_loop(), uvloop.Loop)
    assert make_probe(serving).wait_frames(10), "no frames through libuv's loop"
    assert not isinstance(asyncio.get_event_loop_policy(), uvloop.EventLoopPolicy)
    assert not isinstance(make_app().server.get_event_loop(), uvloop.Loop)
    with libuv_loops():
        loop = asyncio.new_event_loop()
    assert isinstance(loop, uvloop.Loop)
    loop.close()
