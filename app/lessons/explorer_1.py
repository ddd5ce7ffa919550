"""Scene "explorer-1": energy dissipation at fixed |L| turns a spin about the minor axis into a
flat spin about the major axis [BG58; LL76 §37].

What it shows: Explorer 1 (1958), a long cylinder with whip antennas, spun about its long axis
(the axis of least moment). Its flexing antennas dissipated energy inside it while no torque
acted from outside, so |L| stayed fixed and the energy fell: D = |L|²/2T rose from near I₁
towards I₃, the spin widened into a tumble, crossed the separatrix D = I₂ and ended as a flat
spin about the major axis, end over end [BG58]. The stated law here is
dT/dt = −κ(2T − |L|²/I₃): 2T decays exponentially to its minimum |L|²/I₃ at this |L|.

Left, the satellite in space (L fixed and vertical, ω moving); right, the body-frame momentum
sphere |m| = |L| with the polhode family on it (coloured by kind): the point m(t) and its trace
sweep across the family, from the curves around the minor axis, over the separatrix, onto
those around the major axis (the energy ellipsoid Σ mᵢ²/Iᵢ = 2T(t) that cuts the sphere along
the current curve shrinks meanwhile; it is left out: at the start it dwarfs the sphere). A
plot shows D(t), the law against the motion, with I₂ marked.

Readouts: the separatrix crossing t* of the law against the first time the motion's D reaches
I₂; |L| kept and L fixed in space (measured on the motion shown); D and the family now; the
flatness of the final spin.

Physics: :class:`poinsot.physics.models.dissipation.EnergySink` (the law, and the motion, exact in
short windows), :func:`poinsot.physics.models.family.polhode_family` (the family on the sphere); the
moments of the drawn mesh by trimesh (:func:`poinsot.app.model.bodies.body_from_mesh`).
"""

from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np
import trimesh

from poinsot.app.construction.geometry import Geometry, triple
from poinsot.app.construction.palette import Entry
from poinsot.app.construction.sampled.frames import wxyz_from_xyzw
from poinsot.app.construction.view import View
from poinsot.app.lessons.momentum import (
    SPHERE_RADIUS,
    MomentumPicture,
    extent,
    momentum_nodes,
    momentum_rows,
)
from poinsot.app.lessons.support import colors
from poinsot.app.lessons.support.base import TabulatedDrawing, TabulatedModel
from poinsot.app.lessons.support.drawing import THIN_ARROW, arrow_points
from poinsot.app.lessons.support.spec import (
    Canvas,
    Choice,
    Model,
    Part,
    PlotSpec,
    Readout,
    SceneSpec,
    Settings,
)
from poinsot.app.lessons.support.tabulated import Player, Table
from poinsot.app.model.bodies import MeshBody, body_from_mesh
from poinsot.app.model.elements import Control
from poinsot.physics import Regime, attitude_with_L_along_z
from poinsot.physics.core import rotations
from poinsot.physics.models.dissipation import EnergySink
from poinsot.physics.models.family import PolhodeCurve, family_D_values, polhode_family

#: The satellite: a cylinder along its axis 1 with one pair of whip antennas along axis 2.
CYLINDER = (2.0, 0.12)  # length, radius
ANTENNA = (0.8, 0.02)  # length of each, radius
#: The initial spin [rad/time] and its small tilt from the long axis [rad].
SPIN = 3.0
TILT = math.radians(0.5)
#: The dissipation rates offered [1/time], and how long after t* the motion runs: a few 1/κ.
KAPPAS = ("0.05", "0.1", "0.2", "0.5")
AFTER_CROSSING = 2.5
#: Rows of the table per time unit; plot samples.
ROWS_PER_TIME = 60
PLOT_SAMPLES = 500
#: Display: the satellite's length, the ω arrow's longest length, the L arrow, the sphere's place.
SATELLITE_LENGTH = 1.6
OMEGA_LENGTH = 1.0
OMEGA_MIN = 0.35
L_LENGTH = 1.3
MOMENTUM_OFFSET = (2.9, 0.0, 0.1)
MOMENTUM_TITLE = "body frame: m(t) on the sphere |m| = |L|"
MOMENTUM_TURN = math.radians(-40.0)
ROOT = "/space"
SATELLITE_NODE = f"{ROOT}/body/satellite"
OMEGA_NODE = f"{ROOT}/satellite_omega"
L_NODE = f"{ROOT}/satellite_L"
MOMENTUM_ROOT = f"{ROOT}/momentum"
#: Tolerances of the readouts: |m| and L are those of exact motions joined end to end (rounding
#: only); the final spin is flat to within this fraction of G after AFTER_CROSSING/κ.
EXACT = 1e-10
FLAT = 1e-2


