"""Scene "tennis-racket": the racquet's twist, its head turning by almost π while its handle
makes one turn about L [VMS17; VMS20; ACC91].

What it shows: the bundled racquet mesh (its handle along e₁, its head's normal along e₃) tossed
at the angle ε from its middle axis e₂, inside its energy ellipsoid, with its axes, ω and L.
Around the first flip the scene marks the window over which the handle makes one full turn about
L, and draws in space the path of the handle's tip (a circle, nearly) and of the head's normal
(from one side to the other: the faces swap). Controls: the moments (the mesh's at uniform
density, Brody's measured racquet, and three other ratios down to an ideal racket with I₁ → 0)
and the start's offset ε.

Readouts: how far the mesh's moments are from Brody's; ε measured from ω₀; the handle's turn
over the window (one turn, from the attitude); the head's twist Δψ read off the attitude against
the separatrix formula 2 atan(sinh τ₁/c₃), within its stated accuracy (1 − k²) cosh²τ₁; the
defect π − Δψ against the formula's bounds; τ₁ against σ times half the window.

Physics: :func:`poinsot.physics.models.racket.separatrix_twist` (the formula and its bounds, derived
in its docstring: the papers' own text was not available to us), :func:`~.measure_twist` (the
window and the twist from the exact attitude);
:func:`poinsot.physics.models.flip.flip_initial_omega`; :data:`poinsot.app.model.bodies.MEASURED`
(Brody's moments) and :func:`~.bundled_body` (the mesh).
"""

from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np

from poinsot.app.construction import meshes
from poinsot.app.construction.geometry import Geometry
from poinsot.app.construction.palette import Entry
from poinsot.app.construction.view import View
from poinsot.app.lessons.support import colors
from poinsot.app.lessons.support.base import OwnSolid, RidingMesh, SceneModel
from poinsot.app.lessons.support.drawing import segments
from poinsot.app.lessons.support.spec import (
    Canvas,
    Choice,
    Model,
    Part,
    Readout,
    SceneSpec,
    Settings,
)
from poinsot.app.model.bodies import MEASURED, MeshBody, bundled_body
from poinsot.app.model.elements import Control, Element
from poinsot.physics import FreeRigidBody, attitude_with_L_along_z
from poinsot.physics.models.flip import flip_initial_omega
from poinsot.physics.models.racket import (
    LIMIT_ACCURACY,
    TwistMeasurement,
    TwistTheory,
    measure_twist,
    separatrix_twist,
)

BRODY = MEASURED["brody"]
MESH_OPTION = "the mesh (uniform density)"
BRODY_OPTION = "Brody's racquet (measured)"
#: The moments offered, I₁ : I₂ : I₃ (None: the mesh's own).
MOMENTS: dict[str, tuple[float, float, float] | None] = {
    MESH_OPTION: None,
    BRODY_OPTION: BRODY.ratios,
    "ideal racket 0.01 : 0.99 : 1": (0.01, 0.99, 1.0),
    "thick 0.2 : 0.8 : 1": (0.2, 0.8, 1.0),
    "box 0.33 : 0.67 : 1": (1.0 / 3.0, 2.0 / 3.0, 1.0),
}
EPSILONS = (1e-1, 3e-2, 1e-2, 1e-3, 1e-5)
EPSILON_OPTIONS = tuple(f"{e:g}" for e in EPSILONS)
#: |ω₀| [rad/time]; ω₀ is tilted from e₂ towards the head's normal e₃.
SPIN = 2.0
TILT = 0.5 * math.pi
PATH_POINTS = 400
RACQUET_NODE = "/space/body/racquet"
HANDLE_PATH_NODE = "/space/handle_path"
NORMAL_PATH_NODE = "/space/normal_path"
RACQUET = Part("racquet", "racquet (its mesh)", (RACQUET_NODE,), surface=colors.SOLID)
EXACT = 1e-12


@functools.cache
def racquet() -> MeshBody:
    """The bundled racquet mesh, measured once (handle e₁, head's normal e₃)."""
    return bundled_body("racquet")


def ratios_text(ratios: tuple[float, float, float]) -> str:
    return " : ".join(f"{r:.3g}" for r in ratios)


