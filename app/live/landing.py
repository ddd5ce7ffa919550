"""The landing port: a tiny HTTP server that sends each new browser to the least-loaded worker.

The lecturer writes one address on the board; a browser that opens it gets a ``302`` to the
same host on a worker's port, loads the page from that worker and opens its websocket there,
so a session lives in exactly one process. "Least loaded" is the fewest connected clients as
each worker reports them, plus the browsers sent to it that have not connected yet (a class
arriving at once would otherwise all land on the worker that looked empty a moment ago).

The guide (``make docs``, :mod:`poinsot.app.model.docs_site`) is answered here at ``/docs/``, not
redirected: a reader of the guide is no browser on its way to a worker.
``GET /poinsot-status`` answers the workers' ports, clients and health as JSON (the load test
and the tests read it); their process ids only to a client on the same machine (loopback).
"""

from __future__ import annotations

import collections
import http.client
import http.server
import ipaddress
import json
import socket
import threading
import time
import urllib.parse
from collections.abc import Callable, Sequence
from typing import Any, Protocol

from poinsot.app.live.hardening.network import PortError, bind_errno, port_problem
from poinsot.app.model import docs_site

#: A browser sent to a worker that has not connected within this many seconds is forgotten
#: (it closed the tab, reloaded straight on the worker's port, or was a tool that only follows
#: redirects): a page and its websocket take well under a second on a classroom's network.
PENDING_SECONDS = 5.0
STATUS_PATH = "/poinsot-status"


class Backend(Protocol):
    """What the landing needs to know of a worker."""

    @property
    def port(self) -> int: ...
    @property
    def pid(self) -> int | None: ...
    @property
    def alive(self) -> bool: ...
    @property
    def clients(self) -> int:
        """Browsers connected now."""
        ...

    @property
    def connects(self) -> int:
        """Browsers ever connected (only grows)."""
        ...


class Balancer:
    """Choose the least-loaded live backend; thread-safe."""

    def __init__(
        self, backends: Sequence[Backend], clock: Callable[[], float] = time.monotonic
    ) -> None:
        self.backends = list(backends)
        self._clock = clock
        self._lock = threading.Lock()
        self._pending = [collections.deque[float]() for _ in self.backends]
        self._connects = [b.connects for b in self.backends]

    def replace(self, index: int, backend: Backend) -> None:
        """Put a worker started again in the place of the one that ended: it is chosen again,
        from its own counts (a new process counts from zero)."""
        with self._lock:
            self.backends[index] = backend
            self._pending[index].clear()
            self._connects[index] = backend.connects

    def _clients(self, index: int) -> int:
        """A dead backend holds no clients, whatever its last count said."""
        backend = self.backends[index]
        return backend.clients if backend.alive else 0

    def load(self, index: int) -> int:
        """Connected clients plus browsers sent there and not arrived yet (under the lock);
        0 for a dead backend. The clients are read before the arrivals (a worker counts an
        arrival before its client): a browser is never counted both as connected and as
        still on its way."""
        backend, pending = self.backends[index], self._pending[index]
        clients = self._clients(index)
        connects = backend.connects
        if connects < self._connects[index]:  # a new process: its count starts again
            self._connects[index] = connects
        arrived = connects - self._connects[index]
        self._connects[index] += arrived
        for _ in range(min(arrived, len(pending))):
            pending.popleft()
        while pending and (pending[0] < self._clock() - PENDING_SECONDS or not backend.alive):
            pending.popleft()
        return clients + len(pending)

    def choose(self, *, counted: bool = True) -> Backend | None:
        """The live backend with the smallest load (the first on a tie), counted as sent to
        unless ``counted`` is False (a HEAD request: no browser follows it); None when no
        backend is alive."""
        with self._lock:
            loads = [(self.load(i), i) for i, b in enumerate(self.backends) if b.alive]
            if not loads:
                return None
            _, best = min(loads)
            if counted:
                self._pending[best].append(self._clock())
            return self.backends[best]

    def status(self) -> list[dict[str, int | bool | None]]:
        """Per backend: its port, pid, whether it is alive, its clients and its load."""
        with self._lock:
            return [
                {
                    "port": b.port,
                    "pid": b.pid,
                    "alive": b.alive,
                    "clients": self._clients(i),
                    "load": self.load(i),
                }
                for i, b in enumerate(self.backends)
            ]