@functools.cache
def satellite() -> MeshBody:
    """Explorer 1, simplified: the mesh measured by trimesh in its principal frame (axis 1 the
    cylinder's, I₁ < I₂ < I₃: the antennas lie along axis 2 and raise I₃ above I₂)."""
    length, radius = CYLINDER
    reach, thickness = ANTENNA
    body = trimesh.creation.cylinder(
        radius=radius, segment=[[-length / 2, 0, 0], [length / 2, 0, 0]], sections=64
    )
    antennas = [
        trimesh.creation.cylinder(
            radius=thickness, segment=[[0, s * radius, 0], [0, s * (radius + reach), 0]]
        )
        for s in (1.0, -1.0)
    ]
    mesh = trimesh.util.concatenate([body, *antennas])
    assert isinstance(mesh, trimesh.Trimesh)
    return body_from_mesh(mesh, "Explorer 1 (simplified)")


def moments() -> np.ndarray:
    return np.asarray(satellite().ratios, dtype=float)


@dataclasses.dataclass(frozen=True)
class SinkModel(TabulatedModel):
    sink: EnergySink
    times: np.ndarray  # (N,) the table's grid
    omega: np.ndarray  # (N, 3) body frame
    quaternions: np.ndarray  # (N, 4) scalar-last
    D_motion: np.ndarray  # (N,) |L|²/2T of the motion
    family: list[PolhodeCurve]

    def readouts(self, t: float) -> tuple[Readout, ...]:
        sink, k = self.sink, self.row(t)
        now = float(self.times[k])
        law = float(sink.D(now))
        regime = sink.body_at(now).regime
        expected = Regime.MINOR_AXIS if law < sink.inertia[1] else Regime.MAJOR_AXIS
        # Within a window the motion keeps the law's D of the window's start.
        staircase = abs(law - float(sink.D(max(now - sink.window, 0.0)))) / law
        return (
            self.rows[0],
            Readout.compare("D now", law, float(self.D_motion[k]), max(staircase, EXACT)),
            Readout("family now", _kind(expected), _kind(regime)),
            *self.rows[1:],
        )

    @functools.cached_property
    def rows(self) -> tuple[Readout, ...]:
        sink = self.sink
        crossed = np.flatnonzero(self.D_motion >= sink.inertia[1])
        measured = float(self.times[crossed[0]]) if crossed.size else math.nan
        m = self.omega * sink.inertia
        L = rotations.rotate(self.quaternions, m)
        kept = float(np.abs(np.linalg.norm(m, axis=1) / sink.G - 1.0).max())
        fixed = float(np.linalg.norm(L - L[0], axis=1).max()) / sink.G
        flat = abs(float(m[-1, 2])) / sink.G
        return (
            Readout.compare(  # the motion's D is the law's of a window's start, on the grid
                "separatrix crossing t*",
                sink.crossing_time,
                measured,
                (sink.window + self.dt) / sink.crossing_time,
                f"measured: first time the motion's D reaches I₂ (windows of {sink.window:.3g})",
            ),
            Readout("|L| kept: max ||m|/G − 1|", "0", f"{kept:.1e}", gap=kept, tolerance=EXACT),
            Readout(
                "L fixed in space: max |L − L₀|/G", "0", f"{fixed:.1e}", gap=fixed, tolerance=EXACT
            ),
            Readout.compare(
                "flat spin at the end: |m₃|/G", 1.0, flat, FLAT, text=("→ 1", f"{flat:.6f}")
            ),
        )

    def plot(self, key: str, t: float) -> tuple[np.ndarray, ...]:
        times, motion = self.plotted(t, PLOT_SAMPLES, self.D_motion)
        return times, self.sink.D(times), motion, np.full(len(times), self.sink.inertia[1])


