"""``poinsot report``: error against run time, the exact solution beside numerical integrators.

A work-precision study over a matrix of ordinary, stiff and extreme bodies. For every case the
exact solution :class:`physics.FreeRigidBody` is evaluated once on the output grid and every
integrator of :data:`physics.integrators.INTEGRATORS` runs at several step sizes or tolerances;
their errors in omega (relative) and in attitude (geodesic angle) are measured against the
exact solution, whose own error is measured against an independent Taylor-series reference at
32 digits (:mod:`app.highprecision`, built on mpmath, which is optional and imported lazily).

Outputs in ``--out DIR``:

* ``work_precision.csv``: ``case,method,setting,seconds,omega_error,attitude_error,energy_drift``
  (one row per run; errors are maxima over the output grid; the ``exact`` rows carry the
  closed form's errors against the mpmath reference, at its check points);
* ``error_vs_time.csv``: the same errors against simulated time, for every run;
* ``report.md``: tables, a verdict per case, the exact solution's stability findings, and its
  speed-up over DOP853 at equal accuracy at t = 1e4;
* ``work_precision.png``, ``work_precision_attitude.png``, ``error_vs_time.png`` (matplotlib,
  Agg backend, imported lazily; skipped with a note if it is not installed).

This module composes :mod:`physics` and does no physics of its own beyond the error measures.
"""

from __future__ import annotations

import argparse
import csv
import gc
import math
import platform
import statistics
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

import numpy as np
import scipy
from poinsot.physics import FreeRigidBody
from poinsot.physics.integrators import INTEGRATORS, Integrator, integrate
from scipy.spatial.transform import Rotation

__all__ = ["CASES", "Case", "StudyConfig", "main", "run_report"]

T = TypeVar("T")

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
EXACT = "exact"
#: Accuracy levels of the verdicts: max(omega error, attitude error) at or below each.
ACCURACY_LEVELS = (1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12)
#: Far check of the closed form's phase: this many periods (folded in the mpmath reference),
#: plus an irrational fraction of one, so that the check does not land where omega repeats.
FAR_PERIODS = 1e4
#: Where the mpmath check points sit, as fractions of the horizon: irregular on purpose. At a
#: whole or half period omega is (up to signs) omega0 itself and any closed form is exact there.
CHECK_FRACTIONS = {2: (0.5183, 0.9617), 4: (0.2371, 0.5183, 0.7693, 0.9617)}
_OFFSET = 0.3819660112501051  # 2 - golden ratio
#: The speed-up measurement: DOP853 against the exact solution at this time [time units].
SPEEDUP_TIME = 1e4
#: Timed runs of the exact solution (construct + evaluate, evaluate) whose median is reported.
SPEEDUP_REPEATS = 201


# ---------------------------------------------------------------------------------------------
# The case matrix, as data
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Case:
    """One body and initial state of the study, and how long to follow it."""

    name: str
    inertia: tuple[float, float, float]
    omega0: tuple[float, float, float]
    source: str
    """Where the case comes from."""
    periods: float | None = None
    """Horizon in periods of omega (the exact solution's ``period``), or None ..."""
    horizon: float | None = None
    """... the horizon in time units (for motions that never return)."""
    quick: bool = True
    """Part of ``--quick``."""
    quick_periods: float | None = None
    """Shorter horizon in periods for ``--quick`` (None: the same)."""
    tolerances: tuple[float, ...] | None = None
    """Full mode: this case's adaptive tolerances instead of the study's (None: the same)."""
    steps_per_scale: tuple[int, ...] | None = None
    """Full mode: this case's fixed-step settings instead of the study's (None: the same)."""
    run_budget: float | None = None
    """Full mode: this case's per-run budget in seconds (None: the study's)."""


def _near_separatrix(mc: float) -> tuple[float, float, float]:
    # On I = (1, 2, 3) with omega = (w1, 0, 1): Delta2 = 3 - w1^2, Delta1 = 6, so the
    # complementary parameter 1 - m = Delta2 (I3 - I1) / (Delta1 (I3 - I2)) = 1 - w1^2 / 3
    # (major-axis family, PHYSICS.md 'Cancellation'). The float w1 moves 1 - m by ~2e-16.
    return (math.sqrt(3.0 * (1.0 - mc)), 0.0, 1.0)


GENERIC = Case(
    "generic",
    (13.0, 10.0, 5.0),
    (0.3, 0.6, 0.9),
    "uniform 1x2x3 box (I = M (b²+c², a²+c², a²+b²)/12, M = 12); omega0 chosen with m ~ 0.4",
    periods=10,
)

