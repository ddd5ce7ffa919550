"""The load test (``python -m poinsot.app.devtools.load``) at tiny sizes: every phase runs against a
real server child on loopback and produces its figures, with the counts behind them; the goals are
judged from the figures and the bounds alone (met bounds give exit status 0, an impossible one
gives 1). Counts and events are asserted, never the seconds the server took."""

from __future__ import annotations

import dataclasses
import math
import os
import struct

import pytest

from poinsot.app.devtools.load import (
    PHASES,
    Bounds,
    Config,
    Report,
    cli,
    exit_status,
    run,
    services,
)
from poinsot.app.devtools.load.config import server_processes
from poinsot.app.devtools.load.figures import COMPLETES, Figure, at_least, at_most, percentile
from poinsot.app.devtools.load.procfs import usage
from poinsot.app.devtools.load.raw import client_frame
from poinsot.app.devtools.load.server_process import error_lines, thread_kind
from poinsot.app.devtools.load.workloads import follow_fleet, following
from poinsot.app.devtools.load.workloads import hosts as hosts_workload
from poinsot.app.devtools.load.workloads.storm import KINDS
from poinsot.app.live.classroom.cast import CAST_FPS
from poinsot.app.live.server import MAX_FPS
from tests.app.test_nginx import service_or_skip

TINY = Config(
    clients=3,
    workers=1,
    seconds=3.0,
    slider_period=0.5,
    storm=15,
    storm_workers=4,
    storm_steady=2,
    settle_seconds=2.0,
    stall_seconds=4.5,  # its last third judged alone: 1.5 s, frames in it on a loaded machine
    flood_seconds=2.0,
    flood_rate=1000.0,
    hostile_handshakes=100,
    hostile_quiet_seconds=1.0,
)
#: Bounds every tiny run meets on a working server, however loaded the machine.
LENIENT = Bounds(
    min_fps=1.0,
    min_hall_fps=1.0,
    max_redraw_ms=60_000.0,
    max_rss_growth=10.0,
    storm_tolerance=100.0,
    min_keep=0.01,
    max_errors=1000,
    max_hostile_rss_growth=10.0,
    min_innocent_keep=0.01,
    max_follow_ms=60_000.0,
    max_hosts_follow_ms=60_000.0,
    max_recovery_s=60.0,
)
LENIENT_ARGS = [
    "--min-fps=1",
    "--min-hall-fps=1",
    "--max-redraw-ms=60000",
    "--max-rss-growth=10",
    "--storm-tolerance=100",
    "--min-keep=0.01",
    "--max-errors=1000",
    "--max-hostile-rss-growth=10",
    "--min-innocent-keep=0.01",
    "--max-follow-ms=60000",
    "--max-hosts-follow-ms=60000",
    "--max-recovery-s=60",
]


@pytest.fixture(scope="module")
def report() -> Report:
    return run(PHASES, TINY, verbose=False)


@pytest.fixture(scope="module")
def follow_report() -> Report:
    """The follow phase (not in ``make load``'s defaults): one lead, three followers in two
    client processes; a move is lost only if a follower has not redrawn it in 60 s (the count
    is asserted, not the time)."""
    tiny = dataclasses.replace(
        TINY,
        followers=(3,),
        follow_seconds=2.0,
        follow_redraw_timeout=60.0,
        followers_per_process=2,  # two client processes: the lead's and another
    )
    return run(("follow",), tiny, False)


@pytest.fixture(scope="module")
def hosts_report() -> Report:
    """The follow phase on two hosts (``--hosts 2``): a real redis-server, two servers linked
    to it and nginx in front; one lead, four followers (two on each host) in two client
    processes; Redis killed and started again once. Lost only after 60 s (counts asserted)."""
    service_or_skip(services.check_installed)
    tiny = dataclasses.replace(
        TINY,
        hosts=2,
        followers=(4,),
        follow_seconds=2.0,
        follow_redraw_timeout=60.0,
        followers_per_process=2,
    )
    return run(("follow",), tiny, False)