def mesh_against_brody() -> Readout:
    """How far the mesh's moments are from Brody's (ratios to I₃)."""
    mesh, brody = racquet().ratios, BRODY.ratios
    gaps = [m / b - 1.0 for m, b in zip(mesh[:2], brody[:2], strict=True)]
    return Readout(
        "mesh vs Brody's moments",
        f"{ratios_text(brody)} (Brody)",
        f"{ratios_text(mesh)} (mesh)",
        f"I₁/I₃ {gaps[0]:+.1%}, I₂/I₃ {gaps[1]:+.1%} from Brody's Wilson T-2000 [ACC91]",
    )


@dataclasses.dataclass(frozen=True)
class RacketModel(OwnSolid, SceneModel):
    """One toss: the body, the separatrix formula and what the attitude shows."""

    inertia: tuple[float, float, float]
    epsilon: float
    body: FreeRigidBody
    theory: TwistTheory
    measured: TwistMeasurement
    handle_path: np.ndarray  # (n, 3) R(t) e₁ over the window, space frame
    normal_path: np.ndarray  # (n, 3) R(t) e₃

    @property
    def accuracy(self) -> float:
        """The formula's stated accuracy for this toss [rad]."""
        tau = float(self.theory.tau)
        return LIMIT_ACCURACY * self.body.complementary_parameter * math.cosh(tau) ** 2

    @functools.cached_property
    def rows(self) -> tuple[Readout, ...]:
        th, m, body = self.theory, self.measured, self.body
        w0 = body.omega(0.0)
        angle = math.atan2(math.hypot(w0[0], w0[2]), abs(w0[1]))
        twist, low, high = float(th.twist), float(th.defect_low), float(th.defect_high)
        outside = max(low - m.defect, m.defect - high, 0.0)
        sigma = float(th.ratio) * float(np.linalg.norm(body.angular_momentum)) / self.inertia[1]
        half = 0.5 * sigma * (m.end - m.start)
        return (
            Readout("moments I₁ : I₂ : I₃", ratios_text(self.inertia), "—"),
            mesh_against_brody(),
            Readout.compare("ε (angle of ω₀ from e₂)", self.epsilon, angle, EXACT),
            Readout.compare(
                "handle's turn about L",
                2.0 * math.pi,
                m.handle_turn,
                EXACT,
                f"over t = {m.start:.4f} … {m.end:.4f}, around the flip at {m.flip:.4f}",
                text=("360°", f"{math.degrees(m.handle_turn):.9f}°"),
            ),
            _angle_row("head's twist Δψ", twist, m.twist, self.accuracy),
            Readout(
                "defect π − Δψ within the bounds",
                f"{math.degrees(low):.4f}° … {math.degrees(high):.4f}°",
                f"{math.degrees(m.defect):.4f}°",
                "bounds of the separatrix formula; gap: how far outside, in rad",
                gap=outside,
                tolerance=self.accuracy,
            ),
            Readout.compare(
                "τ₁ = σ × half the window",
                float(th.tau),
                half,
                self.accuracy,
                "measured: the window of one turn, read off the attitude",
                digits=9,
            ),
            Readout("1 − k²", f"{body.complementary_parameter:.3e}", "—"),
        )


def _angle_row(quantity: str, theory: float, measured: float, tolerance: float) -> Readout:
    """A row of two angles [rad] shown in degrees, its gap the difference in rad."""
    text = (
        f"{math.degrees(theory):.6f}°",
        f"{math.degrees(measured):.6f}° ({measured - theory:+.1e})",
    )
    note = "theory: the separatrix formula 2 atan(sinh τ₁/c₃); gap in rad, within (1 − k²) cosh²τ₁"
    return Readout.compare(quantity, theory, measured, tolerance, note, scale=1.0, text=text)


