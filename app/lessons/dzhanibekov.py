"""Scene "dzhanibekov": the intermediate-axis flip of a T-handle as a clock, theory against
measurement [ACC91; LL76 §37; FM06 Theorem 7.3; DLMF 19.12.1].

What it shows: the bundled T-handle (its moments from its own mesh through trimesh, uniform
density) spun at the angle ε from its intermediate axis e₂, in Poinsot's construction. The flips
come like a clock: every 2K(k)/λ, the first one at (K ± δ)/λ; the perturbation off e₂ first
grows like exp(σt); and 2K/λ tends to ln(16/(1 − k²))/λ, so the time between flips grows like
ln(1/ε). A dropdown takes ε over the decades 1e-1 … 1e-12; the motion is exact at every one
(an integrator is not at 1e-12: ``python -m poinsot.physics.models.flip``). A plot shows
log₁₀ sin(angle of ω from e₂) against time with the theory's slope σ.

A twin (on by default, ε′ = ε/10; a dropdown takes ε/2 … ε/1000 or none) is the same handle
started at ε′, drawn in bluish green over the first: both exact, it flips later, by t₁(ε′) − t₁(ε) →
ln(ε/ε′)/σ, so ten times closer buys only ln(10)/σ more, whatever ε.

Readouts: the time between flips measured from the motion (the zeros of ω₂) against 2K(k)/λ and
against its asymptote; the first flip against (K ± δ)/λ; the growth rate fitted to the motion
against σ; the twin's first flip, its lag behind the first measured from the two motions
against the theory, and that lag against its small-ε limit ln(ε/ε′)/σ.

Physics: :func:`poinsot.physics.models.flip.flip_initial_omega`, :func:`~.flip_theory`,
:func:`~.measure_flips`, :func:`~.measure_growth_rate`;
:func:`poinsot.physics.models.twins.twin_clock`; :func:`poinsot.app.model.bodies.bundled_body` (the
mesh and its moments).
"""

from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np

from poinsot.app.lessons.support import colors
from poinsot.app.lessons.support.base import CONSTRUCTION, OwnSolid, SceneModel
from poinsot.app.lessons.support.spec import (
    Choice,
    Part,
    PlotSpec,
    Readout,
    SceneSpec,
    Settings,
    number,
)
from poinsot.app.lessons.twins import twin_drawing
from poinsot.app.model.bodies import MeshBody, bundled_body
from poinsot.app.model.elements import Control, Element
from poinsot.physics import FreeRigidBody, attitude_with_L_along_z
from poinsot.physics.models.flip import (
    FlipTheory,
    GrowthFit,
    flip_initial_omega,
    flip_theory,
    measure_flips,
    measure_growth_rate,
)
from poinsot.physics.models.twins import TwinClock, twin_clock

#: The decades of ε offered (the angle of ω₀ from e₂, rad).
DECADES = tuple(range(1, 13))
EPSILON_OPTIONS = tuple(f"1e-{k}" for k in DECADES)
EPSILON_VALUES = tuple(10.0**-k for k in DECADES)
#: |ω₀| [rad/time].
SPIN = 2.0
#: The plot covers the first flip and this many more time-between-flips.
PLOT_FLIPS = 2.0
PLOT_SAMPLES = 800
#: Growth-rate fits tried in turn (start factor, stop amplitude): the first is the physics'
#: default, the looser ones find a stretch for the larger ε (down to 1e-4).
GROWTH_WINDOWS = ((math.exp(5.0), 1e-3), (math.exp(3.0), 1e-2), (math.exp(2.0), 5e-2))
HANDLE_NODE = "/space/body/handle"
HANDLE = Part("handle", "T-handle (its mesh)", (HANDLE_NODE,), surface=colors.SOLID)
#: The twin: the same handle started at ε′ = ε/n, overlaid in bluish green.
TWIN_FRAME, TWIN_NODE = "/space/twin", "/space/twin/handle"
TWIN = Part("twin-body", "its twin at ε′", (TWIN_FRAME, TWIN_NODE), surface=colors.TWIN)
#: The twin's ε/ε′ offered (0: no twin).
TWIN_OPTIONS = ("no twin", "ε′ = ε/2", "ε′ = ε/10", "ε′ = ε/100", "ε′ = ε/1000")
TWIN_RATIOS = (0.0, 2.0, 10.0, 100.0, 1000.0)
#: The twin's readouts (after the first body's).
TWIN_READOUTS = (
    "twin's first flip at ε′",
    "lag of the twin, t₁(ε′) − t₁(ε)",
    "… its small-ε limit ln(ε/ε′)/σ",
)
#: The lag is a difference of two flip times, each to a few ulps of a time ~10 lags long.
LAG = 1e-10
#: Tolerances of the readouts: the flips are zeros of ω₂ refined to a few ulps of t; the fit of
#: the growth rate is a straight line through ln p over a stretch that is not quite exponential.
EXACT = 1e-12
GROWTH_FIT = 1e-3


