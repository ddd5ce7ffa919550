"""A classroom of headless browsers in a child process of its own.

The child connects ``count`` :class:`poinsot.app.devtools.probe.Probe` websockets (each
decodes everything it receives and keeps the scene as a browser would draw it) and then measures on
request, in windows:

- **frames**: the scene-pose messages each client receives (the orientation of
  ``/space/body``, sent once per frame drawn; viser replaces an unsent pose by a newer one, so
  this counts the frames a browser could show), counted per client as they arrive;
- **slider-to-redraw**: every ``slider_period`` seconds one client (in turn) moves the I₂
  slider, and the time until the same client receives the rebuilt ellipsoid (its new scale) is
  taken; a redraw that does not come within :data:`REDRAW_TIMEOUT` counts as lost;
- **silent clients**: clients (not stalled on purpose) that received no pose in the window's
  last :data:`SILENT_SECONDS` seconds: disconnected or starved.

Counting happens in a listener (no batch is kept), so the memory of a long soak stays flat.
"""

from __future__ import annotations

import dataclasses
import threading
import time
from multiprocessing.connection import Connection
from typing import TYPE_CHECKING, Any

from poinsot.app.devtools.load.children import Child

if TYPE_CHECKING:
    from poinsot.app.devtools.probe import Probe

#: The node whose orientation is sent once per frame (the body frame's attitude).
POSE_NODE = "/space/body"
#: The node whose new scale shows that a slider move has been redrawn.
REDRAW_NODE = "/space/body/ellipsoid"
#: The slider moved, and the two values it alternates between (valid for the default preset).
SLIDER_LABEL = "I₂"
SLIDER_VALUES = (1.7, 1.9)
REDRAW_TIMEOUT = 5.0
SILENT_SECONDS = 3.0
#: How long a client may take to receive its scene after connecting.
SCENE_TIMEOUT = 60.0


@dataclasses.dataclass
class _Client:
    """What the listener of one probe counts (written by the probe's receiver thread)."""

    poses: int = 0
    last_pose: float = 0.0  # perf_counter of the last pose
    redraws: int = 0
    last_redraw: float = 0.0
    redrawn: threading.Event = dataclasses.field(default_factory=threading.Event)
    stalled: bool = False
    slider: float | None = None  # the value this client last gave the slider

    def listener(self, message: dict[str, Any], arrived: float) -> None:
        kind = message["type"]
        name = message.get("name")
        if kind == "SetOrientationMessage" and name == POSE_NODE:
            self.poses += 1
            self.last_pose = arrived
        elif (
            kind == "SceneNodeUpdateMessage"
            and name == REDRAW_NODE
            and "scale" in message.get("updates", {})
        ):
            self.redraws += 1
            self.last_redraw = arrived
            self.redrawn.set()


@dataclasses.dataclass
class Window:
    """What the clients received during one window."""

    seconds: float
    fps: list[float]  # per client (stalled clients included; see ``stalled``)
    stalled: list[bool]
    latencies: list[float]  # slider-to-redraw [s]; lost redraws are not in here
    lost_redraws: int
    silent: int  # clients not stalled that received nothing lately


def _slide(probe: Probe, client: _Client) -> float | None:
    """Move the slider to the other of SLIDER_VALUES; the seconds until the redraw arrives,
    None if it does not within REDRAW_TIMEOUT."""
    try:
        uuid, widget = probe.widget(SLIDER_LABEL)
    except KeyError:  # the panel is being redeclared: this move is lost
        return None
    # The server does not echo a value back to the client that set it: remember our own.
    previous = client.slider
    if previous is None:
        previous = float(widget.value) if widget.value is not None else SLIDER_VALUES[0]
    value = max(SLIDER_VALUES, key=lambda v: abs(v - previous))
    client.slider = value
    client.redrawn.clear()
    sent = time.perf_counter()
    probe.set_value(uuid, value)
    if not client.redrawn.wait(REDRAW_TIMEOUT):
        return None
    return client.last_redraw - sent


