"""Running the integrators of :data:`poinsot.physics.integrators.INTEGRATORS` on one case and
measuring each run against the exact solution on the output grid.

Every method runs at a ladder of settings (step sizes as fractions of the case's time scale, or
relative tolerances), cheapest first; a setting whose predicted run time exceeds the budget
ends the ladder. The errors are the project's one set of measures,
:mod:`poinsot.physics.core.errors`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import partial

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from poinsot.app.report.measure.cases import CaseSettings
from poinsot.app.report.measure.conditioning import FlipCounter, separatrix_distance
from poinsot.app.report.measure.progress import Progress
from poinsot.app.report.measure.timing import timed
from poinsot.physics.core import errors
from poinsot.physics.integrators import INTEGRATORS, Integrator, integrate

__all__ = [
    "ExactGrid",
    "IntegratorRun",
    "IntegratorRuns",
    "RunErrors",
    "measure_errors",
    "run_integrators",
    "setting_label",
    "time_scale",
]


def time_scale(inertia: ArrayLike, omega0: ArrayLike) -> float:
    """tau = 2 pi / nu, nu = |omega0| max(1, max_i |I_j - I_k| / I_i): the fastest turning rate.

    Euler's equations [LL76 §36, Eq. 36.5] turn omega at rates up to |omega| |I_j - I_k| / I_i,
    and the attitude at |omega|; step sizes are set as fractions of tau so that every case is
    resolved alike.
    """
    i = np.asarray(inertia, dtype=float)
    ratios = [abs(i[(k + 1) % 3] - i[(k + 2) % 3]) / i[k] for k in range(3)]
    nu = float(np.linalg.norm(omega0)) * max(1.0, *ratios)
    return 2.0 * math.pi / nu


#: The step budget of the report's runs (``integrate``'s ``max_steps``): far above the default,
#: since the ladder already skips a setting predicted to take longer than the case's run budget
#: (the full report's DOP853 at rtol 1e-13 takes ~5e4 steps to t = 1e4).
REPORT_MAX_STEPS = 50_000_000


def setting_label(integrator: Integrator, value: float) -> str:
    """``h=0.04373`` (fixed step) or ``rtol=1e-08`` (adaptive)."""
    return f"h={value:.4g}" if integrator.kind == "fixed" else f"rtol={value:.0e}"


@dataclass
class RunErrors:
    """Errors of one run against the exact solution, per output time, and their worst."""

    omega: NDArray[np.float64]
    """Relative: |omega - omega_exact| / |omega_exact|."""
    attitude: NDArray[np.float64]
    """Geodesic angle between the attitudes [rad]."""
    energy: NDArray[np.float64]
    """Relative drift of the kinetic energy from its initial value."""

    @property
    def worst(self) -> tuple[float, float, float]:
        return float(self.omega.max()), float(self.attitude.max()), float(self.energy.max())


@dataclass(frozen=True)
class ExactGrid:
    """One case's problem and the exact solution on its output grid: what every run of that
    case is measured against."""

    case: str
    inertia: NDArray[np.float64]
    omega0: NDArray[np.float64]
    t_eval: NDArray[np.float64]
    omega: NDArray[np.float64]
    attitude: Rotation
    energy0: float
    flips: FlipCounter
    """Counts the half-turns of a motion on this grid (see :mod:`conditioning`)."""


def measure_errors(exact: ExactGrid, omega: NDArray[np.float64], attitude: Rotation) -> RunErrors:
    """A numerical solution on the grid against the exact one
    (:mod:`poinsot.physics.core.errors`)."""
    return RunErrors(
        errors.omega_error(omega, exact.omega),
        errors.attitude_error(attitude, exact.attitude),
        errors.relative_drift(errors.energy(exact.inertia, omega), exact.energy0),
    )


@dataclass
class IntegratorRun:
    """One integrator at one setting on one case: its cost, timing and errors."""

    case: str
    method: str
    setting: str
    seconds: float
    repeats: int
    cost: int
    """Right-hand-side evaluations (adaptive methods) or steps (fixed-step methods)."""
    omega_error: float
    attitude_error: float
    energy_drift: float
    times: NDArray[np.float64]
    errors: RunErrors
    flips: int
    """Half-turns of the run's motion counted on the output grid."""
    separatrix_range: tuple[float, float]
    """(min, max) over the grid of the run's d = 1 - I2 / D: its side of the separatrix."""

    @property
    def accuracy(self) -> float:
        return max(self.omega_error, self.attitude_error)


@dataclass
class IntegratorRuns:
    """Every integrator's runs on one case, and the settings that did not run."""

    runs: list[IntegratorRun] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
    """``method setting`` predicted over the run budget."""
    failed: list[str] = field(default_factory=list)
    """``method setting: reason``."""


def run_integrators(
    exact: ExactGrid, tau: float, settings: CaseSettings, quick: bool, progress: Progress
) -> IntegratorRuns:
    """Run every registered integrator at its ladder of settings on one case."""
    outcome = IntegratorRuns()
    for integrator in INTEGRATORS.values():
        values = (
            [tau / n for n in settings.steps_per_scale]
            if integrator.kind == "fixed"
            else list(settings.tolerances)
        )
        _run_ladder(exact, integrator, values, settings.run_budget, quick, progress, outcome)
    return outcome


def _predicted_seconds(
    integrator: Integrator, previous: tuple[float, float], value: float
) -> float:
    """Run time at ``value`` predicted from the previous (setting, seconds)."""
    # Cost ~ 1/h for fixed steps, ~ rtol^(-1/order) for the adaptive pairs.
    ratio = previous[0] / value
    if integrator.kind != "fixed":
        ratio = ratio ** (1.0 / integrator.order)
    return previous[1] * ratio


def _run_ladder(
    exact: ExactGrid,
    integrator: Integrator,
    values: list[float],
    budget: float,
    quick: bool,
    progress: Progress,
    outcome: IntegratorRuns,
) -> None:
    """One method's settings, cheapest first, until one is predicted over the budget."""
    name = integrator.name
    previous: tuple[float, float] | None = None  # (setting, seconds)
    for k, value in enumerate(values):
        label = setting_label(integrator, value)
        if previous is not None and _predicted_seconds(integrator, previous, value) > budget:
            outcome.skipped.extend(f"{name} {setting_label(integrator, v)}" for v in values[k:])
            progress.advance(f"{exact.case}: {name} (budget)", len(values) - k)
            return
        progress.show(f"{exact.case}: {name} {label}")
        try:
            run = _run_one(exact, name, label, value, quick)
        except (ValueError, RuntimeError) as exc:
            outcome.failed.append(f"{name} {label}: {exc}")
            progress.advance(f"{exact.case}: {name} {label} failed")
            continue
        outcome.runs.append(run)
        previous = (value, run.seconds)
        progress.advance(f"{exact.case}: {name} {label}")


def _run_one(exact: ExactGrid, name: str, label: str, value: float, quick: bool) -> IntegratorRun:
    call = partial(
        integrate, name, exact.inertia, exact.omega0, None, exact.t_eval, value, REPORT_MAX_STEPS
    )
    seconds, trajectory, repeats = timed(call, quick)
    errs = measure_errors(exact, trajectory.omega, trajectory.attitude)
    w, a, e = errs.worst
    d = separatrix_distance(exact.inertia, trajectory.omega)
    return IntegratorRun(
        exact.case,
        name,
        label,
        seconds,
        repeats,
        trajectory.cost,
        w,
        a,
        e,
        exact.t_eval,
        errs,
        exact.flips.count(trajectory.omega),
        (float(d.min()), float(d.max())),
    )
