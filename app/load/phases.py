"""The four phases. Each starts a fresh server child, its clients in other processes, measures,
stops everything it started, and adds its figures (and notes) to the :class:`Report`.

- :func:`soak`: ``clients`` clients for ``seconds``: frames per client, slider-to-redraw, the
  server's CPU, memory and threads over time, errors;
- :func:`storm`: ``storm`` connects and departures (see :mod:`poinsot.app.load.storm`) beside
  a few steady clients; then threads, memory and live sessions against the baseline;
- :func:`stall`: one client stops reading; the others' frame rate against their own before;
- :func:`flood`: one client sends ``flood_rate`` messages a second; the same comparison.
"""

from __future__ import annotations

import dataclasses
import math
import statistics
import time
from collections.abc import Callable
from typing import Any

from poinsot.app.load import procfs
from poinsot.app.load.figures import (
    COMPLETES,
    Figure,
    at_least,
    at_most,
    info,
    percentile,
)
from poinsot.app.load.fleet import Fleet, Window
from poinsot.app.load.flood import Flooder
from poinsot.app.load.server_process import ServerProcess
from poinsot.app.load.storm import KINDS, Storm

PHASES = ("soak", "storm", "stall", "flood")
#: Seconds every child may outlive its phase's own length before it stops by itself.
SPARE_LIFETIME = 600.0
#: Pause after the clients connected, before anything is measured (the connection burst).
WARMUP_SECONDS = 5.0
#: The others' frame rate is measured for this long before a stall or a flood.
BEFORE_SECONDS = 15.0

MB = 1e6
Say = Callable[[str], None]


@dataclasses.dataclass(frozen=True)
class Config:
    clients: int = 30
    seconds: float = 300.0  # the soak
    slider_period: float = 1.0  # a slider move every this many seconds during the soak
    storm: int = 200
    storm_workers: int = 8
    storm_steady: int = 3  # clients that stay connected through the storm
    settle_seconds: float = 30.0
    settle_tolerance: float = 0.10  # the settling ends early once everything is this close
    stall_seconds: float = 45.0  # client 0 stalled
    flood_seconds: float = 20.0  # flooding
    flood_rate: float = 10_000.0


@dataclasses.dataclass
class Report:
    figures: list[Figure] = dataclasses.field(default_factory=list)
    notes: list[str] = dataclasses.field(default_factory=list)

    def add(self, *figures: Figure) -> None:
        self.figures.extend(figures)


def _warmup(cfg_seconds: float) -> float:
    return min(WARMUP_SECONDS, 0.2 * cfg_seconds)


def _relative(after: float, before: float) -> float:
    """|after / before - 1|; for a zero baseline 0 when equal, else infinite."""
    if before == 0:
        return 0.0 if after == 0 else math.inf
    return abs(after / before - 1.0)


def _fps_text(values: list[float]) -> str:
    if not values:
        return "no clients"
    return f"p50 {statistics.median(values):.1f}, min {min(values):.1f} fps"


def _worst(before: Window, during: Window, others: list[int]) -> tuple[float, list[float]]:
    """The worst of the others' frame rate ratios during/before (NaN if any is unknown), and
    the ratios that are known."""
    ratios = [during.fps[i] / before.fps[i] if before.fps[i] > 0 else math.nan for i in others]
    known = [r for r in ratios if not math.isnan(r)]
    return (min(known) if known and len(known) == len(ratios) else math.nan), known


def _keep(
    phase: str, before: Window, windows: dict[str, Window], others: list[int], what: str
) -> Figure:
    """The others' frame rate in each window of ``what`` against their own before: the worst
    client in the worst window is judged."""
    worst = {label: _worst(before, w, others) for label, w in windows.items()}
    value = min((w for w, _ in worst.values()), default=math.nan)
    if any(math.isnan(w) for w, _ in worst.values()):
        value = math.nan
    parts = [
        f"worst {w:.0%}, p50 {statistics.median(known) if known else math.nan:.0%} {label}"
        for label, (w, known) in worst.items()
    ]
    rates = " -> ".join(
        f"{statistics.median([w.fps[i] for i in others]):.1f}" for w in (before, *windows.values())
    )
    return Figure(
        phase,
        f"others' frame rate {what}",
        value,
        "; ".join(parts) + f" (p50 fps {rates})",
        at_least("min_keep", "each >= {:g} % of before", 100),
    )


