"""``poinsot serve --workers N``, the landing port, the fixed port and the board's address.

The classroom runs as a real ``poinsot serve`` child; headless probes arrive through the
landing as a browser does (:func:`poinsot.app.live.landing.resolve`) and the landing's
``/poinsot-status`` tells which worker holds how many clients. Everything is asserted on
counts and events.
"""

from __future__ import annotations

import dataclasses
import errno
import os
import re
import signal
import socket
import subprocess
import sys
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest
import segno

from poinsot.app.cli import main as cli
from poinsot.app.devtools.probe import Probe
from poinsot.app.live.hardening import network
from poinsot.app.live.landing import PENDING_SECONDS, Balancer, _loopback, resolve, status
from tests.conftest import wait_until

START = 180.0  # seconds two spawned workers may take to import and serve on a loaded box


# -- the balancer, on its own --------------------------------------------------------------
@dataclasses.dataclass
class FakeWorker:
    port: int
    clients: int = 0
    connects: int = 0
    alive: bool = True
    pid: int | None = None

    def arrive(self) -> None:
        self.clients += 1
        self.connects += 1


def test_balancer_sends_each_browser_to_the_fewest_clients():
    a, b = FakeWorker(1, clients=2, connects=2), FakeWorker(2)
    balancer = Balancer([a, b])
    # A class arriving at once: the browsers sent to b count before they connect.
    assert [balancer.choose() for _ in range(3)] == [b, b, a]
    b.arrive(), b.arrive(), a.arrive()  # they connect: the pending ones are settled
    assert [row["load"] for row in balancer.status()] == [3, 2]
    assert balancer.choose() is b


def test_balancer_skips_a_dead_worker_and_says_when_none_is_left():
    a, b = FakeWorker(1, alive=False), FakeWorker(2, clients=5, connects=5)
    balancer = Balancer([a, b])
    assert [balancer.choose() for _ in range(3)] == [b, b, b]
    b.alive = False
    assert balancer.choose() is None


class _Writes(list):
    """A worker's two counters, recording the order they are written in."""

    def __init__(self) -> None:
        super().__init__([0, 0])
        self.order: list[int] = []

    def __setitem__(self, index, value) -> None:  # type: ignore[no-untyped-def]
        self.order.append(index)
        super().__setitem__(index, value)


def test_a_browser_is_never_counted_both_connected_and_on_its_way():
    """A worker counts a browser's arrival before the browser (``_count_clients``), and the
    balancer reads the browsers before the arrivals: a connect landing between its two reads
    is not counted twice (once connected, once still sent there), which once sent the next
    browser to the busier worker."""
    from poinsot.app.live import workers

    callbacks: dict[str, object] = {}

    class Server:
        def on_client_connect(self, f) -> None:  # type: ignore[no-untyped-def]
            callbacks["connect"] = f

        def on_client_disconnect(self, f) -> None:  # type: ignore[no-untyped-def]
            callbacks["disconnect"] = f

    load = _Writes()
    workers._count_clients(Server(), load)
    callbacks["connect"](None)  # type: ignore[operator]
    assert load.order == [1, 0] and list(load) == [1, 1]

    class Connecting:
        """A worker whose browser connects right after the balancer's first read of it."""

        port, alive, pid = 2, True, None

        def __init__(self) -> None:
            self.counts = {"clients": 1, "connects": 1}
            self.armed = False

        def _read(self, name: str) -> int:
            seen = self.counts[name]
            if self.armed:  # the worker's order: the arrival, then the browser
                self.armed = False
                self.counts["connects"] += 1
                self.counts["clients"] += 1
            return seen

        @property
        def clients(self) -> int:
            return self._read("clients")

        @property
        def connects(self) -> int:
            return self._read("connects")

    connecting = Connecting()
    balancer = Balancer([FakeWorker(1, clients=2, connects=2), connecting])
    assert balancer.choose() is connecting  # a browser sent to it: on its way, then it connects
    connecting.armed = True
    assert balancer.load(1) <= 2  # connected, or on its way: once (never 2 + 1)


# -- a real classroom ----------------------------------------------------------------------
@dataclasses.dataclass
class Classroom:
    process: subprocess.Popen[str]
    port: int
    worker_ports: list[int]
    stdout: list[str]
    stderr: list[str]

    def workers(self) -> list[dict]:
        return status(self.port)

    def clients(self) -> list[int]:
        return [w["clients"] for w in self.workers()]


def _read_lines(stream, into: list[str]) -> None:
    for line in stream:
        into.append(line)


