"""``poinsot report``: error against run time, the exact solution beside numerical integrators.

A work-precision study over a matrix of ordinary, stiff and extreme bodies
(:mod:`~poinsot.app.report.measure.cases`). For every case the exact solution
:class:`poinsot.physics.FreeRigidBody` is evaluated once on the output grid and every integrator
of :data:`poinsot.physics.integrators.INTEGRATORS` runs at several step sizes or tolerances
(:mod:`~poinsot.app.report.measure.runs`); their errors in omega (relative) and in attitude
(geodesic angle) are measured against the exact solution, whose own error is measured against an
independent Taylor-series reference at 32 digits (:mod:`~poinsot.app.report.measure.reference`,
built on mpmath, which is optional and imported lazily).

Outputs in the output directory:

* ``work_precision.csv``: ``case,method,setting,seconds,omega_error,attitude_error,energy_drift``
  (one row per run; errors are maxima over the output grid; the ``exact`` rows carry the
  closed form's errors against the mpmath reference, at its check points);
* ``error_vs_time.csv``: the same errors against simulated time, for every run;
* ``game_steps.csv``: the game engines' steps at 1/60 s and 1/240 s on the T-handle (does it
  flip, the first flip's error, the drifts per minute; :mod:`~poinsot.app.report.measure.games`);
* ``report.md``: tables, a verdict per case, the observed orders, each case's conditioning
  (:mod:`~poinsot.app.report.measure.conditioning`), the saturated errors near the separatrix read
  as flips (:mod:`~poinsot.app.report.findings`), the exact solution's stability findings, its
  speed-up over DOP853 at equal accuracy at t = 1e4, and the figures with their captions;
* ``work_precision.png``, ``work_precision_attitude.png``, ``error_vs_time.png`` (matplotlib,
  Agg backend, imported lazily; skipped with a note in report.md and on stderr if it is not
  installed).

The package composes :mod:`poinsot.physics` and does no physics of its own; it never imports
viser or the live server. The command line (``poinsot report``, or
``python -m poinsot.app.report``) is :mod:`poinsot.app.cli.main`'s; this is its typed entry.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

from poinsot.app.report.figures import write_figures
from poinsot.app.report.markdown import ReportInputs, write_markdown
from poinsot.app.report.measure.cases import StudyConfig
from poinsot.app.report.measure.exact import load_reference
from poinsot.app.report.measure.games import game_rows
from poinsot.app.report.measure.games import write_csv as write_games_csv
from poinsot.app.report.measure.progress import Progress
from poinsot.app.report.measure.speedup import Speedup, speedup_study
from poinsot.app.report.measure.study import CaseResult, progress_units, study_case
from poinsot.app.report.tables import write_csvs

__all__ = ["ReportSummary", "run_report", "write_report"]


@dataclass
class ReportSummary:
    """What a report run wrote and found."""

    out: Path
    results: list[CaseResult]
    speedup: Speedup
    elapsed: float
    """Wall time [s]."""


def write_report(out: Path, *, quick: bool, progress: bool = True) -> ReportSummary:
    """Run the study and write the CSVs, report.md and figures into ``out`` (created)."""
    start = time.perf_counter()
    out.mkdir(parents=True, exist_ok=True)
    config = StudyConfig.for_mode(quick)
    reference_cls, reference_note = load_reference()
    bar = Progress(progress_units(config), enabled=progress)
    results = [study_case(case, config, reference_cls, bar) for case in config.cases]
    speedup = speedup_study(config, reference_cls, bar)
    bar.close()
    games = tuple(game_rows())
    write_csvs(out, results)
    write_games_csv(out, list(games))
    figures, figure_note = write_figures(out, results)
    elapsed = time.perf_counter() - start
    inputs = ReportInputs(
        config, results, speedup, reference_note, figures, figure_note, elapsed, games
    )
    write_markdown(out, inputs)
    return ReportSummary(out, results, speedup, elapsed)


def run_report(out: Path, *, quick: bool) -> int:
    """``poinsot report [--quick] [--out DIR]``: write the report, say where; the exit code."""
    summary = write_report(out, quick=quick)
    print(f"report written to {summary.out / 'report.md'} in {summary.elapsed:.1f} s")
    return 0