def run_phase(name: str, cfg: Config, report: Report, say: Say) -> None:
    """Run one phase with its own server child; a phase that fails misses "completed"; the
    server's log is judged in every case."""
    body = {"soak": soak, "storm": storm, "stall": stall, "flood": flood}[name]
    lifetime = cfg.seconds + cfg.stall_seconds + cfg.flood_seconds + SPARE_LIFETIME
    try:
        server = ServerProcess(lifetime)
    except Exception as exc:
        report.add(Figure(name, "completed", 0.0, f"failed: {exc}", COMPLETES))
        return
    try:
        say(f"{name}: server pid {server.pid}, port {server.port}")
        body(server, cfg, report, say, lifetime)
    except Exception as exc:
        failure = f"failed: {type(exc).__name__}: {exc}"
        report.add(Figure(name, "completed", 0.0, failure, COMPLETES))
    finally:
        server.finish()
    lines = server.log_errors()
    goal = at_most("max_errors", "<= {:g} lines") if name == "soak" else None
    text = f"{len(lines)} lines" if lines else "none"
    if lines:
        text += f" (log: {server.log_path})"
        report.notes.append(f"{name}: server log, first error lines:")
        report.notes.extend(f"    {line[:160]}" for line in lines[:5])
    else:
        server.remove_log()
    report.add(Figure(name, "server log errors", float(len(lines)), text, goal))


# -- soak ---------------------------------------------------------------------------------------
def soak(server: ServerProcess, cfg: Config, report: Report, say: Say, lifetime: float) -> None:
    n = cfg.clients
    say(f"soak: connecting {n} clients")
    with Fleet(server.port, n, lifetime) as fleet:
        server.wait_for_sessions(n, 60.0)
        time.sleep(_warmup(cfg.seconds))
        say(f"soak: measuring for {cfg.seconds:g} s (client pid {fleet.pid})")
        interval = min(1.0, max(0.1, cfg.seconds / 10.0))
        status0, t0 = server.status(), time.monotonic()
        min_sessions = status0["sessions"]
        with procfs.Sampler({"server": server.pid, "clients": fleet.pid}, interval) as sampler:
            fleet.begin_window(cfg.seconds, cfg.slider_period)
            deadline = time.monotonic() + cfg.seconds + 120.0
            while not fleet.conn.poll(min(5.0, interval * 5)) and time.monotonic() < deadline:
                min_sessions = min(min_sessions, server.status()["sessions"])
            window = fleet.end_window()
        status1, t1 = server.status(), time.monotonic()
    min_sessions = min(min_sessions, status1["sessions"])
    drawn = (status1["frames"] - status0["frames"]) / (n * (t1 - t0))
    fps = window.fps
    report.add(
        info("soak", "fps per client, p5", f"{percentile(fps, 0.05):.1f}"),
        info("soak", "fps per client, p50", f"{statistics.median(fps):.1f}"),
        Figure(
            "soak",
            f"fps per client, each of {n}",
            min(fps),
            f"min {min(fps):.1f}",
            at_least("min_fps", ">= {:g} fps"),
        ),
        info("soak", "frames drawn by the server", f"{drawn:.1f} per client per second"),
    )
    report.add(_redraw_figure(window))
    _add_usage(report, sampler, window.seconds)
    report.add(
        Figure(
            "soak",
            "clients gone silent",
            float(window.silent),
            str(window.silent),
            at_most("max_errors", "<= {:g}"),
        ),
        Figure(
            "soak",
            "sessions lost (server side)",
            float(n - min_sessions),
            f"{n - min_sessions} (fewest live: {min_sessions} of {n})",
            at_most("max_errors", "<= {:g}"),
        ),
    )


def _redraw_figure(window: Window) -> Figure:
    lat = sorted(window.latencies) + [math.inf] * window.lost_redraws
    p95 = 1e3 * percentile(lat, 0.95)
    text = (
        f"p95 {p95:.0f} ms, p50 {1e3 * percentile(lat, 0.5):.0f} ms "
        f"({len(window.latencies)} moves, {window.lost_redraws} lost)"
    )
    return Figure("soak", "slider-to-redraw", p95, text, at_most("max_redraw_ms", "<= {:g} ms"))