CASES: tuple[Case, ...] = (
    GENERIC,
    *(
        Case(
            f"near-separatrix 1-m={mc:.0e}",
            (1.0, 2.0, 3.0),
            _near_separatrix(mc),
            f"omega0 = (sqrt(3(1-mc)), 0, 1) on I = (1,2,3) puts 1-m at {mc:.0e} (Delta2/Delta1)",
            periods=2,
            quick=mc in (1e-6, 1e-14),
        )
        for mc in (1e-6, 1e-8, 1e-10, 1e-12, 1e-14)
    ),
    Case(
        "separatrix",
        (2.0, 3.0, 6.0),
        (3.0, 0.25, 1.0),
        "G² - 2T I2 == 0 exactly in floating point (72.5625 both): the limiting polhode; "
        "omega tends to the unstable rotation about I2 (rate ~1.4 per time unit)",
        horizon=20.0,
    ),
    Case(
        "near-oblate 1e-6",
        (1.0, 1.0 + 1e-6, 2.0),
        (1.0, 0.5, 0.3),
        "a coin with a 1e-6 asymmetry: I1 ~ I2 < I3, elliptic parameter m ~ 1e-5",
        periods=10,
    ),
    Case(
        "near-prolate 1e-10",
        (1.0, 2.0 - 2e-10, 2.0),
        (1.0, 0.5, 0.3),
        "a rod with a 1e-10 asymmetry: I1 < I2 ~ I3, elliptic parameter m ~ 1e-10",
        periods=10,
    ),
    Case(
        "needle",
        (1e-4, 1.0, 1.0),
        (50.0, 1.0, 0.5),
        "a needle (I1 = 1e-4 I2) spinning fast about its axis: two time scales, 50 vs ~1",
        periods=10,
    ),
    Case(
        "flat plate",
        (1.0, 2.0, 3.0),
        (1.0, 1.0, 1.0),
        "the thin-plate limit I3 = I1 + I2 (the triangle inequality's edge)",
        periods=10,
    ),
    Case(
        "non-physical 1:10:1000",
        (1.0, 10.0, 1000.0),
        (1.0, 1.0, 1.0),
        "violates I3 <= I1 + I2 (no real body); Euler's rates reach ~1e3 |omega|: stiff",
        periods=10,
    ),
    Case(
        "Toutatis",
        (1.0, 3.0836, 3.235),
        (1.714199, 0.0, 0.644256),
        "asteroid 4179 Toutatis: moments from the radar shape model (Hudson & Ostro, Science "
        "270 (1995) 84; Scheeres et al., Icarus 132 (1998) 53); omega0 [rad/day] fitted to its "
        "long-axis mode, periods 5.41 d and 7.35 d",
        periods=10,
    ),
    Case(
        "long horizon",
        GENERIC.inertia,
        GENERIC.omega0,
        "the generic box followed for 1e4 periods (1e3 with --quick); loose settings are "
        "pointless there (errors O(1)), so the full run tries fewer, tighter ones, and longer",
        periods=1e4,
        quick_periods=1e3,
        tolerances=(1e-8, 1e-13),
        steps_per_scale=(16, 128),
        run_budget=90.0,
    ),
)


# ---------------------------------------------------------------------------------------------
# Study configuration
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class StudyConfig:
    """What a run of the report does; :func:`StudyConfig.for_mode` gives the two presets."""

    quick: bool
    cases: tuple[Case, ...]
    steps_per_scale: tuple[int, ...]
    """Fixed-step settings: steps per characteristic time tau = 2 pi / nu (see _time_scale)."""
    tolerances: tuple[float, ...]
    """Adaptive settings: relative tolerances."""
    samples: int
    """Output grid: this many intervals over the horizon."""
    reference_points: int
    """mpmath check points per case inside the horizon (plus one at FAR_PERIODS periods)."""
    run_budget: float
    """Seconds: settings predicted to take longer than this are skipped (the first setting of
    each method always runs)."""
    speedup_tolerances: tuple[float, ...]

    @staticmethod
    def for_mode(quick: bool) -> StudyConfig:
        if quick:
            return StudyConfig(
                quick=True,
                cases=tuple(c for c in CASES if c.quick),
                steps_per_scale=(16, 128, 1024),
                tolerances=(1e-4, 1e-8, 1e-12),
                samples=100,
                reference_points=2,
                run_budget=0.5,
                # DOP853's tightest tolerance only (about 4 s): its most accurate run, the one
                # the speed-up is quoted against in the full report too.
                speedup_tolerances=(1e-13,),
            )
        return StudyConfig(
            quick=False,
            cases=CASES,
            steps_per_scale=(16, 64, 256, 1024, 4096, 16384),
            tolerances=(1e-4, 1e-6, 1e-8, 1e-10, 1e-12, 1e-13),
            samples=200,
            reference_points=4,
            run_budget=20.0,
            speedup_tolerances=(1e-6, 1e-8, 1e-10, 1e-11, 1e-12, 1e-13),
        )


# ---------------------------------------------------------------------------------------------
# Measurement helpers
# ---------------------------------------------------------------------------------------------


def _timed(fn: Callable[[], T], quick: bool) -> tuple[float, T, int]:
    """Median wall time of repeated calls: (seconds, last result, repeats).

    Cheap calls are repeated more (see :func:`_repeats`); longer runs are timed once (their
    spread is a few percent).
    """
    start = time.perf_counter()
    result = fn()
    times = [time.perf_counter() - start]
    repeats = _repeats(times[0], quick)
    for _ in range(repeats - 1):
        start = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times), result, len(times)


def _repeats(first: float, quick: bool) -> int:
    """How many timed calls in all, given the first call's duration [s]."""
    # Many repeats for millisecond calls: on a loaded machine a few of them lose a whole
    # scheduler slice (~5 ms), and the median must not be one of those.
    if quick:
        return 15 if first < 0.01 else 3 if first < 0.1 else 1
    return 21 if first < 0.01 else 5 if first < 0.1 else 3 if first < 1.0 else 1


def _repeats_text(quick: bool) -> str:
    if quick:
        return "15 under 10 ms, 3 under 0.1 s, else one run"
    return "21 under 10 ms, 5 under 0.1 s, 3 under 1 s, else one run"


def _time_scale(inertia: Sequence[float], omega0: Sequence[float]) -> float:
    """tau = 2 pi / nu, nu = |omega0| max(1, max_i |I_j - I_k| / I_i): the fastest turning rate.

    Euler's equations turn omega at rates up to |omega| |I_j - I_k| / I_i, and the attitude at
    |omega|; step sizes are set as fractions of tau so that every case is resolved alike.
    """
    i = np.asarray(inertia, dtype=float)
    ratios = [abs(i[(k + 1) % 3] - i[(k + 2) % 3]) / i[k] for k in range(3)]
    nu = float(np.linalg.norm(omega0)) * max(1.0, *ratios)
    return 2.0 * math.pi / nu


