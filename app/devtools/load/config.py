"""What the phases share: the sizes (:class:`Config`), the report they fill, and small helpers."""

from __future__ import annotations

import dataclasses
import math
import os
import statistics
from collections.abc import Callable

from poinsot.app.devtools.load.figures import Figure

#: Seconds every child may outlive its phase's own length before it stops by itself.
SPARE_LIFETIME = 600.0
#: Pause after the clients connected, before anything is measured (the connection burst).
WARMUP_SECONDS = 5.0
MB = 1e6

#: Progress lines (to stderr in the command).
Say = Callable[[str], None]


@dataclasses.dataclass(frozen=True)
class Config:
    """The sizes of the phases (each has a command-line option)."""

    clients: int = 30  # in the soak, the stall and the flood
    #: Server processes (behind a landing port if more than one); 0: the soak with as many as
    #: ``poinsot serve`` starts here (one per core), the other phases with one.
    workers: int = 0
    seconds: float = 300.0  # the soak
    slider_period: float = 1.0  # a slider move every this many seconds during the soak
    storm: int = 200  # connects and departures
    storm_workers: int = 8  # visits at a time
    storm_steady: int = 3  # clients that stay connected through the storm
    settle_seconds: float = 30.0  # at most, after the storm
    settle_tolerance: float = 0.10  # the settling ends early once everything is this close
    stall_seconds: float = 45.0  # client 0 stalled
    flood_seconds: float = 20.0  # one client flooding
    flood_rate: float = 10_000.0  # its messages a second
    hostile_handshakes: int = 2000  # refused handshakes in the hostile phase
    hostile_quiet_seconds: float = 8.0  # the innocent client's frames before and after it
    followers: tuple[int, ...] = (30, 60)  # the follow phase's sizes, one lead each
    follow_seconds: float = 15.0  # each of its windows (following, then exploring)
    follow_redraw_timeout: float = 5.0  # a lead's move not on a follower by then is lost [s]
    #: Followers per client process. One interpreter decodes about 60 followers' frames at 30
    #: fps in 0.65 of a core (measured): at 40 a process, the clients do not limit their rates.
    followers_per_process: int = 40
    #: Hosts of the follow phase: more than 1 runs that many servers (one process each) linked
    #: by a local Redis behind nginx (:mod:`poinsot.app.devtools.load.workloads.hosts`).
    hosts: int = 1

    @property
    def lifetime(self) -> float:
        """How long any child of any phase may live (they stop by themselves after it)."""
        return self.seconds + self.stall_seconds + self.flood_seconds + SPARE_LIFETIME


@dataclasses.dataclass
class Report:
    figures: list[Figure] = dataclasses.field(default_factory=list)
    notes: list[str] = dataclasses.field(default_factory=list)

    def add(self, *figures: Figure) -> None:
        self.figures.extend(figures)

    def figure(self, phase: str, name: str) -> Figure:
        """The figure of ``phase`` whose name starts with ``name``."""
        for f in self.figures:
            if f.phase == phase and f.name.startswith(name):
                return f
        raise KeyError(f"no figure {name!r} in {phase}")


def warmup(seconds: float) -> float:
    """The pause before measuring, shorter for a short phase."""
    return min(WARMUP_SECONDS, 0.2 * seconds)


def relative(after: float, before: float) -> float:
    """|after / before - 1|; for a zero baseline 0 when equal, else infinite."""
    if before == 0:
        return 0.0 if after == 0 else math.inf
    return abs(after / before - 1.0)


def fps_text(values: list[float]) -> str:
    if not values:
        return "no clients"
    return f"p50 {statistics.median(values):.1f}, min {min(values):.1f} fps"


def server_processes(cfg: Config, phase: str) -> int:
    """The server processes a phase runs against (see :attr:`Config.workers`)."""
    if phase == "follow":  # across workers, as a classroom runs
        return max(cfg.workers, 2)
    if cfg.workers:
        return cfg.workers
    return (os.cpu_count() or 1) if phase == "soak" else 1
