"""The drag rows of ``poinsot benchmark``: from a browser's drag update on the ellipsoid to the
polhode through the pointed start arriving at that browser
(:mod:`poinsot.app.live.pointing.pointer`).

The server runs as ``poinsot serve --workers N`` does (:mod:`poinsot.app.live.workers`), on
loopback; the clients are :class:`~poinsot.app.devtools.probe.Probe` websockets in this
process, one thread each, that all drag at once, each update sent when the last one's polhode has
come (viser sends a dragging browser's updates at about 20 Hz: :data:`PAUSE` between them). Each
round trip is timed by the client, from sending the update to receiving the drawn polhode:
the ray met with the ellipsoid, the body of the start built, its polhode evaluated, sent and
decoded. Goals: p95 <= 50 ms with one client, <= 100 ms with ten on two workers.

Each row also gives the server's share, as the workers measured it
(:attr:`~poinsot.app.live.pointing.pointer.StartPointer.server_seconds`): from the update's arrival
on viser's event loop to its polhode handed to the socket. The rest of a round trip is the
network, the probe's decoding and, on a busy machine, waiting for a core. An update answered by
nothing is counted apart: a start whose polhode is the one drawn already (two starts snapped
onto the same separatrix arc) changes nothing, and viser sends nothing.

``poinsot benchmark --drag`` runs these rows alone.
"""

from __future__ import annotations

import dataclasses
import math
import statistics
import threading
import time
from typing import TYPE_CHECKING

from poinsot.app.devtools.probe import Probe
from poinsot.app.live.workers import start_workers, stop_workers
from poinsot.app.model.presets import DEFAULT_PRESET

if TYPE_CHECKING:
    from poinsot.app.live.server import PoinsotApp

#: The drag rows: (clients, workers, goal for the p95 [ms]).
ROWS: tuple[tuple[int, int, float], ...] = ((1, 1, 50.0), (10, 2, 100.0))
#: The node dragged, and the one its polhode is drawn in.
ELLIPSOID = "/space/body/ellipsoid"
PREVIEW = "/space/body/pointed_polhode"
#: Between two updates of one drag [s] (viser throttles a drag's pointer moves to ~20 Hz).
PAUSE = 0.05
#: A round trip that takes longer than this is counted as lost [s].
TIMEOUT = 5.0


@dataclasses.dataclass(frozen=True)
class DragResult:
    clients: int
    workers: int
    goal_ms: float
    latencies: tuple[float, ...]  # seconds, client round trips
    unanswered: int
    server: tuple[float, ...] = ()  # seconds, arrival to sent, as the workers measured

    @property
    def median_ms(self) -> float:
        return 1e3 * statistics.median(self.latencies) if self.latencies else math.nan

    @property
    def p95_ms(self) -> float:
        return p95_ms(self.latencies)

    @property
    def server_p95_ms(self) -> float:
        return p95_ms(self.server)


def p95_ms(seconds: tuple[float, ...]) -> float:
    """The 95th percentile of ``seconds``, in ms (NaN for none)."""
    if not seconds:
        return math.nan
    ordered = sorted(seconds)
    return 1e3 * ordered[min(len(ordered) - 1, round(0.95 * (len(ordered) - 1)))]


def server_times(app: PoinsotApp) -> list[float]:
    """In a worker: the server's time of every drag update its sessions answered [s]."""
    return [x for session in app.sessions().values() for x in session.pointer.server_seconds]


def pointer_at(k: int) -> tuple[float, float, float]:
    """The k-th pointer position of a drag: a small circle round the ellipsoid's centre, so
    that every ray from the probe's camera meets the ellipsoid at another start."""
    a = 0.37 * k
    return (0.25 * math.cos(a), 0.25 * math.sin(a), 0.1)


def drag_round_trips(probe: Probe, updates: int) -> tuple[list[float], int]:
    """One drag of ``updates`` updates by ``probe``; the round trips [s] and the updates
    answered by nothing within :data:`TIMEOUT`."""
    arrived = threading.Event()
    probe.add_listener(lambda m, _t: arrived.set() if m.get("name") == PREVIEW else None)
    latencies: list[float] = []
    unanswered = 0
    for k in range(updates + 1):
        arrived.clear()
        sent = time.perf_counter()
        probe.drag(ELLIPSOID, "start" if k == 0 else "update", pointer_at(k))
        if arrived.wait(TIMEOUT):
            if k > 0:  # the start's polhode also creates the node: not timed
                latencies.append(time.perf_counter() - sent)
        else:
            unanswered += 1
        time.sleep(PAUSE)
    probe.drag(ELLIPSOID, "end", pointer_at(updates))
    return latencies, unanswered


#: Updates in all of a row (at least :data:`MIN_UPDATES` for each client): enough that its
#: p95 is not one of the few slowest samples.
ROW_UPDATES = 200
MIN_UPDATES = 40


def run_drag(clients: int, workers: int, goal_ms: float, updates: int | None = None) -> DragResult:
    """Start ``workers`` servers, connect ``clients`` probes to them in turn, and let all drag
    at once, ``updates`` each (:data:`ROW_UPDATES` shared out if None)."""
    if updates is None:
        updates = max(MIN_UPDATES, ROW_UPDATES // clients)
    each = updates
    servers = start_workers(workers, "127.0.0.1", 0, DEFAULT_PRESET.key, None)
    probes: list[Probe] = []
    try:
        probes = [Probe(servers[i % workers].port) for i in range(clients)]
        for probe in probes:
            if not probe.wait_for(
                lambda p: bool(ELLIPSOID in p.nodes and p.nodes[ELLIPSOID].owner), 30
            ):
                raise RuntimeError("a client never received the ellipsoid")
            probe.wait_frames(10)
        results: list[tuple[list[float], int]] = [([], 0)] * clients

        def drag(i: int) -> None:
            results[i] = drag_round_trips(probes[i], each)

        threads = [threading.Thread(target=drag, args=(i,)) for i in range(clients)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        server = tuple(x for worker in servers for x in worker.inspect(server_times))
    finally:
        for probe in probes:
            probe.close()
        stop_workers(servers)
    latencies = tuple(x for r in results for x in r[0])
    return DragResult(clients, workers, goal_ms, latencies, sum(r[1] for r in results), server)


def format_drag(r: DragResult) -> str:
    return (
        f"drag update, {r.clients} client{'s' if r.clients > 1 else ''} on {r.workers} "
        f"worker{'s' if r.workers > 1 else ''}: ray to polhode drawn median {r.median_ms:.1f} ms, "
        f"p95 {r.p95_ms:.1f} ms   (goal <= {r.goal_ms:.0f} ms; {len(r.latencies)} updates, "
        f"{r.unanswered} unanswered; server's share p95 {r.server_p95_ms:.1f} ms)"
    )


def main() -> None:
    """Print the drag rows."""
    for clients, workers, goal in ROWS:
        print(format_drag(run_drag(clients, workers, goal)), flush=True)