# -- the phases, run once ----------------------------------------------------------------------
@pytest.mark.slow
def test_every_phase_completes_and_reads_its_server_log(report):
    failures = [f"{f.phase}: {f.text}" for f in report.figures if f.name == "completed"]
    assert not failures, (failures, report.notes)
    for phase in PHASES:
        errors = report.figure(phase, "server log errors")
        assert errors.value >= 0 and (errors.goal is not None) == (phase == "soak")


@pytest.mark.slow
def test_soak_counts_frames_redraws_and_samples(report):
    fps = report.figure("soak", "fps per client, each of")
    assert fps.detail["clients"] == 3
    assert 0 < fps.value <= fps.detail["p5"] <= fps.detail["p50"]
    assert report.figure("soak", "frames drawn by the server").detail["fps"] > 0
    redraw = report.figure("soak", "slider-to-redraw")
    assert redraw.detail["moves"] >= 2 and redraw.detail["lost"] == 0
    assert 0 < redraw.value < math.inf
    assert report.figure("soak", "server RSS").detail["samples"] >= 3
    assert report.figure("soak", "clients gone silent").value == 0
    lost = report.figure("soak", "sessions lost")
    assert lost.value == 0 and lost.detail["fewest"] == 3


@pytest.mark.slow
def test_storm_visits_every_way_and_sessions_come_back(report):
    visits = report.figure("storm", "visits").detail
    assert visits["done"] == TINY.storm and visits["failed"] == visits["unfinished"] == 0
    assert all(visits[f"done_{kind}"] == TINY.storm // len(KINDS) for kind in KINDS)
    sessions = report.figure("storm", "live sessions")
    assert sessions.detail["before"] == sessions.detail["after"] == 2
    assert sessions.detail["session_threads"] == 2
    assert sessions.detail["pending_departures"] == 0
    assert sessions.value == 0
    threads = report.figure("storm", "server threads").detail
    assert threads["before"] > 0 and threads["after"] > 0
    steady = report.figure("storm", "the 2 steady clients after").detail
    assert steady["clients"] == 2 and steady["silent"] == 0


@pytest.mark.slow
def test_stall_stops_one_client_and_measures_the_others(report):
    stalled = report.figure("stall", "the stalled client").detail
    assert stalled["late_fps"] == 0  # nothing read while stalled
    assert stalled["after_fps"] > 0  # a short stall: it reads again (its backlog first)
    assert stalled["sessions"] == 3
    keep = report.figure("stall", "others' frame rate")
    assert keep.detail["clients"] == 2
    assert keep.detail["before_p50"] > 0 and keep.detail["after_p50"] > 0
    assert keep.value > 0


@pytest.mark.slow
def test_flood_sends_and_measures_the_others(report):
    sent = report.figure("flood", "messages sent").detail
    assert 0 < sent["sent"] <= TINY.flood_rate * TINY.flood_seconds + TINY.flood_rate
    # Every session is live after the flood, but the flooder's if the server cut it off.
    after = report.figure("flood", "server CPU").detail
    assert after["sessions"] == TINY.clients + 1 - after["disconnected"], after
    keep = report.figure("flood", "others' frame rate")
    assert keep.detail["clients"] == 3 and keep.value > 0
    for phase in PHASES:
        assert 0 <= report.figure(phase, "the machine meanwhile").detail["busy"] <= 1


@pytest.mark.slow
def test_hostile_replays_every_crafted_input_and_nothing_gets_through(report):
    """Every crafted message closes its sender, every bad handshake is refused, HTTP/1.0 is
    answered, the GUI's crafted inputs hurt no one; no traceback, no share request reaching
    viser, no connection left behind (counts: they hold however loaded the machine)."""
    for name in ("crafted messages", "bad handshakes", "HTTP/1.0", "crafted GUI inputs"):
        figure = report.figure("hostile", name)
        assert figure.value == 1.0, figure.text
    assert report.figure("hostile", "bad handshakes").text == "100/100"
    for name in ("tracebacks", "share tunnel", "leaked connections"):
        assert report.figure("hostile", name).value == 0, report.figure("hostile", name).text
    assert report.figure("hostile", "innocent client's frame rate").value > 0
    assert report.figure("hostile", "server memory").value < 10.0


@pytest.mark.slow
def test_follow_phase_measures_followers_and_their_cost(follow_report):
    """One lead and three followers on two workers: every follower draws frames, the lead's
    slider moves reach every follower, and the CPU per frame is measured both ways."""
    report = follow_report
    failures = [f.text for f in report.figures if f.name == "completed"]
    assert not failures, (failures, report.notes)
    assert report.figure("follow", "3 followers: fps each").value > 0
    moves = report.figure("follow", "3 followers: lead's slider move").detail
    assert moves["moves"] >= 2 and moves["lost"] == 0 and moves["redraws"] == 3 * moves["moves"]
    cost = report.figure("follow", "3 followers: server CPU per frame").detail
    assert cost["explored"] == 1.0 and cost["follower_ms"] > 0 and cost["session_ms"] > 0
    assert math.isfinite(cost["move_ms"])  # (beyond the still window: a difference, any sign)
    cores = report.figure("follow", "3 followers: the machine's cores").detail
    # The clients' two processes, measured beside the server; its own cores while still.
    assert cores["processes"] == 2 and cores["clients_cpu"] > 0 and cores["server_cores"] > 0
    # What the server could give the slowest follower, alone and beside the clients.
    fps = report.figure("follow", "3 followers: fps each").detail
    assert fps["server_alone_fps"] > fps["beside_clients_fps"] > 0
    assert any(n.startswith("follow, 3 followers: the server used") for n in report.notes)
    # The followers' shared poses: their ticks while the lead moved and while nothing moved
    # (each worker's cast ticks while it has followers), the frames held and skipped counted.
    cast = report.figure("follow", "3 followers: the cast").detail
    assert cast["ticks_moving"] > 0 and cast["ticks_still"] > 0
    assert cast["due"] == 2 * min(CAST_FPS, MAX_FPS)  # two workers' casts
    assert {"held", "skipped", "fit_copies"} <= cast.keys()


def test_a_lead_s_move_costs_each_follower_the_moving_window_s_cpu_beyond_the_still_one():
    # 3 s of the server's CPU over 10 s with the lead moving, where the same 10 s nothing moving
    # take 2 s: 1 s for 5 moves of 100 followers, 2 ms a follower a move.
    moving = {"seconds": 10.0, "moves": 5}
    assert following._ms_per_move(3.0, 0.2, moving, 100) == pytest.approx(2.0)
    assert math.isnan(following._ms_per_move(3.0, 0.2, {"seconds": 10.0, "moves": 0}, 100))


def test_the_followers_are_spread_evenly_over_as_few_processes_as_hold_them():
    assert follow_fleet.chunks(30, 40) == [30]
    assert follow_fleet.chunks(60, 40) == [30, 30]
    assert follow_fleet.chunks(150, 40) == [38, 38, 37, 37]
    assert sum(follow_fleet.chunks(301, 40)) == 301 and max(follow_fleet.chunks(301, 40)) <= 40


@pytest.mark.parametrize(
    ("server", "clients", "processes", "limit"),
    [(0.5, 0.6, 2, "server"), (0.4, 1.9, 2, "clients"), (1.2, 1.0, 4, "machine")],
)
def test_the_phase_says_who_limits_the_frame_rates(monkeypatch, server, clients, processes, limit):
    monkeypatch.setattr(following.os, "cpu_count", lambda: 2)
    load = following.Load(server, clients, processes)
    assert load.limit == limit
    assert ("not the server" in load.text()) == (limit != "server")


def _row(
    count: int, fps: list[float], moving: following.Moving, latency: float = 0.05
) -> list[Figure]:
    """The figures of a row of ``count`` followers that drew ``fps`` while the lead moved (each
    redrew its move after ``latency`` seconds), the machine as ``moving`` says, its clients' two
    processes at 0.7 cores."""
    window = {"fps": fps, "latencies": [latency] * count, "moves": 1}
    window["redraws"] = [[latency] * count]
    load = following.Load(0.5, 0.7, 2, moving)
    return following._figures(count, window, window, window, (0.1, 0.5, 1.0), True, load)


def _hall_fps(count: int, fps: list[float], moving: following.Moving) -> Figure:
    """The "fps each" figure of :func:`_row`."""
    return next(f for f in _row(count, fps, moving) if f.name == f"{count} followers: fps each")


def test_a_hall_s_move_is_held_to_the_hall_s_bound():
    """The lead's move on every follower, p95: a class of 150 within 150 ms, a hall of 300
    within 250 (the issue holds only 150 followers to 150 ms; a hall of 300 fills this 2-core
    machine, its clients half of it)."""
    bounds = Bounds()
    moving = following.Moving(1.8, 30.0 * 300, 300, 2)
    for count, latency, goal, verdict in (
        (150, 0.2, "p95 <= 150 ms", "MISSED"),
        (300, 0.2, "p95 <= 250 ms", "met"),
        (300, 0.3, "p95 <= 250 ms", "MISSED"),
    ):
        figures = _row(count, [30.0] * count, moving, latency)
        move = next(f for f in figures if f.name.endswith("lead's slider move on every follower"))
        assert move.goal is not None and move.goal.describe(bounds) == goal
        assert move.verdict(bounds) == verdict, (count, latency)


def test_a_hall_below_its_rate_is_the_clients_limit_only_where_the_server_alone_would_not_be(
    monkeypatch,
):
    """300 followers at 16 fps (min 14) while the lead moved, the machine's 2 cores 1.7 busy,
    the clients 0.7 of them: the server took 1.0 core for 4,800 frames a second, so with the
    machine to itself (0.9 of 2 cores) it could give the slowest follower 25.2 fps, and beside
    the clients 14.8: below 24, but the clients' limit, not a miss. The server at 1.8 cores
    for the same frames is a miss. A hall is held to 24 fps, a class of 150 to 30."""
    monkeypatch.setattr(following.os, "cpu_count", lambda: 2)
    fps = [14.0] + [16.0 * 300 / 299 - 14.0 / 299] * 299  # mean 16, the slowest 14
    bounds = Bounds()
    shared = _hall_fps(300, fps, following.Moving(1.7, sum(fps), 300, 2))
    alone, beside = shared.detail["server_alone_fps"], shared.detail["beside_clients_fps"]
    assert alone == pytest.approx(0.9 * 2 / (1.0 / 4800 * 300) * 14 / 16)
    assert alone == pytest.approx(25.2) and beside == pytest.approx(14.82, abs=0.01)
    assert shared.verdict(bounds) == "clients" and exit_status([shared], bounds) == 0
    assert shared.goal is not None and shared.goal.describe(bounds) == ">= 24 fps"
    costly = _hall_fps(300, fps, following.Moving(2.5, sum(fps), 300, 2))
    assert costly.detail["server_alone_fps"] < 24 and costly.verdict(bounds) == "MISSED"
    # One process for the server: with the machine to itself it still has one core.
    one = _hall_fps(300, fps, following.Moving(1.7, sum(fps), 300, 1))
    assert one.detail["server_alone_fps"] == pytest.approx(alone / 2)
    assert one.verdict(bounds) == "MISSED"
    # A hall at 25 fps each meets its 24; a class of 150 at 25 misses its 30 (one server
    # process: it could give 20 fps with the machine to itself).
    steady = following.Moving(1.8, 25.0 * 300, 300, 2)
    assert _hall_fps(300, [25.0] * 300, steady).verdict(bounds) == "met"
    small = _hall_fps(150, [25.0] * 150, following.Moving(1.8, 25.0 * 150, 150, 1))
    assert small.goal is not None and small.goal.describe(bounds) == ">= 30 fps"
    assert small.detail["server_alone_fps"] == pytest.approx(20.45, abs=0.01)
    assert small.verdict(bounds) == "MISSED"
    # Held to 26 it is below: the clients' limit (the server alone: 40.9 fps); to 45, a miss.
    hall = _hall_fps(300, [25.0] * 300, steady)
    assert hall.detail["server_alone_fps"] == pytest.approx(40.9, abs=0.1)
    assert hall.verdict(Bounds(min_hall_fps=26.0)) == "clients"
    assert hall.verdict(Bounds(min_hall_fps=45.0)) == "MISSED"
    # Measured while the lead moved, a full machine is no longer "the machine's" limit (the
    # rates tell whose); unmeasured (the hosts variant), it still is.
    assert following.Load(1.2, 1.0, 4).limit == "machine"
    load = following.Load(1.2, 1.0, 4, steady)
    assert (
        load.limit == "server" and "56.2 fps with the machine to itself, 25.0 beside" in load.text()
    )


def test_the_follow_figures_are_the_95th_percentile_of_the_redraws_not_the_slowest():
    """100 redraws of 1 to 100 ms: the figure is 95 ms (the slowest, 100 ms, is not it), on
    one host and on the other host of two."""
    redraws = [[0.001 * (10 * m + f + 1) for f in range(10)] for m in range(10)]
    moving = {"fps": [30.0] * 10, "latencies": sum(redraws, []), "redraws": redraws, "moves": 10}
    load = following.Load(0.5, 0.5, 1)
    one = following._figures(10, moving, moving, moving, (0.1, 0.5, 1.0), True, load)
    move = next(f for f in one if f.name == "10 followers: lead's slider move on every follower")
    assert move.value == pytest.approx(95.0) and move.text.startswith("p95 95 ms over 100")
    outage = {"recovery": [1.0], "lost": 0, "early": 0, "told": 1, "others": 1, "refused": 0}
    outage |= {"links_lost": 1, "told_s": 0.5}
    two = hosts_workload._figures("2 hosts", [1] * 10, moving, moving, 0.1, outage, load)
    other = next(f for f in two if f.name == "2 hosts: lead's move on the other hosts")
    assert other.value == pytest.approx(95.0)


def test_a_hall_on_two_hosts_is_held_to_the_hall_s_rate():
    """The two-host phase holds its rows as the one-host phase does: 300 followers at 25 fps
    each meet a hall's 24; 150 at 25 miss a class's 30."""
    outage = {"recovery": [1.0], "lost": 0, "early": 0, "told": 1, "others": 1, "refused": 0}
    outage |= {"links_lost": 1, "told_s": 0.5}
    load = following.Load(0.5, 0.5, 1)
    bounds = Bounds()
    for count, verdict, goal in ((300, "met", ">= 24 fps"), (150, "MISSED", ">= 30 fps")):
        moving = {"fps": [25.0] * count, "latencies": [0.05] * count, "moves": 1}
        moving["redraws"] = [[0.05] * count]
        name = f"2 hosts, {count} followers"
        figures = hosts_workload._figures(name, [1] * count, moving, moving, 0.1, outage, load)
        fps = next(f for f in figures if f.name == f"{name}: fps each")
        assert fps.goal is not None and fps.goal.describe(bounds) == goal
        assert fps.verdict(bounds) == verdict


@pytest.mark.slow
def test_the_follow_phase_on_two_hosts_follows_through_redis_and_recovers(hosts_report):
    """Half the followers are on the other host: every lead's move reaches them through Redis,
    none is lost; Redis killed: each is told it keeps the last state, the lead's move then is
    followed on its own host only, and reaches them once Redis is back."""
    report = hosts_report
    failures = [f.text for f in report.figures if f.name == "completed"]
    assert not failures, (failures, report.notes)
    name = "2 hosts, 4 followers"
    moves = report.figure("follow", f"{name}: lead's move on the other hosts").detail
    assert moves["moves"] >= 2 and moves["lost"] == 0
    assert moves["redraws"] == moves["same_host"] == 2 * moves["moves"]
    restart = report.figure("follow", f"{name}: Redis stopped and started")
    counts = {k: restart.detail[k] for k in ("others", "told", "early", "lost", "refused")}
    assert counts == {"others": 2, "told": 2, "early": 0, "lost": 0, "refused": 0}
    assert restart.detail["links_lost"] == 2  # each host's link saw Redis go, once
    assert math.isfinite(restart.value)
    assert report.figure("follow", f"{name}: fps each").value > 0
    assert report.figure("follow", f"{name}: servers' CPU per frame").detail["follower_ms"] > 0
    # The link's own line when Redis was killed is expected; nothing else was logged.
    assert report.figure("follow", "server log errors").value == 0, report.notes


def test_the_followers_are_seated_evenly_on_the_hosts():
    addresses, hosts = hosts_workload.seats(5, [["a1", "a2"], ["b1"]])
    assert hosts == [0, 1, 0, 1, 0]
    assert addresses == ["a1", "b1", "a2", "b1", "a1"]


def test_hosts_are_for_the_follow_phase_alone():
    for argv in (
        ["--phase", "soak", "--hosts", "2"],
        ["--phase", "follow", "--hosts", "2", "--workers", "2"],
    ):
        with pytest.raises(SystemExit) as exc:
            cli.main(argv)
        assert exc.value.code == 2


# -- the goals, judged on the same figures -----------------------------------------------------
@pytest.mark.slow
def test_met_bounds_give_zero_and_each_impossible_bound_gives_one(
    report, follow_report, hosts_report
):
    # The tiny follow run has no hall: a row of 300 followers at 25 fps, its server in one
    # process (it could give 20 fps alone: its goal is its own, not the clients').
    hall = _row(300, [25.0] * 300, following.Moving(1.8, 25.0 * 300, 300, 1))
    figures = report.figures + follow_report.figures + hosts_report.figures + hall
    assert exit_status(figures, LENIENT) == 0
    impossible = {
        "min_fps": 1e9,
        "min_hall_fps": 1e9,
        "max_redraw_ms": 0.0,
        "max_rss_growth": -1.0,
        "storm_tolerance": -1.0,
        "min_keep": 1e9,
        "max_errors": -1,
        "max_hostile_rss_growth": -1.0,
        "min_innocent_keep": 1e9,
        "max_follow_ms": -1.0,
        "max_hall_follow_ms": -1.0,
        "max_hosts_follow_ms": -1.0,
        "max_recovery_s": -1.0,
    }
    assert set(impossible) == {f.name for f in dataclasses.fields(Bounds)}
    for name, value in impossible.items():
        bounds = dataclasses.replace(LENIENT, **{name: value})
        assert exit_status(figures, bounds) == 1, name


@pytest.mark.slow
def test_main_prints_the_table_and_exits_by_the_goals(report, monkeypatch, capsys):
    monkeypatch.setattr(cli, "run", lambda phases, cfg: report)
    assert cli.main(LENIENT_ARGS) == 0
    out = capsys.readouterr().out
    assert "0 goals missed" in out and "MISSED" not in out
    for phase in PHASES:
        assert f"\n{phase} " in out
    assert cli.main([*LENIENT_ARGS, "--min-fps=1e9"]) == 1
    out = capsys.readouterr().out
    assert "1 goals missed" in out and "MISSED" in out


# -- pieces, without a server ------------------------------------------------------------------
def test_a_phase_that_could_not_run_and_an_empty_run_fail():
    failed = Figure("soak", "completed", 0.0, "failed: no scene", COMPLETES)
    assert exit_status([failed], Bounds()) == 1
    assert exit_status([], Bounds()) == 1  # nothing judged is not a pass


def test_a_figure_not_measured_misses_its_goal():
    assert Figure("x", "y", math.nan, "n/a", at_most("max_redraw_ms", "")).verdict(Bounds()) == (
        "MISSED"
    )
    assert Figure("x", "y", 31.0, "", at_least("min_fps", "")).verdict(Bounds()) == "met"
    assert Figure("x", "y", 29.0, "", at_least("min_fps", "")).verdict(Bounds()) == "MISSED"


def test_the_soak_runs_on_as_many_processes_as_poinsot_serve_starts(monkeypatch):
    """No ``--workers``: the soak runs against one process per core (as a lecturer's ``poinsot
    serve``), the other phases against one; ``--workers N`` is the soak's N."""
    seen = {}
    monkeypatch.setattr(cli, "run", lambda phases, cfg: seen.setdefault("cfg", cfg) and Report())
    cli.main(["--phase", "soak"])
    cfg = seen.pop("cfg")
    cores = os.cpu_count() or 1
    assert cfg.workers == 0
    assert server_processes(cfg, "soak") == cores
    assert all(server_processes(cfg, phase) == 1 for phase in PHASES if phase != "soak")
    cli.main(["--phase", "soak", "--workers", "3"])
    assert server_processes(seen.pop("cfg"), "soak") == 3


def test_stall_and_flood_need_two_clients():
    with pytest.raises(SystemExit) as exc:
        cli.main(["--phase", "stall", "--clients", "1"])
    assert exc.value.code == 2


def test_the_server_log_is_read_for_tracebacks_and_errors():
    log = "\n".join(
        [
            "(viser) Server started",
            "2026-01-01 12:00:00,000 ERROR session 3: KeyError: 'mesh'",
            "Traceback (most recent call last):",
            '  File "session.py", line 1, in _run',
            "KeyError: 'mesh'",
            "a websocket error",
            "Connection closed",
        ]
    )
    assert len(error_lines(log)) == 4
    assert error_lines("") == []


def test_percentile_thread_kinds_and_proc():
    assert percentile([], 0.5) != percentile([], 0.5)  # NaN
    assert percentile([3.0, 1.0, 2.0, 4.0], 0.5) == 2.0
    assert percentile([float(i) for i in range(1, 101)], 0.95) == 95.0
    with pytest.raises(ValueError, match="fraction"):  # 95 for 0.95 would be the largest value
        percentile([1.0, 2.0], 95)
    assert thread_kind("poinsot-session-12") == "poinsot-session"
    assert thread_kind("ThreadPoolExecutor-0_3") == "ThreadPoolExecutor"
    assert thread_kind("MainThread") == "MainThread"
    me = usage(os.getpid())
    assert me.threads >= 1 and me.rss_bytes > 0 and me.cpu_seconds > 0


@pytest.mark.parametrize("size", [0, 5, 125, 126, 70_000])
def test_client_frames_are_masked_and_unmask_to_the_payload(size):
    payload = os.urandom(size)
    frame = client_frame(payload)
    assert frame[0] == 0x82 and frame[1] & 0x80
    length, offset = frame[1] & 0x7F, 2
    if length == 126:
        length, offset = struct.unpack_from("!H", frame, 2)[0], 4
    elif length == 127:
        length, offset = struct.unpack_from("!Q", frame, 2)[0], 10
    mask, body = frame[offset : offset + 4], frame[offset + 4 :]
    assert length == size == len(body)
    assert bytes(b ^ mask[i % 4] for i, b in enumerate(body)) == payload
