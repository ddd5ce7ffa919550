"""The ``follow`` phase: one lead and N followers on two workers
(:mod:`poinsot.app.live.classroom.lead`).

For each size in ``Config.followers``, child processes connect the lead and N followers
through the landing (:class:`~.follow_fleet.FollowFleet`; ``Config.followers_per_process`` at
most each, the lead in the first, so that the clients' interpreters are not the limit of their
frame rates); the lead types the lecturer code and leads, every follower ticks "Follow the
lecturer". Then three
windows of ``follow_seconds``:

- following, moving: each follower's frames (poses received, as in :mod:`.fleet`), and every
  ``slider_period`` the lead moves the I₂ slider: the time until each follower receives the
  rebuilt ellipsoid (the lead's move on every follower's screen);
- following, still: nothing moves but the motion;
- exploring, still: every follower has pressed "Explore from here" and runs as a session.

The server's CPU time (its worker processes) over each still window, divided by the frames the
clients received, gives the CPU per follower-frame against the CPU per session-frame of the
same clients, in the same run, on the same (shared) machine. The server's cores and the client
processes' are stated for each size (:class:`Load`): where the clients, or the server and the
clients together, fill this machine, the frame rates are said to measure them, not the server,
and are not judged.
"""

from __future__ import annotations

import dataclasses
import math
import os
import statistics
import time

from poinsot.app.devtools.load import procfs
from poinsot.app.devtools.load.config import Config, Report, Say, fps_text, warmup
from poinsot.app.devtools.load.figures import Figure, at_least, at_most, info, percentile
from poinsot.app.devtools.load.server_process import ServerProcess
from poinsot.app.devtools.load.workloads.follow_fleet import FollowFleet, chunks


def _cpu(pids: list[int]) -> float:
    return sum(procfs.usage(pid).cpu_seconds for pid in pids)


def phase(server: ServerProcess, cfg: Config, report: Report, say: Say) -> None:
    for count in cfg.followers:
        processes = len(chunks(count, cfg.followers_per_process))
        say(
            f"follow: 1 lead and {count} followers on {len(server.worker_pids)} workers, "
            f"the clients in {processes} process(es)"
        )
        with FollowFleet(
            server.port, server.code, [None] * count, cfg.followers_per_process, cfg.lifetime
        ) as fleet:
            time.sleep(warmup(cfg.follow_seconds))
            pids = server.worker_pids or [server.pid]
            following = fleet.window(
                cfg.follow_seconds, cfg.slider_period, cfg.follow_redraw_timeout
            )
            cpu0 = _cpu(pids)
            still = fleet.window(cfg.follow_seconds, 0.0, 0.0)
            cpu1 = _cpu(pids)
            explored = fleet.explore()
            cpu2 = _cpu(pids)
            own = fleet.window(cfg.follow_seconds, 0.0, 0.0)
            cpu3 = _cpu(pids)
        costs = (_ms_per_frame(cpu1 - cpu0, still), _ms_per_frame(cpu3 - cpu2, own))
        load = Load((cpu1 - cpu0) / still["seconds"], following["clients"], processes)
        report.add(*_figures(count, following, still, own, costs, explored, load))
        report.notes.append(f"follow, {count} followers: {load.text()}")


#: A client process this busy [cores] limits the frame rates it counts, not the server.
CLIENTS_LIMIT = 0.9


@dataclasses.dataclass(frozen=True)
class Load:
    """The machine's cores while following: the server's (its workers, nothing moving), the
    client processes' (all of them, while the lead moved), and how many processes those are."""

    server: float
    clients: float
    processes: int

    @property
    def limit(self) -> str:
        """Who limits the followers' frame rates on this machine: "clients" (a client process
        near a whole core), "machine" (the server and the clients fill its cores) or
        "server"."""
        if self.clients / self.processes >= CLIENTS_LIMIT:
            return "clients"
        if self.server + self.clients >= CLIENTS_LIMIT * (os.cpu_count() or 1):
            return "machine"
        return "server"

    def figure(self, name: str) -> Figure:
        """The figure "``name``: the machine's cores" of the follow phase."""
        return info(
            "follow",
            f"{name}: the machine's cores",
            self.text(),
            server_cores=self.server,
            clients_cpu=self.clients,
            processes=float(self.processes),
        )

    def text(self) -> str:
        cores = os.cpu_count() or 1
        said = (
            f"the server used {self.server:.2f} of {cores} cores (followers still), the "
            f"clients' {self.processes} process(es) {self.clients:.2f}"
        )
        if self.limit == "clients":
            return said + ": the clients, not the server, limit the frame rates"
        if self.limit == "machine":
            return said + ": the machine is full, the frame rates measure it, not the server alone"
        return said


def _ms_per_frame(cpu: float, window: dict) -> float:
    frames = sum(window["fps"]) * window["seconds"]
    return 1e3 * cpu / frames if frames else math.nan


def _figures(
    count: int,
    following: dict,
    still: dict,
    own: dict,
    costs: tuple[float, float],
    explored: bool,
    load: Load,
) -> list[Figure]:
    """The figures of one size. The frame rates judged are those while the lead moves a
    slider every period (each move rebuilds every follower's body); ``still``'s, while nothing
    moves, are shown beside them. They are not judged when the clients or the whole machine,
    not the server, limit them (:attr:`Load.limit`): the table says so instead."""
    fps, latencies = following["fps"], following["latencies"]
    lost = following["moves"] * count - len(latencies)
    p95 = 1e3 * percentile(latencies, 0.95) if latencies else math.nan
    follow_ms, own_ms = costs
    name = f"{count} followers"
    text = f"{fps_text(fps)} (nothing moving: {fps_text(still['fps'])})"
    judged = load.limit == "server"
    if not judged:
        text += f"; limited by the {load.limit}, not the server: not judged"
    return [
        Figure(
            "follow",
            f"{name}: fps each",
            min(fps) if fps else 0.0,
            text,
            at_least("min_fps", ">= {:g} fps") if judged else None,
            {"clients": count, "p50": statistics.median(fps) if fps else 0.0},
        ),
        Figure(
            "follow",
            f"{name}: lead's slider move on every follower",
            p95 if not lost else math.inf,
            f"p95 {p95:.0f} ms over {len(latencies)} redraws ({following['moves']} moves), "
            f"{lost} lost",
            at_most("max_follow_ms", "p95 <= {:g} ms"),
            {"redraws": len(latencies), "moves": following["moves"], "lost": lost},
        ),
        info(
            "follow",
            f"{name}: server CPU per frame",
            f"{follow_ms:.2f} ms per follower-frame, {own_ms:.2f} ms per session-frame "
            f"(the same clients after Explore from here, {own_fps_text(own)}; nothing moved)",
            follower_ms=follow_ms,
            session_ms=own_ms,
            explored=float(explored),
        ),
        load.figure(name),
    ]


def own_fps_text(own: dict) -> str:
    return f"sessions {fps_text(own['fps'])}"
