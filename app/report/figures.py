"""The report's figures (matplotlib, Agg backend; optional: the ``report`` extra).

``work_precision.png`` and ``work_precision_attitude.png``: per case, the worst error over the
horizon against run time, every run of every method, the exact solution as a star.
``error_vs_time.png``: per case, the error along the motion of each method's most accurate
run, and the exact solution's checks against the high-precision reference.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from poinsot.app.report.runs import IntegratorRun
from poinsot.app.report.study import CaseResult
from poinsot.app.report.tables import EXACT
from poinsot.physics.integrators import INTEGRATORS

__all__ = ["write_figures"]

#: Errors are drawn on log axes: an error of exactly 0 is drawn at this floor.
FLOOR = 1e-17

_COLOURS = {
    "RK45": "tab:blue",
    "DOP853": "tab:orange",
    "splitting": "tab:green",
    "midpoint": "tab:purple",
    EXACT: "black",
}


def write_figures(out: Path, results: list[CaseResult]) -> tuple[list[str], str]:
    """Draw the figures into ``out``: (file names written, a note for the report)."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return [], "matplotlib is not installed (`pip install poinsot[report]`): no figures."
    written = []
    for name, pick, ylabel in (
        ("work_precision.png", _omega_error, "omega error (relative)"),
        ("work_precision_attitude.png", _attitude_error, "attitude error [rad]"),
    ):
        fig = _work_precision(plt, results, pick, ylabel)
        fig.savefig(out / name, dpi=90)
        plt.close(fig)
        written.append(name)
    fig = _error_vs_time(plt, results)
    fig.savefig(out / "error_vs_time.png", dpi=90)
    plt.close(fig)
    written.append("error_vs_time.png")
    return written, f"Figures drawn with matplotlib {matplotlib.__version__} (Agg)."


def _omega_error(run: IntegratorRun) -> float:
    return run.omega_error


def _attitude_error(run: IntegratorRun) -> float:
    return run.attitude_error


def _grid(plt: Any, n: int) -> tuple[Any, list[Any]]:
    """A figure with one panel per case (at most four per row); unused panels hidden."""
    cols = min(4, n)
    rows = -(-n // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.4 * rows), squeeze=False)
    flat = list(axes.flat)
    for ax in flat[n:]:
        ax.set_visible(False)
    return fig, flat[:n]


def _arrange(fig: Any) -> None:
    # Fixed margins: tight_layout costs seconds on a 3x4 grid and the panels are uniform.
    fig.subplots_adjust(left=0.06, right=0.98, bottom=0.07, top=0.91, wspace=0.32, hspace=0.5)


def _style(ax: Any, title: str, xlabel: str, ylabel: str) -> None:
    ax.set_title(title, fontsize=9)
    ax.set_xlabel(xlabel, fontsize=8)
    ax.set_ylabel(ylabel, fontsize=8)
    ax.tick_params(labelsize=7)
    ax.grid(True, which="major", alpha=0.3)


def _work_precision(
    plt: Any, results: list[CaseResult], pick: Callable[[IntegratorRun], float], ylabel: str
) -> Any:
    fig, axes = _grid(plt, len(results))
    for ax, r in zip(axes, results, strict=True):
        for method in INTEGRATORS:
            runs = [run for run in r.runs if run.method == method]
            if runs:
                ax.loglog(
                    [run.seconds for run in runs],
                    [max(pick(run), FLOOR) for run in runs],
                    "o-",
                    color=_COLOURS[method],
                    label=method,
                    ms=4,
                )
        w, a = r.exact.worst_inside
        y = w if pick is _omega_error else a
        if math.isfinite(y):
            ax.loglog(
                [r.exact.seconds],
                [max(y, FLOOR)],
                "*",
                color="black",
                ms=12,
                label="exact (vs mpmath)",
            )
        _style(ax, r.case.name, "run time [s]", ylabel)
    axes[0].legend(fontsize=7)
    fig.suptitle("Error against run time (worst over the horizon)")
    _arrange(fig)
    return fig


def _error_vs_time(plt: Any, results: list[CaseResult]) -> Any:
    fig, axes = _grid(plt, len(results))
    for ax, r in zip(axes, results, strict=True):
        for method in INTEGRATORS:
            runs = [run for run in r.runs if run.method == method]
            if not runs:
                continue
            best = min(runs, key=lambda run: run.accuracy)
            ax.loglog(
                best.times[1:],
                np.maximum(best.errors.omega[1:], FLOOR),
                color=_COLOURS[method],
                label=f"{method} {best.setting}",
                lw=1,
            )
        inside = [p for p in r.exact.all_checks if p[0] <= r.t_end * (1 + 1e-12)]
        if inside:
            ax.loglog(
                [p[0] for p in inside],
                [max(p[1], FLOOR) for p in inside],
                "*",
                color="black",
                ms=10,
                label="exact vs mpmath",
            )
        _style(ax, r.case.name, "simulated time", "omega error (relative)")
        ax.legend(fontsize=6)
    fig.suptitle("Error against simulated time (each method's most accurate setting)")
    _arrange(fig)
    return fig
