"""One case of the work-precision study from end to end: the exact solution once on the output
grid (timed, its invariants, its errors against the high-precision reference), then every
integrator at its ladder of settings, measured against it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from poinsot.app.report.measure.cases import Case, StudyConfig
from poinsot.app.report.measure.conditioning import Conditioning, condition_number
from poinsot.app.report.measure.exact import (
    CHECK_FRACTIONS,
    ExactFindings,
    check_against_reference,
    measure_exact,
)
from poinsot.app.report.measure.progress import Progress
from poinsot.app.report.measure.runs import IntegratorRun, run_integrators, time_scale
from poinsot.physics import FreeRigidBody
from poinsot.physics.integrators import INTEGRATORS

if TYPE_CHECKING:
    from poinsot.app.report.measure.reference import TaylorReference

__all__ = ["FLIP_SAMPLES", "CaseResult", "progress_units", "study_case"]

#: Output samples per period of omega needed to count flips: a period has two of them, and the
#: hysteresis count needs a sample in each stay near the intermediate axis.
FLIP_SAMPLES = 8


@dataclass
class CaseResult:
    """Everything the report says about one case."""

    case: Case
    regime: str
    parameter: float
    complementary: float
    period: float
    t_end: float
    tau: float
    exact: ExactFindings
    runs: list[IntegratorRun]
    skipped: list[str]
    failed: list[str]
    run_budget: float
    conditioning: Conditioning
    exact_flips: int
    """Half-turns of the exact motion counted on the output grid."""
    samples: int
    """Intervals of the output grid."""

    @property
    def flips_resolved(self) -> bool:
        """Whether the output grid is fine enough to count flips: at least FLIP_SAMPLES samples
        per period of omega (a motion with no period is taken as resolved)."""
        return not math.isfinite(self.period) or self.samples * self.period >= (
            FLIP_SAMPLES * self.t_end
        )


def progress_units(config: StudyConfig) -> int:
    """Steps of the progress bar for a whole study: per case the exact solution, the reference
    and every setting; then the speed-up's exact timing and its DOP853 runs."""
    units = 1 + len(config.speedup_tolerances)
    for case in config.cases:
        settings = config.settings(case)
        units += 2 + sum(
            len(settings.steps_per_scale) if i.kind == "fixed" else len(settings.tolerances)
            for i in INTEGRATORS.values()
        )
    return units


def study_case(
    case: Case,
    config: StudyConfig,
    reference_cls: type[TaylorReference] | None,
    progress: Progress,
) -> CaseResult:
    """The exact solution and every integrator on one case."""
    inertia = np.asarray(case.inertia, dtype=float)
    omega0 = np.asarray(case.omega0, dtype=float)
    body = FreeRigidBody(inertia, omega0)
    t_end = case.t_end(body.period, config.quick)
    t_eval = np.linspace(0.0, t_end, config.samples + 1)
    tau = time_scale(inertia, omega0)
    settings = config.settings(case)

    findings, grid = measure_exact(case.name, body, t_eval, config.quick)
    progress.advance(f"{case.name}: exact")
    checks = [t_end * f for f in CHECK_FRACTIONS[config.reference_points]]
    check_against_reference(findings, body, reference_cls, checks)
    progress.advance(f"{case.name}: mpmath reference")

    outcome = run_integrators(grid, tau, settings, config.quick, progress)
    conditioning = condition_number(inertia, omega0, t_eval, grid.omega)
    return CaseResult(
        case=case,
        regime=body.regime.name,
        parameter=float(body.parameter),
        complementary=float(body.complementary_parameter),
        period=float(body.period),
        t_end=float(t_end),
        tau=tau,
        exact=findings,
        runs=outcome.runs,
        skipped=outcome.skipped,
        failed=outcome.failed,
        run_budget=settings.run_budget,
        conditioning=conditioning,
        exact_flips=grid.flips.count(grid.omega),
        samples=config.samples,
    )