def _kind(regime: Regime) -> str:
    return {Regime.MINOR_AXIS: "minor-axis family", Regime.MAJOR_AXIS: "major-axis family"}.get(
        regime, regime.value
    )


def build(settings: Settings) -> SinkModel:
    return sink_model(float(settings["kappa"]))


@functools.lru_cache(maxsize=len(KAPPAS))
def sink_model(kappa: float) -> SinkModel:
    """The model for one κ, built once per server (the energy sink's windows take a good part
    of a second; every browser that picks that κ shares the same read-only model)."""
    J = moments()
    w0 = SPIN * np.array([math.cos(TILT), 0.6 * math.sin(TILT), 0.8 * math.sin(TILT)])
    crossing = EnergySink(J, w0, kappa, 1.0).crossing_time  # the law only: one window
    t_end = max(crossing, 0.0) + AFTER_CROSSING / kappa
    sink = EnergySink(J, w0, kappa, t_end, attitude0=attitude_with_L_along_z(J, w0))
    times = np.arange(math.floor(t_end * ROWS_PER_TIME)) / ROWS_PER_TIME
    omega, attitude = sink.state(times)
    D_motion = sink.G**2 / np.sum(J * omega * omega, axis=1)
    family = polhode_family(J, family_D_values(J, 4), momentum=sink.G)
    return SinkModel(sink, times, omega, attitude.as_quat(), D_motion, family)


class SatelliteDrawing(TabulatedDrawing):
    """The satellite, ω and L in space; the momentum sphere with the family and the trace of
    m(t) beside it."""

    contact = "trace"

    def __init__(self, canvas: Canvas) -> None:
        super().__init__(canvas)
        parts = self.parts
        shape = satellite().mesh
        vertices = np.asarray(shape.vertices) * (SATELLITE_LENGTH / CYLINDER[0])
        parts.surface(
            "satellite", SATELLITE_NODE, (vertices, np.asarray(shape.faces)), colors.SOLID
        )
        self.arrows["omega"] = parts.arrow("omega", OMEGA_NODE, colors.OMEGA, THIN_ARROW)
        self.L = parts.arrow("L", L_NODE, colors.L, THIN_ARROW)
        self.L.points = arrow_points((0.0, 0.0, 0.0), (0.0, 0.0, L_LENGTH))
        self.picture = MomentumPicture(
            parts,
            "momentum",
            MOMENTUM_ROOT,
            MOMENTUM_OFFSET,
            title=MOMENTUM_TITLE,
            family=True,
            trace_points=4000,
            ellipsoid=False,
            turn=MOMENTUM_TURN,
        )

    def fit(self, model: Model, geometry: Geometry | None) -> None:
        assert isinstance(model, SinkModel)
        sink, picture = model.sink, self.picture
        J = sink.inertia
        picture.fit(sink.G, model.family)
        # ω slows down tenfold from the spin to the flat spin: the arrow keeps a visible length
        # (OMEGA_MIN of the longest) and grows with |ω|.
        speed = np.linalg.norm(model.omega, axis=1)
        length = OMEGA_LENGTH * (OMEGA_MIN + (1.0 - OMEGA_MIN) * speed / float(speed.max()))
        arrows = np.zeros((len(model.times), 1, 2, 3), np.float32)
        space = rotations.rotate(model.quaternions, model.omega)
        arrows[:, 0, 1] = space * (length / speed)[:, None]
        scale = SPHERE_RADIUS / sink.G
        table = Table(
            1.0 / ROWS_PER_TIME,
            wxyz_from_xyzw(model.quaternions),
            model.omega,
            {"trace": (model.omega * J * scale).astype(np.float32)},
            {"omega": arrows},
        )
        self.player = Player(table, {"trace": picture.trace} if picture.trace else {})

    def show_row(self, table: Table, row: int) -> None:
        self.picture.marker.position = triple(table.points["trace"][row])