def _add_usage(report: Report, sampler: procfs.Sampler, seconds: float) -> None:
    server = sampler.samples["server"]
    cpu = sampler.cpu_percents("server")
    clients = sampler.samples["clients"]
    span = max(0.1 * seconds, 2.0 * sampler.interval)
    early = [u.rss_bytes for u in server if u.at - server[0].at <= span]
    late = [u.rss_bytes for u in server if server[-1].at - u.at <= span]
    rss0, rss1 = statistics.median(early), statistics.median(late)
    growth = rss1 / rss0 - 1.0
    report.add(
        info(
            "soak",
            "server CPU",
            f"mean {procfs.cpu_percent(server[0], server[-1]):.0f} %, "
            f"max {max(cpu, default=math.nan):.0f} % of one core",
        ),
        Figure(
            "soak",
            "server RSS",
            growth,
            f"{rss0 / MB:.0f} -> {rss1 / MB:.0f} MB ({growth:+.1%}; "
            f"max {max(u.rss_bytes for u in server) / MB:.0f} MB)",
            at_most("max_rss_growth", "flat, <= +{:g} %", 100),
        ),
        info("soak", "server threads", f"{server[0].threads} -> {server[-1].threads}"),
        info(
            "soak",
            "client process CPU",
            f"mean {procfs.cpu_percent(clients[0], clients[-1]):.0f} % of one core "
            "(decoding every message)",
        ),
    )


# -- storm --------------------------------------------------------------------------------------
def storm(server: ServerProcess, cfg: Config, report: Report, say: Say, lifetime: float) -> None:
    steady = max(0, min(cfg.storm_steady, cfg.clients))
    say(f"storm: {steady} steady clients, warm-up visits")
    with (
        Fleet(server.port, steady, lifetime) as fleet,
        Storm(server.port, cfg.storm, cfg.storm_workers, lifetime) as visits,
    ):
        server.wait_for_sessions(steady, 30.0)
        time.sleep(2.0)
        before, status0 = procfs.usage(server.pid), server.status()
        say(f"storm: {cfg.storm} connects and departures ({', '.join(KINDS)})")
        result = visits.run()
        say(f"storm: settling (at most {cfg.settle_seconds:g} s)")
        start = time.monotonic()
        while True:
            after, status1 = procfs.usage(server.pid), server.status()
            deviations = (
                _relative(after.threads, before.threads),
                _relative(after.rss_bytes, before.rss_bytes),
                _relative(status1["sessions"], status0["sessions"]),
            )
            waited = time.monotonic() - start
            if max(deviations) <= cfg.settle_tolerance or waited >= cfg.settle_seconds:
                break
            time.sleep(0.5)
        steady_window = fleet.window(min(2.0, cfg.settle_seconds)) if steady else None
    done, failed = result["done"], result["failed"]
    report.add(
        info(
            "storm",
            "visits",
            f"{sum(done.values())} of {cfg.storm} done, {sum(failed.values())} failed, "
            f"{result['unfinished']} unfinished ("
            + ", ".join(f"{k} {done.get(k, 0)}" for k in KINDS)
            + ")",
        ),
    )
    report.notes.extend(f"storm: {reason}" for reason in result["reasons"])
    goal = at_most("storm_tolerance", "back within {:g} %", 100)
    report.add(
        Figure(
            "storm",
            "server threads",
            deviations[0],
            f"{before.threads} -> {after.threads}",
            goal,
        ),
        Figure(
            "storm",
            "server RSS",
            deviations[1],
            f"{before.rss_bytes / MB:.0f} -> {after.rss_bytes / MB:.0f} MB "
            f"({after.rss_bytes / before.rss_bytes - 1:+.1%})",
            goal,
        ),
        Figure(
            "storm",
            "live sessions",
            deviations[2],
            f"{status0['sessions']} -> {status1['sessions']} "
            f"(session threads {status1['session_threads']}, "
            f"pending departures {status1['pending_departures']})",
            goal,
        ),
        info("storm", "settle time", f"{waited:.1f} s (at most {cfg.settle_seconds:g} s)"),
    )
    changed = _thread_changes(status0["threads"], status1["threads"])
    if changed:
        report.notes.append(f"storm: server threads by kind, before -> after: {changed}")
    if steady_window is not None:
        report.add(
            info(
                "storm",
                f"the {steady} steady clients after",
                f"{_fps_text(steady_window.fps)}, {steady_window.silent} silent",
            )
        )