def build(settings: Settings) -> RacketModel:
    choice = str(settings["moments"])
    ratios = MOMENTS[choice] or racquet().ratios
    epsilon = float(settings["epsilon"])
    w0 = flip_initial_omega(epsilon, spin=SPIN, azimuth=TILT)
    body = FreeRigidBody(ratios, w0, attitude_with_L_along_z(ratios, w0))
    measured = measure_twist(body)
    t = np.linspace(measured.start, measured.end, PATH_POINTS)
    R = body.attitude(t)
    return RacketModel(
        ratios,
        epsilon,
        body,
        separatrix_twist(ratios),
        measured,
        R.apply(np.array([1.0, 0.0, 0.0])),
        R.apply(np.array([0.0, 0.0, 1.0])),
    )


class RacketDrawing(RidingMesh):
    """The racquet inside the ellipsoid, and the paths of its handle and head normal in space."""

    def __init__(self, canvas: Canvas) -> None:
        super().__init__(canvas, RACQUET, racquet().mesh)
        self.handle = self.parts.lines("paths", HANDLE_PATH_NODE, colors.HANDLE_PATH, 4.0)
        self.normal = self.parts.lines("paths", NORMAL_PATH_NODE, colors.NORMAL_PATH, 4.0)

    def fit(self, model: Model, geometry: Geometry | None) -> None:
        super().fit(model, geometry)
        assert isinstance(model, RacketModel)
        semi_axes = self.geometry(geometry).semi_axes
        reach = meshes.fit_scale(self.vertices, semi_axes) * float(
            np.max(np.abs(self.vertices[:, 0]))
        )
        self.handle.points = segments(1.08 * reach * model.handle_path, closed=False)
        self.normal.points = segments(1.0 * reach * model.normal_path, closed=False)


SPEC = SceneSpec(
    name="tennis-racket",
    label="Scene: the tennis racket's twist",
    source=(
        "[VMS17; VMS20; ACC91]: toss a racquet about its middle axis so that the handle makes "
        "one full turn: the head turns by almost π about the handle and the faces swap. The "
        "twist against our separatrix formula 2 atan(sinh τ₁/c₃) and its bounds."
    ),
    body="the bundled racquet mesh (assets/bodies/tennis_racquet.stl), moments by trimesh at "
    "uniform density, or Brody's measured moments 0.00121, 0.01638, 0.01748 kg m² [ACC91]",
    motion="FreeRigidBody(I, flip_initial_omega(ε, 2, β = π/2)); measure_twist, separatrix_twist",
    elements=frozenset(
        {Element.ELLIPSOID, Element.AXES, Element.OMEGA, Element.L, Element.POLHODE}
    ),
    parts=(
        RACQUET,
        Part(
            "paths",
            "handle's and head normal's paths",
            (HANDLE_PATH_NODE, NORMAL_PATH_NODE),
            (colors.HANDLE_PATH, colors.NORMAL_PATH),
            legend=(
                Entry("the handle's path", (colors.HANDLE_PATH,), "line"),
                Entry("head normal's path", (colors.NORMAL_PATH,), "line"),
            ),
        ),
    ),
    controls=(
        Choice(
            "moments",
            "moments I₁ : I₂ : I₃",
            tuple(MOMENTS),
            MESH_OPTION,
            hint="The smaller I₁ against I₂ ≈ I₃, the more perfect the twist.",
        ),
        Choice(
            "epsilon",
            "ε from the middle axis",
            EPSILON_OPTIONS,
            "0.01",
            hint="The angle of ω₀ from e₂: the formula holds in the limit ε → 0.",
            values=EPSILONS,
        ),
    ),
    shared=frozenset({Control.SPEED, Control.PLAYBACK, Control.TRAIL, Control.VISIBILITY}),
    readouts=(
        "moments I₁ : I₂ : I₃",
        "mesh vs Brody's moments",
        "ε (angle of ω₀ from e₂)",
        "handle's turn about L",
        "head's twist Δψ",
        "defect π − Δψ within the bounds",
        "τ₁ = σ × half the window",
        "1 − k²",
    ),
    plots=(),
    build=build,
    draw=lambda canvas: RacketDrawing(canvas),
    view=View(position=(1.2, -1.75, 0.85), look_at=(0.0, 0.0, 0.12)),
    speed=1.0,
    trail_points=1600,
    picture_time=4.9,  # just after the default toss's window (t = 1.64 … 4.86)
    table_settings=({}, {"moments": BRODY_OPTION}, {"epsilon": 1e-3}),
)
