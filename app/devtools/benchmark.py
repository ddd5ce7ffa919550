"""Benchmark of the live app: ``poinsot benchmark [--clients 1 20] [--seconds 5]`` (also
``python -m poinsot.app.devtools.benchmark``).

For each number of connected clients it starts a real Poinsot server in this process and the clients
in a *separate* process (so that their decoding does not count as server time). The clients are
:class:`poinsot.app.devtools.probe.Probe` websockets speaking viser's protocol like a browser.
It prints:

- server time per client-frame, two ways: the CPU time of the session's frame thread per
  frame (everything Poinsot does for a client-frame: physics, scene updates, plot and time
  readout, and viser's setters that queue the messages), mean and p95; and the whole server
  process's CPU time (that, plus viser's asyncio transport: serialisation, compression and the
  websocket sends) divided by the frames drawn for all clients; also the wall time of one
  frame in a session's thread (median, p95);
- bytes and messages per frame: what one client receives per frame drawn for it, everything
  (poses, trace increments, labels, the plot at 10 Hz and the time readout: one frame is one
  websocket message), and its viser messages, all and the scene's alone; and the frames the
  session skipped because the client had not yet taken the ones before
  (:mod:`poinsot.app.live.hardening.pacing`);
- slider-to-redraw time: from a client sending a slider value to that client receiving the new
  ellipsoid (the scale of ``/space/body/ellipsoid``), median and p95, and the server's
  rebuild time alone;
- the twins' frame cost: the CPU time of one frame of the ``dzhanibekov`` scene in the thread
  that draws it, with its twin (a second handle at ε′ = ε/10) over without (:func:`twins_cost`).

Targets: <= 1 ms per client-frame, <= 30 ms per redraw, twins <= 1.6 x a single body. Then the
drag rows (:mod:`poinsot.app.devtools.drag_benchmark`): a drag update on the ellipsoid to its
polhode drawn, p95 <= 50 ms with one client, <= 100 ms with ten on two workers; ``poinsot benchmark
--drag`` runs them alone.

``poinsot benchmark --video`` instead films the video row (:func:`video_row`): 10 s of the
T-handle at 1280x720 and 25 frames per second as MP4 (``poinsot video``'s pipeline: headless
Chromium renders, imageio-ffmpeg encodes) and prints the seconds per rendered frame, the whole
time and the file's size. Targets: <= 3 minutes and <= 5 MB.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import multiprocessing as mp
import os
import statistics
import sys
import time
from collections.abc import Callable, Sequence
from multiprocessing.connection import Connection
from typing import TYPE_CHECKING, Any

from poinsot.app.cli.arguments import positive_float, positive_int

if TYPE_CHECKING:
    from poinsot.app.devtools.probe import Probe

#: Values the benchmark's slider alternates between (I2 of the default preset: valid bodies).
SLIDER_LABEL = "I₂"
SLIDER_VALUES = (1.7, 1.9)


def _percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    if not ordered:
        return float("nan")
    k = min(len(ordered) - 1, max(0, round(q * (len(ordered) - 1))))
    return ordered[k]


# -- the client process ----------------------------------------------------------------------
def _clients_main(port: int, count: int, seconds: float, redraws: int, conn: Connection) -> None:
    """Runs in a child process: connect, measure traffic, then measure slider round trips."""
    from poinsot.app.devtools.probe import Probe

    probes = [Probe(port, keep_batches=True) for _ in range(count)]
    for probe in probes:
        if not probe.wait_for(
            lambda p: "/space/body/ellipsoid" in p.nodes and p.has_widget(SLIDER_LABEL), 60
        ):
            conn.send(("error", "a client never received the scene"))
            return
    conn.send(("ready", None))
    assert conn.recv() == "go"
    conn.send(("traffic", _traffic(probes, seconds)))
    assert conn.recv() == "redraw"
    conn.send(("latencies", _slider_latencies(probes, redraws)))
    for probe in probes:
        probe.close()


def _traffic(probes: list[Probe], seconds: float) -> list[tuple[int, int, int, int]]:
    """(bytes, websocket messages, viser messages, scene messages) each probe receives in
    ``seconds``."""
    start = [len(p.batches) for p in probes]
    time.sleep(seconds)
    traffic = []
    for probe, n0 in zip(probes, start, strict=True):
        batches = probe.batches[n0:]
        total = sum(b.nbytes for b in batches)
        messages = sum(len(b.types) for b in batches)
        scene = sum(1 for b in batches for kind in b.types if not kind.startswith("Gui"))
        traffic.append((total, len(batches), messages, scene))
    return traffic


def _slider_latencies(probes: list[Probe], redraws: int) -> list[float]:
    """Seconds from a probe moving the slider to the same probe receiving the new ellipsoid;
    the probes take turns at the slider."""
    latencies: list[float] = []
    arrivals: dict[int, float] = {}

    def listener_for(index: int) -> Callable[[dict[str, Any], float], None]:
        def listener(message: dict[str, Any], arrived: float) -> None:
            if (
                message["type"] == "SceneNodeUpdateMessage"
                and message.get("name") == "/space/body/ellipsoid"
                and "scale" in message.get("updates", {})
            ):
                arrivals.setdefault(index, arrived)

        return listener

    count = len(probes)
    for i, probe in enumerate(probes):
        probe.add_listener(listener_for(i))
    for k in range(redraws):
        index = k % count
        probe = probes[index]
        uuid, _ = probe.widget(SLIDER_LABEL)
        value = SLIDER_VALUES[k % 2] if count == 1 else SLIDER_VALUES[(k // count) % 2]
        arrivals.pop(index, None)
        sent = time.perf_counter()
        probe.set_value(uuid, value)
        deadline = sent + 5.0
        while index not in arrivals and time.perf_counter() < deadline:
            time.sleep(0.0005)
        if index in arrivals:
            latencies.append(arrivals[index] - sent)
        time.sleep(0.12)
    return latencies


# -- the server side ---------------------------------------------------------------------------
@dataclasses.dataclass
class Result:
    clients: int
    cpu_per_client_frame_ms: float
    frame_cpu_mean_ms: float
    frame_cpu_p95_ms: float
    frame_wall_median_ms: float
    frame_wall_p95_ms: float
    frames_per_second_per_client: float
    skipped_per_second_per_client: float
    bytes_per_frame: float
    messages_per_frame: float
    scene_messages_per_frame: float
    redraw_median_ms: float
    redraw_p95_ms: float
    rebuild_median_ms: float
    rebuild_p95_ms: float


def run(clients: int, seconds: float = 5.0, redraws: int = 30) -> Result:
    from poinsot.app.live.server import PoinsotApp

    app = PoinsotApp("127.0.0.1", 0)
    ctx = mp.get_context("spawn")
    parent, child = ctx.Pipe()
    proc = ctx.Process(target=_clients_main, args=(app.port, clients, seconds, redraws, child))
    proc.start()
    try:
        kind, payload = parent.recv()
        if kind == "error":
            raise RuntimeError(payload)
        sessions = app.wait_for_sessions(clients, 30)
        time.sleep(1.0)  # past the connection burst
        for s in sessions:
            s.stats.frame_seconds.clear()
            s.stats.frame_cpu_seconds.clear()
        frames0 = {id(s): s.stats.frames for s in sessions}
        skipped0 = sum(s.pacer.stats.skipped for s in sessions)
        cpu0, wall0 = time.process_time(), time.perf_counter()
        parent.send("go")
        kind, traffic = parent.recv()
        cpu1, wall1 = time.process_time(), time.perf_counter()
        frames = {id(s): s.stats.frames - frames0[id(s)] for s in sessions}
        skipped = sum(s.pacer.stats.skipped for s in sessions) - skipped0
        total_frames = sum(frames.values())
        frame_walls = [x for s in sessions for x in s.stats.frame_seconds]
        frame_cpus = [x for s in sessions for x in s.stats.frame_cpu_seconds]
        for s in sessions:
            s.stats.rebuild_seconds.clear()
        parent.send("redraw")
        kind, latencies = parent.recv()
        rebuilds = [x for s in sessions for x in s.stats.rebuild_seconds]
        proc.join(30)
    finally:
        if proc.is_alive():
            proc.terminate()
        app.stop()
    per_client_frames = total_frames / clients
    elapsed = wall1 - wall0
    per_frame = max(per_client_frames, 1)
    return Result(
        clients=clients,
        cpu_per_client_frame_ms=1e3 * (cpu1 - cpu0) / max(total_frames, 1),
        frame_cpu_mean_ms=1e3 * statistics.fmean(frame_cpus),
        frame_cpu_p95_ms=1e3 * _percentile(frame_cpus, 0.95),
        frame_wall_median_ms=1e3 * statistics.median(frame_walls),
        frame_wall_p95_ms=1e3 * _percentile(frame_walls, 0.95),
        frames_per_second_per_client=per_client_frames / elapsed,
        skipped_per_second_per_client=skipped / clients / elapsed,
        bytes_per_frame=statistics.mean(t[0] for t in traffic) / per_frame,
        messages_per_frame=statistics.mean(t[2] for t in traffic) / per_frame,
        scene_messages_per_frame=statistics.mean(t[3] for t in traffic) / per_frame,
        redraw_median_ms=1e3 * statistics.median(latencies) if latencies else float("nan"),
        redraw_p95_ms=1e3 * _percentile(latencies, 0.95),
        rebuild_median_ms=1e3 * statistics.median(rebuilds) if rebuilds else float("nan"),
        rebuild_p95_ms=1e3 * _percentile(rebuilds, 0.95),
    )


def _probe_main(port: int, seconds: float) -> None:
    """Child process of :func:`viser_floor`: one headless client that just listens."""
    from poinsot.app.devtools.probe import Probe

    Probe(port)
    time.sleep(seconds)


def viser_floor(seconds: float = 4.0) -> float:
    """Server CPU per frame [ms] of a bare viser server sending one pose per frame at 60 Hz.

    The same client, transport and machine as :func:`run`, with no Poinsot code: the part of
    the per-client-frame figure that viser's message path costs by itself, measured in this run
    so that the ratio is meaningful on a noisy machine.
    """
    import threading

    import numpy as np
    import viser

    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    connected: list[Any] = []
    ready = threading.Event()

    @server.on_client_connect
    def _(client) -> None:
        connected.append((client, client.scene.add_frame("/pose", show_axes=False)))
        ready.set()

    proc = mp.get_context("spawn").Process(
        target=_probe_main, args=(server.get_port(), seconds + 4.0)
    )
    proc.start()
    try:
        if not ready.wait(30):
            raise RuntimeError("the floor client never connected")
        time.sleep(1.0)
        client, frame = connected[0]
        n, cpu0, t0 = 0, time.process_time(), time.perf_counter()
        while time.perf_counter() - t0 < seconds:
            with client.atomic():
                frame.wxyz = np.array([math.cos(0.01 * n), 0.0, math.sin(0.01 * n), 0.0])
            n += 1
            time.sleep(1.0 / 60.0)
        return 1e3 * (time.process_time() - cpu0) / max(n, 1)
    finally:
        proc.join(seconds + 30)
        if proc.is_alive():
            proc.terminate()
        server.stop()


def twins_cost(frames: int = 600, rounds: int = 5) -> tuple[float, float]:
    """CPU per frame [ms] of the ``dzhanibekov`` scene without and with its twin (medians).

    Each round advances a stage of each through ``frames`` frames at the scene's speed and 60
    frames per second (rounds alternate, so that a busy machine slows both alike); the time is
    that of the thread that draws (physics batches, rows picked, messages queued), as the
    per-client-frame figure above.
    """
    from poinsot.app.lessons import scene_by_name
    from poinsot.app.stage.scene_stage import SceneStage

    spec = scene_by_name("dzhanibekov")
    dt = spec.speed / 60.0
    costs: dict[float, list[float]] = {0.0: [], 10.0: []}
    stages = {r: SceneStage(spec, {**spec.defaults(), "twin-ratio": r}) for r in costs}
    try:
        for _ in range(rounds):
            for ratio, stage in stages.items():
                stage.restart(0.0)
                t0 = time.thread_time()
                for k in range(1, frames + 1):
                    stage.advance(k * dt)
                costs[ratio].append(1e3 * (time.thread_time() - t0) / frames)
    finally:
        for stage in stages.values():
            stage.stop()
    return statistics.median(costs[0.0]), statistics.median(costs[10.0])


def format_result(r: Result) -> str:
    return "\n".join(
        [
            f"clients: {r.clients}",
            f"  server time per client-frame: {r.frame_cpu_mean_ms:7.3f} ms CPU in the session "
            f"thread (mean; p95 {r.frame_cpu_p95_ms:.3f} ms)   (target <= 1 ms)",
            f"  whole process per client-frame: {r.cpu_per_client_frame_ms:5.3f} ms CPU "
            "(the above plus viser's transport thread)",
            f"  frame in session thread     : median {r.frame_wall_median_ms:.3f} ms, "
            f"p95 {r.frame_wall_p95_ms:.3f} ms (wall)",
            f"  frames per second per client: {r.frames_per_second_per_client:7.1f}"
            f"        (cap 60; {r.skipped_per_second_per_client:.1f}/s skipped, not yet taken)",
            f"  bytes sent per frame        : {r.bytes_per_frame:7.0f} B  (everything: poses, "
            "traces, labels, plot 10 Hz, time 5 Hz)   (target <= 2 kB)",
            f"  messages per frame          : {r.messages_per_frame:7.2f}    (scene "
            f"{r.scene_messages_per_frame:.2f}: 3 poses + a trace increment every 4th frame)",
            f"  slider-to-redraw            : median {r.redraw_median_ms:.1f} ms, "
            f"p95 {r.redraw_p95_ms:.1f} ms   (target <= 30 ms)",
            f"  server rebuild alone        : median {r.rebuild_median_ms:.2f} ms, "
            f"p95 {r.rebuild_p95_ms:.2f} ms",
        ]
    )


#: The video row: what it films, and its targets.
VIDEO_PRESET, VIDEO_SECONDS, VIDEO_SIZE, VIDEO_FPS = "t_handle", 10.0, (1280, 720), 25.0
VIDEO_MAX_SECONDS, VIDEO_MAX_MB = 180.0, 5.0


def video_row() -> str:
    """Film the benchmark's clip (MP4, in a temporary folder) and describe it in one line."""
    import tempfile
    from pathlib import Path

    from poinsot.app.construction.cameras import space_view
    from poinsot.app.exports.chromium import find_chromium
    from poinsot.app.exports.screenshot import THEME_BACKGROUND, open_stage
    from poinsot.app.exports.video import Clip, film
    from poinsot.app.model.presets import preset_by_key

    preset = preset_by_key(VIDEO_PRESET)
    clip = Clip(VIDEO_SECONDS, VIDEO_FPS, VIDEO_SIZE, speed=preset.speed)
    with tempfile.TemporaryDirectory() as folder:
        made = film(
            lambda client_of: open_stage(preset, dark_mode=True, client_of=client_of),
            clip,
            space_view("default"),
            Path(folder) / "clip.mp4",
            chromium=find_chromium(),
            background=THEME_BACKGROUND[True],
        )
    width, height = VIDEO_SIZE
    return (
        f"video ({VIDEO_PRESET}, {VIDEO_SECONDS:g} s at {width}x{height}, {VIDEO_FPS:g} fps, MP4): "
        f"{made.seconds_per_frame:.3f} s per rendered frame, {made.seconds:.0f} s in all "
        f"(target <= {VIDEO_MAX_SECONDS:.0f} s), {made.bytes / 1e6:.2f} MB "
        f"(target <= {VIDEO_MAX_MB:g} MB)"
    )


