"""The study's case matrix, as data, and what a run of the report does with it.

Each :class:`Case` is one body and initial state with a line saying where it comes from;
:class:`StudyConfig` gives the two presets (``--quick`` and full): which cases, which step sizes
and tolerances, how fine the output grid, how many high-precision check points.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["CASES", "GENERIC", "Case", "CaseSettings", "StudyConfig"]


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
    quick_tolerances: tuple[float, ...] | None = None
    """``--quick``: this case's adaptive tolerances instead of the study's (None: the same)."""
    quick_steps_per_scale: tuple[int, ...] | None = None
    """``--quick``: this case's fixed-step settings instead of the study's (None: the same)."""
    time_unit: str = "s"
    """The unit of time of omega0 (rad per this unit) and of the horizon."""

    def t_end(self, period: float, quick: bool) -> float:
        """The horizon [time units], given the exact solution's period of omega."""
        periods = self.quick_periods if (quick and self.quick_periods) else self.periods
        if periods is not None:
            if not math.isfinite(period):
                raise ValueError(
                    f"case {self.name!r}: horizon in periods but the period is infinite"
                )
            return periods * period
        if self.horizon is not None:
            return self.horizon
        raise ValueError(f"case {self.name!r} has no horizon")


def _near_separatrix(mc: float) -> tuple[float, float, float]:
    # On I = (1, 2, 3) with omega = (w1, 0, 1): Delta2 = 3 - w1^2, Delta1 = 6, so the
    # complementary parameter 1 - m = Delta2 (I3 - I1) / (Delta1 (I3 - I2)) = 1 - w1^2 / 3
    # (the major-axis family [LL76 §37, Eq. 37.10]). The float w1 moves 1 - m by ~2e-16.
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
        "asteroid 4179 Toutatis: moments from the radar shape model [HO95]; omega0 [rad/day] "
        "fitted to its long-axis mode, periods 5.41 d and 7.35 d",
        periods=10,
        time_unit="d",
    ),
    Case(
        "long horizon",
        GENERIC.inertia,
        GENERIC.omega0,
        "the generic box followed for 1e4 periods (1e3 with --quick); loose settings are "
        "pointless there (errors O(1)), so it tries fewer, tighter ones and a longer budget "
        "(with --quick one per method, each below error 1 at 1e3 periods)",
        periods=1e4,
        quick_periods=1e3,
        tolerances=(1e-8, 1e-13),
        steps_per_scale=(16, 128),
        run_budget=90.0,
        # At 1e3 periods: DOP853 and RK45 at 1e-8 reach ~2e-3 in 1-4 s, the splitting and the
        # midpoint rule at tau/128 ~0.2 in 0.5-1.2 s; anything looser is O(1).
        quick_tolerances=(1e-8,),
        quick_steps_per_scale=(128,),
    ),
)


@dataclass(frozen=True)
class CaseSettings:
    """The settings the integrators run at in one case."""

    tolerances: tuple[float, ...]
    """Adaptive methods: relative tolerances."""
    steps_per_scale: tuple[int, ...]
    """Fixed-step methods: steps per characteristic time tau (see :func:`runs.time_scale`)."""
    run_budget: float
    """Seconds: settings predicted to take longer are skipped (the first always runs)."""


@dataclass(frozen=True)
class StudyConfig:
    """What a run of the report does; :func:`StudyConfig.for_mode` gives the two presets."""

    quick: bool
    cases: tuple[Case, ...]
    steps_per_scale: tuple[int, ...]
    """Fixed-step settings: steps per characteristic time tau = 2 pi / nu (see time_scale)."""
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

    def settings(self, case: Case) -> CaseSettings:
        """The settings of one case: the study's, or the case's own overrides in full mode."""
        if self.quick:
            return CaseSettings(
                case.quick_tolerances or self.tolerances,
                case.quick_steps_per_scale or self.steps_per_scale,
                self.run_budget,
            )
        return CaseSettings(
            case.tolerances or self.tolerances,
            case.steps_per_scale or self.steps_per_scale,
            case.run_budget or self.run_budget,
        )