def _energy(inertia: np.ndarray, omega: np.ndarray) -> np.ndarray:
    return 0.5 * np.sum(inertia * omega * omega, axis=-1)


@dataclass
class Errors:
    """Errors of one run against the exact solution, per output time and worst."""

    omega: np.ndarray
    attitude: np.ndarray
    energy: np.ndarray

    @property
    def worst(self) -> tuple[float, float, float]:
        return float(self.omega.max()), float(self.attitude.max()), float(self.energy.max())


def _errors(
    inertia: np.ndarray,
    energy0: float,
    omega: np.ndarray,
    attitude: Rotation,
    omega_exact: np.ndarray,
    attitude_exact: Rotation,
) -> Errors:
    rel = np.linalg.norm(omega - omega_exact, axis=1) / np.linalg.norm(omega_exact, axis=1)
    angle = (attitude * attitude_exact.inv()).magnitude()
    drift = np.abs(_energy(inertia, omega) - energy0) / energy0
    return Errors(rel, angle, drift)


def _setting_label(integrator: Integrator, value: float) -> str:
    return f"h={value:.4g}" if integrator.kind == "fixed" else f"rtol={value:.0e}"


# ---------------------------------------------------------------------------------------------
# Results
# ---------------------------------------------------------------------------------------------


@dataclass
class Run:
    case: str
    method: str
    setting: str
    seconds: float
    repeats: int
    cost: int
    omega_error: float
    attitude_error: float
    energy_drift: float
    times: np.ndarray
    errors: Errors

    @property
    def accuracy(self) -> float:
        return max(self.omega_error, self.attitude_error)


@dataclass
class ExactFindings:
    """The closed form's own behaviour in one case."""

    seconds: float
    """Construct + evaluate omega and attitude on the whole output grid (sum of medians)."""
    construct_seconds: float
    points: int
    invariant_energy: float
    invariant_norm: float
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


@dataclass
class CaseResult:
    case: Case
    regime: str
    parameter: float
    complementary: float
    period: float
    t_end: float
    tau: float
    exact: ExactFindings
    runs: list[Run]
    skipped: list[str]
    failed: list[str]
    run_budget: float


@dataclass
class Speedup:
    t: float
    exact_seconds: float
    exact_eval_seconds: float
    exact_error: float
    rows: list[tuple[float, float, int, float]]
    """(rtol, seconds, rhs evaluations, error) of DOP853 at t."""
    chosen: tuple[float, float, int, float] | None
    reached: bool
    against: str

    @property
    def factor(self) -> float:
        return self.chosen[1] / self.exact_seconds if self.chosen else math.nan

    @property
    def factor_eval(self) -> float:
        return self.chosen[1] / self.exact_eval_seconds if self.chosen else math.nan


# ---------------------------------------------------------------------------------------------
# Progress
# ---------------------------------------------------------------------------------------------


class Progress:
    """A one-line text bar on stderr: ``[#####.....]  45%  case / method setting``."""

    def __init__(self, total: int, enabled: bool = True, width: int = 30) -> None:
        self.total = max(total, 1)
        self.done = 0
        self.enabled = enabled
        self.width = width
        self.start = time.perf_counter()

    def advance(self, label: str, units: int = 1) -> None:
        self.done = min(self.done + units, self.total)
        self.show(label)

    def show(self, label: str) -> None:
        if not self.enabled:
            return
        filled = int(self.width * self.done / self.total)
        bar = "#" * filled + "." * (self.width - filled)
        elapsed = time.perf_counter() - self.start
        sys.stderr.write(
            f"\r[{bar}] {100 * self.done // self.total:3d}% {elapsed:6.1f}s  {label[:48]:<48}"
        )
        sys.stderr.flush()

    def close(self) -> None:
        if self.enabled:
            self.done = self.total
            self.show("done")
            sys.stderr.write("\n")
            sys.stderr.flush()


# ---------------------------------------------------------------------------------------------
# The study
# ---------------------------------------------------------------------------------------------


def _load_reference() -> tuple[Any, str]:
    """The mpmath reference class, or None and the reason."""
    try:
        from poinsot.app.report.reference import DIGITS, TaylorReference
    except ImportError as exc:  # mpmath is optional (the `test` extra)
        return None, f"mpmath is not installed ({exc}); the mpmath cross-check was skipped"
    import mpmath

    return TaylorReference, (
        f"Taylor series at {DIGITS} digits (integer fixed point for the series, mpmath "
        f"{mpmath.__version__} for conversions, folding and error measures)"
    )


def _case_settings(
    case: Case, config: StudyConfig
) -> tuple[tuple[float, ...], tuple[int, ...], float]:
    """(tolerances, steps per tau, per-run budget [s]) for a case: its overrides in full mode."""
    if config.quick:
        return config.tolerances, config.steps_per_scale, config.run_budget
    return (
        case.tolerances or config.tolerances,
        case.steps_per_scale or config.steps_per_scale,
        case.run_budget or config.run_budget,
    )