def _loopback(address: str) -> bool:
    """True for a client on this machine (127.0.0.0/8, ::1, or IPv4-mapped 127.x)."""
    try:
        ip = ipaddress.ip_address(address)
    except ValueError:
        return False
    mapped = getattr(ip, "ipv4_mapped", None)
    return bool((mapped or ip).is_loopback)


def _host_name(header: str | None, fallback: str) -> str:
    """The host part of a ``Host`` header (``[::1]:8080`` -> ``[::1]``), else ``fallback``."""
    if not header:
        return fallback
    if header.startswith("["):
        return header[: header.find("]") + 1]
    return header.rsplit(":", 1)[0]


class _Handler(http.server.BaseHTTPRequestHandler):
    server: LandingServer

    def do_GET(self) -> None:  # noqa: N802 (the name http.server calls)
        if urllib.parse.urlsplit(self.path).path == STATUS_PATH:
            status = self.server.balancer.status()
            if not _loopback(self.client_address[0]):  # the LAN sees no process ids
                status = [{k: v for k, v in entry.items() if k != "pid"} for entry in status]
            self._reply(200, "application/json", json.dumps(status))
            return
        guide = docs_site.answer(self.path)  # the guide is served here, not by a worker
        if guide is not None:
            self.send_response(guide.status)
            for name, value in guide.headers:
                self.send_header(name, value)
            self.end_headers()
            if self.command == "GET":
                self.wfile.write(guide.body)
            return
        backend = self.server.balancer.choose(counted=self.command == "GET")
        if backend is None:
            self._reply(503, "text/plain; charset=utf-8", "No Poinsot worker is running.\n")
            return
        host = _host_name(self.headers.get("Host"), self.server.fallback_host)
        self.send_response(302)
        self.send_header("Location", f"http://{host}:{backend.port}{self.path}")
        self.send_header("Cache-Control", "no-store")
        self.send_header("Content-Length", "0")
        self.end_headers()

    do_HEAD = do_GET

    def _reply(self, code: int, kind: str, text: str) -> None:
        body = text.encode()
        self.send_response(code)
        self.send_header("Content-Type", kind)
        self.send_header("Cache-Control", "no-store")
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, format: str, *args: object) -> None:  # noqa: A002 (the base's name)
        """Quiet: one line per browser would bury the board's address."""


class LandingServer(http.server.ThreadingHTTPServer):
    """Listen on ``host:port`` exactly (a busy port raises :class:`PortError`, never moves
    on to the next one) and redirect to ``balancer``'s choice. ``serve_forever`` in a thread
    of the caller's; ``shutdown`` then ``server_close`` to stop."""

    daemon_threads = True

    def __init__(self, host: str, port: int, balancer: Balancer) -> None:
        self.balancer = balancer
        self.fallback_host = "localhost" if host in ("0.0.0.0", "::", "") else host
        self.address_family = socket.AF_INET6 if ":" in host else socket.AF_INET
        try:
            super().__init__((host, port), _Handler)
        except OSError as exc:
            raise PortError(port_problem(host, port, bind_errno(exc))) from None

    @property
    def port(self) -> int:
        return int(self.server_address[1])

    def start(self) -> threading.Thread:
        thread = threading.Thread(target=self.serve_forever, name="poinsot-landing", daemon=True)
        thread.start()
        return thread


def resolve(port: int, host: str = "127.0.0.1", timeout: float = 10.0) -> int:
    """The port a browser opening ``http://host:port/`` ends up on: the worker's port the
    landing redirects to, or ``port`` itself when it is a Poinsot server (headless clients
    use this to arrive as a browser would)."""
    connection = http.client.HTTPConnection(host, port, timeout=timeout)
    try:
        connection.request("GET", "/")
        response = connection.getresponse()
        response.read()
        location = response.getheader("Location")
    finally:
        connection.close()
    if response.status in (301, 302, 303, 307, 308) and location:
        target = urllib.parse.urlsplit(location).port
        if target is not None:
            return target
    return port


def status(port: int, host: str = "127.0.0.1", timeout: float = 10.0) -> list[dict[str, Any]]:
    """The landing's view of its workers (``GET /poinsot-status``)."""
    connection = http.client.HTTPConnection(host, port, timeout=timeout)
    try:
        connection.request("GET", STATUS_PATH)
        result: list[dict[str, Any]] = json.loads(connection.getresponse().read())
    finally:
        connection.close()
    return result
