"""``poinsot serve --workers N``: the sessions of a class spread over N processes.

Each worker is a spawned process running an ordinary :class:`~poinsot.app.live.server.PoinsotApp`
on its own port of the same host; a browser's session lives in one worker from start to end.
A worker reports its connected clients through two shared integers (clients now, connects
ever), which the landing (:mod:`poinsot.app.live.landing`) reads to send each new browser to
the least-loaded one.

Workers never outlive the parent: each holds the read end of a pipe from it and stops when the
pipe closes, which the kernel does however the parent ends (even ``kill -9``). A worker that
ends on its own is reported in one line and gets no more browsers.

The lecturer code is made by the parent and given to every worker; a second pipe per worker
(its feed) carries the lead's state to the others (:mod:`poinsot.app.live.relay`).
"""

from __future__ import annotations

import multiprocessing as mp
import multiprocessing.connection
import os
import signal
import sys
import threading
import traceback
from collections.abc import Callable, Sequence
from multiprocessing.connection import Connection
from typing import TYPE_CHECKING, Any

from poinsot.app.live.classroom.follow import new_code
from poinsot.app.live.hardening.network import PortError, check_port, port_problem

if TYPE_CHECKING:
    from poinsot.app.live.server import PoinsotApp

#: Seconds a worker may take to start (a spawned interpreter importing viser, scipy, trimesh).
START_TIMEOUT = 120.0
#: Seconds a stopping worker may take to close its sessions before it exits regardless.
STOP_GRACE = 5.0


def _count_clients(server: Any, load: Any) -> None:
    """Keep ``load[0]`` = clients connected, ``load[1]`` = clients ever connected. viser may
    run a client's disconnect before its connect: the sums are right in either order. A
    connect counts the arrival first: whoever reads the clients and then the arrivals
    (:meth:`.landing.Balancer.load`) never sees a client that has not arrived."""
    lock = threading.Lock()

    def connected(_client: Any) -> None:
        with lock:
            load[1] += 1
            load[0] += 1

    def disconnected(_client: Any) -> None:
        with lock:
            load[0] -= 1

    server.on_client_connect(connected)
    server.on_client_disconnect(disconnected)


def _worker_main(
    conn: Connection,
    load: Any,
    host: str,
    port: int,
    preset: str,
    scene: str | None,
    origins: tuple[str, ...] = (),
    landing: int = 0,
    feed: Connection | None = None,
    code: str = "",
    redis: str = "",
) -> None:
    """The worker: serve, report ``("ready", port)``, stop when told or when the parent's end
    of the pipe closes (then, whatever happens, the process ends within ``STOP_GRACE``).
    Ctrl-C in the terminal reaches the whole process group: the parent handles it and stops
    the workers, so a worker ignores it."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    # viser's banner names the worker's own port: not the address for the board. Errors still
    # reach the terminal on stderr.
    sys.stdout = open(os.devnull, "w")  # noqa: SIM115 (for the whole life of the process)
    app = None
    status = 0
    try:
        app = _serve(host, port, preset, scene, origins, landing, feed, code, redis)
        if port and app.port != port:  # viser moved on to the next free port: refuse
            conn.send(("error", port_problem(host, port)))
            return
        _count_clients(app.server, load)
        conn.send(("ready", app.port))
        while (request := conn.recv()) != "stop":  # EOFError: the parent is gone
            _, look = request  # ("inspect", function of the app): the load test's questions
            conn.send(look(app))
    except (EOFError, BrokenPipeError):  # the parent is gone
        pass
    except Exception:
        traceback.print_exc()
        status = 1
    finally:
        threading.Timer(STOP_GRACE, os._exit, (status,)).start()  # never hang on the way out
        if app is not None:
            app.stop()
        os._exit(status)


def _serve(
    host: str,
    port: int,
    preset: str,
    scene: str | None,
    origins: tuple[str, ...],
    landing: int = 0,
    feed: Connection | None = None,
    code: str = "",
    redis: str = "",
) -> PoinsotApp:
    from poinsot.app.lessons import scene_by_name
    from poinsot.app.live.relay import worker_hub
    from poinsot.app.live.server import PoinsotApp
    from poinsot.app.model.presets import preset_by_key

    start_scene = scene_by_name(scene) if scene else None
    hub = worker_hub(feed, code) if feed is not None else None
    if hub is not None and redis:  # other hosts' workers too (:mod:`.broker`)
        from poinsot.app.live.broker import link_hub

        link_hub(hub, redis)
    return PoinsotApp(
        host,
        port,
        preset=preset_by_key(preset),
        scene=start_scene,
        allow_origins=origins,
        landing_port=landing,
        follow=hub,
        serving=True,
    )


class Worker:
    """The parent's handle on one worker process (a :class:`~.landing.Backend`)."""

    def __init__(
        self,
        index: int,
        host: str,
        port: int,
        preset: str,
        scene: str | None,
        origins: tuple[str, ...] = (),
        landing: int = 0,
        code: str = "",
        redis: str = "",
    ):
        ctx = mp.get_context("spawn")
        self.index = index
        self.load = ctx.RawArray("q", 2)  # clients now, clients ever (written by the worker)
        self.conn, child_end = ctx.Pipe()
        self.feed, child_feed = ctx.Pipe()  # the lead's state, both ways (:mod:`.relay`)
        self.process = ctx.Process(
            target=_worker_main,
            args=(
                child_end,
                self.load,
                host,
                port,
                preset,
                scene,
                origins,
                landing,
                child_feed,
                code,
                redis,
            ),
            name=f"poinsot-worker-{index}",
            daemon=True,
        )
        self.process.start()
        child_end.close()
        child_feed.close()
        self.port = 0
        self.reported = False  # its unexpected end has been reported

    def wait_ready(self, timeout: float) -> None:
        """Wait for the worker's port; :class:`PortError` or RuntimeError if it cannot serve."""
        if not self.conn.poll(timeout):
            raise RuntimeError(f"worker {self.index} did not start within {timeout:.0f} s")
        try:
            kind, payload = self.conn.recv()
        except EOFError:
            raise RuntimeError(f"worker {self.index} ended while starting") from None
        if kind == "error":
            raise PortError(payload)
        self.port = int(payload)

    def inspect(self, look: Callable[[PoinsotApp], Any], timeout: float = 30.0) -> Any:
        """``look(app)`` run in the worker on its app (a module-level function: it is pickled
        by name), e.g. the load test's count of sessions and frames."""
        self.conn.send(("inspect", look))
        if not self.conn.poll(timeout):
            raise TimeoutError(f"worker {self.index} did not answer within {timeout:.0f} s")
        return self.conn.recv()

    @property
    def pid(self) -> int | None:
        return self.process.pid

    @property
    def alive(self) -> bool:
        return self.process.is_alive()

    @property
    def clients(self) -> int:
        """Browsers connected now: 0 once the process has ended (its last count is stale)."""
        return int(self.load[0]) if self.alive else 0

    @property
    def connects(self) -> int:
        return int(self.load[1])

    def ask_stop(self) -> None:
        try:
            self.conn.send("stop")
        except OSError:  # it has ended already
            pass

    def join(self) -> None:
        """Wait for the worker to end; terminate it if it outlasts its grace period."""
        self.process.join(STOP_GRACE + 5.0)
        if self.process.is_alive():
            self.process.terminate()
            self.process.join(5.0)
        self.conn.close()
        self.feed.close()


