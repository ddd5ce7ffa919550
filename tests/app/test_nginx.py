"""Several Poinsot servers behind Debian's nginx with sticky websockets, on loopback.

The nginx configuration is the guide's own (docs/how-to/classroom.md, "Several machines"),
with the upstream servers and the listening address replaced; nginx runs unprivileged in the
foreground with its pid, logs and temporary files under ``tmp_path``. Headless clients connect
from distinct loopback addresses (127.0.0.1 to 127.0.0.16: Linux answers on all of 127/8), so
that ``hash $remote_addr`` has addresses to spread. Skipped when nginx is missing, except in CI.
"""

from __future__ import annotations

import functools
import re
import shutil
import socket
import subprocess
import urllib.request
from collections.abc import Iterator
from pathlib import Path
from unittest import mock

import pytest
import websockets.sync.client

from poinsot.app.devtools.probe import Probe
from poinsot.app.live.server import PoinsotApp
from tests.conftest import in_ci, wait_until

GUIDE = Path(__file__).resolve().parents[2] / "docs" / "how-to" / "classroom.md"
SOURCES = [f"127.0.0.{i}" for i in range(1, 17)]

pytestmark = pytest.mark.slow


def nginx_or_skip() -> str:
    """nginx's executable; skip (locally) or fail (CI) with how to install it."""
    path = shutil.which("nginx") or shutil.which("nginx", path="/usr/sbin:/sbin")
    if path:
        return path
    message = "nginx not found: run `make chromium` (installs Debian's nginx-light) or apt"
    if in_ci():
        pytest.fail(message + " [CI=true: the load-balancer test must run]")
    pytest.skip(message)


def readme_config() -> str:
    """The nginx block of the guide's classroom page."""
    text = GUIDE.read_text()
    section = text[text.index("## Several machines") :]
    return re.search(r"```nginx\n(.*?)```", section, re.DOTALL).group(1)


def nginx_conf(tmp: Path, listen: int, backends: list[int]) -> str:
    servers = "".join(f"    server 127.0.0.1:{port};\n" for port in backends)
    block = re.sub(r"(    server [\d.:]+;\n)+", servers, readme_config())
    block = re.sub(r"listen \d+;", f"listen 127.0.0.1:{listen};", block)
    assert servers in block and f"127.0.0.1:{listen}" in block, "the guide's block changed"
    temps = "".join(
        f"    {kind}_temp_path {tmp}/{kind};\n"
        for kind in ("client_body", "proxy", "fastcgi", "uwsgi", "scgi")
    )
    return (
        f"daemon off;\nworker_processes 1;\npid {tmp}/nginx.pid;\nerror_log {tmp}/error.log;\n"
        f"events {{ worker_connections 256; }}\n"
        f"http {{\n    access_log off;\n{temps}{block}}}\n"
    )


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


@pytest.fixture
def balancer(tmp_path: Path, make_app) -> Iterator[tuple[int, list[PoinsotApp]]]:
    """Two Poinsot servers behind nginx: (nginx's port, the servers)."""
    nginx = nginx_or_skip()
    apps = [make_app(), make_app()]
    port = free_port()
    conf = tmp_path / "nginx.conf"
    conf.write_text(nginx_conf(tmp_path, port, [app.port for app in apps]))
    process = subprocess.Popen(
        [nginx, "-p", str(tmp_path), "-c", str(conf)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert wait_until(lambda: _listening(port) or process.poll() is not None, 30)
        assert process.poll() is None, f"nginx did not start: {process.stderr.read()}"
        yield port, apps
    finally:
        process.terminate()
        process.wait(30)


def _listening(port: int) -> bool:
    try:
        socket.create_connection(("127.0.0.1", port), timeout=1).close()
        return True
    except OSError:
        return False


def probe_from(source: str, port: int) -> Probe:
    """A headless browser on ``source`` (a loopback address), through ``port``."""
    connect = functools.partial(websockets.sync.client.connect, source_address=(source, 0))
    with mock.patch.object(websockets.sync.client, "connect", connect):
        return Probe(port)


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