def _study_case(
    case: Case, config: StudyConfig, reference_cls: Any, progress: Progress
) -> CaseResult:
    inertia = np.asarray(case.inertia, dtype=float)
    omega0 = np.asarray(case.omega0, dtype=float)
    body = FreeRigidBody(inertia, omega0)
    periods = case.quick_periods if (config.quick and case.quick_periods) else case.periods
    if periods is not None:
        if not math.isfinite(body.period):
            raise ValueError(f"case {case.name!r}: horizon in periods but the period is infinite")
        t_end = periods * body.period
    elif case.horizon is not None:
        t_end = case.horizon
    else:
        raise ValueError(f"case {case.name!r} has no horizon")
    t_eval = np.linspace(0.0, t_end, config.samples + 1)
    tau = _time_scale(inertia, omega0)
    tolerances, steps_per_scale, run_budget = _case_settings(case, config)

    # --- the exact solution, once, timed: construction, then evaluation on the grid ----------
    construct_seconds, _, _ = _timed(lambda: FreeRigidBody(inertia, omega0), config.quick)
    eval_seconds, (omega_ex, attitude_ex), _ = _timed(
        lambda: (body.omega(t_eval), body.attitude(t_eval)), config.quick
    )
    seconds = construct_seconds + eval_seconds
    energy0 = float(_energy(inertia, omega0))
    momentum = attitude_ex.apply(inertia * omega_ex)
    g0 = float(np.linalg.norm(inertia * omega0))
    findings = ExactFindings(
        seconds=seconds,
        construct_seconds=construct_seconds,
        points=len(t_eval),
        invariant_energy=float(np.max(np.abs(_energy(inertia, omega_ex) - energy0)) / energy0),
        invariant_norm=float(np.max(np.abs(np.linalg.norm(momentum, axis=1) - g0)) / g0),
        invariant_direction=float(
            np.max(np.linalg.norm(momentum - body.angular_momentum, axis=1)) / g0
        ),
    )
    progress.advance(f"{case.name}: exact")

    # --- the exact solution against mpmath ------------------------------------------------
    if reference_cls is None:
        findings.reference_note = "no mpmath"
    else:
        start = time.perf_counter()
        reference = reference_cls(inertia, omega0)
        confirmed = math.isfinite(body.period) and reference.find_period(body.period)
        checks = [t_end * f for f in CHECK_FRACTIONS[config.reference_points]]
        for t in checks:
            c = reference.compare(t, body.omega(t), body.attitude(t).as_quat())
            findings.checks.append((t, c.omega_error, c.attitude_error))
        if confirmed:
            t_far = (FAR_PERIODS + _OFFSET) * body.period
            c = reference.compare(t_far, body.omega(t_far), body.attitude(t_far).as_quat())
            findings.far_check = (t_far, c.omega_error, c.attitude_error)
            findings.reference_note = f"period confirmed to {reference.digits} digits"
        elif math.isfinite(body.period):
            findings.reference_note = "period NOT confirmed by the reference"
        else:
            findings.reference_note = "no period (integrated directly)"
        findings.reference_seconds = time.perf_counter() - start
    progress.advance(f"{case.name}: mpmath reference")

    # --- the integrators -------------------------------------------------------------------
    runs: list[Run] = []
    skipped: list[str] = []
    failed: list[str] = []
    for name, integrator in INTEGRATORS.items():
        settings = (
            [tau / n for n in steps_per_scale] if integrator.kind == "fixed" else list(tolerances)
        )
        previous: tuple[float, float] | None = None  # (setting, seconds)
        for k, value in enumerate(settings):
            label = _setting_label(integrator, value)
            if previous is not None:
                # Cost ~ 1/h for fixed steps, ~ rtol^(-1/order) for the adaptive pairs.
                ratio = (
                    previous[0] / value
                    if integrator.kind == "fixed"
                    else (previous[0] / value) ** (1.0 / integrator.order)
                )
                if previous[1] * ratio > run_budget:
                    skipped.extend(f"{name} {_setting_label(integrator, v)}" for v in settings[k:])
                    progress.advance(f"{case.name}: {name} (budget)", len(settings) - k)
                    break
            progress.show(f"{case.name}: {name} {label}")
            try:
                secs, traj, repeats = _timed(
                    lambda v=value, n=name: integrate(n, inertia, omega0, None, t_eval, v),
                    config.quick,
                )
            except (ValueError, RuntimeError) as exc:
                failed.append(f"{name} {label}: {exc}")
                progress.advance(f"{case.name}: {name} {label} failed")
                continue
            errs = _errors(inertia, energy0, traj.omega, traj.attitude, omega_ex, attitude_ex)
            w, a, e = errs.worst
            runs.append(
                Run(case.name, name, label, secs, repeats, traj.cost, w, a, e, t_eval, errs)
            )
            previous = (value, secs)
            progress.advance(f"{case.name}: {name} {label}")
    return CaseResult(
        case=case,
        regime=body.regime.name,
        parameter=float(body.parameter),
        complementary=float(body.complementary_parameter),
        period=float(body.period),
        t_end=float(t_end),
        tau=tau,
        exact=findings,
        runs=runs,
        skipped=skipped,
        failed=failed,
        run_budget=run_budget,
    )


