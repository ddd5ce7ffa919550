"""What the numbers of one case say: per accuracy level the fastest integrator that reaches it,
a one-line verdict against the exact solution, and the observed order of each method."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from poinsot.app.report.formatting import sig
from poinsot.app.report.measure.runs import IntegratorRun
from poinsot.app.report.measure.study import CaseResult
from poinsot.physics.integrators import INTEGRATORS

__all__ = ["ACCURACY_LEVELS", "Verdict", "observed_order", "verdict"]

#: Accuracy levels of the verdicts: max(omega error, attitude error) at or below each.
ACCURACY_LEVELS = (1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12)
#: The error range the observed orders are fitted over: below 1e-2 the error is in its
#: asymptotic regime [HNW93 §II.3], above 1e-13 it is not yet rounding.
ORDER_FIT_RANGE = (1e-13, 1e-2)


@dataclass(frozen=True)
class Verdict:
    text: str
    """One line, ending with a full stop."""
    per_level: list[tuple[float, str]]
    """(accuracy level, the fastest integrator reaching it, or "no integrator")."""
    exact_wins: bool
    """The exact solution is the cheapest way to every accuracy level."""


def fastest_per_level(r: CaseResult) -> dict[float, IntegratorRun | None]:
    """Per accuracy level, the fastest run that reaches it (None if none does)."""
    fastest: dict[float, IntegratorRun | None] = {}
    for level in ACCURACY_LEVELS:
        reaching = [run for run in r.runs if run.accuracy <= level]
        fastest[level] = min(reaching, key=lambda run: run.seconds) if reaching else None
    return fastest


def verdict(r: CaseResult) -> Verdict:
    """One-line verdict and, per accuracy level, the fastest integrator that reaches it."""
    best = fastest_per_level(r)
    per_level = [
        (
            level,
            "no integrator"
            if run is None
            else f"{run.method} {run.setting} ({sig(run.seconds * 1e3)} ms)",
        )
        for level, run in best.items()
    ]
    parts = []
    exact_part, exact_wins = _exact_against_integrators(r, best)
    if exact_part:
        parts.append(exact_part)
    reached = [(lvl, run.method) for lvl, run in best.items() if run is not None]
    if reached:
        winners = ", then ".join(f"{m} down to {lvl:.0e}" for lvl, m in _group_levels(reached))
        parts.append(f"among integrators the fastest is {winners}")
    if r.runs:
        most_accurate = min(r.runs, key=lambda run: run.accuracy)
        parts.append(
            f"the best integrator accuracy is {most_accurate.accuracy:.1e} "
            f"({most_accurate.method} {most_accurate.setting})"
        )
    hopeless = [
        m
        for m in INTEGRATORS
        if (mine := [run for run in r.runs if run.method == m])
        and min(run.accuracy for run in mine) > 0.1
    ]
    if hopeless:
        why = ""
        if r.conditioning.floor >= 0.01:
            why = f" (κ u = {r.conditioning.floor:.2g}: the problem's conditioning)"
        parts.append(f"no setting brings {' or '.join(hopeless)} below an error of 0.1{why}")
    return Verdict("; ".join(parts) + ".", per_level, exact_wins)


def _exact_against_integrators(
    r: CaseResult, best: dict[float, IntegratorRun | None]
) -> tuple[str, bool]:
    """The verdict's first clause (empty when the exact solution was not verified), and whether
    the exact solution is the cheapest at every level."""
    ex_acc = max(r.exact.worst_inside)
    if not math.isfinite(ex_acc):
        return "", False
    exact_ms = sig(r.exact.seconds * 1e3)
    beaten = [
        (lvl, run)
        for lvl, run in best.items()
        if run is not None and run.seconds < r.exact.seconds and lvl >= ex_acc
    ]
    if beaten:
        lvl, run = max(beaten, key=lambda p: p[0])
        return (
            f"an integrator is cheaper than the exact solution at accuracy {lvl:.0e} "
            f"({run.method} {run.setting}, {sig(run.seconds * 1e3)} ms vs {exact_ms} ms)",
            False,
        )
    return (
        f"the exact solution wins at every accuracy ({exact_ms} ms for "
        f"{r.exact.points} points, error {ex_acc:.1e} vs mpmath)",
        True,
    )


def order_fit_runs(runs: list[IntegratorRun], floor: float = 0.0) -> list[IntegratorRun]:
    """The runs an order is fitted over, by cost: omega error inside ORDER_FIT_RANGE and above
    ``floor`` (the case's conditioning floor κ u: below it amplified rounding, not the method's
    truncation, sets the error, and differs from one machine's rounding to another's)."""
    low, high = ORDER_FIT_RANGE
    inside = [r for r in runs if max(low, floor) < r.omega_error < high and r.cost > 0]
    return sorted(inside, key=lambda r: r.cost)


def observed_order(runs: list[IntegratorRun]) -> float:
    """p in omega error ~ cost^-p (cost = steps or RHS evaluations), fitted over
    :func:`order_fit_runs`. NaN with fewer than two, or when the error does not decrease as
    the cost grows: then there is no order to observe (the error sits at a floor, e.g. the
    conditioning floor of :mod:`conditioning`, and a fit would give orders near 0 or < 0)."""
    pts = order_fit_runs(runs)
    if len(pts) < 2 or len({r.cost for r in pts}) < 2:
        return math.nan
    if any(b.omega_error >= a.omega_error for a, b in zip(pts, pts[1:], strict=False)):
        return math.nan
    x = np.log([r.cost for r in pts])
    y = np.log([r.omega_error for r in pts])
    return float(-np.polyfit(x, y, 1)[0])


def _group_levels(items: list[tuple[float, str]]) -> list[tuple[float, str]]:
    """Collapse consecutive accuracy levels won by the same method to the finest level."""
    grouped: list[tuple[float, str]] = []
    for level, method in items:
        if grouped and grouped[-1][1] == method:
            grouped[-1] = (level, method)
        else:
            grouped.append((level, method))
    return grouped
