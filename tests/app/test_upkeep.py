"""A server stays level through a storm: a fixed set of pool threads, memory trimmed after
departures (counted, never timed)."""

from __future__ import annotations

import threading

from conftest import wait_until

from poinsot.app.live.hardening.upkeep import MemoryTrim, fixed_pool


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
