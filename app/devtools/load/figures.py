"""Figures, the goals some of them are held to, and the printed table.

A phase returns :class:`Figure` s: a number (what a goal compares), the text shown, and
optionally a :class:`Goal` naming one of the :class:`Bounds`. Whether a goal is met is decided
here, from the figures and the bounds alone, so the same measurements can be judged against
other bounds (the tests do).
"""

from __future__ import annotations

import dataclasses
import math


@dataclasses.dataclass(frozen=True)
class Bounds:
    """The goals' numbers (each has a command-line option)."""

    min_fps: float = 30.0  # frames per second, for each client during the soak
    min_hall_fps: float = 24.0  # each follower of a hall (more than HALL followers)
    max_redraw_ms: float = 50.0  # slider-to-redraw p95
    max_rss_growth: float = 0.10  # over the soak, as a fraction of the early RSS
    storm_tolerance: float = 0.10  # threads, RSS and sessions after the storm vs before
    min_keep: float = 0.80  # of their frame rate, for the others while one stalls or floods
    max_errors: int = 0  # server log error lines, silent clients, lost sessions in the soak
    max_hostile_rss_growth: float = 0.05  # after the hostile phase's bad handshakes
    min_innocent_keep: float = 0.95  # of its frame rate, for a client while the hostile plays
    max_follow_ms: float = 150.0  # a lead's slider move on every follower's screen, p95
    max_hall_follow_ms: float = 250.0  # the same for a hall's followers (more than HALL), p95
    max_hosts_follow_ms: float = 250.0  # the same on the other hosts (through Redis), p95
    max_recovery_s: float = 5.0  # Redis back: until every other host's follower has the lead


#: The follow phase's rows with more followers than this are a lecture hall's (a first-year
#: lecture has 200 to 400 students): each follower is held to ``Bounds.min_hall_fps``, the
#: lead's move on every follower to ``Bounds.max_hall_follow_ms`` (the two hosts' bound: a
#: hall on this 2-core machine fills it, its clients taking half of it).
HALL = 150


@dataclasses.dataclass(frozen=True)
class Goal:
    """``value <= bound`` (``at_most``) or ``value >= bound``, with ``bound`` a field of
    :class:`Bounds` (None: the figure is a yes/no, met when its value is 1). ``template``
    shows the goal, formatted with the bound times ``scale``. ``rates``: for a frame rate the
    server and its clients share the machine for, the keys of the figure's detail holding the
    rate the server could give with the machine to itself and the rate beside the clients
    (:meth:`clients_limit`)."""

    bound: str | None
    at_most: bool
    template: str
    scale: float = 1.0
    rates: tuple[str, str] | None = None

    def clients_limit(self, detail: dict[str, float], bounds: Bounds) -> bool:
        """Whether a frame rate below its bound is the clients' doing: the server alone could
        give the bound on this machine, and not beside the clients (NaN: not measured)."""
        if self.rates is None or self.bound is None or self.at_most:
            return False
        alone, beside = (detail.get(key, math.nan) for key in self.rates)
        bound = float(getattr(bounds, self.bound)) * self.scale
        return alone >= bound > beside

    def describe(self, bounds: Bounds) -> str:
        if self.bound is None:
            return self.template
        return self.template.format(getattr(bounds, self.bound) * self.scale)

    def met(self, value: float, bounds: Bounds) -> bool:
        if math.isnan(value):
            return False  # not measured: not shown to be met
        if self.bound is None:
            return value >= 1.0
        bound = float(getattr(bounds, self.bound))
        return value <= bound if self.at_most else value >= bound


def at_least(
    bound: str, template: str, scale: float = 1.0, rates: tuple[str, str] | None = None
) -> Goal:
    return Goal(bound, False, template, scale, rates)


def at_most(bound: str, template: str, scale: float = 1.0) -> Goal:
    return Goal(bound, True, template, scale)


#: The goal of a phase's "completed" figure: a phase that could not run misses it.
COMPLETES = Goal(None, False, "completes")


@dataclasses.dataclass(frozen=True)
class Figure:
    """``value`` is what the goal compares, ``text`` what the table shows; ``detail`` holds
    the counts behind it (clients, moves, visits, messages), for the tests and for reading."""

    phase: str
    name: str
    value: float
    text: str
    goal: Goal | None = None
    detail: dict[str, float] = dataclasses.field(default_factory=dict)

    def verdict(self, bounds: Bounds) -> str:
        """ "met", "MISSED", "clients" (missed, but the clients, not the server, are the limit:
        :meth:`Goal.clients_limit`), or "" for a figure without a goal."""
        if self.goal is None:
            return ""
        if self.goal.met(self.value, bounds):
            return "met"
        return "clients" if self.goal.clients_limit(self.detail, bounds) else "MISSED"


def info(phase: str, name: str, text: str, **detail: float) -> Figure:
    """A figure without a goal."""
    return Figure(phase, name, math.nan, text, None, detail)


def missed(figures: list[Figure], bounds: Bounds) -> list[Figure]:
    return [f for f in figures if f.verdict(bounds) == "MISSED"]


def exit_status(figures: list[Figure], bounds: Bounds) -> int:
    """0 when every goal is met (and there was something to judge), else 1."""
    judged = [f for f in figures if f.goal is not None]
    return 0 if judged and not missed(figures, bounds) else 1


def format_table(figures: list[Figure], bounds: Bounds) -> str:
    rows = [("phase", "figure", "value", "goal", "")]
    for f in figures:
        goal = f.goal.describe(bounds) if f.goal is not None else ""
        rows.append((f.phase, f.name, f.text, goal, f.verdict(bounds)))
    widths = [max(len(r[i]) for r in rows) for i in range(4)]
    lines = []
    for k, row in enumerate(rows):
        cells = [row[i].ljust(widths[i]) for i in range(4)]
        lines.append("  ".join([*cells, row[4]]).rstrip())
        if k == 0:
            lines.append("  ".join("-" * w for w in widths))
    return "\n".join(lines)


def percentile(values: list[float], q: float) -> float:
    """The ``q``-quantile (0..1) by nearest rank; NaN for no values. A ``q`` outside 0..1 (a
    percentage, 95 for 0.95, would read as the largest value) is a ValueError."""
    if not 0.0 <= q <= 1.0:
        raise ValueError(f"percentile: q is a fraction from 0 to 1, not {q!r}")
    ordered = sorted(values)
    if not ordered:
        return math.nan
    k = min(len(ordered) - 1, max(0, math.ceil(q * len(ordered)) - 1))
    return ordered[k]