def _thread_changes(before: dict[str, int], after: dict[str, int]) -> str:
    kinds = sorted(set(before) | set(after))
    return ", ".join(
        f"{k} {before.get(k, 0)} -> {after.get(k, 0)}"
        for k in kinds
        if before.get(k, 0) != after.get(k, 0)
    )


# -- stall and flood ----------------------------------------------------------------------------
def _connected_fleet(server: ServerProcess, cfg: Config, lifetime: float, extra: int = 0) -> Fleet:
    fleet = Fleet(server.port, cfg.clients, lifetime)
    server.wait_for_sessions(cfg.clients + extra, 60.0)
    return fleet


def stall(server: ServerProcess, cfg: Config, report: Report, say: Say, lifetime: float) -> None:
    """Client 0 stops reading for ``stall_seconds``. Its kernel buffers and the server's
    socket absorb a few MB first (about 3 MB on this machine's loopback, half a minute of this
    scene); only then does the server's own send path back up, and a keepalive of 20 + 20 s
    runs out. So the stall is long by default, and its last third is judged on its own."""
    n, seconds = cfg.clients, cfg.stall_seconds
    reference = min(BEFORE_SECONDS, seconds)
    tail = seconds / 3.0
    say(f"stall: {n} clients; {reference:g} s before, {seconds:g} s with client 0 stalled")
    with _connected_fleet(server, cfg, lifetime) as fleet:
        time.sleep(_warmup(seconds))
        before = fleet.window(reference)
        rss0 = procfs.usage(server.pid).rss_bytes
        fleet.stall(0)
        early = fleet.window(seconds - tail)
        late = fleet.window(tail)
        rss1 = procfs.usage(server.pid).rss_bytes
        fleet.stall(0, False)
        resumed = fleet.window(min(3.0, seconds))
        sessions = server.status()["sessions"]
    windows = {f"first {seconds - tail:.0f} s": early, f"last {tail:.0f} s": late}
    report.add(
        _keep("stall", before, windows, list(range(1, n)), "while one stalls"),
        info(
            "stall",
            "the stalled client",
            f"{late.fps[0]:.1f} fps late in the stall; after it: "
            + (f"{resumed.fps[0]:.1f} fps (its backlog)" if resumed.fps[0] > 0 else "gone")
            + f"; {sessions} of {n} sessions live",
        ),
        info("stall", "server RSS", f"{rss0 / MB:.0f} -> {rss1 / MB:.0f} MB while stalled"),
    )


def flood(server: ServerProcess, cfg: Config, report: Report, say: Say, lifetime: float) -> None:
    n, seconds = cfg.clients, cfg.flood_seconds
    say(f"flood: {n} clients and one flooding at {cfg.flood_rate:g} messages/s for {seconds:g} s")
    with Flooder(server.port, cfg.flood_rate, seconds, lifetime) as flooder:
        with _connected_fleet(server, cfg, lifetime, extra=1) as fleet:
            time.sleep(_warmup(seconds))
            u0 = procfs.usage(server.pid)
            before = fleet.window(min(BEFORE_SECONDS, seconds))
            u1 = procfs.usage(server.pid)
            flooder.begin()
            during = fleet.window(seconds)
            u2 = procfs.usage(server.pid)
            sent: dict[str, Any] = flooder.end()
            sessions = server.status()["sessions"]
    flags = [k for k in ("cut", "closed_by_server") if sent[k]]
    report.add(
        _keep("flood", before, {"flooded": during}, list(range(n)), "during the flood"),
        info(
            "flood",
            "messages sent",
            f"{sent['sent']} camera messages in {sent['seconds']:.1f} s "
            f"({sent['rate']:.0f}/s of {cfg.flood_rate:g}/s)"
            + (f"; {', '.join(flags)}" if flags else ""),
        ),
        info(
            "flood",
            "server CPU",
            f"{procfs.cpu_percent(u0, u1):.0f} % before, {procfs.cpu_percent(u1, u2):.0f} % "
            f"during (of one core); {sessions} of {n + 1} sessions live after",
        ),
    )
