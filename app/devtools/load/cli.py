"""``python -m poinsot.app.devtools.load`` (``make load``): the command line of the load test."""

from __future__ import annotations

import argparse
import dataclasses
import os
import sys
import time
from collections.abc import Sequence

from poinsot.app.cli.arguments import (
    OneLineParser,
    fraction,
    non_negative_float,
    non_negative_int,
    positive_float,
    positive_int,
    run_guarded,
)
from poinsot.app.devtools.load.config import Config, Report, server_processes
from poinsot.app.devtools.load.figures import Bounds, exit_status, format_table, missed
from poinsot.app.devtools.load.phases import ALL_PHASES, PHASES, run_phase


def build_parser() -> argparse.ArgumentParser:
    cfg, bounds = Config(), Bounds()
    parser = OneLineParser(
        prog="python -m poinsot.app.devtools.load",
        description="Load test of the live server on this machine's loopback: a soak, a storm "
        "of connections, a stalled client, a flooding client, a hostile one. Prints a table of "
        "figures and goals; exits 1 when a goal is missed.",
    )
    add = parser.add_argument
    add(
        "--phase",
        nargs="+",
        choices=ALL_PHASES,
        default=list(PHASES),
        help="phases to run, in order (default: all but follow)",
    )
    add("--clients", type=positive_int, default=cfg.clients, help="clients in each phase")
    add(
        "--workers",
        type=positive_int,
        default=cfg.workers,
        help="server processes of the soak (default: one per core, as poinsot serve)",
    )
    add("--seconds", type=positive_float, default=cfg.seconds, help="length of the soak [s]")
    add("--slider-period", type=positive_float, default=cfg.slider_period, help="slider every [s]")
    add("--storm", type=positive_int, default=cfg.storm, help="connects and departures")
    add("--storm-workers", type=positive_int, default=cfg.storm_workers, help="visits at a time")
    add("--storm-steady", type=non_negative_int, default=cfg.storm_steady, help="kept through it")
    add("--settle-seconds", type=positive_float, default=cfg.settle_seconds, help="after it [s]")
    add("--stall-seconds", type=positive_float, default=cfg.stall_seconds, help="one stalls [s]")
    add("--flood-seconds", type=positive_float, default=cfg.flood_seconds, help="one floods [s]")
    add("--flood-rate", type=positive_float, default=cfg.flood_rate, help="messages a second")
    add(
        "--hostile-handshakes",
        type=positive_int,
        default=cfg.hostile_handshakes,
        help="refused handshakes in the hostile phase",
    )
    add(
        "--hostile-quiet-seconds",
        type=positive_float,
        default=cfg.hostile_quiet_seconds,
        help="the innocent client's reference windows [s]",
    )
    _add_follow(parser, cfg)
    add("--debug", action="store_true", help="show the traceback of a failure (else one line)")
    _add_goals(parser, bounds)
    return parser


def _add_goals(parser: argparse.ArgumentParser, bounds: Bounds) -> None:
    """The goals' bounds (:class:`Bounds`), each an option."""
    goals = parser.add_argument_group("goals")
    goals.add_argument("--min-fps", type=non_negative_float, default=bounds.min_fps)
    goals.add_argument("--min-hall-fps", type=non_negative_float, default=bounds.min_hall_fps)
    goals.add_argument("--max-redraw-ms", type=positive_float, default=bounds.max_redraw_ms)
    goals.add_argument("--max-rss-growth", type=non_negative_float, default=bounds.max_rss_growth)
    goals.add_argument("--storm-tolerance", type=non_negative_float, default=bounds.storm_tolerance)
    goals.add_argument("--min-keep", type=fraction, default=bounds.min_keep)
    goals.add_argument("--max-errors", type=non_negative_int, default=bounds.max_errors)
    goals.add_argument(
        "--max-hostile-rss-growth", type=non_negative_float, default=bounds.max_hostile_rss_growth
    )
    goals.add_argument("--min-innocent-keep", type=fraction, default=bounds.min_innocent_keep)
    goals.add_argument("--max-follow-ms", type=positive_float, default=bounds.max_follow_ms)
    goals.add_argument(
        "--max-hall-follow-ms", type=positive_float, default=bounds.max_hall_follow_ms
    )
    goals.add_argument(
        "--max-hosts-follow-ms", type=positive_float, default=bounds.max_hosts_follow_ms
    )
    goals.add_argument("--max-recovery-s", type=positive_float, default=bounds.max_recovery_s)


