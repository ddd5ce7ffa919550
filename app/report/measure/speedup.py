"""The headline number: how much faster the exact solution is than DOP853 [HNW93 §II.5] at equal
accuracy, at one far time on the generic body.

The exact solution is timed constructing and evaluating at t (and evaluating an already
constructed solution); DOP853 runs from 0 to t at a ladder of tolerances until it reaches the
exact solution's accuracy (or runs out of tolerances). Errors are measured against the mpmath
reference when it is available.
"""

from __future__ import annotations

import gc
import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from poinsot.app.report.measure.cases import GENERIC, StudyConfig
from poinsot.app.report.measure.progress import Progress
from poinsot.app.report.measure.runs import REPORT_MAX_STEPS
from poinsot.app.report.measure.timing import median_seconds, timed
from poinsot.physics import FreeRigidBody
from poinsot.physics.core import errors
from poinsot.physics.integrators import integrate

if TYPE_CHECKING:
    from poinsot.app.report.measure.reference import TaylorReference

__all__ = ["SPEEDUP_REPEATS", "SPEEDUP_TIME", "Speedup", "SpeedupRow", "speedup_study"]

#: The speed-up measurement: DOP853 against the exact solution at this time [time units].
SPEEDUP_TIME = 1e4
#: Timed runs of the exact solution (construct + evaluate, evaluate) whose median is reported.
SPEEDUP_REPEATS = 201

ErrorAt = Callable[[NDArray[np.float64], Rotation], float]


class SpeedupRow(NamedTuple):
    """One DOP853 run to SPEEDUP_TIME."""

    rtol: float
    seconds: float
    cost: int
    """Right-hand-side evaluations."""
    error: float
    """max(omega error, attitude error) at SPEEDUP_TIME."""


@dataclass
class Speedup:
    t: float
    exact_seconds: float
    """Construct and evaluate at t (median)."""
    exact_eval_seconds: float
    """Evaluate an already constructed solution at t (median)."""
    exact_error: float
    rows: list[SpeedupRow]
    chosen: SpeedupRow | None
    reached: bool
    """Whether ``chosen`` reaches the exact solution's accuracy."""
    against: str

    @property
    def factor(self) -> float:
        return self.chosen.seconds / self.exact_seconds if self.chosen else math.nan

    @property
    def factor_eval(self) -> float:
        return self.chosen.seconds / self.exact_eval_seconds if self.chosen else math.nan


def speedup_study(
    config: StudyConfig, reference_cls: type[TaylorReference] | None, progress: Progress
) -> Speedup:
    """DOP853 against the exact solution at t = SPEEDUP_TIME on the generic body."""
    inertia = np.asarray(GENERIC.inertia, dtype=float)
    omega0 = np.asarray(GENERIC.omega0, dtype=float)
    t = SPEEDUP_TIME
    exact_seconds, exact_eval_seconds = _time_exact(inertia, omega0, t)
    body = FreeRigidBody(inertia, omega0)
    omega_ex, attitude_ex = body.state(t)
    if reference_cls is not None:
        error_of = _error_against_reference(reference_cls, body, t)
        exact_error = error_of(omega_ex, attitude_ex)
        against = "the mpmath reference"
    else:
        error_of = _error_against_exact(omega_ex, attitude_ex)
        exact_error = 0.0
        against = "the exact solution (mpmath absent: its own error is unknown)"
    progress.advance("speed-up: exact at t=1e4")
    rows = _dop853_ladder(config, inertia, omega0, t, error_of, exact_error, progress)
    reaching = [r for r in rows if r.error <= exact_error]
    chosen = reaching[0] if reaching else min(rows, key=lambda r: r.error)
    return Speedup(
        t, exact_seconds, exact_eval_seconds, exact_error, rows, chosen, bool(reaching), against
    )


def _time_exact(
    inertia: NDArray[np.float64], omega0: NDArray[np.float64], t: float
) -> tuple[float, float]:
    """(construct and evaluate at t, evaluate at t) [s], medians of SPEEDUP_REPEATS calls."""
    # Many repeats: the call is a fraction of a millisecond and the median must be stable.
    # Garbage left by the studies above is collected first (as timeit would): otherwise the
    # collector's passes over it land inside these sub-millisecond calls and double them.
    gc.collect()
    # Construct, then omega and the attitude from one evaluation (FreeRigidBody.state).
    construct_and_evaluate = median_seconds(
        lambda: FreeRigidBody(inertia, omega0).state(t), SPEEDUP_REPEATS
    )
    body = FreeRigidBody(inertia, omega0)
    evaluate = median_seconds(lambda: body.state(t), SPEEDUP_REPEATS)
    return construct_and_evaluate, evaluate


def _error_against_reference(
    reference_cls: type[TaylorReference], body: FreeRigidBody, t: float
) -> ErrorAt:
    reference = reference_cls(body.inertia, body.omega0)
    if not reference.find_period(body.period):
        raise RuntimeError("the mpmath reference could not confirm the generic period")

    def error_of(omega: NDArray[np.float64], attitude: Rotation) -> float:
        c = reference.compare(t, omega, attitude.as_quat())
        return max(c.omega_error, c.attitude_error)

    return error_of


def _error_against_exact(omega_ex: NDArray[np.float64], attitude_ex: Rotation) -> ErrorAt:
    def error_of(omega: NDArray[np.float64], attitude: Rotation) -> float:
        return max(
            float(errors.omega_error(omega, omega_ex)),
            float(errors.attitude_error(attitude, attitude_ex)),
        )

    return error_of


def _dop853_ladder(
    config: StudyConfig,
    inertia: NDArray[np.float64],
    omega0: NDArray[np.float64],
    t: float,
    error_of: ErrorAt,
    exact_error: float,
    progress: Progress,
) -> list[SpeedupRow]:
    """DOP853 to t at each speed-up tolerance, stopping at the first that reaches the exact
    solution's accuracy."""
    rows: list[SpeedupRow] = []
    for rtol in config.speedup_tolerances:
        progress.show(f"speed-up: DOP853 rtol={rtol:.0e} to t=1e4")
        call = partial(integrate, "DOP853", inertia, omega0, None, [t], rtol, REPORT_MAX_STEPS)
        seconds, trajectory, _ = timed(call, config.quick)
        error = error_of(trajectory.omega[0], trajectory.attitude[0])
        rows.append(SpeedupRow(rtol, seconds, trajectory.cost, error))
        progress.advance(f"speed-up: DOP853 rtol={rtol:.0e}")
        if error <= exact_error:
            progress.advance("speed-up", len(config.speedup_tolerances) - len(rows))
            break
    return rows
