"""``report.md``: the study in words and tables, one function per section.

Each section function takes what it needs and returns its lines; :func:`write_markdown` joins
them in reading order.
"""

from __future__ import annotations

import math
import os
import platform
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy

from poinsot.app.report.figures import caption, takeaway
from poinsot.app.report.findings import (
    conditioning_section,
    orders_section,
    saturation_section,
)
from poinsot.app.report.formatting import exp, sig, vector
from poinsot.app.report.measure.cases import StudyConfig
from poinsot.app.report.measure.exact import FAR_PERIODS
from poinsot.app.report.measure.games import GameRow, games_section
from poinsot.app.report.measure.speedup import SPEEDUP_REPEATS, Speedup
from poinsot.app.report.measure.study import CaseResult
from poinsot.app.report.measure.timing import repeats_text
from poinsot.app.report.verdicts import verdict
from poinsot.physics.integrators import INTEGRATORS

__all__ = ["ReportInputs", "write_markdown"]


@dataclass(frozen=True)
class ReportInputs:
    """Everything report.md is written from."""

    config: StudyConfig
    results: list[CaseResult]
    speedup: Speedup
    reference_note: str
    figures: list[str]
    """File names of the figures written (empty without matplotlib)."""
    figure_note: str
    elapsed: float
    """Wall time of the whole run [s]."""
    games: tuple[GameRow, ...] = ()
    """The game-engine table's rows (:mod:`~poinsot.app.report.measure.games`)."""


def write_markdown(out: Path, inputs: ReportInputs) -> None:
    """Write ``out / "report.md"``."""
    lines = [
        *_header(inputs),
        *_method(inputs.config, inputs.results),
        *_integrator_table(),
        *_cases_table(inputs.results),
        *_speedup(inputs.speedup),
        *_verdicts(inputs.results),
        *(games_section(list(inputs.games)) if inputs.games else []),
        *orders_section(inputs.results),
        *conditioning_section(inputs.results),
        *saturation_section(inputs.results),
        *_stability(inputs.results),
        *_per_case(inputs.results),
        *_figures(inputs.figures, inputs.figure_note, inputs.results),
    ]
    (out / "report.md").write_text("\n".join(lines))


def _header(inputs: ReportInputs) -> list[str]:
    mode = "quick (`--quick`)" if inputs.config.quick else "full"
    return [
        "# Work-precision report: the exact solution beside numerical integrators",
        "",
        f"Mode: {mode}. Wall time {inputs.elapsed:.1f} s on {platform.machine()} "
        f"({platform.processor() or 'cpu'}, {os.cpu_count() or 1} cores), Python "
        f"{platform.python_version()}, numpy {np.__version__}, scipy {scipy.__version__}. "
        f"Reference: {inputs.reference_note}.",
        "",
    ]


def _method(config: StudyConfig, results: list[CaseResult]) -> list[str]:
    reference_seconds = sum(r.exact.reference_seconds for r in results)
    tolerances = [f"{t:.0e}" for t in config.tolerances]
    return [
        "## Method",
        "",
        "Each case is followed over its horizon and sampled on a uniform grid of "
        f"{config.samples + 1} times. The exact solution (`physics.FreeRigidBody`) is evaluated "
        "once on the grid (construction included in its time). Each integrator runs at several "
        "settings; errors are the worst over the grid, against the exact solution:",
        "",
        "- **omega error**: |omega - omega_exact| / |omega_exact| (relative);",
        "- **attitude error**: geodesic angle of R R_exact^T [rad];",
        "- **energy drift**: |T(t) - T(0)| / T(0).",
        "",
        "The `exact` rows carry the closed form's own errors against an independent "
        "high-precision Taylor-series integration (`app/report/measure/reference.py`, no "
        f"formula shared with the closed form), at {config.reference_points} irregularly placed "
        f"points in the horizon and at {FAR_PERIODS:.0e} + 0.38 periods, and its energy drift "
        f"over the grid. The reference took {reference_seconds:.1f} s in all.",
        f"Timings are medians of repeats ({repeats_text(config.quick)}). Fixed steps are set as "
        "h = tau / n, tau = 2 pi / (|omega0| max(1, max |I_j - I_k| / I_i)), "
        f"n in {list(config.steps_per_scale)}; tolerances rtol in {tolerances} (atol = rtol "
        "max|omega0| on omega, rtol on the quaternion). Settings predicted to exceed "
        f"{config.run_budget:g} s are skipped.",
        "",
    ]


