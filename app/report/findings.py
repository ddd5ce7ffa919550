"""The report.md sections that explain numbers which look like bugs: the observed orders (and
why some are blank), the conditioning of each case (why no integrator gets below ~0.1 at
1 - m = 1e-14), and the saturated errors of exactly 2 and pi near the separatrix (flips).

Each function returns its section's lines; the numbers quoted in the text come from the results.
"""

from __future__ import annotations

import math

from poinsot.app.report.formatting import exp, sig
from poinsot.app.report.measure.conditioning import SEPARATRIX_TOLERANCE, Conditioning
from poinsot.app.report.measure.runs import IntegratorRun
from poinsot.app.report.measure.study import FLIP_SAMPLES, CaseResult
from poinsot.app.report.verdicts import ORDER_FIT_RANGE, observed_order, order_fit_runs
from poinsot.physics.integrators import INTEGRATORS

__all__ = ["conditioning_section", "orders_section", "saturation_section", "saturated"]

#: An omega error at or above this is saturated: omega is at least as far from the exact omega
#: as the exact omega's own length (a difference of 60 degrees at equal lengths).
SATURATED = 1.0
#: Floors at or above this get a sentence in the Conditioning section.
NOTABLE_FLOOR = 1e-6


def orders_section(results: list[CaseResult]) -> list[str]:
    """The observed orders, fitted above each case's conditioning floor; blank where the
    error does not converge."""
    low, high = ORDER_FIT_RANGE
    lines = [
        "## Observed orders",
        "",
        "p in omega error ~ cost^-p (cost: steps, or RHS evaluations), fitted over each "
        f"method's runs with {low:.0e} < error < {high:.0e}; expected: the order "
        + ", ".join(f"{i.name} {i.order}" for i in INTEGRATORS.values())
        + ". Blank: fewer than two runs in that range (the case is too hard or too easy), or "
        "errors that do not decrease as the cost grows (listed below the table: they sit at a "
        "floor, and a fit through them would give an order near zero or negative). Errors below "
        "the case's conditioning floor κ u (see Conditioning) are left out of the fit: there "
        "amplified rounding, not the method's truncation, sets the error.",
        "",
        "| case | κ u | " + " | ".join(INTEGRATORS) + " |",
        "|---|---|" + "---|" * len(INTEGRATORS),
    ]
    stalled = []
    for r in results:
        cells = []
        for name in INTEGRATORS:
            mine = [run for run in r.runs if run.method == name]
            fitted = order_fit_runs(mine, r.conditioning.floor)
            p = observed_order(fitted)
            cells.append(f"{p:.2f}" if math.isfinite(p) else "")
            if not math.isfinite(p) and len({run.cost for run in fitted}) >= 2:
                errors = ", ".join(exp(run.omega_error) for run in fitted)
                stalled.append(
                    f"{r.case.name}, {name}: {errors} (κ u = {exp(r.conditioning.floor)})"
                )
        lines.append(f"| {r.case.name} | {exp(r.conditioning.floor)} | " + " | ".join(cells) + " |")
    if stalled:
        lines += [
            "",
            "Errors that do not decrease with the cost (cheapest first): "
            + "; ".join(stalled)
            + ".",
        ]
    return [*lines, ""]


