"""The ``follow`` phase: one lead and N followers on two workers
(:mod:`poinsot.app.live.classroom.lead`).

For each size in ``Config.followers``, child processes connect the lead and N followers
through the landing (:class:`FollowFleet`; ``Config.followers_per_process`` at most each, the lead
in the first, so that the clients' interpreters are not the limit of their frame rates); the
lead types the lecturer code and leads, every follower ticks "Follow the lecturer". Then three
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
from multiprocessing.connection import Connection
from typing import TYPE_CHECKING, Any

from poinsot.app.devtools.load import procfs
from poinsot.app.devtools.load.children import Child
from poinsot.app.devtools.load.config import Config, Report, Say, fps_text, warmup
from poinsot.app.devtools.load.figures import Figure, at_least, at_most, info, percentile
from poinsot.app.devtools.load.fleet import SCENE_TIMEOUT, SLIDER_LABEL, SLIDER_VALUES
from poinsot.app.devtools.load.fleet import _Client as Counter
from poinsot.app.devtools.load.server_process import ServerProcess

if TYPE_CHECKING:
    from poinsot.app.devtools.probe import Probe

FOLLOW_LABEL = "Follow the lecturer"
EXPLORE_LABEL = "Explore from here"
#: Words of the lecture tools' line of keys (:mod:`poinsot.app.live.lecture.lecture`).
READY_WORDS = "Keys: **space**"


def _says(probe: Probe, words: str) -> bool:
    return any(words in str(w.props.get("_markdown", "")) for w in probe.widgets.values())


def _press(probe: Probe, label: str, value: Any = True) -> None:
    probe.set_value(probe.widget(label)[0], value)


def _ready(probe: Probe) -> bool:
    """The page is whole: its panel, and the lecture tools' line of keys, which the session
    mounts last (a widget arrives before its callback is bound: a press of the "Class" folder's
    buttons as soon as they show can be lost on a busy machine)."""
    return probe.has_widget(EXPLORE_LABEL) and _says(probe, READY_WORDS)


def _why(probe: Probe, since: float) -> str:
    """What a client that never saw its answer had seen, ``since`` a monotonic time."""
    waited = f"after {time.monotonic() - since:.1f} s"
    if probe.closed:
        return f"{waited}, its connection closed by the server (code {probe.close_code})"
    _, widgets = probe.snapshot()  # the reading thread may be adding widgets meanwhile
    said = [str(w.props.get("_markdown", "")) for w in widgets.values()]
    return f"{waited}, its messages: {[s for s in said if s][-3:]}"


def chunks(count: int, per: int) -> list[int]:
    """``count`` followers spread evenly over as few processes as hold ``per`` each."""
    processes = max(1, math.ceil(count / per))
    return [count // processes + (i < count % processes) for i in range(processes)]


def _followers(port: int, count: int, deadline: float, probes: list[Probe]) -> list[Probe]:
    """``count`` clients connected, each with its panel (also appended to ``probes``)."""
    from poinsot.app.devtools.probe import Probe
    from poinsot.app.live.landing import resolve

    made = []
    for _ in range(count):
        made.append(Probe(resolve(port), keep_batches=False))
        probes.append(made[-1])
    for probe in made:
        timeout = max(1.0, min(SCENE_TIMEOUT, deadline - time.monotonic()))
        if not probe.wait_for(_ready, timeout):
            raise RuntimeError("a client never received its panel")
    return made


def _lead(port: int, code: str, deadline: float, probes: list[Probe]) -> Probe:
    (lead,) = _followers(port, 1, deadline, probes)
    _press(lead, "Lecturer code", code)
    _press(lead, "Lead this class")
    asked = time.monotonic()
    if not lead.wait_for(lambda p: _says(p, "You lead this class"), SCENE_TIMEOUT):
        raise RuntimeError(f"the lead was refused ({_why(lead, asked)})")
    return lead


def _follow(followers: list[Probe]) -> None:
    for probe in followers:
        _press(probe, FOLLOW_LABEL)
    asked = time.monotonic()
    for probe in followers:
        if not probe.wait_for(lambda p: _says(p, "Following the lecturer"), SCENE_TIMEOUT):
            raise RuntimeError(f"a follower never followed ({_why(probe, asked)})")


class _Clients:
    """What one client process holds: its followers' probes and counters, and the lead's
    probe in the first process."""

    def __init__(self, lead: Probe | None, followers: list[Probe]) -> None:
        self.lead, self.followers = lead, followers
        self.counters = [Counter() for _ in followers]
        for probe, counter in zip(followers, self.counters, strict=True):
            probe.add_listener(counter.listener)

    def answer(self, kind: str, args: list[Any]) -> Any:
        if kind == "count":  # poses so far, the clock, this process's CPU time
            return [c.poses for c in self.counters], time.perf_counter(), time.process_time()
        if kind == "arm":
            for c in self.counters:
                c.redrawn.clear()
            return True
        if kind == "move":  # the lead moves the slider: when it sent the move
            assert self.lead is not None, "the lead is in the first process"
            sent = time.perf_counter()
            _press(self.lead, SLIDER_LABEL, args[0])
            return sent
        if kind == "await":  # each follower's seconds from the move to its redraw
            sent, timeout = args
            for c in self.counters:
                c.redrawn.wait(max(0.0, sent + timeout - time.perf_counter()))
            return [c.last_redraw - sent for c in self.counters if c.redrawn.is_set()]
        if kind == "explore":
            for probe in self.followers:
                _press(probe, EXPLORE_LABEL)
            return all(p.wait_for(lambda p: _says(p, "Exploring"), 60) for p in self.followers)
        raise ValueError(f"unknown request {kind!r}")


def _main(conn: Connection, port: int, code: str, count: int, lead: bool, lifetime: float) -> None:
    """A client process: connect (the lead first, if ``lead``), follow; then answer requests."""
    deadline = time.monotonic() + lifetime
    probes: list[Probe] = []
    try:
        leading = _lead(port, code, deadline, probes) if lead else None
        followers = _followers(port, count, deadline, probes)
        _follow(followers)
        clients = _Clients(leading, followers)
        conn.send(("ready", count))
        while time.monotonic() < deadline and conn.poll(lifetime):
            request = conn.recv()
            if request == "stop":
                break
            kind, *args = request
            conn.send((kind, clients.answer(kind, args)))
    except EOFError:
        pass
    except Exception as exc:
        conn.send(("error", f"{type(exc).__name__}: {exc}"))
    finally:
        for probe in probes:
            probe.close()
    try:
        conn.send(("stopped", count))
    except OSError:
        pass


class FollowFleet:
    """A lead and ``count`` followers of the server on ``port``, ``per`` at most in a process
    (the lead in the first)."""

    def __init__(self, port: int, code: str, count: int, per: int, lifetime: float):
        self.children: list[Child] = []
        try:
            for i, size in enumerate(chunks(count, per)):
                child = Child(f"followers-{i}", _main, port, code, size, i == 0, lifetime)
                self.children.append(child)
                if i == 0:  # the lead leads before anyone follows
                    child.receive(SCENE_TIMEOUT + 10.0 * size, f"the lead and {size} followers")
            for child in self.children[1:]:
                child.receive(SCENE_TIMEOUT + 10.0 * count, f"{count} followers to follow")
        except BaseException:
            self.__exit__()
            raise

    def __enter__(self) -> FollowFleet:
        return self

    def __exit__(self, *exc: object) -> None:
        for child in self.children:
            child.finish()

    @property
    def pids(self) -> list[int]:
        return [c.pid for c in self.children]

    def _all(self, request: tuple[Any, ...], timeout: float, what: str) -> list[Any]:
        for child in self.children:
            child.conn.send(request)
        return [child.receive(timeout, what) for child in self.children]

    def window(self, seconds: float, period: float, timeout: float) -> dict:
        """Frames over ``seconds``; every ``period`` (0: never) a lead's move, lost if not
        redrawn on a follower within ``timeout``. ``clients``: the client processes' CPU
        [cores]."""
        first = self._all(("count",), 60.0, "the poses counted")
        start = time.perf_counter()
        latencies: list[float] = []
        moves = 0
        while time.perf_counter() < start + seconds:
            if period > 0:
                moves += 1
                self._all(("arm",), 60.0, "the followers armed")
                sent = self.children[0].request(("move", SLIDER_VALUES[moves % 2]), 60, "a move")
                for got in self._all(("await", sent, timeout), timeout + 60.0, "the redraws"):
                    latencies += got
            time.sleep(max(0.0, min(period or seconds, start + seconds - time.perf_counter())))
        last = self._all(("count",), 60.0, "the poses counted")
        fps: list[float] = []
        cpu = 0.0
        for (poses0, t0, cpu0), (poses1, t1, cpu1) in zip(first, last, strict=True):
            fps += [(b - a) / (t1 - t0) for a, b in zip(poses0, poses1, strict=True)]
            cpu += (cpu1 - cpu0) / (t1 - t0)
        elapsed = time.perf_counter() - start
        return {
            "fps": fps,
            "latencies": latencies,
            "moves": moves,
            "seconds": elapsed,
            "clients": cpu,
        }

    def explore(self) -> bool:
        return all(self._all(("explore",), 120.0, "the followers to explore"))


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
            server.port, server.code, count, cfg.followers_per_process, cfg.lifetime
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
    p95 = 1e3 * percentile(latencies, 95) if latencies else math.nan
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
        info(
            "follow",
            f"{name}: the machine's cores",
            load.text(),
            server_cores=load.server,
            clients_cpu=load.clients,
            processes=float(load.processes),
        ),
    ]


def own_fps_text(own: dict) -> str:
    return f"sessions {fps_text(own['fps'])}"