@functools.cache
def t_handle() -> MeshBody:
    """The bundled T-handle, measured once (its mesh in its principal frame, I₁ < I₂ < I₃)."""
    return bundled_body("t_handle")


def moments() -> np.ndarray:
    """The T-handle's moments normalised so that the largest is 1 (its shape, not its size)."""
    return np.asarray(t_handle().ratios, dtype=float)


def growth_fit(body: FreeRigidBody) -> GrowthFit | None:
    """The first of :data:`GROWTH_WINDOWS` that finds an exponential stretch, or None."""
    for start_factor, stop in GROWTH_WINDOWS:
        try:
            return measure_growth_rate(body, start_factor, stop)
        except ValueError:
            continue
    return None


@dataclasses.dataclass(frozen=True)
class FlipModel(OwnSolid, SceneModel):
    """The flipping T-handle at one ε, its theory and what is measured from its motion."""

    epsilon: float
    body: FreeRigidBody
    theory: FlipTheory
    flips: np.ndarray  # measured zeros of ω₂ over the plot's span
    growth: GrowthFit | None
    times: np.ndarray  # the plot's grid
    log_p: np.ndarray  # log₁₀ of the perturbation on it
    log_theory: np.ndarray  # log₁₀ ε + σ t / ln 10, capped at 0
    twin: FreeRigidBody | None = None  # the twin at ε′ (None: no twin)
    twins: TwinClock | None = None  # the twins' theory
    twin_flips: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(0))
    twin_log_p: np.ndarray | None = None  # the twin's perturbation on the plot's grid

    @functools.cached_property
    def rows(self) -> tuple[Readout, ...]:
        th, flips = self.theory, self.flips
        w0 = self.body.omega(0.0)
        angle = math.atan2(math.hypot(w0[0], w0[2]), abs(w0[1]))
        between = float(np.mean(np.diff(flips))) if len(flips) >= 2 else math.nan
        first = float(flips[0]) if len(flips) else math.nan
        growth = (
            Readout.compare(
                "growth rate σ",
                th.growth_rate,
                self.growth.rate,
                GROWTH_FIT,
                f"fit of ln p over {self.growth.e_folds:.1f} e-folds",
            )
            if self.growth is not None
            else Readout(
                "growth rate σ",
                number(th.growth_rate),
                "—",
                "no exponential stretch at this ε (needs ε ≤ 1e-4)",
            )
        )
        return (
            Readout.compare("ε (angle of ω₀ from e₂)", self.epsilon, angle, EXACT),
            Readout.compare(
                "time between flips, 2K(k)/λ",
                th.time_between_flips,
                between,
                EXACT,
                "measured: spacing of the zeros of ω₂",
                digits=9,
            ),
            Readout.compare(  # 2K = ln(16/(1 − k²)) + O(1 − k²)
                "… its asymptote ln(16/(1−k²))/λ",
                th.asymptotic_time_between_flips,
                between,
                max(th.complementary_parameter, EXACT),
                digits=9,
            ),
            Readout.compare("first flip, (K ± δ)/λ", th.first_flip_time, first, EXACT, digits=9),
            growth,
            Readout("1 − k²", f"{th.complementary_parameter:.3e}", "—"),
            *self.twin_rows(first),
        )

    def twin_rows(self, first: float) -> tuple[Readout, ...]:
        """The twin's first flip, the lag behind the first body and its small-ε limit."""
        names = TWIN_READOUTS
        if self.twins is None:
            return tuple(Readout(name, "—", "—", "no twin (choose ε′)") for name in names)
        clock, flips = self.twins, self.twin_flips
        second = float(flips[0]) if len(flips) else math.nan
        lag = second - first
        # lag − ln(ε/ε′)/σ = O(ε²)/σ (λ = σ (1 + O(ε²)), K = ln(4/√(1 − k²)) + O(ε² ln ε)),
        # relative to the lag ln(ε/ε′)/σ: a few ε²/ln(ε/ε′)
        limit_tolerance = max(5.0 * self.epsilon**2 / math.log(ratio_of(clock)), EXACT)
        return (
            Readout.compare(names[0], clock.second_flip, second, EXACT, digits=9),
            Readout.compare(
                names[1], clock.lag, lag, LAG, "measured: first zeros of ω₂ of both", digits=9
            ),
            Readout.compare(names[2], clock.limit, lag, limit_tolerance, digits=9),
        )

    def plot(self, key: str, t: float) -> tuple[np.ndarray, ...]:
        n = max(2, int(np.searchsorted(self.times, t, side="right")))
        twin = self.log_p if self.twin_log_p is None else self.twin_log_p
        return self.times[:n], self.log_p[:n], self.log_theory[:n], twin[:n]


