"""The hostile phase: a student's script tries what a browser never does, an innocent client plays.

A child process (the barrage) replays every crafted input of
:mod:`poinsot.app.devtools.load.crafted`: refused handshakes (two or no ``Host``, DNS rebinding,
foreign and null origins) ``--hostile-handshakes`` times, then messages viser's client never sends
(a share request, unknown types, wrong field types, deep nesting, invalid UTF-8, an unsolicited
render, oversized values) and HTTP/1.0 requests. Then a client of this process sends crafted GUI
inputs (out of range, NaN, wrong types, another client's widget ids, a 1 MB string, an upload to
a slider).

Counted: each outcome, the tracebacks and share-tunnel lines in the server's log, the
connections viser still holds once the hostile clients are gone, the server's memory after the
bad handshakes against before them (after a warm-up of a tenth as many), and the frames of an
innocent client during the bad handshakes against its frames before and after (their mean). The
barrage runs at the lowest CPU priority, as if from another machine, and spreads its handshakes
over as long as each reference window (``--hostile-quiet-seconds``), so that the three windows
are alike: a sustained attack, not a blip that the frame pacing would smooth or exaggerate.

The handshakes come first and alone in the measured window: the crafted messages each open a
session, and the memory those sessions hold until they are collected (measured: 13 MB for a
moment on a 145 MB server) is not the handshakes', and made the figure range from +1.8 to +10 %
when the window held both (the storm phase measures sessions come and gone, once settled).
"""

from __future__ import annotations

import math
import os
import threading
import time
from collections import Counter
from multiprocessing.connection import Connection
from typing import Any

import websockets

from poinsot.app.devtools.load import crafted, procfs
from poinsot.app.devtools.load.children import Child
from poinsot.app.devtools.load.config import Config, Report, Say
from poinsot.app.devtools.load.figures import COMPLETES, Figure, at_least, at_most, info
from poinsot.app.devtools.load.server_process import ServerProcess
from poinsot.app.devtools.probe import Probe
from poinsot.app.live.hardening.guard import MESSAGE_BURST, MESSAGE_RATE
from poinsot.app.viser_private import wire_message

PHASE = "hostile"
#: Each crafted message is sent this many times, each HTTP/1.0 request too.
ROUNDS = 3
#: Values no browser sends for a widget (the GUI's crafted inputs).
JUNK: list[Any] = [math.nan, -math.inf, 1e300, "abc", None, [1, 2]]
#: The crafted GUI inputs keep within half the message budget (the budget is the flood phase's
#: matter: a message beyond it is dropped unread, and a dropped 1 MB string would close nothing).
PACE = MESSAGE_RATE / 2
FREE = MESSAGE_BURST / 2


