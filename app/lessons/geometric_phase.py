"""Scene "geometric-phase": Montgomery's formula, the classroom example of a geometric (Berry)
phase [Mon91; LL76 §37].

What it shows: the energy ellipsoid of the presets' 3 × 2 × 1 box, its axes, ω, L and the
polhode, and riding with the body the cone that L/|L| sweeps in the body frame over one period
of ω, with the cap it cuts from a sphere around the ellipsoid, shaded. In space L stays put (the
vertical arrow); the body carries the cone round so that its rim always passes through L. After
one period P of ω the body has turned about L by ``2TP/|L| − Ω`` (mod 2π): a dynamic part,
proportional to the time, and a geometric part, minus the cap's solid angle, which depends only
on the cone. A dropdown moves D = |L|²/2T across the polhode family and ever closer to I₂ on
either side: the cap tends to a lune bounded by the two planes of the separatrix, and Ω to its
limit. A plot shows Ω(D) with that limit.

Readouts: D of the motion; the dynamic and geometric parts; Ω from its closed form (through the
complete elliptic integral of the third kind in Carlson's form) against a quadrature of
``∮ (1 − l·p) dα`` over ω(t); Montgomery's sum against the angle the attitude turns about L over
one period; Ω against its separatrix limit.

Physics: :func:`poinsot.physics.models.geometric_phase.solid_angle`, :func:`~.montgomery_phase`,
:func:`~.solid_angle_quadrature`, :func:`~.separatrix_solid_angles`, :func:`~.cone_of_L`.
"""

from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np
import viser

from poinsot.app.construction.geometry import Geometry
from poinsot.app.construction.palette import Entry
from poinsot.app.construction.view import View
from poinsot.app.lessons.support import colors
from poinsot.app.lessons.support.base import PartsDrawing, SceneModel
from poinsot.app.lessons.support.drawing import cone_mesh, segments
from poinsot.app.lessons.support.spec import (
    Canvas,
    Choice,
    Model,
    Part,
    PlotSpec,
    Readout,
    SceneSpec,
    Settings,
    number,
)
from poinsot.app.model.elements import Control, Element, Solid
from poinsot.app.model.presets import preset_by_key
from poinsot.physics import FreeRigidBody
from poinsot.physics.models.geometric_phase import (
    MontgomeryPhase,
    cone_of_L,
    montgomery_phase,
    separatrix_solid_angles,
    solid_angle,
    solid_angle_quadrature,
)

#: The body: the presets' 3 × 2 × 1 box, I₁ < I₂ < I₃.
BOX = preset_by_key("major")
INERTIA: tuple[float, float, float] = BOX.inertia
I1, I2, I3 = INERTIA
OMEGA_NORM = 1.2
#: The values of D offered: across both families and ever closer to I₂ on either side.
D_VALUES = (1.2, 1.5, 1.9, 1.99, 1.9999, I2 - 1e-8, I2 + 1e-8, 2.0001, 2.01, 2.1, 2.3, 2.55)
D_OPTIONS = tuple(
    f"I₂ {'−' if d < I2 else '+'} 1e{round(math.log10(abs(d - I2)))}"
    if abs(d - I2) < 2e-4
    else f"{d:g}"
    for d in D_VALUES
)
#: Rim points of the cone, rings of the cap, generators drawn.
RIM_POINTS = 192
CAP_RINGS = 24
GENERATORS = 16
#: The sphere the cap lies on, in units of the ellipsoid's largest semi-axis.
SPHERE_RADIUS = 1.12
PLOT_POINTS = 400
ROOT = "/space/body/phase"
CONE_NODE = f"{ROOT}/cone"
RIM_NODE = f"{ROOT}/rim"
CAP_NODE = f"{ROOT}/cap"
#: Tolerances: the closed form against a quadrature (Gauss-Kronrod to 1e-13), Montgomery's sum
#: against the attitude's turn (rounding of the exact motion), D read off the motion.
QUADRATURE = 1e-10
MONTGOMERY = 1e-12
EXACT = 1e-12


