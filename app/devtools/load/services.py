"""The classroom's other programs, on loopback: Debian's ``redis-server`` and ``nginx``.

A lecture across hosts runs several ``poinsot serve`` behind nginx, their hubs linked through one
Redis (docs/how-to/classroom.md, "Several machines"; :mod:`poinsot.app.live.broker`). The follow
phase's two-host variant and the tests run both here, unprivileged, with their files in a
temporary folder: :class:`RedisServer` (no persistence; :meth:`~RedisServer.kill` and
:meth:`~RedisServer.start` again on the same port) and :class:`Nginx` (the guide's own block,
its upstream servers and listening address replaced). Both come with ``make chromium``; a
missing one raises :class:`Missing`, whose message says how to install it.
"""

from __future__ import annotations

import re
import shutil
import socket
import subprocess
import time
from pathlib import Path

#: The guide whose nginx block is run (the repository's; the load test runs from a checkout).
GUIDE = Path(__file__).resolve().parents[3] / "docs" / "how-to" / "classroom.md"
START_TIMEOUT = 30.0


class Missing(RuntimeError):
    """A program the classroom needs is not installed (the message says how to get it)."""


def free_port() -> int:
    """A loopback port free at the time of asking."""
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def listening(port: int) -> bool:
    """Whether something accepts connections on the loopback ``port``."""
    try:
        socket.create_connection(("127.0.0.1", port), timeout=1).close()
        return True
    except OSError:
        return False


def _program(name: str, package: str) -> str:
    path = shutil.which(name) or shutil.which(name, path="/usr/sbin:/sbin")
    if path is None:
        raise Missing(f"{name} not found: run `make chromium` (installs Debian's {package}) or apt")
    return path


def check_installed() -> None:
    """Raise :class:`Missing` unless both redis-server and nginx are installed."""
    _program("redis-server", "redis-server")
    _program("nginx", "nginx-light")


def _wait(ready: object, process: subprocess.Popen[bytes], what: str) -> None:
    """Until ``ready()`` (a callable) is true; raise if ``process`` ends first or it never is."""
    deadline = time.monotonic() + START_TIMEOUT
    while not ready():  # type: ignore[operator]
        if process.poll() is not None:
            error = process.stderr.read().decode(errors="replace") if process.stderr else ""
            raise RuntimeError(f"{what} did not start: {error.strip()[-300:]}")
        if time.monotonic() > deadline:
            raise RuntimeError(f"{what} did not answer within {START_TIMEOUT:.0f} s")
        time.sleep(0.05)


class RedisServer:
    """Debian's redis-server on a free loopback port, no persistence, files under ``folder``."""

    def __init__(self, folder: Path) -> None:
        self.path = _program("redis-server", "redis-server")
        self.folder, self.port = folder, free_port()
        self.url = f"redis://127.0.0.1:{self.port}/0"
        self.process: subprocess.Popen[bytes] | None = None

    def start(self) -> RedisServer:
        """Start it (again, on the same port) and wait until it answers a PING."""
        args = [self.path, "--port", str(self.port), "--bind", "127.0.0.1", "--save", ""]
        args += ["--appendonly", "no", "--dir", str(self.folder)]
        self.process = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        _wait(self.answers, self.process, "redis-server")
        return self

    def answers(self) -> bool:
        import redis  # the optional extra, in the test extras

        try:
            client = redis.Redis.from_url(self.url, socket_connect_timeout=1, socket_timeout=1)
            with client:
                return bool(client.ping())
        except redis.RedisError:
            return False

    def kill(self) -> None:
        """Kill it at once (SIGKILL: a host lost, not a clean shutdown)."""
        if self.process is not None:
            self.process.kill()
            self.process.wait(30)
            self.process = None


def guide_block(guide: Path = GUIDE) -> str:
    """The nginx block of the guide's "Several machines" section."""
    text = guide.read_text()
    section = text[text.index("## Several machines") :]
    found = re.search(r"```nginx\n(.*?)```", section, re.DOTALL)
    if found is None:
        raise ValueError(f"{guide}: no nginx block under 'Several machines'")
    return found.group(1)


def nginx_conf(folder: Path, listen: int, backends: list[int], block: str) -> str:
    """A whole nginx.conf for an unprivileged nginx in the foreground: ``block`` with its
    upstream servers replaced by ``backends`` (loopback ports) and its listening address by
    ``listen``; pid, logs and temporary files under ``folder``."""
    servers = "".join(f"    server 127.0.0.1:{port};\n" for port in backends)
    block = re.sub(r"(    server [\d.:]+;\n)+", servers, block)
    block = re.sub(r"listen \d+;", f"listen 127.0.0.1:{listen};", block)
    if servers not in block or f"127.0.0.1:{listen}" not in block:
        raise ValueError("the guide's nginx block has no upstream servers or listen line")
    temps = "".join(
        f"    {kind}_temp_path {folder}/{kind};\n"
        for kind in ("client_body", "proxy", "fastcgi", "uwsgi", "scgi")
    )
    return (
        f"daemon off;\nworker_processes 1;\npid {folder}/nginx.pid;\n"
        f"error_log {folder}/error.log;\nevents {{ worker_connections 1024; }}\n"
        f"http {{\n    access_log off;\n{temps}{block}}}\n"
    )


class Nginx:
    """nginx on a free loopback port in front of ``backends``, with the guide's block."""

    def __init__(self, folder: Path, backends: list[int], block: str | None = None) -> None:
        self.path = _program("nginx", "nginx-light")
        self.folder, self.port = folder, free_port()
        self.conf = folder / "nginx.conf"
        self.conf.write_text(nginx_conf(folder, self.port, backends, block or guide_block()))
        self.process: subprocess.Popen[bytes] | None = None

    def start(self) -> Nginx:
        args = [self.path, "-p", str(self.folder), "-c", str(self.conf)]
        self.process = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        _wait(lambda: listening(self.port), self.process, "nginx")
        return self

    def stop(self) -> None:
        if self.process is not None:
            self.process.terminate()
            self.process.wait(30)
            self.process = None
