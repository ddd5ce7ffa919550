"""The Poinsot server under test, in a child process of its own.

The child runs :class:`poinsot.app.live.server.PoinsotApp` on a free loopback port, writes
everything it prints or logs (tracebacks included) to a log file, and answers questions over a
pipe from its otherwise idle main thread: how many sessions are live, how many threads of which
kind it runs, how many frames its sessions drew. Its CPU time, memory and threads are read from
``/proc/<pid>`` by the parent (:mod:`poinsot.app.devtools.load.procfs`). It stops when asked, when
the parent goes away, or after ``lifetime`` seconds, whichever comes first.
"""

from __future__ import annotations

import collections
import logging
import os
import pathlib
import re
import sys
import tempfile
import threading
import time
from multiprocessing.connection import Connection
from typing import Any

from poinsot.app import viser_private
from poinsot.app.devtools.load.children import Child

#: What counts as an error in the server's log (case-insensitive).
ERROR_PATTERN = re.compile(r"traceback|error", re.IGNORECASE)


def thread_kind(name: str) -> str:
    """``poinsot-session-12`` -> ``poinsot-session``, ``ThreadPoolExecutor-0_3`` ->
    ``ThreadPoolExecutor``, ``Thread-4 (run)`` -> ``Thread``."""
    return re.sub(r"[-_ ]?\d.*$", "", name) or name


def error_lines(log: str) -> list[str]:
    """The lines of a log that mention a traceback or an error (so a traceback usually counts
    twice: its first line, and the last one naming the ...Error)."""
    return [line.strip() for line in log.splitlines() if ERROR_PATTERN.search(line)]


def _status(app: Any) -> dict[str, Any]:
    sessions = app.sessions()
    kinds = collections.Counter(thread_kind(t.name) for t in threading.enumerate())
    return {
        "sessions": len(sessions),
        "pending_departures": app.pending_departures(),
        "frames": sum(s.stats.frames for s in sessions.values()),
        "session_errors": sum(s.stats.errors for s in sessions.values()),
        "session_threads": kinds.get("poinsot-session", 0),
        "connections": viser_private.connection_count(app.server),
        "disconnected": app.guard.disconnected,  # cut off for exceeding the message budget
        "threads": dict(kinds),
        **cast_counts(app.follow.cast),
    }


#: The followers' cast's counters in a status (its
#: :class:`~poinsot.app.live.classroom.cast.FollowCast`): its thread's ticks, the frames it held
#: while a move was rebuilt, the followers it skipped (a socket busy or behind), the windows it
#: encoded and the copies it handed to sockets, the lead's new bodies one follower handed to
#: others and the copies of those.
CAST_COUNTS = ("ticks", "held", "skipped", "encoded", "handed", "fits", "fit_copies")


def cast_counts(cast: Any) -> dict[str, float]:
    """``cast``'s counters, named ``cast_<counter>`` (:data:`CAST_COUNTS`), and its ticks due a
    second (``cast_due``: summed over a classroom's workers, each worker's cast ticks)."""
    counts: dict[str, float] = {f"cast_{name}": getattr(cast, name) for name in CAST_COUNTS}
    return counts | {"cast_due": cast.fps}


class _Classroom:
    """``poinsot serve --workers N`` inside the child: N worker processes behind a landing
    port (:mod:`poinsot.app.live.workers`); its status sums the workers' own."""

    def __init__(self, count: int) -> None:
        from poinsot.app.live.classroom.follow import new_code
        from poinsot.app.live.landing import Balancer, LandingServer
        from poinsot.app.live.relay import Relay
        from poinsot.app.live.workers import start_workers
        from poinsot.app.model.presets import DEFAULT_PRESET

        self.code = new_code()  # the lecturer's, as poinsot serve makes it
        self.workers = start_workers(count, "127.0.0.1", 0, DEFAULT_PRESET.key, None, (), self.code)
        self.relay = Relay([w.feed for w in self.workers]).start()
        self.landing = LandingServer("127.0.0.1", 0, Balancer(self.workers))
        self.landing.start()
        self.port = self.landing.port

    def status(self) -> dict[str, Any]:
        parts = [w.inspect(_status) for w in self.workers if w.alive]
        total: dict[str, Any] = {k: sum(p[k] for p in parts) for k in parts[0] if k != "threads"}
        total["threads"] = dict(
            sum((collections.Counter(p["threads"]) for p in parts), start=collections.Counter())
        )
        return total

    def stop(self) -> None:
        from poinsot.app.live.workers import stop_workers

        self.landing.shutdown()
        self.landing.server_close()
        stop_workers(self.workers)
        self.relay.stop()


