"""One client that floods the server with messages, from a child process of its own.

A :class:`~poinsot.app.devtools.load.raw.RawClient` opens a websocket, sends its camera (it becomes
a client with a session of its own, and keeps reading what it is sent), and on ``go`` writes
viewer-camera messages, what a browser sends while the user orbits, at ``rate`` messages a
second for ``seconds``: bursts of pre-built frames every 10 ms, so the flooder's own cost stays
small next to the server's. When the server stops reading (its socket buffers are full) the
writes wait: the rate achieved is then the rate the server took.
"""

from __future__ import annotations

import bisect
import itertools
import time
from multiprocessing.connection import Connection
from typing import Any

from poinsot.app.devtools.load.children import Child, answer_requests
from poinsot.app.devtools.load.raw import RawClient, camera_message, client_frame

TICK = 0.01  # seconds between bursts
VARIANTS = 50  # distinct camera messages cycled through


def _flood(client: RawClient, rate: float, seconds: float) -> dict[str, Any]:
    per_tick = max(1, round(rate * TICK))
    variants = [client_frame(camera_message(i)) for i in range(VARIANTS)]
    frames = [variants[i % VARIANTS] for i in range(per_tick)]
    ends = list(itertools.accumulate(len(f) for f in frames))
    burst = b"".join(frames)
    start = time.monotonic()
    end = start + seconds
    sent = ticks = 0
    while (now := time.monotonic()) < end:
        due = start + ticks * TICK
        if now < due:
            time.sleep(due - now)
            continue
        ticks += 1
        # Blocks while the server does not read (its socket is full): the flood then goes at
        # the pace the server takes it, as a real client's would.
        written = client.send(burst, end)
        sent += bisect.bisect_right(ends, written)
        if written < len(burst):
            break  # the end came in the middle of a burst
    elapsed = time.monotonic() - start
    return {
        "sent": sent,
        "seconds": elapsed,
        "rate": sent / elapsed if elapsed > 0 else 0.0,
        "closed_by_server": client.closed_by_server,
    }


def _ready(client: RawClient) -> tuple[str, int]:
    """Connect, send the camera and wait until the session draws (messages keep coming after
    the initial scene)."""
    client.open()
    client.send(client_frame(camera_message()), time.monotonic() + 10.0)
    wait_until = time.monotonic() + 60.0
    while client.messages_received < 100 and time.monotonic() < wait_until:
        time.sleep(0.05)
    if client.messages_received < 100:
        raise TimeoutError("the flooding client's session never started drawing")
    return ("ready", client.messages_received)


def _main(conn: Connection, port: int, rate: float, seconds: float, lifetime: float) -> None:
    clients: list[RawClient] = []  # the one client, once it connected

    def ready() -> tuple[str, int]:
        clients.append(RawClient(port))
        return _ready(clients[0])

    def leave() -> None:
        for client in clients:
            client.drop()

    answer_requests(
        conn, lifetime, ready, "flood", lambda: _flood(clients[0], rate, seconds), leave=leave
    )


class Flooder(Child):
    def __init__(self, port: int, rate: float, seconds: float, lifetime: float):
        super().__init__("flooder", _main, port, rate, seconds, lifetime)
        self.seconds = seconds
        self.receive(90.0, "the flooding client to connect")

    def __enter__(self) -> Flooder:
        return self

    def begin(self) -> None:
        self.conn.send("go")

    def end(self) -> dict[str, Any]:
        """What was sent: ``sent`` (whole messages), ``seconds``, ``rate``,
        ``closed_by_server``."""
        result: dict[str, Any] = self.receive(self.seconds + 30.0, "the flood")
        return result
