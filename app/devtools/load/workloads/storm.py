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

The phase (:func:`phase`) keeps ``storm_steady`` clients connected throughout, takes the
server's threads, RSS and live sessions as the baseline, storms, then gives the server up to
``settle_seconds`` to come back within the tolerance, and judges where it got.
"""

from __future__ import annotations

import collections
import dataclasses
import queue
import threading
import time
from multiprocessing.connection import Connection
from typing import Any

from poinsot.app.devtools.load import procfs
from poinsot.app.devtools.load.children import Child, answer_requests
from poinsot.app.devtools.load.config import MB, Config, Report, Say, fps_text, relative
from poinsot.app.devtools.load.figures import Figure, at_most, info
from poinsot.app.devtools.load.fleet import REDRAW_NODE, Fleet
from poinsot.app.devtools.load.raw import RawClient, camera_message, client_frame
from poinsot.app.devtools.load.server_process import ServerProcess

KINDS = ("clean", "early", "fin", "rst", "half")
WARMUP_VISITS = 3
#: The longest one visit may take before it is abandoned (each step has its own timeout).
VISIT_TIMEOUT = 30.0


def _visit(port: int, kind: str, index: int) -> None:
    from poinsot.app.devtools.probe import Probe

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


def _warm_up(port: int) -> tuple[str, int]:
    for i in range(WARMUP_VISITS):
        _visit(port, "clean", i)
    return ("warm", WARMUP_VISITS)


def _main(conn: Connection, port: int, count: int, workers: int, lifetime: float) -> None:
    answer_requests(
        conn, lifetime, lambda: _warm_up(port), "storm", lambda: _storm(port, count, workers)
    )


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


# -- the phase ----------------------------------------------------------------------------------
P = "storm"


@dataclasses.dataclass(frozen=True)
class _Look:
    """The server's threads and RSS (``/proc``) and its own status, at one moment."""

    usage: procfs.Usage
    status: dict[str, Any]

    @staticmethod
    def take(server: ServerProcess) -> _Look:
        return _Look(procfs.usage(server.pid), server.status())

    def deviations(self, baseline: _Look) -> tuple[float, float, float]:
        """|after / before - 1| of threads, RSS and live sessions."""
        return (
            relative(self.usage.threads, baseline.usage.threads),
            relative(self.usage.rss_bytes, baseline.usage.rss_bytes),
            relative(self.status["sessions"], baseline.status["sessions"]),
        )


def phase(server: ServerProcess, cfg: Config, report: Report, say: Say) -> None:
    steady = max(0, min(cfg.storm_steady, cfg.clients))
    say(f"storm: {steady} steady clients, warm-up visits")
    with (
        Fleet(server.port, steady, cfg.lifetime) as fleet,
        Storm(server.port, cfg.storm, cfg.storm_workers, cfg.lifetime) as visits,
    ):
        server.wait_for_sessions(steady, 30.0)
        time.sleep(2.0)
        before = _Look.take(server)
        say(f"storm: {cfg.storm} connects and departures ({', '.join(KINDS)})")
        result = visits.run()
        say(f"storm: settling (at most {cfg.settle_seconds:g} s)")
        after, waited = _settle(server, before, cfg)
        steady_window = fleet.window(min(2.0, cfg.settle_seconds)) if steady else None
    _add_visits(report, cfg, result)
    _add_return(report, before, after)
    report.add(info(P, "settle time", f"{waited:.1f} s (at most {cfg.settle_seconds:g} s)"))
    if steady_window is not None:
        report.add(
            info(
                P,
                f"the {steady} steady clients after",
                f"{fps_text(steady_window.fps)}, {steady_window.silent} silent",
                clients=len(steady_window.fps),
                silent=steady_window.silent,
            )
        )


def _settle(server: ServerProcess, before: _Look, cfg: Config) -> tuple[_Look, float]:
    """Look every half second until everything is back within the tolerance and every
    departed session's thread has ended, or the settle time is up; the last look and the
    seconds waited."""
    start = time.monotonic()
    while True:
        after = _Look.take(server)
        waited = time.monotonic() - start
        status = after.status
        departed = status["session_threads"] == status["sessions"]
        departed = departed and status["pending_departures"] == 0
        within = max(after.deviations(before)) <= cfg.settle_tolerance
        if (within and departed) or waited >= cfg.settle_seconds:
            return after, waited
        time.sleep(0.5)


def _add_visits(report: Report, cfg: Config, result: dict[str, Any]) -> None:
    done, failed = result["done"], result["failed"]
    report.add(
        info(
            P,
            "visits",
            f"{sum(done.values())} of {cfg.storm} done, {sum(failed.values())} failed, "
            f"{result['unfinished']} unfinished ("
            + ", ".join(f"{k} {done.get(k, 0)}" for k in KINDS)
            + ")",
            done=sum(done.values()),
            failed=sum(failed.values()),
            unfinished=result["unfinished"],
            **{f"done_{k}": done.get(k, 0) for k in KINDS},
        ),
    )
    report.notes.extend(f"storm: {reason}" for reason in result["reasons"])


def _add_return(report: Report, before: _Look, after: _Look) -> None:
    goal = at_most("storm_tolerance", "back within {:g} %", 100)
    threads, rss, sessions = after.deviations(before)
    b, a = before.usage, after.usage
    report.add(
        Figure(
            P,
            "server threads",
            threads,
            f"{b.threads} -> {a.threads}",
            goal,
            {"before": b.threads, "after": a.threads},
        ),
        Figure(
            P,
            "server RSS",
            rss,
            f"{b.rss_bytes / MB:.0f} -> {a.rss_bytes / MB:.0f} MB "
            f"({a.rss_bytes / b.rss_bytes - 1:+.1%})",
            goal,
        ),
        Figure(
            P,
            "live sessions",
            sessions,
            f"{before.status['sessions']} -> {after.status['sessions']} "
            f"(session threads {after.status['session_threads']}, "
            f"pending departures {after.status['pending_departures']})",
            goal,
            {
                "before": before.status["sessions"],
                "after": after.status["sessions"],
                "session_threads": after.status["session_threads"],
                "pending_departures": after.status["pending_departures"],
            },
        ),
    )
    changed = _thread_changes(before.status["threads"], after.status["threads"])
    if changed:
        report.notes.append(f"storm: server threads by kind, before -> after: {changed}")


def _thread_changes(before: dict[str, int], after: dict[str, int]) -> str:
    kinds = sorted(set(before) | set(after))
    return ", ".join(
        f"{k} {before.get(k, 0)} -> {after.get(k, 0)}"
        for k in kinds
        if before.get(k, 0) != after.get(k, 0)
    )
