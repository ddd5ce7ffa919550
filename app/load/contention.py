"""Stall and flood: one client misbehaves; do the others keep their frame rate?

Both phases measure the others' frames for :data:`~poinsot.app.load.config.BEFORE_SECONDS`
first, then while client 0 stops reading (:func:`stall`) or while a raw client floods the
server with camera messages (:func:`flood`, see :mod:`poinsot.app.load.flood`), and judge the
worst of the others: its frame rate then, as a fraction of its own before.
"""

from __future__ import annotations

import math
import statistics
import time
from typing import Any

from poinsot.app.load import procfs
from poinsot.app.load.config import BEFORE_SECONDS, MB, Config, Report, Say, warmup
from poinsot.app.load.figures import Figure, at_least, info
from poinsot.app.load.fleet import Fleet, Window
from poinsot.app.load.flood import Flooder
from poinsot.app.load.server_process import ServerProcess


def _worst(before: Window, during: Window, others: list[int]) -> tuple[float, list[float]]:
    """The worst of the others' ratios during/before (NaN if one is unknown: no frames
    before), and the ratios that are known."""
    ratios = [during.fps[i] / before.fps[i] if before.fps[i] > 0 else math.nan for i in others]
    known = [r for r in ratios if not math.isnan(r)]
    return (min(known) if known and len(known) == len(ratios) else math.nan), known


def keep(
    phase: str, before: Window, windows: dict[str, Window], others: list[int], what: str
) -> Figure:
    """The others' frame rate in each window of ``what`` against their own before: the worst
    client in the worst window is judged."""
    worst = {label: _worst(before, w, others) for label, w in windows.items()}
    values = [w for w, _ in worst.values()]
    value = math.nan if not values or any(math.isnan(v) for v in values) else min(values)
    parts = [
        f"worst {w:.0%}, p50 {statistics.median(known) if known else math.nan:.0%} {label}"
        for label, (w, known) in worst.items()
    ]
    medians = [statistics.median([w.fps[i] for i in others]) for w in (before, *windows.values())]
    return Figure(
        phase,
        f"others' frame rate {what}",
        value,
        "; ".join(parts) + f" (p50 fps {' -> '.join(f'{m:.1f}' for m in medians)})",
        at_least("min_keep", "each >= {:g} % of before", 100),
        {"clients": len(others), "before_p50": medians[0]},
    )


def _fleet(server: ServerProcess, cfg: Config, sessions: int) -> Fleet:
    """The clients, once the server has ``sessions`` sessions."""
    fleet = Fleet(server.port, cfg.clients, cfg.lifetime)
    try:
        server.wait_for_sessions(sessions, 60.0)
    except BaseException:
        fleet.finish()
        raise
    return fleet


def stall(server: ServerProcess, cfg: Config, report: Report, say: Say) -> None:
    """Client 0 stops reading for ``stall_seconds``. Its kernel buffers and the server's
    socket absorb a few MB first (about 3 MB on this machine's loopback, half a minute of this
    scene); only then does the server's own send path back up, and a keepalive of 20 + 20 s
    runs out. So the stall is long by default, and its last third is judged on its own."""
    n, seconds = cfg.clients, cfg.stall_seconds
    reference, tail = min(BEFORE_SECONDS, seconds), seconds / 3.0
    say(f"stall: {n} clients; {reference:g} s before, {seconds:g} s with client 0 stalled")
    with _fleet(server, cfg, n) as fleet:
        time.sleep(warmup(seconds))
        before = fleet.window(reference)
        rss0 = procfs.usage(server.pid).rss_bytes
        fleet.stall(0)
        early = fleet.window(seconds - tail)
        late = fleet.window(tail)
        rss1 = procfs.usage(server.pid).rss_bytes
        fleet.stall(0, False)
        resumed = fleet.window(min(2.0, seconds))
        sessions = server.status()["sessions"]
    windows = {f"first {seconds - tail:.0f} s": early, f"last {tail:.0f} s": late}
    after = f"{resumed.fps[0]:.1f} fps (its backlog)" if resumed.fps[0] > 0 else "gone"
    report.add(
        keep("stall", before, windows, list(range(1, n)), "while one stalls"),
        info(
            "stall",
            "the stalled client",
            f"{late.fps[0]:.1f} fps late in the stall; after it: {after}; "
            f"{sessions} of {n} sessions live",
            late_fps=late.fps[0],
            resumed_fps=resumed.fps[0],
            sessions=sessions,
        ),
        info("stall", "server RSS", f"{rss0 / MB:.0f} -> {rss1 / MB:.0f} MB while stalled"),
    )


def flood(server: ServerProcess, cfg: Config, report: Report, say: Say) -> None:
    n, seconds = cfg.clients, cfg.flood_seconds
    say(f"flood: {n} clients and one flooding at {cfg.flood_rate:g} messages/s for {seconds:g} s")
    with (
        Flooder(server.port, cfg.flood_rate, seconds, cfg.lifetime) as flooder,
        _fleet(server, cfg, n + 1) as fleet,
    ):
        time.sleep(warmup(seconds))
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
        keep("flood", before, {"flooded": during}, list(range(n)), "during the flood"),
        info(
            "flood",
            "messages sent",
            f"{sent['sent']} camera messages in {sent['seconds']:.1f} s "
            f"({sent['rate']:.0f}/s of {cfg.flood_rate:g}/s)"
            + (f"; {', '.join(flags)}" if flags else ""),
            sent=sent["sent"],
            rate=sent["rate"],
        ),
        info(
            "flood",
            "server CPU",
            f"{procfs.cpu_percent(u0, u1):.0f} % before, {procfs.cpu_percent(u1, u2):.0f} % "
            f"during (of one core); {sessions} of {n + 1} sessions live after",
            sessions=sessions,
        ),
    )
