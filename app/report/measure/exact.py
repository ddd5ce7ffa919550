"""The exact solution's own findings in one case: its cost on the output grid, how well it keeps
the invariants, and its errors against the independent high-precision reference
(:mod:`poinsot.app.report.measure.reference`, which needs the optional mpmath).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from poinsot.app.report.measure.conditioning import FlipCounter
from poinsot.app.report.measure.runs import ExactGrid
from poinsot.app.report.measure.timing import timed
from poinsot.physics import FreeRigidBody
from poinsot.physics.core import errors

if TYPE_CHECKING:
    from poinsot.app.report.measure.reference import TaylorReference

__all__ = [
    "CHECK_FRACTIONS",
    "FAR_OFFSET",
    "FAR_PERIODS",
    "ExactFindings",
    "check_against_reference",
    "load_reference",
    "measure_exact",
]

#: Far check of the closed form's phase: this many periods (folded in the mpmath reference),
#: plus an irrational fraction of one, so that the check does not land where omega repeats.
FAR_PERIODS = 1e4
#: The irrational fraction of a period added to FAR_PERIODS: 2 - golden ratio.
FAR_OFFSET = 0.3819660112501051
#: Where the mpmath check points sit, as fractions of the horizon: irregular on purpose. At a
#: whole or half period omega is (up to signs) omega0 itself and any closed form is exact there.
CHECK_FRACTIONS = {2: (0.5183, 0.9617), 4: (0.2371, 0.5183, 0.7693, 0.9617)}


@dataclass
class ExactFindings:
    """The closed form's own behaviour in one case."""

    seconds: float
    """Construct + evaluate omega and attitude on the whole output grid (sum of medians)."""
    construct_seconds: float
    points: int
    invariant_energy: float
    """max |T(t) - T(0)| / T(0) over the grid."""
    invariant_norm: float
    """max |G(t) - G(0)| / G(0), G = |I omega| (body frame)."""
    invariant_direction: float
    """max |L(t) - L(0)| / |L|, with L(t) = R(t) I omega(t) (space frame)."""
    checks: list[tuple[float, float, float]] = field(default_factory=list)
    """(t, omega error, attitude error) against mpmath, inside the horizon."""
    far_check: tuple[float, float, float] | None = None
    """The same at FAR_PERIODS periods (when the reference confirmed the period)."""
    reference_note: str = ""
    reference_seconds: float = 0.0

    @property
    def worst_inside(self) -> tuple[float, float]:
        if not self.checks:
            return math.nan, math.nan
        return max(c[1] for c in self.checks), max(c[2] for c in self.checks)

    @property
    def all_checks(self) -> list[tuple[float, float, float]]:
        """The checks inside the horizon, then the far one if there is one."""
        return self.checks + ([self.far_check] if self.far_check else [])


def load_reference() -> tuple[type[TaylorReference] | None, str]:
    """The mpmath reference class, or None and the reason."""
    try:
        from poinsot.app.report.measure.reference import DIGITS, TaylorReference
    except ImportError as exc:  # mpmath is optional (the `test` extra)
        return None, f"mpmath is not installed ({exc}); the mpmath cross-check was skipped"
    import mpmath

    return TaylorReference, (
        f"Taylor series at {DIGITS} digits (integer fixed point for the series, mpmath "
        f"{mpmath.__version__} for conversions, folding and error measures)"
    )


def measure_exact(
    case: str, body: FreeRigidBody, t_eval: NDArray[np.float64], quick: bool
) -> tuple[ExactFindings, ExactGrid]:
    """Time the exact solution on the grid (construction, then evaluation) and measure how it
    keeps the energy, |L| and the space vector L."""
    inertia, omega0 = body.inertia, body.omega0
    construct_seconds, _, _ = timed(lambda: FreeRigidBody(inertia, omega0), quick)
    eval_seconds, (omega, attitude), _ = timed(
        lambda: (body.omega(t_eval), body.attitude(t_eval)), quick
    )
    energy0 = float(errors.energy(inertia, omega0))
    g0 = float(errors.angular_momentum_norm(inertia, omega0))
    momentum = attitude.apply(inertia * omega)
    findings = ExactFindings(
        seconds=construct_seconds + eval_seconds,
        construct_seconds=construct_seconds,
        points=len(t_eval),
        invariant_energy=float(
            np.max(errors.relative_drift(errors.energy(inertia, omega), energy0))
        ),
        invariant_norm=float(
            np.max(errors.relative_drift(errors.angular_momentum_norm(inertia, omega), g0))
        ),
        invariant_direction=float(
            np.max(np.linalg.norm(momentum - body.angular_momentum, axis=1)) / g0
        ),
    )
    flips = FlipCounter.for_motion(inertia, omega)
    grid = ExactGrid(case, inertia, omega0, t_eval, omega, attitude, energy0, flips)
    return findings, grid


def check_against_reference(
    findings: ExactFindings,
    body: FreeRigidBody,
    reference_cls: type[TaylorReference] | None,
    check_times: list[float],
) -> None:
    """The closed form against the Taylor reference at ``check_times`` and, when the reference
    confirms the period, at FAR_PERIODS + FAR_OFFSET periods; fills ``findings`` in place."""
    if reference_cls is None:
        findings.reference_note = "no mpmath"
        return
    start = time.perf_counter()
    reference = reference_cls(body.inertia, body.omega0)
    confirmed = math.isfinite(body.period) and reference.find_period(body.period)
    for t in check_times:
        c = reference.compare(t, body.omega(t), body.attitude(t).as_quat())
        findings.checks.append((t, c.omega_error, c.attitude_error))
    if confirmed:
        t_far = (FAR_PERIODS + FAR_OFFSET) * body.period
        c = reference.compare(t_far, body.omega(t_far), body.attitude(t_far).as_quat())
        findings.far_check = (t_far, c.omega_error, c.attitude_error)
        findings.reference_note = f"period confirmed to {reference.digits} digits"
    elif math.isfinite(body.period):
        findings.reference_note = "period NOT confirmed by the reference"
    else:
        findings.reference_note = "no period (integrated directly)"
    findings.reference_seconds = time.perf_counter() - start