def conditioning_section(results: list[CaseResult]) -> list[str]:
    """Each case's condition number and distance to the separatrix, and what they imply."""
    lines = [
        "## Conditioning",
        "",
        "κ is the largest amplification, over the horizon, of a relative perturbation of omega0 "
        "into a relative change of omega(t), estimated with the exact solution itself (each "
        "component of omega0 moved by 2^20, 2^10 or 1 ulp either way, the largest that stays "
        "in the linear range; ≥: even 1 ulp left it, κ is at least this). κ u (u = 2^-53) is "
        "the omega error that rounding omega0 alone can cause. An integrator rounds its state "
        "at every step, so errors near or above κ u are the problem's, not the method's. The "
        "exact solution is not subject to it: it evaluates the motion of the given floats, "
        "with the regime classified in exact arithmetic, and accumulates nothing. "
        "d = 1 - I2 / D (D = G²/2T [Pars65 §13.12]) is the signed distance to the separatrix: "
        "> 0 around the major axis, < 0 around the minor axis.",
        "",
        "| case | 1-m | d | κ | κ u | exact omega error | best integrator omega error |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in results:
        c = r.conditioning
        best = min(r.runs, key=lambda run: run.omega_error) if r.runs else None
        best_text = f"{exp(best.omega_error)} ({best.method} {best.setting})" if best else "-"
        lines.append(
            f"| {r.case.name} | {sig(r.complementary)} | {sig(c.separatrix_distance)} | "
            f"{_kappa(c)} | {exp(c.floor)} | {exp(r.exact.worst_inside[0])} | {best_text} |"
        )
    notable = [r for r in results if r.conditioning.floor >= NOTABLE_FLOOR]
    if notable:
        lines += ["", *(_conditioning_note(r) for r in notable)]
    return [*lines, ""]


def _kappa(c: Conditioning) -> str:
    return ("≥ " if c.lower_bound else "") + sig(c.kappa)


def _conditioning_note(r: CaseResult) -> str:
    """One bullet: a badly conditioned case, its floor, and where each method's best run ends."""
    c = r.conditioning
    bests = []
    for name in INTEGRATORS:
        runs = [run for run in r.runs if run.method == name]
        if runs:
            bests.append(f"{name} {exp(min(run.omega_error for run in runs))}")
    return (
        f"- **{r.case.name}**: κ {_kappa(c)}, so κ u = {exp(c.floor)}: no run that rounds its "
        f"state can be trusted below about that. Best omega error per method: "
        f"{', '.join(bests)}; the exact solution: {exp(r.exact.worst_inside[0])}."
    )


def saturated(r: CaseResult) -> list[IntegratorRun]:
    """The runs of a case whose omega error is saturated (>= SATURATED)."""
    return [run for run in r.runs if run.omega_error >= SATURATED]


def saturation_section(results: list[CaseResult]) -> list[str]:
    """Runs with saturated errors: flips gained, missed, or at other times, and why."""
    rows = [(r, run) for r in results for run in saturated(r)]
    if not rows:
        return []
    lines = [
        "## Saturated errors: flips and the separatrix",
        "",
        "An omega error of 2 is omega reversed (|ω - (-ω)| / |ω| = 2) and an attitude error of "
        "π is a half-turn: with L fixed in space, a reversed omega can only be carried by a body "
        "turned half a turn. Near the separatrix the motion is a sequence of such flips between "
        "long stays near the intermediate axis (the Dzhanibekov effect [ACC91]); a run that is "
        "one flip away from the exact motion shows these errors at every step size. Below, the "
        "flips are counted on the output grid (passages of the intermediate-axis component of "
        "omega between ± half its largest value), and d = 1 - I2 / D gives the side of the "
        "separatrix (see Conditioning). The splitting keeps |L| to rounding but the energy only "
        "to O(h²) [HLW06 §IX]: once its energy error exceeds the case's |d|, d changes sign, "
        "the motion crosses the separatrix and makes flips the exact motion does not make.",
        "",
        "| case | method | setting | omega error | attitude error | flips (run / exact) | "
        "d exact | d run (min, max) | reading |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r, run in rows:
        lo, hi = run.separatrix_range
        flips = f"{run.flips} / {r.exact_flips}" if r.flips_resolved else "-"
        lines.append(
            f"| {r.case.name} | {run.method} | {run.setting} | {exp(run.omega_error)} | "
            f"{exp(run.attitude_error)} | {flips} | {sig(r.conditioning.separatrix_distance)} | "
            f"({sig(lo)}, {sig(hi)}) | {flip_reading(r, run)} |"
        )
    lines.append("")
    lines += [_uncrossed_note(r) for r in results if saturated(r) and r.flips_resolved]
    return [*lines, ""]


def crossed(d0: float, d_range: tuple[float, float]) -> bool:
    """Whether a run's d left the side of the separatrix the exact motion is on (or, on the
    separatrix, left it), beyond rounding."""
    lo, hi = d_range
    tol = SEPARATRIX_TOLERANCE
    if d0 > tol:
        return lo < -tol
    if d0 < -tol:
        return hi > tol
    return max(-lo, hi) > tol


def flip_reading(r: CaseResult, run: IntegratorRun) -> str:
    """What a saturated run's flips and side of the separatrix say, in a few words."""
    if not r.flips_resolved:
        per_period = r.samples * r.period / r.t_end
        return (
            f"grid too coarse to count flips ({per_period:.2g} samples per period, "
            f"{FLIP_SAMPLES} needed): a phase lost over {r.t_end / r.period:.3g} periods"
        )
    n, m = run.flips, r.exact_flips
    if crossed(r.conditioning.separatrix_distance, run.separatrix_range):
        on_it = abs(r.conditioning.separatrix_distance) <= SEPARATRIX_TOLERANCE
        where = "left the separatrix" if on_it else "crossed the separatrix"
        more = "extra flips" if n > m else "flips missed" if n < m else "as many flips"
        return f"{where}: {more}"
    if n != m:
        return f"same side, flips at other times ({'more' if n > m else 'fewer'} in the horizon)"
    return "same side, same flips at other times: a phase lost"


def _uncrossed_note(r: CaseResult) -> str:
    """Which methods never crossed the separatrix in this case, and their worst error."""
    d0 = r.conditioning.separatrix_distance
    kept = [
        f"{name} (worst {exp(max(run.omega_error for run in runs))})"
        for name in INTEGRATORS
        if (runs := [run for run in r.runs if run.method == name])
        and not any(crossed(d0, run.separatrix_range) for run in runs)
    ]
    stayed = ", ".join(kept) if kept else "none"
    return f"- **{r.case.name}**: methods whose every run stayed on the exact side: {stayed}."