def start_workers(
    count: int,
    host: str,
    port: int,
    preset: str,
    scene: str | None,
    origins: tuple[str, ...] = (),
    code: str = "",
    redis: str = "",
) -> list[Worker]:
    """Start ``count`` workers (all at once) and wait until every one serves. With a fixed
    ``port`` they take the next ports, ``port + 1`` to ``port + count`` (one range to open in
    a firewall); with 0, any free ports. Raises :class:`PortError` (one line) if a port is
    taken, after stopping the others."""
    ports = [port + 1 + i if port else 0 for i in range(count)]
    for p in ports:
        check_port(host, p)
    # Links copied from a worker's page name the landing (a fixed port: known now).
    code = code or new_code()
    workers = [
        Worker(i, host, p, preset, scene, origins, port, code, redis) for i, p in enumerate(ports)
    ]
    try:
        for worker in workers:
            worker.wait_ready(START_TIMEOUT)
    except BaseException:
        stop_workers(workers)
        raise
    return workers


def stop_workers(workers: Sequence[Worker]) -> None:
    """Ask every worker to stop, then wait for each (they close their sessions in parallel)."""
    for worker in workers:
        worker.ask_stop()
    for worker in workers:
        worker.join()


def report_ended(workers: Sequence[Worker], timeout: float) -> int:
    """Wait up to ``timeout`` s for a worker to end; print one line on stderr for each that
    ended unexpectedly. Returns how many are still alive."""
    watched = [w for w in workers if not w.reported]
    if watched:
        mp.connection.wait([w.process.sentinel for w in watched], timeout)
    for worker in watched:
        if not worker.process.is_alive():
            worker.reported = True
            process = worker.process
            print(
                f"poinsot serve: worker {worker.index} (port {worker.port}, pid {process.pid}) "
                f"stopped unexpectedly (exit code {process.exitcode}); new browsers go to the "
                "others",
                file=sys.stderr,
                flush=True,
            )
    return sum(w.alive for w in workers)


def serve_classroom(
    host: str,
    port: int,
    count: int,
    preset: str,
    scene: str | None,
    *,
    announce: bool = True,
    origins: tuple[str, ...] = (),
    link: str = "",
    code: str = "",
    redis: str = "",
) -> int:
    """Run ``count`` workers behind a landing on ``host:port`` until Ctrl-C (exit status 0),
    or until every worker has ended (1). A port that cannot be served raises
    :class:`PortError` before anything runs. ``link``: a link's query printed with the board
    (:func:`~poinsot.app.live.hardening.network.board`)."""
    from poinsot.app.live.hardening.network import board
    from poinsot.app.live.landing import Balancer, LandingServer
    from poinsot.app.live.relay import Relay

    check_port(host, port)
    code = code or new_code()
    workers = start_workers(count, host, port, preset, scene, origins, code, redis)
    relay = Relay([w.feed for w in workers]).start()
    try:
        landing = LandingServer(host, port, Balancer(workers))
    except PortError:
        stop_workers(workers)
        raise
    landing.start()
    if announce:
        print(board(host, landing.port, link), flush=True)
        ports = ", ".join(str(w.port) for w in workers)
        print(f"{count} workers on ports {ports}; each new browser goes to the least busy")
        print(lecturer_line(code), flush=True)
    try:
        while report_ended(workers, 1.0):
            pass
        print("poinsot serve: every worker has stopped", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 0
    finally:
        landing.shutdown()
        landing.server_close()
        stop_workers(workers)
        relay.stop()


def lecturer_line(code: str) -> str:
    """What ``poinsot serve`` prints for the lecturer: the code "Lead this class" takes."""
    return f'Lecturer code: {code} (type it under "Class: lead or follow" to lead this class)'
