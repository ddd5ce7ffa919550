"""The ``follow`` phase: one lead and N followers on two workers
(:mod:`poinsot.app.live.classroom.lead`).

For each size in ``Config.followers``, a child process connects the lead and N followers
through the landing (:class:`FollowFleet`); the lead types the lecturer code and leads, every
follower ticks "Follow the lecturer". Then three windows of ``follow_seconds``:

- following, moving: each follower's frames (poses received, as in :mod:`.fleet`), and every
  ``slider_period`` the lead moves the I₂ slider: the time until each follower receives the
  rebuilt ellipsoid (the lead's move on every follower's screen);
- following, still: nothing moves but the motion;
- exploring, still: every follower has pressed "Explore from here" and runs as a session.

The server's CPU time (its worker processes) over each still window, divided by the frames the
clients received, gives the CPU per follower-frame against the CPU per session-frame of the
same clients, in the same run, on the same (shared) machine.
"""

from __future__ import annotations

import math
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


def _says(probe: Probe, words: str) -> bool:
    return any(words in str(w.props.get("_markdown", "")) for w in probe.widgets.values())


def _press(probe: Probe, label: str, value: Any = True) -> None:
    probe.set_value(probe.widget(label)[0], value)


def _why(probe: Probe, since: float) -> str:
    """What a client that never saw its answer had seen, ``since`` a monotonic time."""
    waited = f"after {time.monotonic() - since:.1f} s"
    if probe.closed:
        return f"{waited}, its connection closed by the server (code {probe.close_code})"
    _, widgets = probe.snapshot()  # the reading thread may be adding widgets meanwhile
    said = [str(w.props.get("_markdown", "")) for w in widgets.values()]
    return f"{waited}, its messages: {[s for s in said if s][-3:]}"


def _connect(port: int, code: str, count: int, deadline: float) -> tuple[Probe, list[Probe]]:
    from poinsot.app.devtools.probe import Probe
    from poinsot.app.live.landing import resolve

    probes = [Probe(resolve(port), keep_batches=False) for _ in range(count + 1)]
    for probe in probes:
        timeout = max(1.0, min(SCENE_TIMEOUT, deadline - time.monotonic()))
        if not probe.wait_for(lambda p: p.has_widget(EXPLORE_LABEL), timeout):
            raise RuntimeError("a client never received its panel")
    lead, *followers = probes
    _press(lead, "Lecturer code", code)
    _press(lead, "Lead this class")
    asked = time.monotonic()
    if not lead.wait_for(lambda p: _says(p, "You lead this class"), SCENE_TIMEOUT):
        raise RuntimeError(f"the lead was refused ({_why(lead, asked)})")
    for probe in followers:
        _press(probe, FOLLOW_LABEL)
    asked = time.monotonic()
    for probe in followers:
        if not probe.wait_for(lambda p: _says(p, "Following the lecturer"), SCENE_TIMEOUT):
            raise RuntimeError(f"a follower never followed ({_why(probe, asked)})")
    return lead, followers


def _move(lead: Probe, value: float, counters: list[Counter], timeout: float) -> list[float]:
    """The lead moves the slider: each follower's seconds until its redraw (lost: absent, not
    redrawn within ``timeout`` seconds)."""
    for c in counters:
        c.redrawn.clear()
    sent = time.perf_counter()
    _press(lead, SLIDER_LABEL, value)
    end = sent + timeout
    for c in counters:
        c.redrawn.wait(max(0.0, end - time.perf_counter()))
    return [c.last_redraw - sent for c in counters if c.redrawn.is_set()]


def _window(
    lead: Probe, counters: list[Counter], seconds: float, period: float, timeout: float
) -> dict:
    poses0 = [c.poses for c in counters]
    start = time.perf_counter()
    latencies: list[float] = []
    moves = 0
    while time.perf_counter() < start + seconds:
        if period > 0:
            moves += 1
            latencies += _move(lead, SLIDER_VALUES[moves % 2], counters, timeout)
        time.sleep(max(0.0, min(period or seconds, start + seconds - time.perf_counter())))
    elapsed = time.perf_counter() - start
    fps = [(c.poses - p0) / elapsed for c, p0 in zip(counters, poses0, strict=True)]
    return {"fps": fps, "latencies": latencies, "moves": moves, "seconds": elapsed}