def main(
    clients: Sequence[int] = (1, 20),
    seconds: float = 5.0,
    redraws: int = 30,
    video: bool = False,
    drag: bool = False,
) -> int:
    """Run the benchmark for each number of ``clients`` and print the results, then the drag
    rows and the twins' row (with ``video``: the video row alone; with ``drag``: the drag rows
    alone)."""
    from poinsot.app.devtools.drag_benchmark import main as drag_main

    print(
        f"Poinsot app benchmark (python {sys.version.split()[0]}, {os.cpu_count()} CPUs, "
        f"load average {os.getloadavg()[0]:.1f})"
    )
    if video:
        print(video_row(), flush=True)
        return 0
    if drag:
        drag_main()
        return 0
    for n in clients:
        print(format_result(run(n, seconds, redraws)), flush=True)
    drag_main()  # the drag rows (:mod:`poinsot.app.devtools.drag_benchmark`)
    print(
        f"viser floor: a bare viser server sending one pose per frame costs "
        f"{viser_floor():.3f} ms CPU per client-frame here (no Poinsot code)"
    )
    single, twins = twins_cost()
    print(
        f"twins (dzhanibekov, ε′ = ε/10): {twins:.3f} ms CPU per frame against {single:.3f} ms "
        f"for one body: {twins / single:.2f}x   (target <= 1.6x)"
    )
    return 0


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the benchmark's options on ``parser`` (``poinsot benchmark``'s, or this module's
    own when run with ``python -m``)."""
    parser.add_argument(
        "--clients",
        type=positive_int,
        nargs="+",
        default=[1, 20],
        help="browsers per run, one run each",
    )
    parser.add_argument("--seconds", type=positive_float, default=5.0, help="steady-state window")
    parser.add_argument("--redraws", type=positive_int, default=30, help="slider moves per run")
    parser.add_argument(
        "--video",
        action="store_true",
        help="instead, film 10 s at 1280x720 (poinsot video): seconds per frame and MB",
    )
    parser.add_argument(
        "--drag",
        action="store_true",
        help="only the drag rows: a drag update to its polhode drawn, 1 and 10 clients",
    )
    parser.set_defaults(func=main)


if __name__ == "__main__":
    _parser = argparse.ArgumentParser(prog="python -m poinsot.app.devtools.benchmark")
    add_arguments(_parser)
    _args = _parser.parse_args()
    raise SystemExit(main(_args.clients, _args.seconds, _args.redraws, _args.video, _args.drag))
