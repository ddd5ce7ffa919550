"""The five phases, run one by one, each against a fresh server child (its log judged too).

- ``soak`` (:mod:`poinsot.app.devtools.load.workloads.soak`): many clients for minutes;
- ``storm`` (:mod:`poinsot.app.devtools.load.workloads.storm`): connects and departures, clean and
abrupt;
- ``stall``, ``flood`` (:mod:`poinsot.app.devtools.load.workloads.contention`): one client
misbehaves;
- ``hostile`` (:mod:`poinsot.app.devtools.load.workloads.hostile`): crafted messages, handshakes and
inputs;
- ``follow`` (:mod:`poinsot.app.devtools.load.workloads.following`, on request): a lead and its
followers; with ``--hosts 2`` (:mod:`poinsot.app.devtools.load.workloads.hosts`) on two hosts
linked by Redis behind nginx.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable
from typing import Any

from poinsot.app.devtools.load import procfs
from poinsot.app.devtools.load.config import Config, Report, Say, server_processes
from poinsot.app.devtools.load.figures import COMPLETES, Figure, at_most, info
from poinsot.app.devtools.load.server_process import ServerProcess
from poinsot.app.devtools.load.workloads import contention, following, hostile, soak, storm
from poinsot.app.devtools.load.workloads.hosts import Classroom
from poinsot.app.devtools.load.workloads.hosts import phase as hosts_phase

Phase = Callable[[ServerProcess, Config, Report, Say], None]
BODIES: dict[str, Phase] = {
    "soak": soak.phase,
    "storm": storm.phase,
    "stall": contention.stall,
    "flood": contention.flood,
    "hostile": hostile.phase,
    "follow": following.phase,
}
#: The phases ``make load`` runs by default; every phase that can be asked for.
PHASES = ("soak", "storm", "stall", "flood", "hostile")
ALL_PHASES = tuple(BODIES)


def run_phase(name: str, cfg: Config, report: Report, say: Say) -> None:
    """Run one phase with a server child of its own. A phase that fails (a child that does
    not start, clients that never get their scene) misses its "completed" goal; the server's
    log is read in every case, and judged in the soak."""
    hosts = name == "follow" and cfg.hosts > 1
    server: Any
    try:
        if hosts:  # a classroom of hosts linked by Redis, behind nginx
            server = Classroom(cfg.hosts, cfg.lifetime)
        else:
            server = ServerProcess(cfg.lifetime, workers=server_processes(cfg, name))
    except Exception as exc:
        report.add(Figure(name, "completed", 0.0, f"failed: {exc}", COMPLETES))
        return
    machine, load, started = procfs.Machine.now(), os.getloadavg()[0], time.monotonic()
    pids = [server.pid, *server.worker_pids]
    server_cpu = _cpu_seconds(pids)
    try:
        say(f"{name}: server pid {server.pid}, port {server.port}")
        (hosts_phase if hosts else BODIES[name])(server, cfg, report, say)
    except Exception as exc:
        failure = f"failed: {type(exc).__name__}: {exc}"
        report.add(Figure(name, "completed", 0.0, failure, COMPLETES))
        report.notes.append(f"{name} failed; the server log's last lines:")
        report.notes.extend(f"    {line[:200]}" for line in server.log_tail(8))
    finally:
        server_cpu = _cpu_seconds(pids) - server_cpu
        report.add(_machine(name, machine, load, server_cpu, time.monotonic() - started))
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


def _cpu_seconds(pids: list[int]) -> float:
    """The CPU time of the server's processes (the one, or the landing and its workers)."""
    try:
        return sum(procfs.usage(pid).cpu_seconds for pid in pids)
    except OSError:
        return math.nan


def _machine(
    phase: str, machine: procfs.Machine, load: float, server_cpu: float, seconds: float
) -> Figure:
    """How busy the (shared) machine was during the phase, and how much of it was the server:
    the rest is the clients and whatever else runs here."""
    cores = os.cpu_count() or 1
    busy = procfs.Machine.now().busy_since(machine)
    server = server_cpu / (seconds * cores) if seconds > 0 else math.nan
    return info(
        phase,
        "the machine meanwhile",
        f"load average {load:.1f} -> {os.getloadavg()[0]:.1f}; {cores} cores {busy:.0%} busy, "
        f"{server:.0%} of them the server",
        busy=busy,
    )
