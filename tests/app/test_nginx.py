"""Several Poinsot servers behind Debian's nginx with sticky websockets, on loopback.

The nginx configuration is the guide's own (docs/how-to/classroom.md, "Several machines"),
with the upstream servers and the listening address replaced; nginx runs unprivileged in the
foreground with its pid, logs and temporary files under ``tmp_path``. Headless clients connect
from distinct loopback addresses (127.0.0.1 to 127.0.0.16: Linux answers on all of 127/8), so
that ``hash $remote_addr`` has addresses to spread. Skipped when nginx is missing, except in CI.
"""

from __future__ import annotations

import urllib.request
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TypeVar

import pytest

from poinsot.app.devtools.load import services
from poinsot.app.devtools.probe import Probe
from poinsot.app.live.server import PoinsotApp
from tests.conftest import in_ci, wait_until

SOURCES = [f"127.0.0.{i}" for i in range(1, 17)]

pytestmark = pytest.mark.slow
T = TypeVar("T")


def service_or_skip(make: Callable[[], T]) -> T:
    """``make()``, or skip (locally) / fail (CI) with how to install what is missing."""
    try:
        return make()
    except services.Missing as exc:
        if in_ci():
            pytest.fail(f"{exc} [CI=true: the classroom's programs must run]")
        pytest.skip(str(exc))


@pytest.fixture
def balancer(tmp_path: Path, make_app) -> Iterator[tuple[int, list[PoinsotApp]]]:
    """Two Poinsot servers behind nginx: (nginx's port, the servers)."""
    apps = [make_app(), make_app()]
    nginx = service_or_skip(lambda: services.Nginx(tmp_path, [app.port for app in apps]))
    nginx.start()
    try:
        yield nginx.port, apps
    finally:
        nginx.stop()


def probe_from(source: str, port: int) -> Probe:
    """A headless browser on ``source`` (a loopback address), through ``port``."""
    return Probe(port, source=source)


def _arrive(apps: list[PoinsotApp], source: str, port: int, probes: list[Probe]) -> int:
    """Connect a client from ``source``; the index of the server that got its session."""
    before = [len(app.sessions()) for app in apps]
    probes.append(probe_from(source, port))
    assert wait_until(lambda: sum(len(a.sessions()) for a in apps) == sum(before) + 1, 60)
    grown = [i for i, app in enumerate(apps) if len(app.sessions()) > before[i]]
    assert len(grown) == 1
    return grown[0]


def test_sessions_spread_over_servers_behind_nginx_and_stay_put(balancer):
    port, apps = balancer
    with urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=30) as page:
        assert page.status == 200 and b"<html" in page.read().lower()
    probes: list[Probe] = []
    try:
        server_of = {source: _arrive(apps, source, port, probes) for source in SOURCES}
        assert set(server_of.values()) == {0, 1}, "every client reached the same server"
        for probe in probes:  # each session plays, on the one server that holds it
            assert probe.wait_frames(3), "a client behind nginx received no frames"
        counts = [len(app.sessions()) for app in apps]
        assert counts == [list(server_of.values()).count(i) for i in (0, 1)]
        for probe in probes:
            probe.close()
        assert wait_until(lambda: all(not app.sessions() for app in apps), 60)
        probes.clear()
        for source in (SOURCES[0], SOURCES[0], SOURCES[1], SOURCES[1]):  # returning browsers
            assert _arrive(apps, source, port, probes) == server_of[source], "not sticky"
    finally:
        for probe in probes:
            probe.close()