SPEC = SceneSpec(
    name="explorer-1",
    label="Scene: Explorer 1, energy sink to a flat spin",
    source=(
        "[BG58] Explorer 1 (1958): spun about its long axis, its whip antennas dissipated "
        "energy at fixed |L|, so D = |L|²/2T rose from I₁ to I₃: the spin crossed the separatrix "
        "and ended flat, about the major axis (the energy-sink argument). Law here: "
        "dT/dt = −κ(2T − |L|²/I₃). Polhodes on the sphere [LL76 §37]."
    ),
    body="a cylinder 2 long, radius 0.12, with two whip antennas 0.8 long (Explorer 1 "
    "simplified), moments by trimesh, normalised to I₃ = 1",
    motion="EnergySink(I, ω₀ = 3 at 0.5° from e₁, κ, t* + 2.5/κ): exact in short windows; "
    "polhode_family on the sphere |m| = G",
    elements=frozenset(),
    parts=(
        Part("satellite", "the satellite", (SATELLITE_NODE,), surface=colors.SOLID),
        Part(
            "omega",
            "ω (its direction)",
            (OMEGA_NODE,),
            surface=colors.OMEGA,
            legend=(Entry("ω (its direction)", (colors.OMEGA,), "arrow"),),
        ),
        Part(
            "L",
            "L (fixed)",
            (L_NODE,),
            surface=colors.L,
            legend=(Entry("L (fixed)", (colors.L,), "arrow"),),
        ),
        Part(
            "momentum",
            "momentum sphere and family",
            momentum_nodes(MOMENTUM_ROOT, family=True, current=False, trace=True, ellipsoid=False),
            (colors.MINOR_FAMILY, colors.MAJOR_FAMILY, colors.SEPARATRIX, colors.MOMENTUM_TRACE),
            trails=(f"{MOMENTUM_ROOT}/trace",),
            surface=colors.SPHERE,
            legend=momentum_rows(family=True, current=False, trace=True, ellipsoid=False),
        ),
    ),
    controls=(
        Choice(
            "kappa",
            "dissipation rate κ",
            KAPPAS,
            "0.1",
            hint="dT/dt = −κ(2T − |L|²/I₃): the larger κ, the sooner the flat spin.",
            values=tuple(float(k) for k in KAPPAS),
        ),
    ),
    shared=frozenset({Control.SPEED, Control.PLAYBACK}),
    readouts=(
        "separatrix crossing t*",
        "D now",
        "family now",
        "|L| kept: max ||m|/G − 1|",
        "L fixed in space: max |L − L₀|/G",
        "flat spin at the end: |m₃|/G",
    ),
    plots=(
        PlotSpec(
            "D",
            "D = |L|²/2T rising to I₃",
            "t",
            "D",
            (
                ("law", colors.PLOT_THEORY),
                ("motion", colors.PLOT_MEASURED),
                ("I₂ (separatrix)", colors.PLOT_LEVEL),
            ),
        ),
    ),
    build=build,
    draw=SatelliteDrawing,
    view=View(position=(2.95, -7.8, 3.1), look_at=(1.45, 0.0, 0.1)),
    beside=(extent(MOMENTUM_OFFSET, MOMENTUM_TITLE),),
    speed=2.0,
    picture_time=48.0,
)
