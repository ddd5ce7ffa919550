"""Scene "dzhanibekov": the intermediate-axis flip of a T-handle as a clock, theory against
measurement [ACC91; LL76 §37; FM06 Theorem 7.3; DLMF 19.12.1].

What it shows: the bundled T-handle (its moments from its own mesh through trimesh, uniform
density) spun at the angle ε from its intermediate axis e₂, in Poinsot's construction. The flips
come like a clock: every 2K(k)/λ, the first one at (K ± δ)/λ; the perturbation off e₂ first
grows like e^{σt}; and 2K/λ tends to ln(16/(1 − k²))/λ, so the time between flips grows like
ln(1/ε). A dropdown takes ε over the decades 1e-1 … 1e-12; the motion is exact at every one
(an integrator is not at 1e-12: ``python -m poinsot.physics.flip``). A plot shows
log₁₀ sin(angle of ω from e₂) against time with the theory's slope σ.

Readouts: the time between flips measured from the motion (the zeros of ω₂) against 2K(k)/λ and
against its asymptote; the first flip against (K ± δ)/λ; the growth rate fitted to the motion
against σ.

Physics: :func:`poinsot.physics.flip.flip_initial_omega`, :func:`~.flip_theory`,
:func:`~.measure_flips`, :func:`~.measure_growth_rate`; :func:`poinsot.app.bodies.bundled_body`
(the mesh and its moments).
"""

from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np

from poinsot.app.bodies import MeshBody, bundled_body
from poinsot.app.elements import Control, Element, Solid
from poinsot.app.scene import meshes
from poinsot.app.scene.batch import Frame
from poinsot.app.scene.geometry import Geometry, triple
from poinsot.app.scenes import colors
from poinsot.app.scenes.drawing import Parts
from poinsot.app.scenes.spec import (
    Canvas,
    Choice,
    Model,
    Part,
    PlotSpec,
    Readout,
    SceneSpec,
    Settings,
    number,
    relative,
)
from poinsot.physics import FreeRigidBody, attitude_with_L_along_z
from poinsot.physics.flip import (
    FlipTheory,
    GrowthFit,
    flip_initial_omega,
    flip_theory,
    measure_flips,
    measure_growth_rate,
)

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
class FlipModel:
    """The flipping T-handle at one ε, its theory and what is measured from its motion."""

    epsilon: float
    body: FreeRigidBody
    theory: FlipTheory
    flips: np.ndarray  # measured zeros of ω₂ over the plot's span
    growth: GrowthFit | None
    times: np.ndarray  # the plot's grid
    log_p: np.ndarray  # log₁₀ of the perturbation on it
    log_theory: np.ndarray  # log₁₀ ε + σ t / ln 10, capped at 0

    @property
    def solid(self) -> Solid | None:
        return None  # the handle is drawn from its own mesh (HandleDrawing)

    def readouts(self, t: float) -> tuple[Readout, ...]:
        return self.rows

    @functools.cached_property
    def rows(self) -> tuple[Readout, ...]:
        th, flips = self.theory, self.flips
        w0 = self.body.omega(0.0)
        angle = math.atan2(math.hypot(w0[0], w0[2]), abs(w0[1]))
        between = float(np.mean(np.diff(flips))) if len(flips) >= 2 else math.nan
        first = float(flips[0]) if len(flips) else math.nan
        sigma = self.growth.rate if self.growth is not None else math.nan
        sigma_note = (
            f"fit of ln p over {self.growth.e_folds:.1f} e-folds"
            if self.growth is not None
            else "no exponential stretch at this ε (needs ε ≤ 1e-4)"
        )
        return (
            Readout("ε (angle of ω₀ from e₂)", number(self.epsilon), relative(angle, self.epsilon)),
            Readout(
                "time between flips, 2K(k)/λ",
                number(th.time_between_flips, 9),
                relative(between, th.time_between_flips, 9),
                "measured: spacing of the zeros of ω₂",
            ),
            Readout(
                "… its asymptote ln(16/(1−k²))/λ",
                number(th.asymptotic_time_between_flips, 9),
                relative(between, th.asymptotic_time_between_flips, 9),
            ),
            Readout(
                "first flip, (K ± δ)/λ",
                number(th.first_flip_time, 9),
                relative(first, th.first_flip_time, 9),
            ),
            Readout(
                "growth rate σ", number(th.growth_rate), relative(sigma, th.growth_rate), sigma_note
            ),
            Readout("1 − k²", f"{th.complementary_parameter:.3e}", "—"),
        )

    def plot(self, key: str, t: float) -> tuple[np.ndarray, ...]:
        n = max(2, int(np.searchsorted(self.times, t, side="right")))
        return self.times[:n], self.log_p[:n], self.log_theory[:n]