def _integrator_table() -> list[str]:
    lines = [
        "| method | kind | order | conserves abs(L) | description |",
        "|---|---|---|---|---|",
    ]
    for integ in INTEGRATORS.values():
        lines.append(
            f"| {integ.name} | {integ.kind} | {integ.order} | "
            f"{'yes' if integ.conserves_norm else 'no'} | {integ.title} |"
        )
    return [*lines, ""]


def _cases_table(results: list[CaseResult]) -> list[str]:
    lines = [
        "## Cases",
        "",
        "| case | I | omega0 [rad per time unit] | regime | m | 1-m | period | horizon | source |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        c = r.case
        lines.append(
            f"| {c.name} | {vector(c.inertia)} | {vector(c.omega0)} | {r.regime} | "
            f"{sig(r.parameter)} | {sig(r.complementary)} | {sig(r.period, 6)} {c.time_unit} | "
            f"{sig(r.t_end, 6)} {c.time_unit} | {c.source} |"
        )
    return [*lines, ""]


def _speedup(speedup: Speedup) -> list[str]:
    lines = [
        "## Speed-up of the exact solution over DOP853 at t = 1e4",
        "",
        f"Generic body, errors at t = {speedup.t:g} against {speedup.against}. The exact "
        f"solution: {sig(speedup.exact_seconds * 1e3)} ms to construct and evaluate omega and "
        f"the attitude at t (`FreeRigidBody(I, omega0).state(t)`: one evaluation gives both; "
        f"median of {SPEEDUP_REPEATS} runs after a `gc.collect()`), "
        f"{sig(speedup.exact_eval_seconds * 1e3)} ms to evaluate an already constructed "
        f"solution (`state(t)`), error {speedup.exact_error:.2e}.",
        "",
        "| DOP853 rtol | seconds | RHS evaluations | error at t=1e4 |",
        "|---|---|---|---|",
    ]
    for row in speedup.rows:
        lines.append(f"| {row.rtol:.0e} | {sig(row.seconds)} | {row.cost} | {row.error:.2e} |")
    lines.append("")
    chosen = speedup.chosen
    if chosen is not None:
        how = (
            "the cheapest DOP853 run that reaches the exact solution's accuracy"
            if speedup.reached
            else "DOP853's most accurate run (none reaches the exact solution's accuracy)"
        )
        lines.append(
            f"**Speed-up: {speedup.factor:.3g}x** ({how}: rtol {chosen.rtol:.0e}, "
            f"{sig(chosen.seconds)} s, error {chosen.error:.2e}; against construct + "
            f"evaluate). Against evaluation only: {speedup.factor_eval:.3g}x. "
            f"Goal >= 1e4x: {'met' if speedup.factor >= 1e4 else 'NOT met'} counting the "
            f"construction, {'met' if speedup.factor_eval >= 1e4 else 'NOT met'} for the "
            "evaluation alone."
        )
    return [*lines, ""]


def _verdicts(results: list[CaseResult]) -> list[str]:
    verdicts = [verdict(r) for r in results]
    wins = sum(v.exact_wins for v in verdicts)
    return [
        "## Verdicts",
        "",
        f"The exact solution is the cheapest way to every accuracy level in {wins} of "
        f"{len(results)} cases (accuracy: max of the omega and attitude errors).",
        "",
        *(f"- **{r.case.name}**: {v.text}" for r, v in zip(results, verdicts, strict=True)),
        "",
    ]


def _stability(results: list[CaseResult]) -> list[str]:
    lines = [
        "## Stability of the exact solution",
        "",
        "Worst error against mpmath inside the horizon and at 1e4 periods, drift of the "
        "invariants over the grid (energy, abs(L) and the space vector L, relative), and cost: "
        "construction, then evaluation per point on the grid (omega and attitude).",
        "",
        "| case | omega err | attitude err | omega err @1e4 P | attitude err @1e4 P | "
        "energy drift | abs(L) drift | L drift | construct [us] | per point [us] | note |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        ex = r.exact
        w, a = ex.worst_inside
        fw, fa = (ex.far_check[1], ex.far_check[2]) if ex.far_check else (math.nan, math.nan)
        lines.append(
            f"| {r.case.name} | {exp(w)} | {exp(a)} | {exp(fw)} | {exp(fa)} | "
            f"{exp(ex.invariant_energy)} | {exp(ex.invariant_norm)} | "
            f"{exp(ex.invariant_direction)} | {sig(ex.construct_seconds * 1e6)} | "
            f"{sig((ex.seconds - ex.construct_seconds) / ex.points * 1e6)} | "
            f"{ex.reference_note} |"
        )
    return [*lines, ""]


def _per_case(results: list[CaseResult]) -> list[str]:
    lines = ["## Per case"]
    for r in results:
        lines += ["", *_case_levels(r), "", *_case_runs(r)]
    return [*lines, ""]


def _case_levels(r: CaseResult) -> list[str]:
    """A case's heading, verdict and its accuracy-level table."""
    v = verdict(r)
    lines = [
        f"### {r.case.name}",
        "",
        f"I = {vector(r.case.inertia)}, omega0 = {vector(r.case.omega0)}, regime {r.regime}, "
        f"horizon {sig(r.t_end, 6)}, tau = {sig(r.tau)}. {r.case.source}.",
        "",
        f"Verdict: {v.text}",
        "",
        "| accuracy | fastest integrator reaching it | exact solution |",
        "|---|---|---|",
    ]
    ex_acc = max(r.exact.worst_inside)
    for level, text in v.per_level:
        if not math.isfinite(ex_acc):
            exact_text = "not verified"
        elif ex_acc <= level:
            exact_text = f"{sig(r.exact.seconds * 1e3)} ms"
        else:
            exact_text = "not reached"
        lines.append(f"| {level:.0e} | {text} | {exact_text} |")
    return lines


def _case_runs(r: CaseResult) -> list[str]:
    """A case's table of every run, then what was skipped or failed."""
    w, a = r.exact.worst_inside
    lines = [
        "| method | setting | seconds | repeats | cost | omega error | attitude error | "
        "energy drift |",
        "|---|---|---|---|---|---|---|---|",
        f"| exact | closed form | {sig(r.exact.seconds)} | - | - | {exp(w)} | {exp(a)} | "
        f"{exp(r.exact.invariant_energy)} |",
    ]
    for run in r.runs:
        lines.append(
            f"| {run.method} | {run.setting} | {sig(run.seconds)} | {run.repeats} | "
            f"{run.cost} | {exp(run.omega_error)} | {exp(run.attitude_error)} | "
            f"{exp(run.energy_drift)} |"
        )
    if r.skipped:
        lines += ["", f"Skipped (predicted over {r.run_budget:g} s): {', '.join(r.skipped)}."]
    if r.failed:
        lines += ["", f"Failed: {'; '.join(r.failed)}."]
    return lines


def _figures(figures: list[str], note: str, results: list[CaseResult]) -> list[str]:
    """Each figure with its caption and a one-line takeaway."""
    lines = ["## Figures", ""]
    for number, name in enumerate(figures, start=1):
        lines += [
            f"![{name}]({name})",
            "",
            f"*Figure {number} ({name}).* {caption(name)}",
            "",
            f"**Takeaway:** {takeaway(name, results)}",
            "",
        ]
    return [*lines, note, ""]
