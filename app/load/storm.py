"""A storm of connections and departures, from a child process of its own.

``count`` clients come and go through ``workers`` threads, taking in turn one of five ways:

- ``clean``: a probe connects, waits for its whole scene, and closes the websocket properly;
- ``early``: a probe connects and closes at once (its session is still being built);
- ``fin``: a raw client opens the websocket, sends its camera (so its session starts), reads
  for a while and closes the TCP socket without a websocket close;
- ``rst``: the same, but the socket is reset (SO_LINGER 0: what a pulled cable looks like
  once the kernel gives up);
- ``half``: a raw client sends half of the HTTP upgrade and closes.

The raw clients read for 0.1 to 1.45 s before dropping, so some leave while their session is
being built and most after it started drawing. Before the storm the child warms the server up
with a few clean visits (first-use imports and caches are not a leak).
"""

from __future__ import annotations

import collections
import queue
import threading
import time
from multiprocessing.connection import Connection
from typing import Any

from poinsot.app.load.children import Child
from poinsot.app.load.fleet import REDRAW_NODE
from poinsot.app.load.raw import RawClient, camera_message, client_frame

KINDS = ("clean", "early", "fin", "rst", "half")
WARMUP_VISITS = 5
#: The longest one visit may take before it is abandoned (each step has its own timeout).
VISIT_TIMEOUT = 30.0


def _visit(port: int, kind: str, index: int) -> None:
    from poinsot.app.live.probe import Probe

    if kind in ("clean", "early"):
        probe = Probe(port, keep_batches=False)
        try:
            if kind == "clean" and not probe.wait_for(lambda p: REDRAW_NODE in p.nodes, 20.0):
                raise TimeoutError("no scene within 20 s")
        finally:
            probe.close()
        return
    client = RawClient(port)
    if kind == "half":
        client.send_half_upgrade()
        client.drop()
        return
    try:
        client.open()
        client.send(client_frame(camera_message(index)), time.monotonic() + 10.0)
        time.sleep(0.1 + 0.15 * (index % 10))
    finally:
        client.drop(reset=kind == "rst")


def _storm(port: int, count: int, workers: int) -> dict[str, Any]:
    jobs: queue.SimpleQueue[tuple[int, str]] = queue.SimpleQueue()
    for i in range(count):
        jobs.put((i, KINDS[i % len(KINDS)]))
    done: collections.Counter[str] = collections.Counter()
    failed: collections.Counter[str] = collections.Counter()
    reasons: list[str] = []
    lock = threading.Lock()

    def work() -> None:
        while True:
            try:
                index, kind = jobs.get_nowait()
            except queue.Empty:
                return
            try:
                _visit(port, kind, index)
            except Exception as exc:
                with lock:
                    failed[kind] += 1
                    if len(reasons) < 5:
                        reasons.append(f"{kind}: {type(exc).__name__}: {exc}")
            else:
                with lock:
                    done[kind] += 1

    threads = [
        threading.Thread(target=work, name=f"load-storm-{k}", daemon=True) for k in range(workers)
    ]
    for t in threads:
        t.start()
    deadline = time.monotonic() + VISIT_TIMEOUT * (count / max(workers, 1) + 1)
    for t in threads:
        t.join(max(0.0, deadline - time.monotonic()))
    return {
        "done": dict(done),
        "failed": dict(failed),
        "unfinished": count - sum(done.values()) - sum(failed.values()),
        "reasons": reasons,
    }


def _main(conn: Connection, port: int, count: int, workers: int, lifetime: float) -> None:
    deadline = time.monotonic() + lifetime
    try:
        for i in range(WARMUP_VISITS):
            _visit(port, "clean", i)
        conn.send(("warm", WARMUP_VISITS))
        while time.monotonic() < deadline:
            if not conn.poll(0.5):
                continue
            request = conn.recv()
            if request == "go":
                conn.send(("storm", _storm(port, count, workers)))
            elif request == "stop":
                break
    except EOFError:
        return
    except Exception as exc:
        conn.send(("error", f"{type(exc).__name__}: {exc}"))
        return
    try:
        conn.send(("stopped", None))
    except OSError:
        pass


class Storm(Child):
    """The storm's child process: warms the server up on start, storms on :meth:`run`."""

    def __init__(self, port: int, count: int, workers: int, lifetime: float):
        super().__init__("storm", _main, port, count, workers, lifetime)
        self.count, self.workers = count, workers
        self.receive(WARMUP_VISITS * VISIT_TIMEOUT, "the warm-up visits")

    def __enter__(self) -> Storm:
        return self

    def run(self) -> dict[str, Any]:
        """Counts per kind: ``done``, ``failed``, ``unfinished`` and a few ``reasons``."""
        timeout = VISIT_TIMEOUT * (self.count / max(self.workers, 1) + 2)
        result: dict[str, Any] = self.request("go", timeout, "the storm")
        return result
