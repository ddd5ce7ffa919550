"""The report's CSV files: ``work_precision.csv`` (one row per run, errors worst over the grid)
and ``error_vs_time.csv`` (the same errors at every output time)."""

from __future__ import annotations

import csv
from collections.abc import Iterator
from pathlib import Path

from poinsot.app.report.formatting import csv_float
from poinsot.app.report.measure.study import CaseResult

__all__ = ["ERROR_VS_TIME_COLUMNS", "EXACT", "WORK_PRECISION_COLUMNS", "write_csvs"]

#: The ``method`` of the exact solution's rows.
EXACT = "exact"
WORK_PRECISION_COLUMNS = (
    "case",
    "method",
    "setting",
    "seconds",
    "omega_error",
    "attitude_error",
    "energy_drift",
)
ERROR_VS_TIME_COLUMNS = (
    "case",
    "method",
    "setting",
    "t",
    "omega_error",
    "attitude_error",
    "energy_drift",
)


def write_csvs(out: Path, results: list[CaseResult]) -> None:
    """Write both CSV files into ``out``."""
    _write(out / "work_precision.csv", WORK_PRECISION_COLUMNS, _work_precision_rows(results))
    _write(out / "error_vs_time.csv", ERROR_VS_TIME_COLUMNS, _error_vs_time_rows(results))


def _write(path: Path, columns: tuple[str, ...], rows: Iterator[list[str]]) -> None:
    with open(path, "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(columns)
        writer.writerows(rows)


def _work_precision_rows(results: list[CaseResult]) -> Iterator[list[str]]:
    for r in results:
        ex = r.exact
        w, a = ex.worst_inside
        yield [
            r.case.name,
            EXACT,
            "closed form",
            f"{ex.seconds:.6g}",
            csv_float(w),
            csv_float(a),
            csv_float(ex.invariant_energy),
        ]
        for run in r.runs:
            yield [
                run.case,
                run.method,
                run.setting,
                f"{run.seconds:.6g}",
                csv_float(run.omega_error),
                csv_float(run.attitude_error),
                csv_float(run.energy_drift),
            ]


def _error_vs_time_rows(results: list[CaseResult]) -> Iterator[list[str]]:
    for r in results:
        for t, w, a in r.exact.all_checks:
            yield [r.case.name, EXACT, "closed form", csv_float(t), csv_float(w), csv_float(a), ""]
        for run in r.runs:
            for i, t in enumerate(run.times):
                yield [
                    run.case,
                    run.method,
                    run.setting,
                    csv_float(float(t)),
                    csv_float(float(run.errors.omega[i])),
                    csv_float(float(run.errors.attitude[i])),
                    csv_float(float(run.errors.energy[i])),
                ]