def start_classroom(*args: str, workers: int = 2) -> Classroom:
    """``poinsot serve --workers N --port 0 ARGS`` in a child; wait until it announces its
    workers (it prints the landing's URL first)."""
    # A test run started in the background by a script has SIGINT ignored, and a child would
    # inherit that: Python then never turns SIGINT into KeyboardInterrupt, and the classroom
    # would sit out stop_classroom's SIGINT for its whole minute. A handled SIGINT is reset to
    # the default in the child.
    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)
    process = subprocess.Popen(
        [sys.executable, "-m", "poinsot.app", "serve", "--workers", str(workers), "--port", "0"]
        + list(args),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    out: list[str] = []
    err: list[str] = []
    for stream, lines in ((process.stdout, out), (process.stderr, err)):
        threading.Thread(target=_read_lines, args=(stream, lines), daemon=True).start()
    announced = wait_until(lambda: any(" workers on ports " in line for line in out), START)
    if not announced:
        process.kill()
        pytest.fail(f"the classroom did not start: {''.join(out + err)[-2000:]}")
    port = int(re.search(r"running at http://\S+:(\d+)", "".join(out)).group(1))
    ports = re.search(r"workers on ports ([\d, ]+);", "".join(out)).group(1)
    return Classroom(process, port, [int(p) for p in ports.split(",")], out, err)


def stop_classroom(room: Classroom) -> None:
    if room.process.poll() is None:
        room.process.send_signal(signal.SIGINT)
        try:
            room.process.wait(60)
        except subprocess.TimeoutExpired:
            room.process.kill()
            room.process.wait(10)


@pytest.fixture(scope="module")
def classroom() -> Iterator[Classroom]:
    """One classroom for the module, on all interfaces as a lecturer serves it (so it prints
    the board too): the tests that leave it as they found it use it first, in file order, and
    the one that crashes a worker last."""
    room = start_classroom("--host", "0.0.0.0")
    yield room
    stop_classroom(room)


def _children(pid: int) -> list[int]:
    """The processes whose parent is ``pid`` (from /proc)."""
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                found.append(int(entry.name))
    return found


def _running(pid: int) -> bool:
    """Alive and not a zombie."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


@pytest.mark.slow
def test_landing_sends_new_browsers_to_the_least_loaded_worker(classroom: Classroom):
    first, second = classroom.worker_ports
    assert classroom.clients() == [0, 0]
    probes = [Probe(first), Probe(first)]  # two browsers went straight to the first worker
    try:
        assert wait_until(lambda: classroom.clients() == [2, 0], 60)
        arrived = []
        for expected in ([2, 1], [2, 2], [3, 2], [3, 3]):
            port = resolve(classroom.port)
            arrived.append(port)
            probes.append(Probe(port))
            assert wait_until(lambda e=expected: classroom.clients() == e, 60), classroom.clients()
        assert arrived == [second, second, first, second]
        for probe in probes:  # each session lives on its worker and plays
            assert probe.wait_frames(3), "a client received no frames"
    finally:
        for probe in probes:
            probe.close()
    assert wait_until(lambda: classroom.clients() == [0, 0], 60)


@pytest.mark.slow
def test_serve_on_all_interfaces_prints_the_board(classroom: Classroom):
    text = "".join(classroom.stdout)
    for _, address in network.lan_addresses():
        assert f"http://{address}:{classroom.port}" in text
    if network.lan_addresses():
        assert "█" in text and "Students open" in text


@pytest.mark.slow
def test_a_crashed_worker_is_reported_and_gets_no_new_browsers(classroom: Classroom):
    first, second = classroom.workers()
    browser = Probe(first["port"])  # a browser on the worker that will crash
    assert wait_until(lambda: classroom.clients() == [1, 0], 60)
    os.kill(first["pid"], signal.SIGKILL)
    assert wait_until(lambda: any("stopped unexpectedly" in line for line in classroom.stderr), 30)
    browser.close()
    assert classroom.clients() == [0, 0]  # its last count was 1: a dead worker holds none
    report = [line for line in classroom.stderr if "stopped unexpectedly" in line]
    assert len(report) == 1 and f"port {first['port']}" in report[0]
    assert [w["alive"] for w in classroom.workers()] == [False, True]
    assert {resolve(classroom.port) for _ in range(4)} == {second["port"]}
    assert classroom.process.poll() is None  # the class goes on with one worker


@pytest.mark.slow
def test_workers_die_with_the_parent():
    room = start_classroom()
    children = _children(room.process.pid)
    workers = [w["pid"] for w in room.workers()]
    assert set(workers) <= set(children) and len(workers) == 2
    room.process.kill()  # no chance to clean up
    room.process.wait(10)
    assert wait_until(lambda: not any(_running(pid) for pid in children), 60), [
        pid for pid in children if _running(pid)
    ]


# -- the fixed port ------------------------------------------------------------------------
@pytest.fixture
def busy_port() -> Iterator[int]:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        sock.listen()
        yield sock.getsockname()[1]


def _serve(*args: str) -> subprocess.CompletedProcess[str]:
    command = [sys.executable, "-m", "poinsot.app", "serve", *args]
    return subprocess.run(command, capture_output=True, text=True, timeout=START)


@pytest.mark.parametrize("workers", ["1", "2"])
def test_a_busy_port_is_one_line_and_exit_2(busy_port: int, workers: str, capsys):
    """Through ``main`` in this process (the next test runs ``poinsot serve`` as a process)."""
    status = cli.main(["serve", "--port", str(busy_port), "--workers", workers])
    out, err = capsys.readouterr()
    assert status == 2
    assert err.count("\n") == 1, err
    assert f"port {busy_port} " in err and "busy" in err
    assert "running at" not in out


@pytest.mark.server  # it starts a process of its own
def test_a_busy_worker_port_is_one_line_and_exit_2(busy_port: int):
    """The workers take the ports after the landing's: one of them taken is refused too (a
    real ``poinsot serve`` process: one line, no traceback)."""
    result = _serve("--port", str(busy_port - 1), "--workers", "2")
    if f"port {busy_port - 1} " in result.stderr:
        pytest.skip(f"port {busy_port - 1} happens to be busy as well")
    assert result.returncode == 2 and result.stderr.count("\n") == 1, result.stderr
    assert f"port {busy_port} " in result.stderr


def test_the_server_refuses_the_port_viser_moved_to(busy_port: int, monkeypatch, capsys):
    """Past the check (a port taken between the check and the server), the server itself
    notices that viser listened elsewhere, and stops."""
    monkeypatch.setattr(network, "check_port", lambda host, port: None)
    assert cli.main(["serve", "--port", str(busy_port), "--workers", "1"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"port {busy_port} " in err


@pytest.mark.skipif(os.geteuid() == 0, reason="root may listen on any port")
def test_a_port_without_permission_is_one_line():
    with pytest.raises(network.PortError, match="port 80 .* not allowed"):
        network.check_port("127.0.0.1", 80)


def test_each_reason_a_port_cannot_be_served_is_named():
    assert "not allowed" in network.port_problem("0.0.0.0", 80, errno.EACCES)
    assert "busy" in network.port_problem("0.0.0.0", 8080, errno.EADDRINUSE)
    assert "not an address" in network.port_problem("10.9.9.9", 8080, errno.EADDRNOTAVAIL)
    with pytest.raises(network.PortError, match="not a TCP port"):
        network.check_port("127.0.0.1", 70000)
    with pytest.raises(network.PortError, match="203.0.113.7 is not an address"):
        network.check_port("203.0.113.7", 8080)  # TEST-NET-3: no interface has it
    assert network.bind_errno(socket.gaierror(-2, "Name or service not known")) == (
        errno.EADDRNOTAVAIL
    )  # a host name that resolves to nothing of ours


def test_port_zero_takes_any_free_port(capsys, monkeypatch):
    network.check_port("127.0.0.1", 0)  # never refused
    with pytest.raises(SystemExit):
        cli.build_parser().parse_args(["serve", "--workers", "0"])
    assert "whole number >= 1" in capsys.readouterr().err


# -- the board -----------------------------------------------------------------------------
def _unprint(qr: str) -> list[list[bool]]:
    """The modules drawn by :func:`network.qr_text` (True = dark)."""
    bits = {"█": (False, False), "▄": (True, False), "▀": (False, True), " ": (True, True)}
    rows: list[list[bool]] = []
    for line in qr.splitlines():
        pairs = [bits[c] for c in line]
        rows += [[p[0] for p in pairs], [p[1] for p in pairs]]
    return rows


def test_the_qr_code_draws_exactly_the_address():
    url = "http://192.168.1.23:8080"
    expected = [[bool(v) for v in row] for row in segno.make(url, error="m").matrix_iter(border=4)]
    drawn = _unprint(network.qr_text(url))
    assert drawn[: len(expected)] == expected
    assert not any(any(row) for row in drawn[len(expected) :])  # padding only


def test_the_board_shows_the_lan_addresses_and_a_qr_code(monkeypatch):
    monkeypatch.setattr(
        network, "_interface_addresses", lambda: [("lo", "127.0.0.1"), ("wlan0", "10.0.0.7")]
    )
    monkeypatch.setattr(network, "_route_address", lambda: "10.0.0.7")
    text = network.board("0.0.0.0", 8080)
    assert "http://10.0.0.7:8080    (wlan0)" in text and "127.0.0.1" not in text
    assert text.endswith("\n" + network.qr_text("http://10.0.0.7:8080"))  # the first one's
    assert network.board("127.0.0.1", 8080).count("\n") == 0  # not on the network: no board


def test_the_board_says_when_the_machine_has_no_address(monkeypatch):
    monkeypatch.setattr(network, "_interface_addresses", lambda: [("lo", "127.0.0.1")])
    monkeypatch.setattr(network, "_route_address", lambda: None)
    assert "No network address found" in network.board("0.0.0.0", 8080)


def test_the_real_interfaces_give_non_loopback_ipv4_addresses():
    for _, address in network.lan_addresses():
        assert socket.inet_aton(address) and not address.startswith("127.")


# -- the load test through a landing -------------------------------------------------------
@pytest.mark.slow
def test_the_load_test_soaks_a_classroom_of_workers():
    """``python -m poinsot.app.devtools.load --phase soak --workers 2``: the clients arrive through
    the landing, the sessions are counted in both workers, their CPU and memory are summed."""
    from poinsot.app.devtools.load.cli import run
    from poinsot.app.devtools.load.config import Config

    report = run(["soak"], Config(clients=4, workers=2, seconds=3.0), verbose=False)
    assert report.figure("soak", "sessions lost").value == 0
    assert report.figure("soak", "clients gone silent").value == 0
    assert not [f for f in report.figures if f.name == "completed"], report.figures
    assert report.figure("soak", "fps per client, each").detail["clients"] == 4
    assert report.figure("soak", "fps per client, each").value > 0


def test_the_load_test_takes_workers_for_the_soak_only(capsys):
    from poinsot.app.devtools.load import cli as load_cli

    with pytest.raises(SystemExit):
        load_cli.main(["--phase", "storm", "--workers", "2"])
    assert "only with --phase soak" in capsys.readouterr().err


def test_only_a_client_on_this_machine_is_shown_the_workers_process_ids():
    """/poinsot-status gives pids to loopback clients (the tests, the load test) only."""
    assert all(_loopback(a) for a in ("127.0.0.1", "127.8.0.1", "::1", "::ffff:127.0.0.1"))
    assert not any(_loopback(a) for a in ("192.168.1.5", "10.0.0.1", "::ffff:10.0.0.1", "fe80::1"))


# -- the status page tells the truth ------------------------------------------------------------
class FakeClock:
    def __init__(self) -> None:
        self.now = 1000.0

    def __call__(self) -> float:
        return self.now


def test_a_dead_worker_shows_no_clients_and_no_load():
    a, b = FakeWorker(1, clients=2, connects=2), FakeWorker(2, clients=1, connects=1)
    balancer = Balancer([a, b])
    balancer.choose()  # one browser on its way to b
    a.alive = b.alive = False  # killed: their last counts stay in shared memory
    assert [(row["clients"], row["load"]) for row in balancer.status()] == [(0, 0), (0, 0)]


def test_a_redirect_that_never_connects_stops_counting_after_five_seconds():
    assert PENDING_SECONDS <= 5.0
    clock = FakeClock()
    a = FakeWorker(1, clients=3, connects=3)
    balancer = Balancer([a], clock=clock)
    for _ in range(6):  # six redirects (curl, a closed tab): none connects
        balancer.choose()
    assert balancer.status()[0]["load"] == 9
    clock.now += PENDING_SECONDS - 0.1
    assert balancer.status()[0]["load"] == 9  # still on their way
    clock.now += 0.2
    assert balancer.status()[0]["load"] == 3  # only the real clients


def test_a_head_request_is_not_a_browser_on_its_way():
    a = FakeWorker(1)
    balancer = Balancer([a])
    assert balancer.choose(counted=False) is a
    assert balancer.status()[0]["load"] == 0


def test_a_worker_started_again_is_used_again():
    a, b = FakeWorker(1, clients=4, connects=9), FakeWorker(2, clients=3, connects=3)
    balancer = Balancer([a, b])
    a.alive = False
    assert balancer.choose() is b
    # started again (a new process on the same port counts from zero)
    a.alive, a.clients, a.connects = True, 0, 0
    assert balancer.choose() is a
    a.arrive()
    assert [row["load"] for row in balancer.status()] == [1, 4]
    # or put in its place as a new backend
    fresh = FakeWorker(3)
    balancer.replace(0, fresh)
    assert balancer.choose() is fresh
