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
processes' are stated for each size (:class:`Load`): where a client process is near a whole
core, the frame rates are said to measure the clients, not the server, and are not judged.
Each follower is held to ``Bounds.min_fps``, or ``Bounds.min_hall_fps`` in a hall (more than
``HALL`` followers), the lead's move to ``Bounds.max_follow_ms``, or ``max_hall_follow_ms``.
The clients share this machine with the server: from the CPU each took per frame while the
lead moved (the server's: all that the machine used but the clients'),
the phase states the rate the server could give the slowest follower with the machine to
itself and beside the clients (:meth:`Load.rates`); a rate below its goal that the server
alone could give, and not beside the clients, is the clients' limit, not the server's
(``Goal.clients_limit``).
"""

from __future__ import annotations

import dataclasses
import math
import os
import statistics
import time

from poinsot.app.devtools.load import procfs
from poinsot.app.devtools.load.config import Config, Report, Say, fps_text, warmup
from poinsot.app.devtools.load.figures import (
    HALL,
    Figure,
    at_least,
    at_most,
    info,
    percentile,
)
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
            machine, casts, cpu_moving = procfs.Machine.now(), [server.status()], _cpu(pids)
            following = fleet.window(
                cfg.follow_seconds, cfg.slider_period, cfg.follow_redraw_timeout
            )
            busy = procfs.Machine.now().busy_since(machine) * (os.cpu_count() or 1)
            casts.append(server.status())
            cpu0 = _cpu(pids)
            still = fleet.window(cfg.follow_seconds, 0.0, 0.0)
            cpu1 = _cpu(pids)
            casts.append(server.status())
            explored = fleet.explore()
            cpu2 = _cpu(pids)
            own = fleet.window(cfg.follow_seconds, 0.0, 0.0)
            cpu3 = _cpu(pids)
        costs = (
            _ms_per_frame(cpu1 - cpu0, still),
            _ms_per_frame(cpu3 - cpu2, own),
            _ms_per_move(cpu0 - cpu_moving, (cpu1 - cpu0) / still["seconds"], following, count),
        )
        load = Load(
            (cpu1 - cpu0) / still["seconds"],
            following["clients"],
            processes,
            Moving(busy, sum(following["fps"]), count, len(pids)),
        )
        report.add(*_figures(count, following, still, own, costs, explored, load))
        report.add(cast_figure(f"{count} followers", casts, following, still))
        report.notes.append(f"follow, {count} followers: {load.text()}")


#: A client process this busy [cores] limits the frame rates it counts, not the server; the
#: share of the machine's cores the server and the clients can use (:meth:`Load.rates`).
CLIENTS_LIMIT = 0.9
#: The fps figure's detail keys of :meth:`Load.rates` (the slowest follower's share): its goal
#: is the clients' when the server alone could meet it, and not beside them.
RATES = ("server_alone_fps", "beside_clients_fps")


@dataclasses.dataclass(frozen=True)
class Moving:
    """While the lead moved: the machine's busy cores (all of its processes and its kernel),
    the follower-frames the clients received a second, the followers and the server's
    processes."""

    busy: float
    frames: float
    followers: int
    workers: int


@dataclasses.dataclass(frozen=True)
class Load:
    """The machine's cores while following: the server's (its workers, nothing moving), the
    client processes' (all of them, while the lead moved), how many processes those are, and
    (``moving``) the machine while the lead moved, for :meth:`rates`."""

    server: float
    clients: float
    processes: int
    moving: Moving | None = None

    @property
    def limit(self) -> str:
        """Who limits the followers' frame rates on this machine: "clients" (a client process
        near a whole core), "machine" (the server and the clients fill its cores, where
        :meth:`rates` cannot tell which) or "server"."""
        if self.clients / self.processes >= CLIENTS_LIMIT:
            return "clients"
        if self.rates() is None and self.server + self.clients >= CLIENTS_LIMIT * (
            os.cpu_count() or 1
        ):
            return "machine"
        return "server"

    def rates(self) -> tuple[float, float] | None:
        """(alone, beside): the mean frame rate each follower could get with the machine to
        the server (CLIENTS_LIMIT of as many cores as it has processes, at most the machine's)
        and beside these clients (of all the cores, for both), at the CPU each took per frame
        received while the lead moved. Everything the machine used but the clients, its kernel
        included, counts as the server's. None: not measured."""
        moving = self.moving
        if moving is None or moving.frames <= 0 or moving.followers <= 0:
            return None
        cores = os.cpu_count() or 1
        server = max(moving.busy - self.clients, 1e-9) / moving.frames  # core-s per frame
        clients = self.clients / moving.frames
        alone = CLIENTS_LIMIT * min(cores, moving.workers) / (server * moving.followers)
        beside = CLIENTS_LIMIT * cores / ((server + clients) * moving.followers)
        return alone, beside

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
        rates, moving = self.rates(), self.moving
        if rates is not None and moving is not None:
            said += (
                f"; while the lead moved the machine used {moving.busy:.2f} cores, the clients "
                f"{self.clients:.2f}: the server could give each follower {rates[0]:.1f} fps "
                f"with the machine to itself, {rates[1]:.1f} beside the clients (means)"
            )
        if self.limit == "clients":
            return said + ": the clients, not the server, limit the frame rates"
        if self.limit == "machine":
            return said + ": the machine is full, the frame rates measure it, not the server alone"
        return said


def _ms_per_frame(cpu: float, window: dict) -> float:
    frames = sum(window["fps"]) * window["seconds"]
    return 1e3 * cpu / frames if frames else math.nan


def _ms_per_move(cpu: float, still_cores: float, moving: dict, followers: int) -> float:
    """The server's CPU [ms] a lead's move cost each follower: what the window with the lead
    moving took (``cpu`` [s]) beyond the same seconds with nothing moving (``still_cores``),
    over its moves and the followers."""
    moves = moving["moves"] * followers
    extra = cpu - still_cores * moving["seconds"]
    return 1e3 * extra / moves if moves else math.nan


def fps_bound(count: int) -> str:
    """The bound a row of ``count`` followers' frame rates is held to: ``Bounds.min_fps``, or
    ``Bounds.min_hall_fps`` in a hall (more than ``HALL`` followers), on one host or several."""
    return "min_hall_fps" if count > HALL else "min_fps"


def move_bound(count: int) -> str:
    """The bound the lead's move on every follower of a row of ``count`` is held to on one
    host: ``Bounds.max_follow_ms``, or ``Bounds.max_hall_follow_ms`` in a hall."""
    return "max_hall_follow_ms" if count > HALL else "max_follow_ms"


def _figures(
    count: int,
    following: dict,
    still: dict,
    own: dict,
    costs: tuple[float, float, float],
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
    name = f"{count} followers"
    text = f"{fps_text(fps)} (nothing moving: {fps_text(still['fps'])})"
    detail = {"clients": count, "p50": statistics.median(fps) if fps else 0.0}
    rates = load.rates()
    if rates is not None and fps and statistics.mean(fps) > 0:
        spread = min(fps) / statistics.mean(fps)  # the slowest follower's share of the mean
        alone, beside = (rate * spread for rate in rates)
        detail |= {"server_alone_fps": alone, "beside_clients_fps": beside}
        text += f"; the slowest could get {alone:.1f} from the server alone, {beside:.1f} beside"
    judged = load.limit == "server"
    if not judged:
        text += f"; limited by the {load.limit}, not the server: not judged"
    bound = fps_bound(count)
    return [
        Figure(
            "follow",
            f"{name}: fps each",
            min(fps) if fps else 0.0,
            text,
            at_least(bound, ">= {:g} fps", rates=RATES) if judged else None,
            detail,
        ),
        Figure(
            "follow",
            f"{name}: lead's slider move on every follower",
            p95 if not lost else math.inf,
            f"p95 {p95:.0f} ms over {len(latencies)} redraws ({following['moves']} moves), "
            f"{lost} lost",
            at_most(move_bound(count), "p95 <= {:g} ms"),
            {"redraws": len(latencies), "moves": following["moves"], "lost": lost},
        ),
        _cost_figure(name, costs, own, explored),
        load.figure(name),
    ]


def _cost_figure(name: str, costs: tuple[float, float, float], own: dict, explored: bool) -> Figure:
    """The figure "``name``: server CPU per frame" (and per follower a lead's move)."""
    follow_ms, own_ms, move_ms = costs
    ratio = own_ms / follow_ms if follow_ms > 0 else math.nan
    return info(
        "follow",
        f"{name}: server CPU per frame",
        f"{follow_ms:.2f} ms per follower-frame, {own_ms:.2f} ms per session-frame "
        f"({ratio:.1f} times as much; the same clients after Explore from here, "
        f"{own_fps_text(own)}; nothing moved); "
        f"a lead's move {move_ms:.2f} ms per follower (the moving window beyond the still)",
        follower_ms=follow_ms,
        session_ms=own_ms,
        move_ms=move_ms,
        explored=float(explored),
    )


def own_fps_text(own: dict) -> str:
    return f"sessions {fps_text(own['fps'])}"


def cast_figure(name: str, casts: list[dict], moving: dict, still: dict) -> Figure:
    """The figure "``name``: the cast" from the server's status before the moving window,
    after it and after the still one (:func:`~..server_process.cast_counts`): the followers'
    shared poses (:mod:`poinsot.app.live.classroom.cast`), how many of their ticks came while
    the lead moved and while nothing moved, and where the moving window's frames went."""
    before, after, last = casts
    seconds = moving["seconds"]

    def rate(a: dict, b: dict, window: dict) -> float:
        return (b["cast_ticks"] - a["cast_ticks"]) / window["seconds"]

    due = after["cast_due"]
    diff = {key: after[key] - before[key] for key in after if key.startswith("cast_")}
    text = (
        f"{rate(before, after, moving):.1f} ticks a second of {due:g} due (its workers "
        f"together) while the lead moved, {rate(after, last, still):.1f} with nothing moving; "
        f"while it moved: {diff['cast_held']:.0f} frames held for the followers' rebuilds, "
        f"{diff['cast_skipped']:.0f} followers skipped (a socket busy or behind), "
        f"{diff['cast_encoded'] / seconds:.1f} windows encoded and "
        f"{diff['cast_handed'] / seconds:.0f} copies handed a second, the lead's new body "
        f"handed {diff['cast_fits']:.0f} times by one follower to {diff['cast_fit_copies']:.0f} "
        f"others ({moving['moves']} moves)"
    )
    return info(
        "follow",
        f"{name}: the cast",
        text,
        ticks_moving=rate(before, after, moving),
        ticks_still=rate(after, last, still),
        due=due,
        held=diff["cast_held"],
        skipped=diff["cast_skipped"],
        fit_copies=diff["cast_fit_copies"],
    )
