"""A lead and its followers, headless, in child processes of their own (the follow phase's
clients, :mod:`.following` and :mod:`.hosts`).

Each child process connects its share of the followers (``per`` at most: one interpreter decodes
only so many frames a second), the first one the lead before them; the lead types the lecturer
code and leads, every follower ticks "Follow the lecturer". Each client may connect from a
loopback address of its own (``sources``), so that a balancer that hashes the client's address
(nginx's ``hash $remote_addr``) sends it to the host chosen for it. Then every child answers the
parent's requests: its followers' poses counted, a lead's move and each follower's redraw of it
(its rebuilt ellipsoid), what they were told, exploring.
"""

from __future__ import annotations

import gc
import math
import time
from collections.abc import Sequence
from multiprocessing.connection import Connection
from typing import TYPE_CHECKING, Any

from poinsot.app.devtools.load.children import Child
from poinsot.app.devtools.load.fleet import SCENE_TIMEOUT, SLIDER_LABEL, SLIDER_VALUES
from poinsot.app.devtools.load.fleet import _Client as Counter

if TYPE_CHECKING:
    from poinsot.app.devtools.probe import Probe

FOLLOW_LABEL = "Follow the lecturer"
EXPLORE_LABEL = "Explore from here"
#: Words of the lecture tools' line of keys (:mod:`poinsot.app.live.lecture.lecture`).
READY_WORDS = "Keys: **space**"
#: A client's loopback address to connect from (None: the system's choice).
Source = str | None


def says(probe: Probe, words: str) -> bool:
    return any(words in str(w.props.get("_markdown", "")) for w in probe.widgets.values())


def _press(probe: Probe, label: str, value: Any = True) -> None:
    probe.set_value(probe.widget(label)[0], value)


def _ready(probe: Probe) -> bool:
    """The page is whole: its panel, and the lecture tools' line of keys, which the session
    mounts last (a widget arrives before its callback is bound: a press of the "Class" folder's
    buttons as soon as they show can be lost on a busy machine)."""
    return probe.has_widget(EXPLORE_LABEL) and says(probe, READY_WORDS)


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


def _followers(
    port: int, sources: Sequence[Source], deadline: float, probes: list[Probe]
) -> list[Probe]:
    """A client connected from each of ``sources``, each with its panel (also appended to
    ``probes``)."""
    from poinsot.app.devtools.probe import Probe
    from poinsot.app.live.landing import resolve

    made = []
    for source in sources:
        made.append(Probe(resolve(port), keep_batches=False, source=source))
        probes.append(made[-1])
    for probe in made:
        timeout = max(1.0, min(SCENE_TIMEOUT, deadline - time.monotonic()))
        if not probe.wait_for(_ready, timeout):
            raise RuntimeError("a client never received its panel")
    return made


def _lead(port: int, code: str, source: Source, deadline: float, probes: list[Probe]) -> Probe:
    (lead,) = _followers(port, [source], deadline, probes)
    _press(lead, "Lecturer code", code)
    _press(lead, "Lead this class")
    asked = time.monotonic()
    if not lead.wait_for(lambda p: says(p, "You lead this class"), SCENE_TIMEOUT):
        raise RuntimeError(f"the lead was refused ({_why(lead, asked)})")
    return lead


def _follow(followers: list[Probe]) -> None:
    for probe in followers:
        _press(probe, FOLLOW_LABEL)
    asked = time.monotonic()
    for probe in followers:
        if not probe.wait_for(lambda p: says(p, "Following the lecturer"), SCENE_TIMEOUT):
            raise RuntimeError(f"a follower never followed ({_why(probe, asked)})")


def _settle() -> None:
    """The connected clients' objects, out of this process's collector's scans: a whole-heap
    collection of 40 probes paused all of them 0.1 to 0.16 s, a delay the phase would count as
    the server's (each browser of a lecture hall is a process of its own)."""
    gc.collect()
    gc.freeze()


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
        if kind == "await":  # each follower's seconds from ``sent`` to its redraw (None: not)
            sent, timeout, which = args
            for c, waits in zip(self.counters, which, strict=True):
                if waits:
                    c.redrawn.wait(max(0.0, sent + timeout - time.perf_counter()))
            return [c.last_redraw - sent if c.redrawn.is_set() else None for c in self.counters]
        if kind == "told":  # whether each follower asked was told ``words`` within ``timeout``
            words, timeout, which = args
            return [
                bool(asked) and p.wait_for(lambda p: says(p, words), timeout)
                for p, asked in zip(self.followers, which, strict=True)
            ]
        if kind == "explore":
            for probe in self.followers:
                _press(probe, EXPLORE_LABEL)
            return all(p.wait_for(lambda p: says(p, "Exploring"), 60) for p in self.followers)
        raise ValueError(f"unknown request {kind!r}")