def _speedup_study(config: StudyConfig, reference_cls: Any, progress: Progress) -> Speedup:
    """DOP853 against the exact solution at t = SPEEDUP_TIME on the generic body."""
    inertia = np.asarray(GENERIC.inertia, dtype=float)
    omega0 = np.asarray(GENERIC.omega0, dtype=float)
    t = SPEEDUP_TIME

    def exact_at_t() -> tuple[np.ndarray, Rotation]:
        # Construct, then omega and the attitude from one evaluation (FreeRigidBody.state).
        return FreeRigidBody(inertia, omega0).state(t)

    # Many repeats: the call is a fraction of a millisecond and the median must be stable.
    # Garbage left by the studies above is collected first (as timeit would): otherwise the
    # collector's passes over it land inside these sub-millisecond calls and double them.
    gc.collect()
    samples = []
    for _ in range(SPEEDUP_REPEATS):
        start = time.perf_counter()
        omega_ex, attitude_ex = exact_at_t()
        samples.append(time.perf_counter() - start)
    exact_seconds = statistics.median(samples)
    body = FreeRigidBody(inertia, omega0)
    samples = []
    for _ in range(SPEEDUP_REPEATS):
        start = time.perf_counter()
        body.state(t)
        samples.append(time.perf_counter() - start)
    exact_eval_seconds = statistics.median(samples)

    if reference_cls is not None:
        reference = reference_cls(inertia, omega0)
        if not reference.find_period(body.period):
            raise RuntimeError("the mpmath reference could not confirm the generic period")

        def error_of(omega: np.ndarray, attitude: Rotation) -> float:
            c = reference.compare(t, omega, attitude.as_quat())
            return max(c.omega_error, c.attitude_error)

        exact_error = error_of(omega_ex, attitude_ex)
        against = "the mpmath reference"
    else:

        def error_of(omega: np.ndarray, attitude: Rotation) -> float:
            rel = float(np.linalg.norm(omega - omega_ex) / np.linalg.norm(omega_ex))
            return max(rel, float((attitude * attitude_ex.inv()).magnitude()))

        exact_error = 0.0
        against = "the exact solution (mpmath absent: its own error is unknown)"
    progress.advance("speed-up: exact at t=1e4")

    rows: list[tuple[float, float, int, float]] = []
    for rtol in config.speedup_tolerances:
        progress.show(f"speed-up: DOP853 rtol={rtol:.0e} to t=1e4")
        secs, traj, _ = _timed(
            lambda r=rtol: integrate("DOP853", inertia, omega0, None, [t], r), config.quick
        )
        rows.append((rtol, secs, traj.cost, error_of(traj.omega[0], traj.attitude[0])))
        progress.advance(f"speed-up: DOP853 rtol={rtol:.0e}")
        if rows[-1][3] <= exact_error:
            progress.advance("speed-up", len(config.speedup_tolerances) - len(rows))
            break
    reaching = [r for r in rows if r[3] <= exact_error]
    chosen = reaching[0] if reaching else min(rows, key=lambda r: r[3])
    return Speedup(
        t, exact_seconds, exact_eval_seconds, exact_error, rows, chosen, bool(reaching), against
    )


# ---------------------------------------------------------------------------------------------
# Writing
# ---------------------------------------------------------------------------------------------


def _g(x: float, digits: int = 3) -> str:
    return f"{x:.{digits}g}" if math.isfinite(x) else str(x)


def _e(x: float) -> str:
    return f"{x:.2e}" if math.isfinite(x) else str(x)


