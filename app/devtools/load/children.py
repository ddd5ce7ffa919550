"""Child processes of the tool and the pipe each one talks over.

Every child is started with the ``forkserver`` method and gets a pipe: a fresh interpreter,
started once, imports what the children run (:data:`PRELOAD`: the server, the clients) and
forks each child from itself, so no child inherits the tool's threads or sockets and none pays
those imports again (seconds each on a busy machine, a dozen children a run). A child answers
each request with one message; a failure comes back as ``("error", text)``. Every wait on a
child has a timeout, and a child that does not stop when asked is terminated.
"""

from __future__ import annotations

import contextlib
import multiprocessing as mp
import time
from collections.abc import Callable
from multiprocessing.connection import Connection
from typing import Any

#: What the fork server imports once, before it forks any child.
PRELOAD = (
    "poinsot.app.devtools.load",
    "poinsot.app.live.server",
    "poinsot.app.devtools.probe",
    "poinsot.app.live.landing",
)


def _context() -> Any:
    ctx = mp.get_context("forkserver")
    ctx.set_forkserver_preload(list(PRELOAD))
    return ctx


def answer_requests(
    conn: Connection,
    lifetime: float,
    ready: Callable[[], tuple[str, Any]],
    kind: str,
    work: Callable[[], Any],
    leave: Callable[[], None] = lambda: None,
) -> None:
    """The loop of a child that works on request, run in the child: ``ready()`` prepares it
    and gives its first message; then each ``"go"`` runs ``work()`` and answers ``(kind,
    result)``, until ``"stop"`` or ``lifetime`` seconds. ``leave()`` runs on the way out, before
    the last message, ``("stopped", None)``. A failure is answered ``("error", text)``; a parent
    that has gone ends the loop quietly."""
    deadline = time.monotonic() + lifetime
    try:
        conn.send(ready())
        while time.monotonic() < deadline:
            if not conn.poll(0.5):
                continue
            request = conn.recv()
            if request == "go":
                conn.send((kind, work()))
            elif request == "stop":
                break
    except EOFError:
        return
    except Exception as exc:
        conn.send(("error", f"{type(exc).__name__}: {exc}"))
        return
    finally:
        leave()
    with contextlib.suppress(OSError):
        conn.send(("stopped", None))


def receive(conn: Connection, timeout: float, what: str) -> Any:
    """The next message from a child, or an error naming what was awaited. A ``(kind,
    payload)`` pair gives its payload; ``("error", text)`` raises."""
    if not conn.poll(timeout):
        raise TimeoutError(f"timed out after {timeout:.0f} s waiting for {what}")
    try:
        message = conn.recv()
    except EOFError as exc:
        raise RuntimeError(f"a child process ended while the tool waited for {what}") from exc
    if isinstance(message, tuple) and len(message) == 2 and isinstance(message[0], str):
        kind, payload = message
        if kind == "error":
            raise RuntimeError(f"{what}: {payload}")
        return payload
    return message


class Child:
    """A spawned process running ``target(conn, *args)``; a context manager that reaps it."""

    def __init__(self, name: str, target: Callable[..., None], *args: Any) -> None:
        ctx = _context()
        self.conn, child_end = ctx.Pipe()
        self.name = name
        self._process = ctx.Process(target=target, args=(child_end, *args), name=name)
        self._process.start()
        child_end.close()
        assert self._process.pid is not None
        self.pid: int = self._process.pid

    def __enter__(self) -> Child:
        return self

    def __exit__(self, *exc: object) -> None:
        self.finish()

    @property
    def alive(self) -> bool:
        return self._process.is_alive()

    def receive(self, timeout: float, what: str) -> Any:
        return receive(self.conn, timeout, f"{what} ({self.name})")

    def request(self, message: Any, timeout: float, what: str) -> Any:
        self.conn.send(message)
        return self.receive(timeout, what)

    def finish(self, stop_message: Any = "stop", timeout: float = 30.0) -> None:
        """Ask the child to stop (if alive), wait for it, terminate it if it does not end."""
        if self._process.is_alive():
            try:
                self.conn.send(stop_message)
                if self.conn.poll(timeout):
                    self.conn.recv()
            except (OSError, EOFError):
                pass
        self._process.join(timeout)
        if self._process.is_alive():
            self._process.terminate()
            self._process.join(10.0)
        self.conn.close()