def _window(
    probes: list[Probe], clients: list[_Client], seconds: float, slider_period: float
) -> Window:
    poses0 = [c.poses for c in clients]
    start = time.perf_counter()
    end = start + seconds
    latencies: list[float] = []
    lost = 0
    turn = 0
    next_slide = start + slider_period if slider_period > 0 else float("inf")
    running = [i for i, c in enumerate(clients) if not c.stalled]
    while (now := time.perf_counter()) < end:
        if now >= next_slide and running:
            index = running[turn % len(running)]
            turn += 1
            latency = _slide(probes[index], clients[index])
            if latency is None:
                lost += 1
            else:
                latencies.append(latency)
            next_slide += slider_period
            continue
        time.sleep(max(0.0, min(next_slide, end) - time.perf_counter()))
    elapsed = time.perf_counter() - start
    now = time.perf_counter()
    return Window(
        seconds=elapsed,
        fps=[(c.poses - p0) / elapsed for c, p0 in zip(clients, poses0, strict=True)],
        stalled=[c.stalled for c in clients],
        latencies=latencies,
        lost_redraws=lost,
        silent=sum(1 for c in clients if not c.stalled and now - c.last_pose > SILENT_SECONDS),
    )


def _main(conn: Connection, port: int, count: int, lifetime: float) -> None:
    """The child: connect ``count`` clients, then serve window and stall requests."""
    from poinsot.app.devtools.probe import Probe
    from poinsot.app.live.landing import resolve

    deadline = time.monotonic() + lifetime
    probes: list[Probe] = []
    clients: list[_Client] = []
    try:
        for _ in range(count):
            client = _Client()
            probe = Probe(resolve(port), keep_batches=False)  # through a landing, if any
            probe.add_listener(client.listener)
            probes.append(probe)
            clients.append(client)
        for probe in probes:
            if not probe.wait_for(
                lambda p: REDRAW_NODE in p.nodes and p.has_widget(SLIDER_LABEL),
                max(1.0, min(SCENE_TIMEOUT, deadline - time.monotonic())),
            ):
                raise RuntimeError("a client never received its scene")
        conn.send(("ready", len(probes)))
        while time.monotonic() < deadline:
            if not conn.poll(0.5):
                continue
            request = conn.recv()
            if request == "stop":
                break
            kind, *args = request
            if kind == "window":
                conn.send(("window", _window(probes, clients, *args)))
            elif kind == "stall":
                index, stalled = args
                probes[index].stall(stalled)
                clients[index].stalled = stalled
                conn.send(("stalled", stalled))
    except EOFError:  # the tool is gone
        pass
    except Exception as exc:
        conn.send(("error", f"{type(exc).__name__}: {exc}"))
    finally:
        for probe in probes:
            probe.stall(False)
            probe.close()
    try:
        conn.send(("stopped", len(probes)))
    except OSError:
        pass


class Fleet(Child):
    """``count`` clients of the server on ``port``, in their own process."""

    def __init__(self, port: int, count: int, lifetime: float):
        super().__init__("clients", _main, port, count, lifetime)
        self.count = count
        self._window_timeout = 60.0
        self.receive(SCENE_TIMEOUT + 10.0 * count, f"{count} clients to receive their scene")

    def __enter__(self) -> Fleet:
        return self

    def begin_window(self, seconds: float, slider_period: float = 0.0) -> None:
        """Start measuring for ``seconds`` (moving a slider every ``slider_period`` s if > 0);
        :meth:`end_window` gives the result."""
        self._window_timeout = seconds + 2.0 * REDRAW_TIMEOUT + 60.0
        self.conn.send(("window", seconds, slider_period))

    def end_window(self) -> Window:
        result: Window = self.receive(self._window_timeout, "a measuring window")
        return result

    def window(self, seconds: float, slider_period: float = 0.0) -> Window:
        self.begin_window(seconds, slider_period)
        return self.end_window()

    def stall(self, index: int, stalled: bool = True) -> None:
        """Client ``index`` stops (or resumes) reading from its socket."""
        self.request(("stall", index, stalled), 30.0, "a stall")