def _linked_app(url: str) -> tuple[Any, Any]:
    """One process whose hub is linked to the Redis at ``url``, as ``poinsot serve --redis URL
    --workers 1`` runs on each host (:mod:`poinsot.app.live.broker`); the lecturer code is the
    one shared there. (The app, its link.)"""
    from poinsot.app.live import broker
    from poinsot.app.live.classroom.follow import FollowHub, new_code
    from poinsot.app.live.server import PoinsotApp

    code, line, reachable = broker.shared_code(url, None, new_code())
    if not reachable:
        raise RuntimeError(line)
    hub = FollowHub(code)
    app = PoinsotApp("127.0.0.1", 0, follow=hub, serving=True)
    return app, broker.link_hub(hub, url)


def _link_status(link: Any) -> dict[str, Any]:
    """The Redis link's connections lost and messages refused (none without one)."""
    if link is None:
        return {}
    return {"redis": {"lost": link.lost, "refused": link.refused}}


def _main(
    conn: Connection, log_path: str, lifetime: float, workers: int = 1, redis: str = ""
) -> None:
    """The child: serve on a free port (through a landing port and ``workers`` processes if
    more than one; linked to the Redis at ``redis`` if given, in one process), answer the
    parent, stop within ``lifetime`` seconds."""
    log = os.open(log_path, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o644)
    os.dup2(log, 1)
    os.dup2(log, 2)
    sys.stdout.reconfigure(line_buffering=True)  # type: ignore[union-attr]
    sys.stderr.reconfigure(line_buffering=True)  # type: ignore[union-attr]
    logging.basicConfig(
        level=logging.WARNING, stream=sys.stderr, format="%(asctime)s %(levelname)s %(message)s"
    )
    from poinsot.app.live.server import PoinsotApp

    link = None
    if redis:
        app, link = _linked_app(redis)
    else:
        app = PoinsotApp("127.0.0.1", 0, serving=True) if workers == 1 else _Classroom(workers)
    pids = [w.pid for w in app.workers] if workers > 1 else []
    code = app.code if workers > 1 else app.follow.code
    conn.send(("ready", (app.port, pids, code)))
    deadline = time.monotonic() + lifetime
    try:
        while time.monotonic() < deadline:
            if not conn.poll(0.5):
                continue
            try:
                request = conn.recv()
            except EOFError:  # the parent is gone
                break
            if request == "status":
                conn.send({**_status(app), **_link_status(link)} if workers == 1 else app.status())
            elif request == "stop":
                break
    finally:
        if link is not None:
            link.close()
        app.stop()
    try:
        conn.send(("stopped", None))
    except OSError:
        pass


class ServerProcess(Child):
    """Start the server child; a context manager that stops and reaps it."""

    def __init__(
        self, lifetime: float, start_timeout: float = 120.0, workers: int = 1, redis: str = ""
    ):
        """``redis``: a Redis URL to link one process's hub to (a host of a classroom)."""
        if redis and workers != 1:
            raise ValueError("a host linked to Redis runs one process here")
        fd, path = tempfile.mkstemp(prefix="poinsot-load-server-", suffix=".log")
        os.close(fd)
        self.log_path = pathlib.Path(path)
        super().__init__("server", _main, str(self.log_path), lifetime, workers, redis)
        self.port: int
        #: The worker processes' pids (none for one process): their CPU and memory count too.
        self.worker_pids: list[int]
        self.code: str  # the lecturer code (:mod:`poinsot.app.live.classroom.follow`)
        self.port, self.worker_pids, self.code = self.receive(start_timeout, "the server to start")

    def __enter__(self) -> ServerProcess:
        return self

    def status(self, timeout: float = 30.0) -> dict[str, Any]:
        """Sessions, pending departures, frames drawn, threads by kind (see ``_status``)."""
        result: dict[str, Any] = self.request("status", timeout, "the server's status")
        return result

    def wait_for_sessions(self, count: int, timeout: float) -> int:
        """Poll until exactly ``count`` sessions are live (or ``timeout``); the last count."""
        deadline = time.monotonic() + timeout
        while True:
            sessions: int = self.status()["sessions"]
            if sessions == count or time.monotonic() >= deadline:
                return sessions
            time.sleep(0.25)

    def log_errors(self) -> list[str]:
        """Lines of the server's log that mention a traceback or an error."""
        try:
            return error_lines(self.log_path.read_text(errors="replace"))
        except OSError:
            return []

    def log_tail(self, count: int) -> list[str]:
        """The last ``count`` lines of the server's log (warnings included)."""
        try:
            return self.log_path.read_text(errors="replace").splitlines()[-count:]
        except OSError:
            return []

    def remove_log(self) -> None:
        self.log_path.unlink(missing_ok=True)