def _barrage_main(
    conn: Connection, port: int, handshakes: int, seconds: float, lifetime: float
) -> None:
    """The child: warm up, report, wait for ``go``, make the bad handshakes and report them,
    then replay the rest and report its outcomes.
    It runs at the lowest priority: a student's script runs on the student's laptop, so its
    own CPU is not the server's to pay (on loopback it would be, on two cores most of one)."""
    os.nice(19)
    deadline = time.monotonic() + lifetime
    crafted.bad_handshakes(port, max(1, handshakes // 10))
    conn.send(("warm", None))
    if not conn.poll(max(0.0, deadline - time.monotonic())) or conn.recv() != "go":
        return
    conn.send(("handshakes", crafted.bad_handshakes(port, handshakes, seconds)))
    messages: Counter[str] = Counter()
    for _ in range(ROUNDS):
        for payload in crafted.MESSAGES.values():
            messages[crafted.send_message(port, payload)] += 1
    http10 = Counter(crafted.exchange(port, r) for r in crafted.HTTP10.values() for _ in "abc")
    conn.send(("done", {"messages": messages, "http10": http10}))
    if conn.poll(max(0.0, deadline - time.monotonic())):
        conn.recv()
    conn.send(("stopped", None))


class FrameCount:
    """The body's poses one probe has received (a listener on its receiver thread)."""

    def __init__(self, probe: Probe) -> None:
        self.frames = 0
        self._lock = threading.Lock()
        probe.add_listener(self._seen)

    def _seen(self, message: dict[str, Any], _at: float) -> None:
        if message["type"] == "SetOrientationMessage" and message.get("name") == "/space/body":
            with self._lock:
                self.frames += 1

    def rate(self, seconds: float) -> float:
        """Frames a second over the next ``seconds``."""
        start = self.frames
        time.sleep(seconds)
        return (self.frames - start) / seconds


class _Paced:
    """Sends no faster than the budget refills: the first :data:`FREE` at once, then
    :data:`PACE` a second."""

    def __init__(self, probe: Probe, outcomes: Counter[str]) -> None:
        self.probe, self.outcomes = probe, outcomes
        self._start = time.monotonic()

    def __call__(self, message: Any) -> None:
        due = self._start + max(0.0, self.outcomes["sent"] - FREE) / PACE
        time.sleep(max(0.0, due - time.monotonic()))
        self.probe.send(message)
        self.outcomes["sent"] += 1


def _crafted_gui(port: int, innocent: Probe) -> Counter[str]:
    """A client of its own sends every junk value to every input, values for the innocent
    client's widgets, an upload to a slider, then a 1 MB string (closes it); the outcomes."""
    outcomes: Counter[str] = Counter()
    with Probe(port, keep_batches=False) as hostile:
        if not hostile.wait_frames(1, 30):
            return Counter({"no session": 1})
        own = list(hostile.snapshot()[1])
        slider = own[0] if own else "x"
        send = _Paced(hostile, outcomes)
        try:
            for uuid in own:
                for junk in JUNK:
                    send(wire_message("GuiUpdateMessage", uuid, {"value": junk}))
            for uuid in innocent.snapshot()[1]:  # another client's widgets
                send(wire_message("GuiUpdateMessage", uuid, {"value": 0.0}))
            send(wire_message("FileTransferStartUpload", slider, "t", "a.stl", "x", 3, 3_000_000))
            for k in range(3):
                send(wire_message("FileTransferPart", slider, "t", k, b"\0" * 1_000_000))
            send(wire_message("GuiUpdateMessage", slider, {"value": "x" * 1_000_000}))
        except websockets.ConnectionClosed:
            outcomes["closed early"] += 1
        closed = hostile.wait_for(lambda p: p.closed, 60)
        code = hostile.close_code if closed else None
        outcomes["closed 1008" if code == 1008 else f"closed {code}" if closed else "open"] += 1
    return outcomes


def phase(server: ServerProcess, cfg: Config, report: Report, say: Say) -> None:
    port = server.port
    with Probe(port, keep_batches=False) as innocent:
        count = FrameCount(innocent)
        if not innocent.wait_frames(10, 60):
            raise RuntimeError("the innocent client got no frames")
        before = count.rate(cfg.hostile_quiet_seconds)
        barrage = (port, cfg.hostile_handshakes, cfg.hostile_quiet_seconds, cfg.lifetime)
        with Child("barrage", _barrage_main, *barrage) as child:
            child.receive(300.0, "the barrage's warm-up")
            first = procfs.usage(server.pid)
            say(f"{PHASE}: the barrage ({cfg.hostile_handshakes} bad handshakes)")
            frames = count.frames
            handshook: Counter[str] = child.request("go", 600.0, "the bad handshakes")
            last = procfs.usage(server.pid)
            during = (count.frames - frames) / (last.at - first.at)
            outcomes: dict[str, Counter[str]] = child.receive(600.0, "the crafted messages")
            outcomes["handshakes"] = handshook
        after = count.rate(cfg.hostile_quiet_seconds)
        say(f"{PHASE}: crafted GUI inputs")
        gui = _crafted_gui(port, innocent)
        connections = _settled_connections(server, 1, 20.0)
        unhurt = _unhurt(server.status()["session_errors"], innocent)
    report.add(*_outcome_figures(outcomes, gui, unhurt))
    report.add(*_log_figures(server.log_path.read_text(errors="replace"), connections))
    report.add(_memory(first.rss_bytes, last.rss_bytes, cfg.hostile_handshakes))
    report.add(_keep(before, during, after))
    busy = procfs.cpu_percent(first, last)
    text = f"{busy:.0f} % of a core for {last.at - first.at:.1f} s (frames and the refusals)"
    report.add(info(PHASE, "server CPU during the bad handshakes", text, cpu_percent=busy))


def _unhurt(session_errors: int, innocent: Probe) -> str:
    """The word "yes" when no session raised and the innocent client, still open, gets 5 more frames
    (within a minute: its reader shares a busy machine); else what went wrong."""
    wrong = [f"{session_errors} session error(s)"] if session_errors else []
    if innocent.closed:  # no frame to wait for
        wrong.append(f"the innocent client was closed ({innocent.close_code})")
    elif not innocent.wait_frames(5, 60):
        closed = f", then closed ({innocent.close_code})" if innocent.closed else ""
        wrong.append(f"the innocent client got fewer than 5 frames in 60 s{closed}")
    return "; ".join(wrong) or "yes"


def _outcome_figures(
    outcomes: dict[str, Counter[str]], gui: Counter[str], unhurt: str
) -> list[Figure]:
    rows = [
        ("crafted messages closed (1008)", outcomes["messages"], "closed 1008"),
        ("bad handshakes refused (403)", outcomes["handshakes"], "403"),
        ("HTTP/1.0 GETs answered (200)", outcomes["http10"], "200"),
    ]
    figures = []
    for name, counts, good in rows:
        total = sum(counts.values())
        others = ", ".join(f"{n} {k}" for k, n in counts.items() if k != good)
        text = f"{counts[good]}/{total}" + (f" ({others})" if others else "")
        value = 1.0 if total and counts[good] == total else 0.0
        figures.append(Figure(PHASE, name, value, text, COMPLETES))
    closed = gui["closed 1008"] == 1
    ends = ", ".join(f"{k} {n}" for k, n in gui.items() if k != "sent")
    text = f"{gui['sent']} sent ({ends}); sender closed (1008) at the end: {closed}; " + (
        f"others unhurt: {unhurt}"
    )
    passed = closed and unhurt == "yes"
    figures.append(Figure(PHASE, "crafted GUI inputs", float(passed), text, COMPLETES))
    return figures


def _log_figures(log: str, connections: int) -> list[Figure]:
    zero = at_most("max_errors", "<= {:g}")
    tracebacks, share = log.count("Traceback"), log.count("Share URL")
    return [
        Figure(PHASE, "tracebacks in the server's log", float(tracebacks), str(tracebacks), zero),
        Figure(PHASE, "share tunnel requests reaching viser", float(share), str(share), zero),
        Figure(
            PHASE,
            "leaked connections",
            float(connections - 1),
            f"{connections - 1} (viser holds {connections} for the 1 client left)",
            zero,
        ),
    ]


def _memory(before: int, after: int, handshakes: int) -> Figure:
    growth = after / before - 1.0 if before else math.nan
    return Figure(
        PHASE,
        f"server memory after {handshakes} bad handshakes",
        growth,
        f"{growth:+.1%} ({before / 1e6:.0f} -> {after / 1e6:.0f} MB)",
        at_most("max_hostile_rss_growth", "<= {:g} %", 100.0),
    )


def _keep(before: float, during: float, after: float) -> Figure:
    """The innocent client's frames during the bad handshakes against the mean of before and
    after."""
    reference = 0.5 * (before + after)
    keep = during / reference if reference > 0 else math.nan
    return Figure(
        PHASE,
        "innocent client's frame rate",
        keep,
        f"{keep:.0%} ({during:.1f} fps during, {before:.1f} before, {after:.1f} after)",
        at_least("min_innocent_keep", ">= {:g} %", 100.0),
    )


def _settled_connections(server: ServerProcess, expected: int, timeout: float) -> int:
    """The connections viser holds, once they are down to ``expected`` (or ``timeout``)."""
    deadline = time.monotonic() + timeout
    while True:
        connections: int = server.status()["connections"]
        if connections <= expected or time.monotonic() >= deadline:
            return connections
        time.sleep(0.25)