@dataclasses.dataclass(frozen=True)
class PhaseModel(SceneModel):
    """The body on the polhode of D, its cone of L, and Montgomery's split."""

    D: float
    body: FreeRigidBody
    phase: MontgomeryPhase
    quadrature: float
    rim: np.ndarray  # (n, 3) unit vectors L/|L| in the body frame
    pole: np.ndarray  # (3,)

    @property
    def solid(self) -> Solid | None:
        return None

    @functools.cached_property
    def rows(self) -> tuple[Readout, ...]:
        body, ph = self.body, self.phase
        w = body.omega(np.linspace(0.0, ph.period, 32, endpoint=False))
        m = w * np.asarray(INERTIA)
        D_motion = float(np.mean(np.sum(m * m, axis=1) / np.sum(m * w, axis=1)))
        major, minor = separatrix_solid_angles(INERTIA)
        limit = major if self.D > I2 else minor
        return (
            Readout.compare("D = |L|²/2T", self.D, D_motion, EXACT, "measured: |L|²/2T of ω(t)"),
            Readout("period P = 4K/λ", number(ph.period), "—"),
            Readout("dynamic part 2TP/|L|", f"{ph.dynamic:.9f} rad", "—"),
            Readout("geometric part −Ω", f"{ph.geometric:.9f} rad", "—"),
            absolute(
                "Ω: closed form vs quadrature",
                ph.solid_angle,
                self.quadrature,
                QUADRATURE,
                "measured: ∮ (1 − l·p) dα over ω(t) (scipy quad); gap in sr",
            ),
            absolute(
                "2TP/|L| − Ω vs the turn about L",
                ph.predicted,
                ph.predicted + ph.gap,
                MONTGOMERY,
                "measured: R(P) R(0)ᵀ about L, mod 2π; gap in rad",
            ),
            Readout(
                "Ω → separatrix limit",
                f"{limit:.9f}",
                f"{ph.solid_angle:.9f} ({ph.solid_angle - limit:+.1e})",
                "the lune between the separatrix planes: 4 atan √(I₁(I₃−I₂)/(I₃(I₂−I₁))) "
                "above I₂, minus the other lune below",
            ),
        )

    def plot(self, key: str, t: float) -> tuple[np.ndarray, ...]:
        return omega_curve()


def absolute(quantity: str, theory: float, measured: float, tolerance: float, note: str) -> Readout:
    """A row whose gap is the difference itself (an angle: radians or steradians)."""
    text = (number(theory, 12), f"{number(measured, 12)} ({measured - theory:+.1e})")
    return Readout.compare(quantity, theory, measured, tolerance, note, scale=1.0, text=text)


