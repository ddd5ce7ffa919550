"""The Poinsot server under test, in a child process of its own.

The child runs :class:`poinsot.app.live.server.PoinsotApp` on a free loopback port, writes
everything it prints or logs (tracebacks included) to a log file, and answers questions over a
pipe from its otherwise idle main thread: how many sessions are live, how many threads of which
kind it runs, how many frames its sessions drew. Its CPU time, memory and threads are read from
``/proc/<pid>`` by the parent (:mod:`poinsot.app.load.procfs`). It stops when asked, when the
parent goes away, or after ``lifetime`` seconds, whichever comes first.
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

from poinsot.app.load.children import Child

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
        "threads": dict(kinds),
    }


def _main(conn: Connection, log_path: str, lifetime: float) -> None:
    """The child: serve on a free port, answer the parent, stop within ``lifetime`` seconds."""
    log = os.open(log_path, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o644)
    os.dup2(log, 1)
    os.dup2(log, 2)
    sys.stdout.reconfigure(line_buffering=True)  # type: ignore[union-attr]
    sys.stderr.reconfigure(line_buffering=True)  # type: ignore[union-attr]
    logging.basicConfig(
        level=logging.WARNING, stream=sys.stderr, format="%(asctime)s %(levelname)s %(message)s"
    )
    from poinsot.app.live.server import PoinsotApp

    app = PoinsotApp("127.0.0.1", 0)
    conn.send(("ready", app.port))
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
                conn.send(_status(app))
            elif request == "stop":
                break
    finally:
        app.stop()
    try:
        conn.send(("stopped", None))
    except OSError:
        pass


class ServerProcess(Child):
    """Start the server child; a context manager that stops and reaps it."""

    def __init__(self, lifetime: float, start_timeout: float = 120.0):
        fd, path = tempfile.mkstemp(prefix="poinsot-load-server-", suffix=".log")
        os.close(fd)
        self.log_path = pathlib.Path(path)
        super().__init__("server", _main, str(self.log_path), lifetime)
        self.port: int = self.receive(start_timeout, "the server to start")

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

    def remove_log(self) -> None:
        self.log_path.unlink(missing_ok=True)
