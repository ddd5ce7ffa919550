"""The soak: ``clients`` clients for ``seconds``, as a class would keep the app open.

Measured: the frames each client receives (p5, p50, and the worst client, which is judged),
the frames the server drew (so that a gap between drawn and received shows), slider-to-redraw
(a slider move every ``slider_period`` seconds), the server's CPU, resident memory and threads
over time (``/proc``, every second), the client process's CPU (if it were saturated, the frame
rates would be the clients' limit, not the server's), and errors: clients that went silent,
sessions the server lost, and (in :func:`run_phase`) error lines in the server's log.

The slider is moved by one of the clients, the *sensor*, in a process of its own, as a student's
browser runs on a machine of its own. The others share one process (a fleet): a message for one
of them waits there behind the other clients' frames for that process's one interpreter lock,
which a classroom does not have. Measured in the fleet, 30 clients on one server process gave a
slider p95 of 64 ms, of which 30 ms between the server's send and the fleet's decoding; measured
by the sensor, 38-57 ms over two runs (on this 2-core machine, the clients' processes on the same
cores).
"""

from __future__ import annotations

import math
import statistics
import time

from poinsot.app.devtools.load import procfs
from poinsot.app.devtools.load.config import MB, Config, Report, Say, warmup
from poinsot.app.devtools.load.figures import Figure, at_least, at_most, info, percentile
from poinsot.app.devtools.load.fleet import Fleet, Window
from poinsot.app.devtools.load.server_process import ServerProcess

P = "soak"


def phase(server: ServerProcess, cfg: Config, report: Report, say: Say) -> None:
    n = cfg.clients
    say(f"soak: connecting {n} clients ({n - 1} in one process, the sensor in its own)")
    with (
        Fleet(server.port, 1, cfg.lifetime) as sensor,
        Fleet(server.port, n - 1, cfg.lifetime) as fleet,
    ):
        server.wait_for_sessions(n, 60.0)
        time.sleep(warmup(cfg.seconds))
        say(f"soak: measuring for {cfg.seconds:g} s (client pids {fleet.pid}, {sensor.pid})")
        interval = min(1.0, max(0.1, cfg.seconds / 10.0))
        status0, t0 = server.status(), time.monotonic()
        fewest = status0["sessions"]
        pids = {"server": server.pid, "clients": fleet.pid, "sensor": sensor.pid}
        pids.update({f"worker-{i}": pid for i, pid in enumerate(server.worker_pids)})
        with procfs.Sampler(pids, interval) as sampler:
            fleet.begin_window(cfg.seconds)
            sensor.begin_window(cfg.seconds, cfg.slider_period)
            deadline = time.monotonic() + cfg.seconds + 120.0
            while not fleet.conn.poll(min(5.0, 5 * interval)) and time.monotonic() < deadline:
                fewest = min(fewest, server.status()["sessions"])
            window = _joined(fleet.end_window(), sensor.end_window())
        status1, t1 = server.status(), time.monotonic()
    fewest = min(fewest, status1["sessions"])
    drawn = (status1["frames"] - status0["frames"]) / (n * (t1 - t0))
    _add_frames(report, window, drawn)
    report.add(_redraw(window))
    _add_usage(report, sampler, window.seconds)
    report.add(
        Figure(
            P,
            "clients gone silent",
            float(window.silent),
            str(window.silent),
            at_most("max_errors", "<= {:g}"),
        ),
        Figure(
            P,
            "sessions lost (server side)",
            float(n - fewest),
            f"{n - fewest} (fewest live: {fewest} of {n})",
            at_most("max_errors", "<= {:g}"),
            {"fewest": fewest},
        ),
    )


def _joined(fleet: Window, sensor: Window) -> Window:
    """The fleet's clients and the sensor as one window (the sensor's slider moves)."""
    return Window(
        seconds=fleet.seconds,
        fps=fleet.fps + sensor.fps,
        stalled=fleet.stalled + sensor.stalled,
        latencies=sensor.latencies,
        lost_redraws=sensor.lost_redraws,
        silent=fleet.silent + sensor.silent,
    )


def _add_frames(report: Report, window: Window, drawn: float) -> None:
    fps = window.fps
    p5, p50, worst = percentile(fps, 0.05), statistics.median(fps), min(fps)
    report.add(
        info(P, "fps per client, p5", f"{p5:.1f}"),
        info(P, "fps per client, p50", f"{p50:.1f}"),
        Figure(
            P,
            f"fps per client, each of {len(fps)}",
            worst,
            f"min {worst:.1f}",
            at_least("min_fps", ">= {:g} fps"),
            {"clients": len(fps), "p5": p5, "p50": p50},
        ),
        info(P, "frames drawn by the server", f"{drawn:.1f} per client per second", fps=drawn),
    )


def _redraw(window: Window) -> Figure:
    latencies = sorted(window.latencies) + [math.inf] * window.lost_redraws
    p95 = 1e3 * percentile(latencies, 0.95)
    text = (
        f"p95 {p95:.0f} ms, p50 {1e3 * percentile(latencies, 0.5):.0f} ms "
        f"({len(window.latencies)} moves, {window.lost_redraws} lost)"
    )
    return Figure(
        P,
        "slider-to-redraw",
        p95,
        text,
        at_most("max_redraw_ms", "<= {:g} ms"),
        {"moves": len(window.latencies), "lost": window.lost_redraws},
    )


def _add_usage(report: Report, sampler: procfs.Sampler, seconds: float) -> None:
    """CPU over the soak; RSS early against late (the median of the first and the last tenth
    of the samples); threads at both ends."""
    clients = sampler.samples["clients"]
    # The server's processes: the one, or the landing and its workers, summed.
    server = procfs.combined(
        [v for k, v in sampler.samples.items() if k not in ("clients", "sensor")]
    )
    span = max(0.1 * seconds, 2.0 * sampler.interval)
    rss0 = statistics.median(u.rss_bytes for u in server if u.at - server[0].at <= span)
    rss1 = statistics.median(u.rss_bytes for u in server if server[-1].at - u.at <= span)
    growth = rss1 / rss0 - 1.0
    peak = max(
        (procfs.cpu_percent(a, b) for a, b in zip(server, server[1:], strict=False)),
        default=math.nan,
    )
    report.add(
        info(
            P,
            "server CPU",
            f"mean {procfs.cpu_percent(server[0], server[-1]):.0f} %, max {peak:.0f} % of one core",
            samples=len(server),
        ),
        Figure(
            P,
            "server RSS",
            growth,
            f"{rss0 / MB:.0f} -> {rss1 / MB:.0f} MB ({growth:+.1%}; "
            f"max {max(u.rss_bytes for u in server) / MB:.0f} MB)",
            at_most("max_rss_growth", "flat, <= +{:g} %", 100),
            {"samples": len(server)},
        ),
        info(P, "server threads", f"{server[0].threads} -> {server[-1].threads}"),
        info(
            P,
            "client process CPU",
            f"mean {procfs.cpu_percent(clients[0], clients[-1]):.0f} % of one core "
            "(decoding every message)",
        ),
    )