@functools.cache
def omega_curve() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Ω(D) across (I₁, I₃) and the separatrix limit on each side (the plot)."""
    D = np.linspace(I1, I3, PLOT_POINTS)
    D = D[D != I2]
    major, minor = separatrix_solid_angles(INERTIA)
    return D, solid_angle(INERTIA, D), np.where(D > I2, major, minor)


def build(settings: Settings) -> PhaseModel:
    D = float(settings["D"])
    body = FreeRigidBody.from_energy(INERTIA, D, omega_norm=OMEGA_NORM)
    rim, pole = cone_of_L(body, RIM_POINTS)
    return PhaseModel(D, body, montgomery_phase(body), solid_angle_quadrature(body), rim, pole)


def cap_mesh(rim: np.ndarray, pole: np.ndarray, rings: int) -> tuple[np.ndarray, np.ndarray]:
    """The cap of the unit sphere inside the closed ``rim`` (n, 3) around ``pole`` (3,): rings
    of normalised blends from the pole to the rim (every rim point lies within π/2 of the pole),
    as (vertices, faces)."""
    n = len(rim)
    s = np.linspace(0.0, 1.0, rings + 1)[1:, None, None]
    blend = (1.0 - s) * pole + s * rim[None]
    points = blend / np.linalg.norm(blend, axis=2, keepdims=True)
    vertices = np.vstack([pole[None], points.reshape(-1, 3)])
    i = np.arange(n)
    fan = np.stack([np.zeros(n, dtype=np.int64), 1 + i, 1 + (i + 1) % n], axis=1)
    quads = []
    for j in range(rings - 1):  # one band per ring: a loop over rings, not samples
        a, b = 1 + j * n + i, 1 + j * n + (i + 1) % n
        c, d = a + n, b + n
        quads += [np.stack([a, c, b], axis=1), np.stack([b, c, d], axis=1)]
    return vertices, np.concatenate([fan, *quads])


class PhaseDrawing(PartsDrawing):
    """The cone of L and its cap, in the body frame (they turn with the body)."""

    def __init__(self, canvas: Canvas) -> None:
        super().__init__(canvas)
        self.parts.frame("cone", ROOT)
        dummy = cone_mesh(np.eye(3))
        self.cone: viser.MeshHandle = self.parts.surface(
            "cone", CONE_NODE, dummy, colors.PHASE_CONE, colors.CONE_OPACITY
        )
        self.rim = self.parts.lines("cone", RIM_NODE, colors.PHASE_CONE, 2.5)
        self.cap: viser.MeshHandle = self.parts.surface(
            "cap", CAP_NODE, dummy, colors.PHASE_CAP, colors.PHASE_CAP_OPACITY
        )

    def fit(self, model: Model, geometry: Geometry | None) -> None:
        assert isinstance(model, PhaseModel)
        g = self.geometry(geometry)
        radius = SPHERE_RADIUS * g.scale * float(np.max(g.semi_axes))
        rim = model.rim * radius
        vertices, faces = cone_mesh(rim)
        self.cone.vertices = vertices.astype(np.float32)
        self.cone.faces = faces.astype(np.uint32)
        generators = np.zeros((GENERATORS, 2, 3), np.float32)
        generators[:, 1] = rim[:: RIM_POINTS // GENERATORS]
        self.rim.points = np.concatenate([segments(rim, closed=True), generators])
        cap_vertices, cap_faces = cap_mesh(model.rim, model.pole, CAP_RINGS)
        self.cap.vertices = (cap_vertices * radius).astype(np.float32)
        self.cap.faces = cap_faces.astype(np.uint32)


SPEC = SceneSpec(
    name="geometric-phase",
    label="Scene: the geometric phase (Montgomery)",
    source=(
        "[Mon91; LL76 §37]: after one period P of ω the body has turned about L by "
        "2TP/|L| − Ω (mod 2π), Ω the solid angle of the cone L sweeps in the body: a dynamic "
        "part and a geometric (Berry) phase. Ω in closed form through Π (Carlson's R_F, R_J)."
    ),
    body="the presets' homogeneous 3 × 2 × 1 box, I = (1, 2, 2.6)",
    motion="FreeRigidBody.from_energy(I, D, |ω₀| = 1.2); solid_angle, montgomery_phase, "
    "solid_angle_quadrature, separatrix_solid_angles",
    elements=frozenset(
        {
            Element.ELLIPSOID,
            Element.AXES,
            Element.OMEGA,
            Element.L,
            Element.POLHODE,
            Element.POLHODE_FULL,
        }
    ),
    parts=(
        Part(
            "cone",
            "cone of L in the body",
            (ROOT, CONE_NODE, RIM_NODE),
            (colors.PHASE_CONE,),
            legend=(Entry("cone of L (body)", (colors.PHASE_CONE,), "line"),),
        ),
        Part("cap", "its cap Ω (shaded)", (CAP_NODE,), surface=colors.PHASE_CAP, translucent=True),
    ),
    controls=(
        Choice(
            "D",
            "D = |L|²/2T, toward I₂",
            D_OPTIONS,
            "2.1",
            hint="Which polhode: D < I₂ = 2 circles the minor axis (Ω < 0), D > I₂ the major "
            "axis; close to I₂ the cap becomes a lune and Ω tends to its limit.",
            values=D_VALUES,
        ),
    ),
    shared=frozenset({Control.SPEED, Control.PLAYBACK, Control.TRAIL, Control.VISIBILITY}),
    readouts=(
        "D = |L|²/2T",
        "period P = 4K/λ",
        "dynamic part 2TP/|L|",
        "geometric part −Ω",
        "Ω: closed form vs quadrature",
        "2TP/|L| − Ω vs the turn about L",
        "Ω → separatrix limit",
    ),
    plots=(
        PlotSpec(
            "omega",
            "solid angle Ω of the cone of L",
            "D",
            "Ω (sr)",
            (("Ω(D), closed form", colors.PLOT_MEASURED), ("separatrix limit", colors.PLOT_THEORY)),
        ),
    ),
    build=build,
    draw=PhaseDrawing,
    view=View(position=(3.2, -4.2, 2.4), look_at=(0.0, 0.0, 0.2)),
    speed=1.0,
    trail_points=1600,
    picture_time=3.0,
    table_settings=({}, {"D": 1.5}, {"D": I2 + 1e-8}, {"D": I2 - 1e-8}),
)
