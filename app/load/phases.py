"""The four phases, run one by one, each against a fresh server child (its log judged too).

- ``soak`` (:mod:`poinsot.app.load.soak`): many clients for minutes;
- ``storm`` (:mod:`poinsot.app.load.storm`): connects and departures, clean and abrupt;
- ``stall``, ``flood`` (:mod:`poinsot.app.load.contention`): one client misbehaves.
"""

from __future__ import annotations

from collections.abc import Callable

from poinsot.app.load import contention, soak, storm
from poinsot.app.load.config import Config, Report, Say
from poinsot.app.load.figures import COMPLETES, Figure, at_most
from poinsot.app.load.server_process import ServerProcess

Phase = Callable[[ServerProcess, Config, Report, Say], None]
BODIES: dict[str, Phase] = {
    "soak": soak.phase,
    "storm": storm.phase,
    "stall": contention.stall,
    "flood": contention.flood,
}
PHASES = tuple(BODIES)


def run_phase(name: str, cfg: Config, report: Report, say: Say) -> None:
    """Run one phase with a server child of its own. A phase that fails (a child that does
    not start, clients that never get their scene) misses its "completed" goal; the server's
    log is read in every case, and judged in the soak."""
    try:
        server = ServerProcess(cfg.lifetime)
    except Exception as exc:
        report.add(Figure(name, "completed", 0.0, f"failed: {exc}", COMPLETES))
        return
    try:
        say(f"{name}: server pid {server.pid}, port {server.port}")
        BODIES[name](server, cfg, report, say)
    except Exception as exc:
        failure = f"failed: {type(exc).__name__}: {exc}"
        report.add(Figure(name, "completed", 0.0, failure, COMPLETES))
    finally:
        server.finish()
    lines = server.log_errors()
    goal = at_most("max_errors", "<= {:g} lines") if name == "soak" else None
    text = f"{len(lines)} lines (log kept: {server.log_path})" if lines else "none"
    if lines:
        report.notes.append(f"{name}: the server log's first error lines:")
        report.notes.extend(f"    {line[:160]}" for line in lines[:5])
    else:
        server.remove_log()
    report.add(Figure(name, "server log errors", float(len(lines)), text, goal))
