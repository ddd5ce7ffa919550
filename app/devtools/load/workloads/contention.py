"""Stall and flood: one client misbehaves; do the others keep their frame rate?

Both phases measure the others' frames for ``REFERENCE_SECONDS`` before, then while client 0
stops reading (:func:`stall`) or while a raw client floods the server with camera messages
(:func:`flood`, see :mod:`poinsot.app.devtools.load.workloads.flood`), then ``REFERENCE_SECONDS``
after. Each client's reference is the mean of its before and after: on a shared machine a change in
the other load lands in both, the misbehaving client only in the middle. The worst client is
judged, its frame rate during as a fraction of its reference; the p50 of before, during and
after is shown, so a lasting loss shows too.
"""

from __future__ import annotations

import math
import statistics
import time
from typing import Any

from poinsot.app.devtools.load import procfs
from poinsot.app.devtools.load.config import MB, Config, Report, Say, warmup
from poinsot.app.devtools.load.figures import Figure, at_least, info
from poinsot.app.devtools.load.fleet import Fleet, Window
from poinsot.app.devtools.load.server_process import ServerProcess
from poinsot.app.devtools.load.workloads.flood import Flooder

#: The others' frame rate is measured for this long before and after a stall or a flood.
REFERENCE_SECONDS = 10.0
#: After a flood, the server first works through what its socket still holds.
AFTER_FLOOD_PAUSE = 2.0


def _ratios(before: Window, during: Window, after: Window, others: list[int]) -> list[float]:
    """Each client's frames during against the mean of before and after (NaN: no frames in
    either)."""
    out = []
    for i in others:
        reference = 0.5 * (before.fps[i] + after.fps[i])
        out.append(during.fps[i] / reference if reference > 0 else math.nan)
    return out


def keep(
    phase: str,
    before: Window,
    during: dict[str, Window],
    after: Window,
    others: list[int],
    what: str,
) -> Figure:
    """The others' frame rate in each window ``during`` against their reference: the worst
    client in the worst window is judged (NaN, so missed, if a client had no reference)."""
    worst: dict[str, tuple[float, float]] = {}
    for label, window in during.items():
        ratios = _ratios(before, window, after, others)
        known = [r for r in ratios if not math.isnan(r)]
        low = min(ratios) if ratios and len(known) == len(ratios) else math.nan
        worst[label] = (low, statistics.median(known) if known else math.nan)
    lows = [low for low, _ in worst.values()]
    value = math.nan if not lows or any(math.isnan(x) for x in lows) else min(lows)
    parts = [f"worst {low:.0%}, p50 {p50:.0%} {label}" for label, (low, p50) in worst.items()]
    windows = (before, *during.values(), after)
    medians = [statistics.median([w.fps[i] for i in others]) for w in windows]
    return Figure(
        phase,
        f"others' frame rate {what}",
        value,
        "; ".join(parts) + f" (p50 fps {' -> '.join(f'{m:.1f}' for m in medians)})",
        at_least("min_keep", "each >= {:g} % of before/after", 100),
        {"clients": len(others), "before_p50": medians[0], "after_p50": medians[-1]},
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
    reference, tail = min(REFERENCE_SECONDS, seconds), seconds / 3.0
    say(f"stall: {n} clients, client 0 stalls for {seconds:g} s ({reference:g} s either side)")
    with _fleet(server, cfg, n) as fleet:
        time.sleep(warmup(seconds))
        before = fleet.window(reference)
        rss0 = procfs.usage(server.pid).rss_bytes
        fleet.stall(0)
        early = fleet.window(seconds - tail)
        late = fleet.window(tail)
        rss1 = procfs.usage(server.pid).rss_bytes
        fleet.stall(0, False)
        after = fleet.window(reference)
        sessions = server.status()["sessions"]
    during = {f"first {seconds - tail:.0f} s": early, f"last {tail:.0f} s": late}
    resumed = f"{after.fps[0]:.1f} fps (its backlog first)" if after.fps[0] > 0 else "gone"
    report.add(
        keep("stall", before, during, after, list(range(1, n)), "while one stalls"),
        info(
            "stall",
            "the stalled client",
            f"{late.fps[0]:.1f} fps late in the stall; after it: {resumed}; "
            f"{sessions} of {n} sessions live",
            late_fps=late.fps[0],
            after_fps=after.fps[0],
            sessions=sessions,
        ),
        info("stall", "server RSS", f"{rss0 / MB:.0f} -> {rss1 / MB:.0f} MB while stalled"),
    )


def flood(server: ServerProcess, cfg: Config, report: Report, say: Say) -> None:
    n, seconds = cfg.clients, cfg.flood_seconds
    reference = min(REFERENCE_SECONDS, seconds)
    say(f"flood: {n} clients, one floods at {cfg.flood_rate:g} messages/s for {seconds:g} s")
    with (
        Flooder(server.port, cfg.flood_rate, seconds, cfg.lifetime) as flooder,
        _fleet(server, cfg, n + 1) as fleet,
    ):
        time.sleep(warmup(seconds))
        u0 = procfs.usage(server.pid)
        before = fleet.window(reference)
        u1 = procfs.usage(server.pid)
        flooder.begin()
        during = fleet.window(seconds)
        u2 = procfs.usage(server.pid)
        sent: dict[str, Any] = flooder.end()
        time.sleep(min(AFTER_FLOOD_PAUSE, reference))
        after = fleet.window(reference)
        # A flooder the server has cut off leaves within a second of it.
        cut = server.status()["disconnected"]
        sessions = server.wait_for_sessions(n + 1 - cut, 10.0)
    gone = "; the server closed it" if sent["closed_by_server"] else ""
    report.add(
        keep("flood", before, {"flooded": during}, after, list(range(n)), "during the flood"),
        info(
            "flood",
            "messages sent",
            f"{sent['sent']} camera messages in {sent['seconds']:.1f} s "
            f"({sent['rate']:.0f}/s of {cfg.flood_rate:g}/s){gone}",
            sent=sent["sent"],
            rate=sent["rate"],
        ),
        info(
            "flood",
            "server CPU",
            f"{procfs.cpu_percent(u0, u1):.0f} % before, {procfs.cpu_percent(u1, u2):.0f} % "
            f"during (of one core); {sessions} of {n + 1} sessions live after"
            f" ({cut} cut off)",
            sessions=sessions,
            disconnected=cut,
        ),
    )