def _add_follow(parser: argparse.ArgumentParser, cfg: Config) -> None:
    """The follow phase's sizes (``--phase follow``)."""
    parser.add_argument(
        "--followers",
        type=positive_int,
        nargs="+",
        default=list(cfg.followers),
        help="followers of one lead in the follow phase, one run per number",
    )
    parser.add_argument(
        "--follow-seconds", type=positive_float, default=cfg.follow_seconds, help="each window"
    )
    parser.add_argument(
        "--follow-redraw-timeout",
        type=positive_float,
        default=cfg.follow_redraw_timeout,
        help="seconds after which a lead's move not yet on a follower counts as lost",
    )
    parser.add_argument(
        "--hosts",
        type=positive_int,
        default=cfg.hosts,
        help="hosts of the follow phase: more than 1 runs them linked by a local redis-server "
        "behind nginx (both from make chromium), the lead on the first",
    )
    parser.add_argument(
        "--followers-per-process",
        type=positive_int,
        default=cfg.followers_per_process,
        help="followers in each client process (as many processes as they need)",
    )


def _options(args: argparse.Namespace) -> tuple[list[str], Config, Bounds]:
    fields = vars(args)
    bounds = Bounds(**{f.name: fields[f.name] for f in dataclasses.fields(Bounds)})
    names = {f.name for f in dataclasses.fields(Config)} - {"settle_tolerance"}
    values = {name: fields[name] for name in names}
    values["followers"] = tuple(values["followers"])
    cfg = Config(**values, settle_tolerance=bounds.storm_tolerance)
    return list(args.phase), cfg, bounds


def _check(parser: argparse.ArgumentParser, phases: list[str], cfg: Config) -> None:
    """What the converters cannot see alone (each option is checked by its ``type``)."""
    if cfg.workers > 1 and set(phases) - {"soak", "follow"}:
        parser.error("--workers more than 1 only with --phase soak or follow")
    if cfg.hosts > 1 and (phases != ["follow"] or cfg.workers > 1):
        parser.error("--hosts more than 1 only with --phase follow alone, one process per host")
    if {"stall", "flood"} & set(phases) and cfg.clients < 2:
        parser.error("stall and flood need --clients >= 2 (one stalls, the others are measured)")


def _load_average() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def run(phases: Sequence[str], cfg: Config, verbose: bool = True) -> Report:
    """Run the phases in order; their figures and notes."""
    report = Report()

    def say(message: str) -> None:
        if verbose:
            print(f"[{time.strftime('%H:%M:%S')}] {message}", file=sys.stderr, flush=True)

    for name in phases:
        run_phase(name, cfg, report, say)
    return report


def main(argv: Sequence[str] | None = None) -> int:
    """Parse and run; a bad argument is one line and exit status 2, an unexpected failure one
    line and exit status 1 (with its traceback under ``--debug``)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    phases, cfg, bounds = _options(args)
    _check(parser, phases, cfg)
    return run_guarded(parser.prog, lambda: _run(phases, cfg, bounds), debug=args.debug)


def _run(phases: list[str], cfg: Config, bounds: Bounds) -> int:
    print(
        f"Poinsot load test: {' '.join(phases)}; {cfg.clients} clients, "
        f"{server_processes(cfg, 'soak')} server process(es) in the soak, soak {cfg.seconds:g} s, "
        f"storm {cfg.storm}; python {sys.version.split()[0]}, {os.cpu_count()} CPUs, "
        f"load average {_load_average()} (1, 5, 15 min)",
        flush=True,
    )
    started = time.monotonic()
    report = run(phases, cfg)
    print(format_table(report.figures, bounds))
    for note in report.notes:
        print(note)
    status = exit_status(report.figures, bounds)
    print(
        f"{len(missed(report.figures, bounds))} goals missed; "
        f"{time.monotonic() - started:.0f} s; load average now {_load_average()}"
    )
    return status
