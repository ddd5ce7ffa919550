"""The follow phase across hosts (``--phase follow --hosts 2``): a classroom of several
``poinsot serve --workers 1`` linked through one Redis, behind nginx, on this machine's loopback.

:class:`Classroom` starts Debian's ``redis-server``, one server child per host, each linked to it
(:mod:`poinsot.app.live.broker`; the lecturer code is the one shared there), and nginx with the
guide's block in front of them (:mod:`..services`). Its clients connect through nginx, each from a
loopback address that nginx's ``hash $remote_addr`` sends to a known host (:func:`map_sources`):
the lead on the first host, the followers spread evenly over all of them. For each size in
``Config.followers``:

- following, moving: each follower's frames, and every ``slider_period`` the lead moves the I₂
  slider: the time until each follower receives the rebuilt ellipsoid, on the lead's host and
  on the others (where the move crossed Redis);
- following, still: nothing moves but the motion (the servers' CPU per follower-frame);
- Redis killed and started again: the followers on the other hosts are told that they keep the
  last state; the lead moves meanwhile (followed on its own host only); then, from the moment
  Redis answers again, the time until every follower on the other hosts has that move.
"""

from __future__ import annotations

import contextlib
import math
import statistics
import tempfile
import time
from pathlib import Path

from poinsot.app.devtools.load import procfs
from poinsot.app.devtools.load.config import Config, Report, Say, fps_text, warmup
from poinsot.app.devtools.load.figures import Figure, at_least, at_most, info, percentile
from poinsot.app.devtools.load.fleet import SLIDER_VALUES
from poinsot.app.devtools.load.server_process import ServerProcess
from poinsot.app.devtools.load.services import Nginx, RedisServer
from poinsot.app.devtools.load.workloads.follow_fleet import FollowFleet, Source, chunks
from poinsot.app.devtools.load.workloads.following import Load, fps_bound

#: What a follower on another host is told when Redis is lost (``broker.LOST``'s words).
LOST_WORDS = "keep the last state"
#: The link's own line when Redis is lost: expected here, so not one of the log's errors.
OUTAGE_LINE = "followers keep the last state; reconnecting"
#: Loopback addresses tried for each host, and how many each host needs.
CANDIDATES = tuple(f"127.0.0.{i}" for i in range(1, 65))
SOURCES_PER_HOST = 4
#: Seconds a follower on another host may take to have the lead's move once Redis is back
#: before it counts as lost (the goal is :attr:`Bounds.max_recovery_s`).
RECOVERY_TIMEOUT = 30.0


class Classroom:
    """Redis, ``hosts`` servers linked to it, nginx in front (:meth:`finish` stops them all; so
    does a failure to start any). It stands for the phase's server
    (:func:`poinsot.app.devtools.load.phases.run_phase`): ``port`` is nginx's, ``pid`` the
    first host's and ``worker_pids`` the others'; its logs are theirs."""

    def __init__(self, hosts: int, lifetime: float) -> None:
        self._folder = tempfile.TemporaryDirectory(prefix="poinsot-load-hosts-")
        self.servers: list[ServerProcess] = []
        self.nginx: Nginx | None = None
        try:
            self.redis = RedisServer(Path(self._folder.name)).start()
            for _ in range(hosts):
                self.servers.append(ServerProcess(lifetime, redis=self.redis.url))
            codes = {s.code for s in self.servers}
            if len(codes) != 1:
                raise RuntimeError(f"the hosts did not share one lecturer code: {codes}")
            self.code = codes.pop()
            backends = [s.port for s in self.servers]
            self.nginx = Nginx(Path(self._folder.name), backends).start()
        except BaseException:
            self.finish()
            raise
        self.port = self.nginx.port
        self.pid = self.servers[0].pid
        self.worker_pids = [s.pid for s in self.servers[1:]]
        self.log_path = ", ".join(str(s.log_path) for s in self.servers)

    def finish(self) -> None:
        if self.nginx is not None:
            self.nginx.stop()
        for server in self.servers:
            server.finish()
        with contextlib.suppress(AttributeError):
            self.redis.kill()
        self._folder.cleanup()

    def log_errors(self) -> list[str]:
        """The hosts' error lines, but the link's own line when Redis was killed on purpose."""
        lines = [line for s in self.servers for line in s.log_errors()]
        return [line for line in lines if OUTAGE_LINE not in line]

    def log_tail(self, count: int) -> list[str]:
        return [line for s in self.servers for line in s.log_tail(count)]

    def remove_log(self) -> None:
        for server in self.servers:
            server.remove_log()