def _write_csvs(out: Path, results: list[CaseResult]) -> None:
    with open(out / "work_precision.csv", "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(WORK_PRECISION_COLUMNS)
        for r in results:
            ex = r.exact
            w, a = ex.worst_inside
            writer.writerow(
                [
                    r.case.name,
                    EXACT,
                    "closed form",
                    f"{ex.seconds:.6g}",
                    _csv_float(w),
                    _csv_float(a),
                    _csv_float(ex.invariant_energy),
                ]
            )
            for run in r.runs:
                writer.writerow(
                    [
                        run.case,
                        run.method,
                        run.setting,
                        f"{run.seconds:.6g}",
                        _csv_float(run.omega_error),
                        _csv_float(run.attitude_error),
                        _csv_float(run.energy_drift),
                    ]
                )
    with open(out / "error_vs_time.csv", "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(ERROR_VS_TIME_COLUMNS)
        for r in results:
            for t, w, a in r.exact.checks + ([r.exact.far_check] if r.exact.far_check else []):
                writer.writerow(
                    [
                        r.case.name,
                        EXACT,
                        "closed form",
                        _csv_float(t),
                        _csv_float(w),
                        _csv_float(a),
                        "",
                    ]
                )
            for run in r.runs:
                for i, t in enumerate(run.times):
                    writer.writerow(
                        [
                            run.case,
                            run.method,
                            run.setting,
                            _csv_float(float(t)),
                            _csv_float(float(run.errors.omega[i])),
                            _csv_float(float(run.errors.attitude[i])),
                            _csv_float(float(run.errors.energy[i])),
                        ]
                    )


def _csv_float(x: float) -> str:
    return f"{x:.6e}" if math.isfinite(x) else "nan"


def _verdict(r: CaseResult) -> tuple[str, list[tuple[float, str]]]:
    """One-line verdict and, per accuracy level, the fastest integrator that reaches it."""
    ex_w, ex_a = r.exact.worst_inside
    ex_acc = max(ex_w, ex_a)
    per_level: list[tuple[float, str]] = []
    best_integrator: dict[float, Run | None] = {}
    for level in ACCURACY_LEVELS:
        reaching = [run for run in r.runs if run.accuracy <= level]
        fastest = min(reaching, key=lambda run: run.seconds) if reaching else None
        best_integrator[level] = fastest
        if fastest is None:
            text = "no integrator"
        else:
            text = f"{fastest.method} {fastest.setting} ({_g(fastest.seconds * 1e3)} ms)"
        per_level.append((level, text))
    most_accurate = min(r.runs, key=lambda run: run.accuracy) if r.runs else None
    exact_ms = _g(r.exact.seconds * 1e3)
    parts = []
    if math.isfinite(ex_acc):
        beaten = [
            (lvl, run)
            for lvl, run in best_integrator.items()
            if run is not None and run.seconds < r.exact.seconds and lvl >= ex_acc
        ]
        if beaten:
            lvl, run = max(beaten, key=lambda p: p[0])
            parts.append(
                f"an integrator is cheaper than the exact solution at accuracy {lvl:.0e} "
                f"({run.method} {run.setting}, {_g(run.seconds * 1e3)} ms vs {exact_ms} ms)"
            )
        else:
            parts.append(
                f"the exact solution wins at every accuracy ({exact_ms} ms for "
                f"{r.exact.points} points, error {ex_acc:.1e} vs mpmath)"
            )
    levels_reached = [(lvl, run) for lvl, run in best_integrator.items() if run is not None]
    if levels_reached:
        grouped = _group_levels([(lvl, run.method) for lvl, run in levels_reached])
        winners_text = ", then ".join(f"{m} down to {lvl:.0e}" for lvl, m in grouped)
        parts.append(f"among integrators the fastest is {winners_text}")
    if most_accurate is not None:
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
        parts.append(f"no setting brings {' or '.join(hopeless)} below an error of 0.1")
    return "; ".join(parts) + ".", per_level


def _observed_order(runs: list[Run]) -> float:
    """p in omega error ~ cost^-p (cost = steps or RHS evaluations), fitted over the runs in the
    asymptotic range 1e-13 < error < 1e-2 (NaN with fewer than two)."""
    pts = [(r.cost, r.omega_error) for r in runs if 1e-13 < r.omega_error < 1e-2 and r.cost > 0]
    if len(pts) < 2 or len({c for c, _ in pts}) < 2:
        return math.nan
    x, y = np.log([c for c, _ in pts]), np.log([e for _, e in pts])
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


def _write_markdown(
    out: Path,
    config: StudyConfig,
    results: list[CaseResult],
    speedup: Speedup,
    reference_note: str,
    figures: list[str],
    figure_note: str,
    elapsed: float,
) -> None:
    lines: list[str] = []
    add = lines.append
    mode = "quick (`--quick`)" if config.quick else "full"
    add("# Work-precision report: the exact solution beside numerical integrators")
    add("")
    add(
        f"Mode: {mode}. Wall time {elapsed:.1f} s on {platform.machine()} "
        f"({platform.processor() or 'cpu'}, {_cpu_count()} cores), Python "
        f"{platform.python_version()}, numpy {np.__version__}, scipy {scipy.__version__}. "
        f"Reference: {reference_note}."
    )
    add("")
    add("## Method")
    add("")
    add(
        "Each case is followed over its horizon and sampled on a uniform grid of "
        f"{config.samples + 1} times. The exact solution (`physics.FreeRigidBody`) is evaluated "
        "once on the grid (construction included in its time). Each integrator runs at several "
        "settings; errors are the worst over the grid, against the exact solution:"
    )
    add("")
    add("- **omega error**: |omega - omega_exact| / |omega_exact| (relative);")
    add("- **attitude error**: geodesic angle of R R_exact^T [rad];")
    add("- **energy drift**: |T(t) - T(0)| / T(0).")
    add("")
    add(
        "The `exact` rows carry the closed form's own errors against an independent "
        "high-precision Taylor-series integration (`app/highprecision.py`, no formula shared "
        "with the closed form), at "
        f"{config.reference_points} irregularly placed points in the horizon and at "
        f"{FAR_PERIODS:.0e} + 0.38 periods, "
        "and its energy drift over the grid. The reference took "
        f"{sum(r.exact.reference_seconds for r in results):.1f} s in all."
    )
    add(
        f"Timings are medians of repeats ({_repeats_text(config.quick)}). "
        "Fixed steps are set as "
        "h = tau / n, tau = 2 pi / (|omega0| max(1, max |I_j - I_k| / I_i)), "
        f"n in {list(config.steps_per_scale)}; tolerances rtol in "
        f"{[f'{t:.0e}' for t in config.tolerances]} (atol = rtol max|omega0| on omega, rtol on "
        f"the quaternion). Settings predicted to exceed {config.run_budget:g} s are skipped."
    )
    add("")
    add("| method | kind | order | conserves abs(L) | description |")
    add("|---|---|---|---|---|")
    for integ in INTEGRATORS.values():
        add(
            f"| {integ.name} | {integ.kind} | {integ.order} | "
            f"{'yes' if integ.conserves_norm else 'no'} | {integ.title} |"
        )
    add("")

    add("## Cases")
    add("")
    add("| case | I | omega0 | regime | m | 1-m | period | horizon | source |")
    add("|---|---|---|---|---|---|---|---|---|")
    for r in results:
        c = r.case
        add(
            f"| {c.name} | {_tuple(c.inertia)} | {_tuple(c.omega0)} | {r.regime} | "
            f"{_g(r.parameter)} | {_g(r.complementary)} | {_g(r.period, 6)} | {_g(r.t_end, 6)} | "
            f"{c.source} |"
        )
    add("")

    add("## Speed-up of the exact solution over DOP853 at t = 1e4")
    add("")
    add(
        f"Generic body, errors at t = {speedup.t:g} against {speedup.against}. The exact "
        f"solution: {_g(speedup.exact_seconds * 1e3)} ms to construct and evaluate omega and "
        f"the attitude at t (`FreeRigidBody(I, omega0).state(t)`: one evaluation gives both; "
        f"median of {SPEEDUP_REPEATS} runs after a `gc.collect()`), "
        f"{_g(speedup.exact_eval_seconds * 1e3)} ms to "
        f"evaluate an already constructed solution (`state(t)`), error "
        f"{speedup.exact_error:.2e}."
    )
    add("")
    add("| DOP853 rtol | seconds | RHS evaluations | error at t=1e4 |")
    add("|---|---|---|---|")
    for rtol, secs, nfev, err in speedup.rows:
        add(f"| {rtol:.0e} | {_g(secs)} | {nfev} | {err:.2e} |")
    add("")
    if speedup.chosen is not None:
        how = (
            "the cheapest DOP853 run that reaches the exact solution's accuracy"
            if speedup.reached
            else "DOP853's most accurate run (none reaches the exact solution's accuracy)"
        )
        add(
            f"**Speed-up: {speedup.factor:.3g}x** ({how}: rtol {speedup.chosen[0]:.0e}, "
            f"{_g(speedup.chosen[1])} s, error {speedup.chosen[3]:.2e}; against construct + "
            f"evaluate). Against evaluation only: {speedup.factor_eval:.3g}x. "
            f"Goal >= 1e4x: {'met' if speedup.factor >= 1e4 else 'NOT met'} counting the "
            f"construction, {'met' if speedup.factor_eval >= 1e4 else 'NOT met'} for the "
            "evaluation alone."
        )
    add("")

    add("## Verdicts")
    add("")
    wins = sum("wins at every accuracy" in _verdict(r)[0] for r in results)
    add(
        f"The exact solution is the cheapest way to every accuracy level in {wins} of "
        f"{len(results)} cases (accuracy: max of the omega and attitude errors)."
    )
    add("")
    for r in results:
        verdict, _ = _verdict(r)
        add(f"- **{r.case.name}**: {verdict}")
    add("")

    add("## Observed orders")
    add("")
    add(
        "p in omega error ~ cost^-p (cost: steps, or RHS evaluations), fitted over each "
        "method's runs with 1e-13 < error < 1e-2; expected: the order "
        + ", ".join(f"{i.name} {i.order}" for i in INTEGRATORS.values())
        + ". Blank: fewer than two runs in that range (the case is too hard or too easy)."
    )
    add("")
    add("| case | " + " | ".join(INTEGRATORS) + " |")
    add("|---|" + "---|" * len(INTEGRATORS))
    for r in results:
        cells = []
        for name in INTEGRATORS:
            p = _observed_order([run for run in r.runs if run.method == name])
            cells.append(f"{p:.2f}" if math.isfinite(p) else "")
        add(f"| {r.case.name} | " + " | ".join(cells) + " |")
    add("")

    add("## Stability of the exact solution")
    add("")
    add(
        "Worst error against mpmath inside the horizon and at 1e4 periods, drift of the "
        "invariants over the grid (energy, abs(L) and the space vector L, relative), and cost: "
        "construction, then evaluation per point on the grid (omega and attitude)."
    )
    add("")
    add(
        "| case | omega err | attitude err | omega err @1e4 P | attitude err @1e4 P | "
        "energy drift | abs(L) drift | L drift | construct [us] | per point [us] | note |"
    )
    add("|---|---|---|---|---|---|---|---|---|---|---|")
    for r in results:
        ex = r.exact
        w, a = ex.worst_inside
        fw, fa = (ex.far_check[1], ex.far_check[2]) if ex.far_check else (math.nan, math.nan)
        add(
            f"| {r.case.name} | {_e(w)} | {_e(a)} | {_e(fw)} | {_e(fa)} | "
            f"{_e(ex.invariant_energy)} | {_e(ex.invariant_norm)} | "
            f"{_e(ex.invariant_direction)} | {_g(ex.construct_seconds * 1e6)} | "
            f"{_g((ex.seconds - ex.construct_seconds) / ex.points * 1e6)} | "
            f"{ex.reference_note} |"
        )
    add("")

    add("## Per case")
    for r in results:
        add("")
        add(f"### {r.case.name}")
        add("")
        add(
            f"I = {_tuple(r.case.inertia)}, omega0 = {_tuple(r.case.omega0)}, regime "
            f"{r.regime}, horizon {_g(r.t_end, 6)}, tau = {_g(r.tau)}. {r.case.source}."
        )
        add("")
        verdict, per_level = _verdict(r)
        add(f"Verdict: {verdict}")
        add("")
        add("| accuracy | fastest integrator reaching it | exact solution |")
        add("|---|---|---|")
        ex_w, ex_a = r.exact.worst_inside
        ex_acc = max(ex_w, ex_a)
        for level, text in per_level:
            exact_text = (
                f"{_g(r.exact.seconds * 1e3)} ms"
                if math.isfinite(ex_acc) and ex_acc <= level
                else "not verified"
                if not math.isfinite(ex_acc)
                else "not reached"
            )
            add(f"| {level:.0e} | {text} | {exact_text} |")
        add("")
        add(
            "| method | setting | seconds | repeats | cost | omega error | attitude error | "
            "energy drift |"
        )
        add("|---|---|---|---|---|---|---|---|")
        w, a = r.exact.worst_inside
        add(
            f"| exact | closed form | {_g(r.exact.seconds)} | - | - | {_e(w)} | {_e(a)} | "
            f"{_e(r.exact.invariant_energy)} |"
        )
        for run in r.runs:
            add(
                f"| {run.method} | {run.setting} | {_g(run.seconds)} | {run.repeats} | "
                f"{run.cost} | {_e(run.omega_error)} | {_e(run.attitude_error)} | "
                f"{_e(run.energy_drift)} |"
            )
        if r.skipped:
            add("")
            add(f"Skipped (predicted over {r.run_budget:g} s): {', '.join(r.skipped)}.")
        if r.failed:
            add("")
            add(f"Failed: {'; '.join(r.failed)}.")
    add("")
    add("## Figures")
    add("")
    if figures:
        for name in figures:
            add(f"![{name}]({name})")
            add("")
    add(figure_note)
    add("")
    (out / "report.md").write_text("\n".join(lines))


def _tuple(values: Sequence[float]) -> str:
    return "(" + ", ".join(f"{v:.10g}" for v in values) + ")"


def _cpu_count() -> int:
    import os

    return os.cpu_count() or 1


# ---------------------------------------------------------------------------------------------
# Figures (matplotlib is optional: the `report` extra)
# ---------------------------------------------------------------------------------------------

_COLOURS = {
    "RK45": "tab:blue",
    "DOP853": "tab:orange",
    "splitting": "tab:green",
    "midpoint": "tab:purple",
    EXACT: "black",
}


def _arrange(fig: Any) -> None:
    # Fixed margins: tight_layout costs seconds on a 3x4 grid and the panels are uniform.
    fig.subplots_adjust(left=0.06, right=0.98, bottom=0.07, top=0.91, wspace=0.32, hspace=0.5)


def _write_figures(out: Path, results: list[CaseResult]) -> tuple[list[str], str]:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return [], "matplotlib is not installed (`pip install poinsot[report]`): no figures."
    n = len(results)
    cols = min(4, n)
    rows = -(-n // cols)
    written = []
    for name, pick, ylabel in (
        ("work_precision.png", lambda run: run.omega_error, "omega error (relative)"),
        ("work_precision_attitude.png", lambda run: run.attitude_error, "attitude error [rad]"),
    ):
        fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.4 * rows), squeeze=False)
        for ax, r in zip(axes.flat, results, strict=False):
            for method in INTEGRATORS:
                runs = [run for run in r.runs if run.method == method]
                if runs:
                    ax.loglog(
                        [run.seconds for run in runs],
                        [max(pick(run), 1e-17) for run in runs],
                        "o-",
                        color=_COLOURS[method],
                        label=method,
                        ms=4,
                    )
            w, a = r.exact.worst_inside
            y = w if "omega" in ylabel else a
            if math.isfinite(y):
                ax.loglog(
                    [r.exact.seconds],
                    [max(y, 1e-17)],
                    "*",
                    color="black",
                    ms=12,
                    label="exact (vs mpmath)",
                )
            ax.set_title(r.case.name, fontsize=9)
            ax.set_xlabel("run time [s]", fontsize=8)
            ax.set_ylabel(ylabel, fontsize=8)
            ax.tick_params(labelsize=7)
            ax.grid(True, which="major", alpha=0.3)
        for ax in list(axes.flat)[n:]:
            ax.set_visible(False)
        axes.flat[0].legend(fontsize=7)
        fig.suptitle("Error against run time (worst over the horizon)")
        _arrange(fig)
        fig.savefig(out / name, dpi=90)
        plt.close(fig)
        written.append(name)

    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.4 * rows), squeeze=False)
    for ax, r in zip(axes.flat, results, strict=False):
        for method in INTEGRATORS:
            runs = [run for run in r.runs if run.method == method]
            if not runs:
                continue
            best = min(runs, key=lambda run: run.accuracy)
            t = best.times[1:]
            ax.loglog(
                t,
                np.maximum(best.errors.omega[1:], 1e-17),
                color=_COLOURS[method],
                label=f"{method} {best.setting}",
                lw=1,
            )
        pts = r.exact.checks + ([r.exact.far_check] if r.exact.far_check else [])
        inside = [p for p in pts if p[0] <= r.t_end * (1 + 1e-12)]
        if inside:
            ax.loglog(
                [p[0] for p in inside],
                [max(p[1], 1e-17) for p in inside],
                "*",
                color="black",
                ms=10,
                label="exact vs mpmath",
            )
        ax.set_title(r.case.name, fontsize=9)
        ax.set_xlabel("simulated time", fontsize=8)
        ax.set_ylabel("omega error (relative)", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.legend(fontsize=6)
        ax.grid(True, which="major", alpha=0.3)
    for ax in list(axes.flat)[n:]:
        ax.set_visible(False)
    fig.suptitle("Error against simulated time (each method's most accurate setting)")
    _arrange(fig)
    fig.savefig(out / "error_vs_time.png", dpi=90)
    plt.close(fig)
    written.append("error_vs_time.png")
    return written, f"Figures drawn with matplotlib {matplotlib.__version__} (Agg)."


# ---------------------------------------------------------------------------------------------
# Entry points
# ---------------------------------------------------------------------------------------------


@dataclass
class ReportSummary:
    out: Path
    results: list[CaseResult]
    speedup: Speedup
    elapsed: float


def run_report(out: Path | str, quick: bool = False, progress: bool = True) -> ReportSummary:
    """Run the study and write the CSVs, report.md and figures into ``out`` (created)."""
    start = time.perf_counter()
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    config = StudyConfig.for_mode(quick)
    reference_cls, reference_note = _load_reference()
    units = 1 + len(config.speedup_tolerances)
    for case in config.cases:
        tolerances, steps_per_scale, _ = _case_settings(case, config)
        units += 2 + sum(
            len(steps_per_scale) if i.kind == "fixed" else len(tolerances)
            for i in INTEGRATORS.values()
        )
    bar = Progress(units, enabled=progress)
    results = [_study_case(case, config, reference_cls, bar) for case in config.cases]
    speedup = _speedup_study(config, reference_cls, bar)
    bar.close()
    _write_csvs(out, results)
    figures, figure_note = _write_figures(out, results)
    elapsed = time.perf_counter() - start
    _write_markdown(out, config, results, speedup, reference_note, figures, figure_note, elapsed)
    return ReportSummary(out, results, speedup, elapsed)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The ``report`` subcommand's options."""
    parser.add_argument(
        "--quick", action="store_true", help="a reduced matrix and fewer settings (< 60 s)"
    )
    parser.add_argument("--out", default="out/report", help="output directory (created)")


def main(args: argparse.Namespace | Sequence[str] | None = None) -> int:
    """``poinsot report [--quick] --out DIR``; also runnable as ``python -m poinsot.app.report``."""
    if not isinstance(args, argparse.Namespace):
        parser = argparse.ArgumentParser(prog="poinsot report", description=__doc__.split("\n")[0])
        add_arguments(parser)
        args = parser.parse_args(args)
    summary = run_report(args.out, quick=args.quick, progress=True)
    print(f"report written to {summary.out / 'report.md'} in {summary.elapsed:.1f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