def _main(
    conn: Connection,
    port: int,
    code: str,
    sources: list[Source],
    lead: tuple[Source, ...],
    lifetime: float,
) -> None:
    """A client process: connect the lead (from ``lead``'s one source, if any) and a follower
    from each of ``sources``, follow; then answer requests."""
    deadline = time.monotonic() + lifetime
    probes: list[Probe] = []
    try:
        leading = _lead(port, code, lead[0], deadline, probes) if lead else None
        followers = _followers(port, sources, deadline, probes)
        _follow(followers)
        _settle()
        clients = _Clients(leading, followers)
        conn.send(("ready", len(sources)))
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
        conn.send(("stopped", len(sources)))
    except OSError:
        pass


class FollowFleet:
    """A lead and a follower from each of ``sources`` (loopback addresses; None: any) of the
    server on ``port``, ``per`` at most in a process, the lead (from ``lead_source``) in the
    first. The followers keep their order: every answer lists them as ``sources`` does."""

    def __init__(
        self,
        port: int,
        code: str,
        sources: Sequence[Source],
        per: int,
        lifetime: float,
        lead_source: Source = None,
    ):
        self.children: list[Child] = []
        self.sizes = chunks(len(sources), per)
        self.slider: float | None = None  # the value the lead last gave the slider
        count, start = len(sources), 0
        try:
            for i, size in enumerate(self.sizes):
                mine = list(sources[start : start + size])
                start += size
                lead = (lead_source,) if i == 0 else ()
                child = Child(f"followers-{i}", _main, port, code, mine, lead, lifetime)
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

    def _each(
        self, kind: str, args: tuple[Any, ...], which: Sequence[bool], timeout: float, what: str
    ) -> list[Any]:
        """``(kind, *args, mask)`` to every child, ``which``'s share of it as the mask; the
        answers, one per follower, in order."""
        start = 0
        for child, size in zip(self.children, self.sizes, strict=True):
            child.conn.send((kind, *args, list(which[start : start + size])))
            start += size
        return [x for child in self.children for x in child.receive(timeout, what)]

    def arm(self) -> None:
        """From now on, each follower's next redraw counts (:meth:`redraws`)."""
        self._all(("arm",), 60.0, "the followers armed")

    def move(self, value: float) -> float:
        """The lead moves the slider to ``value``: when it sent the move (``perf_counter``)."""
        sent: float = self.children[0].request(("move", value), 60.0, "a move")
        self.slider = value
        return sent

    def redraws(
        self, since: float, timeout: float, which: Sequence[bool] | None = None
    ) -> list[float | None]:
        """Each follower's seconds from ``since`` to its redraw after :meth:`arm` (None: not
        within ``timeout`` of ``since``); only the followers ``which`` says are waited for."""
        which = [True] * sum(self.sizes) if which is None else which
        return self._each("await", (since, timeout), which, timeout + 60.0, "the redraws")

    def told(self, words: str, timeout: float, which: Sequence[bool]) -> list[bool]:
        """Whether each follower ``which`` names was told ``words`` within ``timeout``."""
        return self._each("told", (words, timeout), which, timeout + 60.0, f"{words!r} told")

    def window(self, seconds: float, period: float, timeout: float) -> dict:
        """Frames over ``seconds``; every ``period`` from the start (0: never) a lead's move,
        lost if not redrawn on a follower within ``timeout`` (the next move waits for it, and
        is made at once if it is due). ``clients``: the client processes' CPU
        [cores]; ``redraws``: per move, each follower's seconds to its redraw (None: lost)."""
        first = self._all(("count",), 60.0, "the poses counted")
        start = time.perf_counter()
        end = due = start + seconds
        redraws: list[list[float | None]] = []
        while time.perf_counter() < end:
            if period > 0:  # a move every period from the start (at once if one was late)
                self.arm()
                sent = self.move(SLIDER_VALUES[(len(redraws) + 1) % 2])
                redraws.append(self.redraws(sent, timeout))
                due = start + len(redraws) * period
            time.sleep(max(0.0, min(due, end) - time.perf_counter()))
        last = self._all(("count",), 60.0, "the poses counted")
        fps: list[float] = []
        cpu = 0.0
        for (poses0, t0, cpu0), (poses1, t1, cpu1) in zip(first, last, strict=True):
            fps += [(b - a) / (t1 - t0) for a, b in zip(poses0, poses1, strict=True)]
            cpu += (cpu1 - cpu0) / (t1 - t0)
        return {
            "fps": fps,
            "latencies": [x for move in redraws for x in move if x is not None],
            "redraws": redraws,
            "moves": len(redraws),
            "seconds": time.perf_counter() - start,
            "clients": cpu,
        }

    def explore(self) -> bool:
        return all(self._all(("explore",), 120.0, "the followers to explore"))