def map_sources(classroom: Classroom, say: Say) -> list[list[str]]:
    """Each host's loopback addresses (:data:`SOURCES_PER_HOST` at most): a client connects
    from each candidate in turn, through nginx, and the host whose sessions grew is its host
    (nginx's hash keeps it there)."""
    from poinsot.app.devtools.probe import Probe

    found: list[list[str]] = [[] for _ in classroom.servers]
    probes: list[Probe] = []
    try:
        for source in CANDIDATES:
            if all(len(f) >= SOURCES_PER_HOST for f in found):
                break
            before = [s.status()["sessions"] for s in classroom.servers]
            probes.append(Probe(classroom.port, keep_batches=False, source=source))
            grown = _grown(classroom, before)
            found[grown].append(source)
    finally:
        for probe in probes:
            probe.close()
    for server in classroom.servers:
        server.wait_for_sessions(0, 60.0)
    if not all(found):
        raise RuntimeError(f"nginx sent none of {len(CANDIDATES)} addresses to some host")
    say(f"follow: nginx's hosts of the clients' addresses: {found}")
    return [f[:SOURCES_PER_HOST] for f in found]


def _grown(classroom: Classroom, before: list[int], timeout: float = 60.0) -> int:
    """The host that got the one new session."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        now = [s.status()["sessions"] for s in classroom.servers]
        grown = [i for i, (a, b) in enumerate(zip(before, now, strict=True)) if b > a]
        if grown:
            return grown[0]
        time.sleep(0.05)
    raise RuntimeError("a client through nginx got no session on any host")


def seats(count: int, sources: list[list[str]]) -> tuple[list[Source], list[int]]:
    """``count`` followers spread evenly over the hosts: each one's address and host."""
    hosts = [i % len(sources) for i in range(count)]
    return [sources[h][(i // len(sources)) % len(sources[h])] for i, h in enumerate(hosts)], hosts


def phase(classroom: Classroom, cfg: Config, report: Report, say: Say) -> None:
    sources = map_sources(classroom, say)
    pids = [s.pid for s in classroom.servers]
    for count in cfg.followers:
        addresses, hosts = seats(count, sources)
        processes = len(chunks(count, cfg.followers_per_process))
        say(
            f"follow: 1 lead and {count} followers on {len(pids)} hosts linked by Redis behind "
            f"nginx, the clients in {processes} process(es)"
        )
        with FollowFleet(
            classroom.port,
            classroom.code,
            addresses,
            cfg.followers_per_process,
            cfg.lifetime,
            lead_source=sources[0][0],
        ) as fleet:
            time.sleep(warmup(cfg.follow_seconds))
            moving = fleet.window(cfg.follow_seconds, cfg.slider_period, cfg.follow_redraw_timeout)
            cpu0 = _cpu(pids)
            still = fleet.window(cfg.follow_seconds, 0.0, 0.0)
            cpu1 = _cpu(pids)
            outage = _outage(fleet, classroom, [h != 0 for h in hosts], cfg)
        load = Load((cpu1 - cpu0) / still["seconds"], moving["clients"], processes)
        frames = sum(still["fps"]) * still["seconds"]
        cost = 1e3 * (cpu1 - cpu0) / frames if frames else math.nan
        name = f"{len(pids)} hosts, {count} followers"
        report.add(*_figures(name, hosts, moving, still, cost, outage, load))
        report.notes.append(f"follow, {name}: {load.text()}")


def _cpu(pids: list[int]) -> float:
    return sum(procfs.usage(pid).cpu_seconds for pid in pids)


def _outage(fleet: FollowFleet, classroom: Classroom, other: list[bool], cfg: Config) -> dict:
    """Redis killed; the lead moves; Redis started again: how the other hosts' followers
    recover (each one's seconds from Redis answering again to its redraw of that move)."""
    same = [not o for o in other]
    classroom.redis.kill()
    killed = time.perf_counter()
    told = fleet.told(LOST_WORDS, RECOVERY_TIMEOUT, other)
    told_s = time.perf_counter() - killed
    fleet.arm()
    value = SLIDER_VALUES[0] if fleet.slider == SLIDER_VALUES[1] else SLIDER_VALUES[1]
    sent = fleet.move(value)
    during = fleet.redraws(sent, cfg.follow_redraw_timeout, same)
    classroom.redis.start()
    back = time.perf_counter()
    after = fleet.redraws(back, RECOVERY_TIMEOUT, other)
    links = [server.status()["redis"] for server in classroom.servers]
    return {
        "links_lost": sum(link["lost"] for link in links),  # each host's link, once
        "refused": sum(link["refused"] for link in links),  # junk on the channel: none
        "told": sum(told),
        "told_s": told_s,
        "same_host": [x for x, s in zip(during, same, strict=True) if s and x is not None],
        "early": sum(1 for x, o in zip(during, other, strict=True) if o and x is not None),
        "recovery": [x for x, o in zip(after, other, strict=True) if o and x is not None],
        "lost": sum(1 for x, o in zip(after, other, strict=True) if o and x is None),
        "others": sum(other),
    }


def _split(moving: dict, hosts: list[int]) -> tuple[list[float], list[float], int]:
    """The moving window's redraw latencies on the lead's host and on the others, and the
    redraws lost (on any host)."""
    same: list[float] = []
    other: list[float] = []
    lost = 0
    for move in moving["redraws"]:
        for latency, host in zip(move, hosts, strict=True):
            if latency is None:
                lost += 1
            else:
                (same if host == 0 else other).append(latency)
    return same, other, lost


def _p95_ms(values: list[float]) -> float:
    return 1e3 * percentile(values, 0.95) if values else math.nan


def _figures(
    name: str,
    hosts: list[int],
    moving: dict,
    still: dict,
    cost: float,
    outage: dict,
    load: Load,
) -> list[Figure]:
    """One size's figures: the frame rates (judged as the one-host phase judges them), the
    lead's move on the other hosts (p95; lost ones make it infinite), the recovery from a
    Redis restart (the slowest follower; a lost one makes it infinite), the cost and cores."""
    same, other, lost = _split(moving, hosts)
    recovery, missing = outage["recovery"], outage["lost"] + outage["early"]
    slowest = max(recovery) if recovery and not missing else math.inf
    return [
        _fps(name, moving["fps"], still["fps"], load),
        Figure(
            "follow",
            f"{name}: lead's move on the other hosts",
            _p95_ms(other) if not lost else math.inf,
            f"p95 {_p95_ms(other):.0f} ms over {len(other)} redraws (on the lead's host "
            f"{_p95_ms(same):.0f} ms over {len(same)}), {lost} lost, {moving['moves']} moves",
            at_most("max_hosts_follow_ms", "p95 <= {:g} ms"),
            {"redraws": len(other), "same_host": len(same), "lost": lost, "moves": moving["moves"]},
        ),
        Figure(
            "follow",
            f"{name}: Redis stopped and started",
            slowest,
            _outage_text(outage),
            at_most("max_recovery_s", "all <= {:g} s"),
            {k: float(v) for k, v in outage.items() if not isinstance(v, list)},
        ),
        info(
            "follow",
            f"{name}: servers' CPU per frame",
            f"{cost:.2f} ms per follower-frame (nothing moving, all hosts)",
            follower_ms=cost,
        ),
        load.figure(name),
    ]


def _fps(name: str, fps: list[float], still: list[float], load: Load) -> Figure:
    """The followers' frame rates while the lead moves (judged as the one-host phase judges
    them), and while nothing moves."""
    judged = load.limit == "server"
    text = f"{fps_text(fps)} (nothing moving: {fps_text(still)})"
    if not judged:
        text += f"; limited by the {load.limit}, not the servers: not judged"
    return Figure(
        "follow",
        f"{name}: fps each",
        min(fps) if fps else 0.0,
        text,
        at_least(fps_bound(len(fps)), ">= {:g} fps") if judged else None,
        {"clients": len(fps), "p50": statistics.median(fps) if fps else 0.0},
    )


def _outage_text(outage: dict) -> str:
    recovery = outage["recovery"]
    after = (
        f"p50 {statistics.median(recovery):.1f} s, slowest {max(recovery):.1f} s"
        if recovery
        else "none"
    )
    return (
        f"{outage['told']} of {outage['others']} followers on the other hosts told they keep "
        f"the last state ({outage['told_s']:.2f} s after the kill); the lead's move meanwhile "
        f"reached them {after} after Redis answered again; {outage['lost']} never, "
        f"{outage['early']} during the outage; the hosts' links lost Redis "
        f"{outage['links_lost']} times and refused {outage['refused']} messages"
    )