def build(settings: Settings) -> FlipModel:
    epsilon = float(settings["epsilon"])
    J = moments()
    w0 = flip_initial_omega(epsilon, spin=SPIN)
    theory = flip_theory(J, w0)
    body = FreeRigidBody(J, w0, attitude_with_L_along_z(J, w0))
    span = theory.first_flip_time + PLOT_FLIPS * theory.time_between_flips
    flips = measure_flips(body, span + 0.25 * theory.time_between_flips)
    times = np.linspace(0.0, span, PLOT_SAMPLES)
    w = body.omega(times)
    p = np.hypot(w[:, 0], w[:, 2]) / np.linalg.norm(w, axis=1)
    log_p = np.log10(np.maximum(p, 1e-300))
    line = math.log10(math.sin(epsilon)) + theory.growth_rate * times / math.log(10.0)
    return FlipModel(
        epsilon, body, theory, flips, growth_fit(body), times, log_p, np.minimum(line, 0.0)
    )


class HandleDrawing:
    """The T-handle's own mesh, inside the ellipsoid (body frame)."""

    def __init__(self, canvas: Canvas) -> None:
        self.parts = Parts(canvas.api)
        shape = t_handle().mesh
        self.vertices = np.asarray(shape.vertices)
        self.mesh = self.parts.surface(
            "handle", HANDLE_NODE, (self.vertices, np.asarray(shape.faces)), colors.SOLID
        )

    def fit(self, model: Model, geometry: Geometry | None) -> None:
        if geometry is None:
            raise ValueError("the T-handle rides in the Poinsot construction")
        self.mesh.scale = triple(np.full(3, meshes.fit_scale(self.vertices, geometry.semi_axes)))

    def advance(self, t: float, frame: Frame | None) -> Frame:
        if frame is None:
            raise RuntimeError("the T-handle rides in the Poinsot construction")
        return frame

    def set_visible(self, part: str, visible: bool) -> None:
        self.parts.set_visible(part, visible)

    def remove(self) -> None:
        self.parts.remove()


SPEC = SceneSpec(
    name="dzhanibekov",
    label="Scene: Dzhanibekov flip, theory vs measurement",
    source=(
        "[ACC91; LL76 §37; FM06 Theorem 7.3; DLMF 19.12.1]: a T-handle spun at ε from its "
        "intermediate axis flips every 2K(k)/λ → ln(16/(1−k²))/λ; the perturbation first grows "
        "like e^{σt}, so the flip time grows like ln(1/ε). Dzhanibekov's wing nut, Salyut 7 (1985)."
    ),
    body="the bundled T-handle mesh (assets/bodies/t_handle.stl), moments by trimesh at "
    "uniform density, normalised to I₃ = 1",
    motion="FreeRigidBody(I, flip_initial_omega(ε, |ω₀| = 2)); flip_theory, measure_flips, "
    "measure_growth_rate",
    elements=frozenset(
        {
            Element.ELLIPSOID,
            Element.AXES,
            Element.PLANE,
            Element.CONTACT,
            Element.OMEGA,
            Element.L,
            Element.POLHODE,
            Element.POLHODE_FULL,
            Element.HERPOLHODE,
        }
    ),
    parts=(Part("handle", "T-handle (its mesh)", (HANDLE_NODE,), surface=colors.SOLID),),
    controls=(
        Choice(
            "epsilon",
            "ε from the intermediate axis",
            EPSILON_OPTIONS,
            "1e-3",
            hint="The angle of ω₀ from e₂: each decade adds ln(10)/σ to the time between flips.",
            values=EPSILON_VALUES,
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
    ),
    plots=(
        PlotSpec(
            "perturbation",
            "perturbation off e₂ (log scale)",
            "t",
            "log₁₀ sin(angle from e₂)",
            (("motion", colors.PLOT_MEASURED), ("ε e^{σt}", colors.PLOT_THEORY)),
        ),
    ),
    build=build,
    draw=HandleDrawing,
    speed=2.0,
    trail_points=2400,
    picture_time=8.0,
)