def build(settings: Settings) -> FlipModel:
    epsilon = float(settings["epsilon"])
    ratio = float(settings.get("twin-ratio", 0.0))
    J = moments()
    w0 = flip_initial_omega(epsilon, spin=SPIN)
    theory = flip_theory(J, w0)
    body = FreeRigidBody(J, w0, attitude_with_L_along_z(J, w0))
    twins = twin_clock(J, epsilon, epsilon / ratio, SPIN) if ratio > 0.0 else None
    last_first = theory.first_flip_time if twins is None else twins.second_flip
    span = max(theory.first_flip_time + PLOT_FLIPS * theory.time_between_flips, last_first)
    end = span + 0.25 * theory.time_between_flips
    flips = measure_flips(body, end)
    times = np.linspace(0.0, span, PLOT_SAMPLES)
    line = math.log10(math.sin(epsilon)) + theory.growth_rate * times / math.log(10.0)
    model = FlipModel(
        epsilon,
        body,
        theory,
        flips,
        growth_fit(body),
        times,
        _log_perturbation(body, times),
        np.minimum(line, 0.0),
    )
    if twins is None:
        return model
    w1 = flip_initial_omega(epsilon / ratio, spin=SPIN)
    twin = FreeRigidBody(J, w1, attitude_with_L_along_z(J, w1))
    return dataclasses.replace(
        model,
        twin=twin,
        twins=twins,
        twin_flips=measure_flips(twin, end),
        twin_log_p=_log_perturbation(twin, times),
    )


def ratio_of(clock: TwinClock) -> float:
    """ε/ε′ of the twins."""
    return math.exp(clock.limit * clock.growth_rate)


def _log_perturbation(body: FreeRigidBody, times: np.ndarray) -> np.ndarray:
    """log₁₀ sin(angle of ω from e₂) on ``times`` (N,)."""
    w = body.omega(times)
    p = np.hypot(w[:, 0], w[:, 2]) / np.linalg.norm(w, axis=1)
    return np.log10(np.maximum(p, 1e-300))


SPEC = SceneSpec(
    name="dzhanibekov",
    label="Scene: Dzhanibekov flip, theory vs measurement",
    source=(
        "[ACC91; LL76 §37; FM06 Theorem 7.3; DLMF 19.12.1]: a T-handle spun at ε from its "
        "intermediate axis flips every 2K(k)/λ → ln(16/(1−k²))/λ; the perturbation first grows "
        "like exp(σt), so the flip time grows like ln(1/ε). Dzhanibekov's wing nut, Salyut 7 "
        "(1985)."
    ),
    body="the bundled T-handle mesh (assets/bodies/t_handle.stl), moments by trimesh at "
    "uniform density, normalised to I₃ = 1",
    motion="FreeRigidBody(I, flip_initial_omega(ε, |ω₀| = 2)); flip_theory, measure_flips, "
    "measure_growth_rate",
    elements=CONSTRUCTION | {Element.POLHODE, Element.POLHODE_FULL},
    parts=(HANDLE, TWIN),
    controls=(
        Choice(
            "epsilon",
            "ε from the intermediate axis",
            EPSILON_OPTIONS,
            "1e-3",
            hint="The angle of ω₀ from e₂: each decade adds ln(10)/σ to the time between flips.",
            values=EPSILON_VALUES,
        ),
        Choice(
            "twin-ratio",
            "twin at ε′ (a second start)",
            TWIN_OPTIONS,
            "ε′ = ε/10",
            hint="A second handle, in bluish green, started at ε′: ten times closer to e₂ flips "
            "only "
            "ln(10)/σ later.",
            values=TWIN_RATIOS,
        ),
    ),
    shared=frozenset({Control.SPEED, Control.PLAYBACK, Control.TRAIL, Control.VISIBILITY}),
    readouts=(
        "ε (angle of ω₀ from e₂)",
        "time between flips, 2K(k)/λ",
        "… its asymptote ln(16/(1−k²))/λ",
        "first flip, (K ± δ)/λ",
        "growth rate σ",
        "1 − k²",
        *TWIN_READOUTS,
    ),
    plots=(
        PlotSpec(
            "perturbation",
            "perturbation off e₂ (log scale)",
            "t",
            "log₁₀ sin ∠(ω, e₂)",
            (
                ("motion", colors.PLOT_MEASURED),
                ("theory ε·exp(σt)", colors.PLOT_THEORY),
                ("twin at ε′", colors.PLOT_TWIN),
            ),
        ),
    ),
    build=build,
    draw=twin_drawing(HANDLE, TWIN, lambda: t_handle().mesh, colors.TWIN),
    speed=2.0,
    trail_points=2400,
    picture_time=8.0,
    table_settings=({}, {"epsilon": 1e-8}, {"epsilon": 1e-12}),
)