def _main(conn: Connection, port: int, code: str, count: int, lifetime: float) -> None:
    """The child: connect, lead and follow; then measure windows on request."""
    deadline = time.monotonic() + lifetime
    probes: list[Probe] = []
    try:
        lead, followers = _connect(port, code, count, deadline)
        probes = [lead, *followers]
        counters = [Counter() for _ in followers]
        for probe, counter in zip(followers, counters, strict=True):
            probe.add_listener(counter.listener)
        conn.send(("ready", len(followers)))
        while time.monotonic() < deadline and conn.poll(lifetime):
            request = conn.recv()
            if request == "stop":
                break
            kind, *args = request
            if kind == "window":
                conn.send(("window", _window(lead, counters, *args)))
            elif kind == "explore":
                for probe in followers:
                    _press(probe, EXPLORE_LABEL)
                gone = all(p.wait_for(lambda p: _says(p, "Exploring"), 60) for p in followers)
                conn.send(("explored", gone))
    except EOFError:
        pass
    except Exception as exc:
        conn.send(("error", f"{type(exc).__name__}: {exc}"))
    finally:
        for probe in probes:
            probe.close()
    try:
        conn.send(("stopped", len(probes)))
    except OSError:
        pass


class FollowFleet(Child):
    """A lead and ``count`` followers of the server on ``port``, in their own process."""

    def __init__(self, port: int, code: str, count: int, lifetime: float):
        super().__init__("followers", _main, port, code, count, lifetime)
        self.receive(SCENE_TIMEOUT + 10.0 * count, f"{count} followers to follow")

    def __enter__(self) -> FollowFleet:
        return self

    def window(self, seconds: float, period: float, timeout: float) -> dict:
        """Frames over ``seconds``; every ``period`` (0: never) a lead's move, lost if not
        redrawn on a follower within ``timeout``."""
        wait = seconds + 120.0 + (timeout * seconds / period if period else 0.0)
        result: dict = self.request(("window", seconds, period, timeout), wait, "a window")
        return result

    def explore(self) -> bool:
        return bool(self.request(("explore",), 120.0, "the followers to explore"))


def _cpu(pids: list[int]) -> float:
    return sum(procfs.usage(pid).cpu_seconds for pid in pids)


def phase(server: ServerProcess, cfg: Config, report: Report, say: Say) -> None:
    for count in cfg.followers:
        say(f"follow: 1 lead and {count} followers on {len(server.worker_pids)} workers")
        with FollowFleet(server.port, server.code, count, cfg.lifetime) as fleet:
            time.sleep(warmup(cfg.follow_seconds))
            pids = server.worker_pids or [server.pid]
            clients0 = _cpu([fleet.pid])
            following = fleet.window(
                cfg.follow_seconds, cfg.slider_period, cfg.follow_redraw_timeout
            )
            clients = (_cpu([fleet.pid]) - clients0) / following["seconds"]
            cpu0 = _cpu(pids)
            still = fleet.window(cfg.follow_seconds, 0.0, 0.0)
            cpu1 = _cpu(pids)
            explored = fleet.explore()
            cpu2 = _cpu(pids)
            own = fleet.window(cfg.follow_seconds, 0.0, 0.0)
            cpu3 = _cpu(pids)
        costs = (_ms_per_frame(cpu1 - cpu0, still), _ms_per_frame(cpu3 - cpu2, own))
        report.add(*_figures(count, following, still, own, costs, explored, clients))


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
    clients: float,
) -> list[Figure]:
    """The figures of one size. The frame rates judged are those while the lead moves a
    slider every period (each move rebuilds every follower's body); ``still``'s, while nothing
    moves, are shown beside them. ``clients``: the CPU of the clients' process while following
    [cores] (near 1, its one interpreter would be the limit of the frame rates, not the
    server)."""
    fps, latencies = following["fps"], following["latencies"]
    lost = following["moves"] * count - len(latencies)
    p95 = 1e3 * percentile(latencies, 95) if latencies else math.nan
    follow_ms, own_ms = costs
    name = f"{count} followers"
    return [
        Figure(
            "follow",
            f"{name}: fps each",
            min(fps) if fps else 0.0,
            f"{fps_text(fps)} (nothing moving: {fps_text(still['fps'])})",
            at_least("min_fps", ">= {:g} fps"),
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
            f"(the same clients after Explore from here, {own_fps_text(own)}; nothing moved); "
            f"the clients' process {100 * clients:.0f} % of a core while following",
            follower_ms=follow_ms,
            session_ms=own_ms,
            explored=float(explored),
            clients_cpu=clients,
        ),
    ]


def own_fps_text(own: dict) -> str:
    return f"sessions {fps_text(own['fps'])}"
