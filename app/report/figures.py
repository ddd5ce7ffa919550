"""The report's figures (matplotlib, Agg backend; optional: the ``report`` extra).

``work_precision.png`` and ``work_precision_attitude.png``: per case, the worst error over the
horizon against run time, every run of every method, the exact solution as a star.
``error_vs_time.png``: per case, the error along the motion of each method's most accurate
run, and the exact solution's checks against the high-precision reference.

Legends sit outside the panels, so that they hide no data: one figure legend above the panels
for what is common to all of them, and in ``error_vs_time.png`` one legend under each panel for
that panel's settings. :func:`caption` and :func:`takeaway` give the text report.md shows under
each figure.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from poinsot.app.report.measure.runs import IntegratorRun
from poinsot.app.report.measure.study import CaseResult
from poinsot.app.report.tables import EXACT
from poinsot.physics.integrators import INTEGRATORS

__all__ = [
    "FIGURE_NAMES",
    "caption",
    "draw_error_vs_time",
    "draw_work_precision",
    "takeaway",
    "write_figures",
]

FIGURE_NAMES = ("work_precision.png", "work_precision_attitude.png", "error_vs_time.png")
#: Errors are drawn on log axes: an error of exactly 0 is drawn at this floor.
FLOOR = 1e-17
MISSING = "matplotlib is not installed (`pip install poinsot[report]`): no figures."

_COLOURS = {
    "RK45": "tab:blue",
    "DOP853": "tab:orange",
    "splitting": "tab:green",
    "midpoint": "tab:purple",
    EXACT: "black",
}
_FLOOR_STYLE: dict[str, Any] = {"ls": "--", "color": "0.45", "lw": 0.9}
_STAR_LABEL = "exact solution (error vs the 32-digit reference)"
_FLOOR_LABEL = "κ u: error that rounding ω0 alone can cause"
_OMEGA_LABEL = "relative omega error [1]"
_ATTITUDE_LABEL = "attitude error [rad]"


def write_figures(out: Path, results: list[CaseResult]) -> tuple[list[str], str]:
    """Draw the figures into ``out``: (file names written, a note for the report). Without
    matplotlib, nothing is drawn and the console (stderr) says so."""
    try:
        plt = _pyplot()
    except ImportError:
        print(f"poinsot report: {MISSING}", file=sys.stderr)
        return [], MISSING
    drawings = (
        draw_work_precision(results, "omega"),
        draw_work_precision(results, "attitude"),
        draw_error_vs_time(results),
    )
    for name, fig in zip(FIGURE_NAMES, drawings, strict=True):
        fig.savefig(out / name, dpi=90)
        plt.close(fig)
    import matplotlib

    return list(FIGURE_NAMES), f"Figures drawn with matplotlib {matplotlib.__version__} (Agg)."


def _pyplot() -> Any:
    """matplotlib.pyplot on the Agg backend (ImportError without matplotlib)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _grid(n: int, row_height: float) -> tuple[Any, list[Any]]:
    """A figure with one panel per case (at most four per row); unused panels hidden."""
    cols = min(4, n)
    rows = -(-n // cols)
    fig, axes = _pyplot().subplots(
        rows, cols, figsize=(4.2 * cols, row_height * rows), squeeze=False
    )
    flat = list(axes.flat)
    for ax in flat[n:]:
        ax.set_visible(False)
    return fig, flat[:n]


def _style(ax: Any, title: str, xlabel: str, ylabel: str) -> None:
    ax.set_title(title, fontsize=9)
    ax.set_xlabel(xlabel, fontsize=8)
    ax.set_ylabel(ylabel, fontsize=8)
    ax.tick_params(labelsize=7)
    ax.grid(True, which="major", alpha=0.3)


def _figure_legend(fig: Any, handles: list[Any], title: str) -> None:
    """The suptitle, and under it one legend for what every panel shares, above the panels."""
    fig.suptitle(title, y=0.995)
    labels = [h.get_label() for h in handles]
    fig.legend(
        handles,
        labels,
        loc="upper center",
        bbox_to_anchor=(0.5, 0.965),
        ncol=len(handles),
        fontsize=8,
        frameon=False,
    )


def _handles() -> tuple[Any, Any]:
    """Legend handles for the star and the dashed conditioning floor."""
    from matplotlib.lines import Line2D

    star = Line2D([], [], marker="*", ls="none", color="black", ms=11, label=_STAR_LABEL)
    floor = Line2D([], [], label=_FLOOR_LABEL, **_FLOOR_STYLE)
    return star, floor


def draw_work_precision(results: list[CaseResult], quantity: str) -> Any:
    """Worst error over the horizon against run time, one panel per case; ``quantity`` is
    ``"omega"`` (with the conditioning floor) or ``"attitude"``."""
    pick: Callable[[IntegratorRun], float] = (
        (lambda run: run.omega_error) if quantity == "omega" else (lambda run: run.attitude_error)
    )
    fig, axes = _grid(len(results), 3.4)
    method_lines: dict[str, Any] = {}
    for ax, r in zip(axes, results, strict=True):
        for method in INTEGRATORS:
            runs = [run for run in r.runs if run.method == method]
            if runs:
                (method_lines[method],) = ax.loglog(
                    [run.seconds for run in runs],
                    [max(pick(run), FLOOR) for run in runs],
                    "o-",
                    color=_COLOURS[method],
                    label=method,
                    ms=4,
                )
        w, a = r.exact.worst_inside
        y = w if quantity == "omega" else a
        if math.isfinite(y):
            ax.loglog([r.exact.seconds], [max(y, FLOOR)], "*", color="black", ms=12)
        if quantity == "omega":
            ax.axhline(max(r.conditioning.floor, FLOOR), **_FLOOR_STYLE)
        ylabel = _OMEGA_LABEL if quantity == "omega" else _ATTITUDE_LABEL
        _style(ax, r.case.name, "run time [s]", ylabel)
    star, floor = _handles()
    handles = [*method_lines.values(), star] + ([floor] if quantity == "omega" else [])
    _figure_legend(fig, handles, f"Worst {quantity} error over the horizon against run time")
    fig.subplots_adjust(left=0.06, right=0.98, bottom=0.07, top=0.88, wspace=0.32, hspace=0.5)
    return fig


def draw_error_vs_time(results: list[CaseResult]) -> Any:
    """Relative omega error along the motion, each method's most accurate run; one panel per
    case, its settings in a legend under it."""
    fig, axes = _grid(len(results), 4.3)
    for ax, r in zip(axes, results, strict=True):
        for method in INTEGRATORS:
            runs = [run for run in r.runs if run.method == method]
            if runs:
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
            )
        ax.axhline(max(r.conditioning.floor, FLOOR), **_FLOOR_STYLE)
        _style(ax, r.case.name, f"simulated time [{r.case.time_unit}]", _OMEGA_LABEL)
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=2, fontsize=6, frameon=False)
    _figure_legend(
        fig, list(_handles()), "Omega error along the motion (each method's most accurate run)"
    )
    fig.subplots_adjust(left=0.06, right=0.98, bottom=0.08, top=0.9, wspace=0.32, hspace=0.75)
    return fig


def caption(name: str) -> str:
    """What a figure shows, for report.md."""
    return {
        "work_precision.png": (
            "Worst relative omega error over the horizon against run time, one panel per case. "
            "Dots joined by lines: one integrator at its ladder of settings (cheapest left). "
            "★: the exact solution, its error measured against the 32-digit Taylor reference "
            "and its time including the construction. Dashed: κ u, the conditioning floor "
            "(see Conditioning)."
        ),
        "work_precision_attitude.png": (
            "The same for the attitude: geodesic angle [rad] between the run's attitude and the "
            "exact one, worst over the horizon, against run time."
        ),
        "error_vs_time.png": (
            "Relative omega error along the motion for each method's most accurate run (the "
            "settings are under each panel), against simulated time in the case's unit (s; "
            "days for Toutatis). ★: the exact solution's checks against the reference inside the "
            "horizon. Dashed: κ u."
        ),
    }[name]


def takeaway(name: str, results: list[CaseResult]) -> str:
    """One line on what a figure shows, computed from the results."""
    if name == "error_vs_time.png":
        return _growth_takeaway(results)
    quantity = "attitude" if name == "work_precision_attitude.png" else "omega"
    beats = sum(_exact_dominates(r, quantity) for r in results)
    return (
        f"★ lies left of and below every integrator run in {beats} of {len(results)} panels: "
        f"there the exact solution is cheaper than the cheapest run and its {quantity} error "
        "smaller than the most accurate run's."
    )


def _exact_dominates(r: CaseResult, quantity: str) -> bool:
    error = r.exact.worst_inside[0 if quantity == "omega" else 1]
    if not (math.isfinite(error) and r.runs):
        return False
    run_errors = [run.omega_error if quantity == "omega" else run.attitude_error for run in r.runs]
    return r.exact.seconds < min(run.seconds for run in r.runs) and error < min(run_errors)


def growth_exponent(run: IntegratorRun) -> float:
    """p in error ~ t^p, fitted over the run's last nine tenths of the horizon (NaN if the
    error vanishes there)."""
    t, e = run.times, run.errors.omega
    keep = (t >= 0.1 * t[-1]) & (e > 0.0)
    if np.count_nonzero(keep) < 2:
        return math.nan
    return float(np.polyfit(np.log(t[keep]), np.log(e[keep]), 1)[0])


def _growth_takeaway(results: list[CaseResult]) -> str:
    first = results[0]
    rates = []
    for method in INTEGRATORS:
        runs = [run for run in first.runs if run.method == method]
        if runs:
            p = growth_exponent(min(runs, key=lambda run: run.accuracy))
            rates.append(f"{method} t^{p:.1f}")
    parts = []
    if rates:
        parts.append(
            f"On {first.case.name} the best runs' error grows like {', '.join(rates)} (t^1: a "
            "phase that drifts at a constant rate; faster: the invariants drift too)"
        )
    checks = [c[1] for r in results for c in r.exact.all_checks]
    if checks:
        far = any(r.exact.far_check for r in results)
        parts.append(
            f"the exact solution's checks stay at or below {max(checks):.1e}"
            + (", 1e4 periods out included" if far else "")
        )
    text = "; ".join(parts)
    return text[:1].upper() + text[1:] + "." if text else "No runs."
