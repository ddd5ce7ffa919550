"""Scene "gyroscope-torque": a symmetric body under a constant torque fixed in the body
[FM06 §7.11, Eqs. 7.85-7.98; HLW06 §IV.7].

What it shows: the presets' homogeneous disc (I₁ = I₂ = J, I₃ = J₃) spinning about its axis
while a torque of constant size M acts along its own axis x₂ (the red arrow, turning with the
body). Euler's equations with the torque give ω(t) in closed form: ω₃ stays constant and
(ω₁ − ω₁*, ω₂) turns uniformly at ν = ((J₃ − J)/J) ω₃ about the nutation centre
ω₁* = −M/((J₃ − J) ω₃) [FM06 Eqs. 7.88-7.95]. The attitude has no closed form: it is integrated
from that ω(t) by the fourth-order Magnus method, with an error estimate from a run with half
the steps (Richardson). On average the axis moves towards the torque at the rate
M/((J₃ − J) ω₃) [FM06 Eq. 7.98], the green arrow at the axis's tip; the yellow trace is the
path of the axis's tip in space. L is not conserved here, so there is no invariable plane.

Readouts: the drift rate against the mean velocity of the axis measured from the integrated
attitude (and the drift across the torque, 0 in theory); the nutation centre against ω
recovered from the integrated attitude (ω = 2 Im(q* q̇), fourth-order differences of the
quaternions drawn), and the attitude's error estimate at the time shown. The plot: log₁₀ of the
error estimate and of the mismatch between that recovered ω and the closed-form ω.

Physics: :class:`poinsot.physics.models.gyroscope.Gyroscope` (``omega``, ``attitude``,
``measure_drift``), :mod:`poinsot.physics.core.rotations` (products of the drawn quaternions).
"""

from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np

from poinsot.app.construction import meshes
from poinsot.app.construction.geometry import Geometry
from poinsot.app.construction.palette import Entry
from poinsot.app.construction.sampled.frames import wxyz_from_xyzw
from poinsot.app.construction.view import View
from poinsot.app.lessons.support import colors
from poinsot.app.lessons.support.base import TabulatedDrawing, TabulatedModel
from poinsot.app.lessons.support.drawing import THIN_ARROW, arrow_points
from poinsot.app.lessons.support.spec import (
    Canvas,
    Model,
    Part,
    PlotSpec,
    Readout,
    SceneSpec,
    Settings,
    Slider,
    number,
)
from poinsot.app.lessons.support.tabulated import Player, Table
from poinsot.app.model.elements import Control
from poinsot.app.model.presets import preset_by_key
from poinsot.physics.core import rotations
from poinsot.physics.models.gyroscope import AttitudeRun, DriftMeasurement, Gyroscope

#: The body: the presets' homogeneous disc (its moments checked against trimesh by
#: tests/app/test_parts.py); J transverse, J₃ axial.
DISC = preset_by_key("oblate")
J, _, J3 = DISC.inertia
#: Rows of the table per time unit, and its span: whole nutation periods, at least MIN_SPAN.
ROWS_PER_TIME = 120
NUTATIONS = 8
MIN_SPAN, MAX_SPAN = 30.0, 120.0
#: Error plot samples, and the floor of its log scale (rounding).
PLOT_SAMPLES = 600
ERROR_FLOOR = 1e-16
#: Display sizes: the disc's radius, the half-length of the drawn axis, the ω arrow's longest
#: length, and the time over which the drift arrow shows the axis's mean displacement.
DISC_RADIUS = 0.75
AXIS_LENGTH = 1.15
OMEGA_LENGTH = 1.0
DRIFT_TIME = 1.0
ROOT = "/space"
DISC_NODE = f"{ROOT}/body/disc"
AXIS_NODE = f"{ROOT}/body/symmetry_axis"
TORQUE_NODE = f"{ROOT}/body/torque"
DRIFT_NODE = f"{ROOT}/body/drift"
PATH_NODE = f"{ROOT}/axis_path"
OMEGA_NODE = f"{ROOT}/gyro_omega"
#: Tolerances of the readouts: the attitude is integrated by Magnus-4 (error estimate below
#: ATTITUDE), the drift is its mean velocity over whole nutation periods, the nutation centre a
#: circle through ω read off the drawn quaternions by fourth-order differences.
ATTITUDE = 1e-9
DRIFT = 1e-8
CENTRE = 1e-6


def omega_from_attitude(quaternions: np.ndarray, dt: float) -> np.ndarray:
    """Body-frame ω (N - 4, 3) read off attitudes (N, 4) (scalar-last, continuous in sign)
    sampled every ``dt``, at the rows 2 … N - 3: ``ω = 2 Im(q* ⊗ q̇)`` with q̇ from
    fourth-order central differences."""
    q = np.asarray(quaternions, dtype=float)
    dq = (q[:-4] - 8.0 * q[1:-3] + 8.0 * q[3:-1] - q[4:]) / (12.0 * dt)
    conj = q[2:-2] * np.array([-1.0, -1.0, -1.0, 1.0])
    return 2.0 * rotations.multiply(conj, dq)[:, :3]


def circle_center(points: np.ndarray) -> tuple[float, float]:
    """The centre of the circle through points (N, 2), by linear least squares on
    ``x² + y² + a x + b y + c = 0`` (exact for points on a circle, whatever arc they cover)."""
    x, y = points[:, 0], points[:, 1]
    system = np.stack([x, y, np.ones_like(x)], axis=1)
    (a, b, _), *_ = np.linalg.lstsq(system, -(x * x + y * y), rcond=None)
    return -0.5 * float(a), -0.5 * float(b)


@dataclasses.dataclass(frozen=True)
class GyroModel(TabulatedModel):
    gyro: Gyroscope
    times: np.ndarray  # (N,) the table's grid
    run: AttitudeRun
    omega: np.ndarray  # (N, 3) closed form
    mismatch: np.ndarray  # (N,) |ω from the attitude - ω| / |ω| (the two end rows repeated)
    drift: DriftMeasurement

    def readouts(self, t: float) -> tuple[Readout, ...]:
        g = self.gyro
        error = float(self.run.error_estimate[self.row(t)])
        return (
            *self.rows,
            Readout(
                "attitude error estimate now",
                "—",
                f"{error:.1e} rad",
                f"Magnus-4, {self.run.steps} steps against half as many (Richardson)",
                gap=error,
                tolerance=ATTITUDE,
            ),
            Readout("nutation period 2π/|ν|", number(g.nutation_period), "—"),
        )

    @functools.cached_property
    def rows(self) -> tuple[Readout, ...]:
        g, d = self.gyro, self.drift
        recovered_center = circle_center(self.recovered()[:, :2])[0]
        mismatch = float(self.mismatch.max())
        return (
            Readout.compare(
                "drift rate M/((J₃−J)ω₃)",
                g.drift_rate,
                d.along_torque,
                DRIFT,
                f"measured: mean velocity of the axis over {d.periods} nutation periods",
                digits=9,
            ),
            Readout.compare(  # in units of the drift along the torque
                "drift across the torque",
                0.0,
                d.across,
                DRIFT,
                scale=abs(g.drift_rate) or 1.0,
                text=("0", f"{d.across:.1e}"),
            ),
            Readout.compare(
                "nutation centre ω₁* = −M/((J₃−J)ω₃)",
                g.nutation_center,
                recovered_center,
                CENTRE,
                "measured: centre of the circle (ω₁, ω₂) recovered from the integrated attitude",
                digits=9,
            ),
            Readout(
                "ω from the attitude vs closed form",
                "0",
                f"{mismatch:.1e} rel.",
                gap=mismatch,
                tolerance=DRIFT,
            ),
        )

    def recovered(self) -> np.ndarray:
        return omega_from_attitude(self.run.quaternions, self.dt)

    def plot(self, key: str, t: float) -> tuple[np.ndarray, ...]:
        times, error, gap = self.plotted(t, PLOT_SAMPLES, self.run.error_estimate, self.mismatch)
        return (
            times,
            np.log10(np.maximum(error, ERROR_FLOOR)),
            np.log10(np.maximum(gap, ERROR_FLOOR)),
        )


def build(settings: Settings) -> GyroModel:
    torque, spin = float(settings["M"]), float(settings["spin"])
    gyro = Gyroscope(J, J3, torque, (0.0, 0.0, spin))
    span = min(max(NUTATIONS * gyro.nutation_period, MIN_SPAN), MAX_SPAN)
    times = np.arange(round(span * ROWS_PER_TIME)) / ROWS_PER_TIME
    run = gyro.attitude(times)
    omega = gyro.omega(times)
    recovered = omega_from_attitude(run.quaternions, 1.0 / ROWS_PER_TIME)
    inner = omega[2:-2]
    gap = np.linalg.norm(recovered - inner, axis=1) / np.linalg.norm(inner, axis=1)
    mismatch = np.pad(gap, 2, mode="edge")
    drift = gyro.measure_drift(periods=4)
    return GyroModel(gyro, times, run, omega, mismatch, drift)


class GyroDrawing(TabulatedDrawing):
    """The disc, its axis, the torque and drift arrows (body frame), ω and the axis's path."""

    contact = "path"

    def __init__(self, canvas: Canvas) -> None:
        super().__init__(canvas)
        parts = self.parts
        mesh = meshes.solid_mesh(DISC.solid) if DISC.solid is not None else None
        assert mesh is not None
        vertices = np.asarray(mesh.vertices) * (DISC_RADIUS / float(np.max(mesh.extents) / 2.0))
        parts.surface("gyroscope", DISC_NODE, (vertices, np.asarray(mesh.faces)), colors.SOLID)
        axis = parts.lines("axis", AXIS_NODE, colors.SYMMETRY_AXIS, 3.0)
        axis.points = np.array([[[0, 0, -AXIS_LENGTH], [0, 0, AXIS_LENGTH]]], np.float32)
        self.torque = parts.arrow("torque", TORQUE_NODE, colors.TORQUE, THIN_ARROW)
        self.torque_label = parts.label("torque", f"{TORQUE_NODE}_label", "M", (0, 1, 0))
        self.drift = parts.arrow("drift", DRIFT_NODE, colors.DRIFT, THIN_ARROW)
        self.drift_label = parts.label("drift", f"{DRIFT_NODE}_label", "drift", (0, 0, 1))
        self.arrows["omega"] = parts.arrow("omega", OMEGA_NODE, colors.OMEGA, THIN_ARROW)
        self.path = parts.trail("path", PATH_NODE, colors.AXIS_PATH, 3.0, 2400)

    def fit(self, model: Model, geometry: Geometry | None) -> None:
        assert isinstance(model, GyroModel)
        g = model.gyro
        quats = model.run.quaternions
        tip = rotations.rotate(quats, np.array([0.0, 0.0, AXIS_LENGTH]))
        omega_space = rotations.rotate(quats, model.omega)
        reach = float(np.max(np.linalg.norm(model.omega, axis=1)))
        arrows = np.zeros((len(quats), 1, 2, 3), np.float32)
        arrows[:, 0, 1] = omega_space * (OMEGA_LENGTH / reach)
        table = Table(
            1.0 / ROWS_PER_TIME,
            wxyz_from_xyzw(quats),
            model.omega,
            {"path": tip.astype(np.float32)},
            {"omega": arrows},
        )
        # The torque from the disc's rim outwards along ±x₂ (longer for a larger |M|), the drift
        # from the axis's tip: the mean displacement of the tip in DRIFT_TIME.
        side = math.copysign(1.0, g.torque)
        reach = DISC_RADIUS + 0.15 + 0.45 * min(1.0, abs(g.torque))
        self.torque.points = arrow_points((0, side * DISC_RADIUS, 0), (0, side * reach, 0))
        self.torque_label.position = (0.0, side * reach, 0.05)
        shift = g.drift_rate * DRIFT_TIME * AXIS_LENGTH
        self.drift.points = arrow_points((0, 0, AXIS_LENGTH), (0, shift, AXIS_LENGTH))
        self.drift_label.position = (0.0, shift, AXIS_LENGTH + 0.05)
        self.player = Player(table, {"path": self.path})


SPEC = SceneSpec(
    name="gyroscope-torque",
    label="Scene: gyroscope with a body-fixed torque",
    source=(
        "[FM06 §7.11, Eqs. 7.85-7.98]: J ω₁' = (J − J₃) ω₂ω₃, J ω₂' = (J₃ − J) ω₃ω₁ + M, "
        "ω₃ constant; ω in closed form, the attitude by Magnus-4 [HLW06 §IV.7]; the axis "
        "drifts towards the torque at M/((J₃ − J) ω₃) (tendency to parallelism)."
    ),
    body="the presets' homogeneous disc (r 1, thickness 0.25), J = 1, J₃ = 1.9592",
    motion="Gyroscope(J, J₃, M, (0, 0, ω₃)): omega (closed form), attitude (Magnus-4), "
    "measure_drift",
    elements=frozenset(),
    parts=(
        Part("gyroscope", "the disc", (DISC_NODE,), surface=colors.SOLID),
        Part("axis", "symmetry axis e₃", (AXIS_NODE,), (colors.SYMMETRY_AXIS,)),
        Part(
            "torque",
            "torque M (along x₂)",
            (TORQUE_NODE, f"{TORQUE_NODE}_label"),
            surface=colors.TORQUE,
            legend=(Entry("torque M (along x₂)", (colors.TORQUE,), "arrow"),),
        ),
        Part(
            "drift",
            "mean drift of the axis",
            (DRIFT_NODE, f"{DRIFT_NODE}_label"),
            surface=colors.DRIFT,
            legend=(Entry("drift of the axis", (colors.DRIFT,), "arrow"),),
        ),
        Part(
            "omega",
            "ω",
            (OMEGA_NODE,),
            surface=colors.OMEGA,
            legend=(Entry("ω", (colors.OMEGA,), "arrow"),),
        ),
        Part("path", "path of the axis", (PATH_NODE,), (colors.AXIS_PATH,), trails=(PATH_NODE,)),
    ),
    controls=(
        Slider("M", "torque M", -1.0, 1.0, 0.05, 0.5, hint="Along the body's own x₂."),
        Slider("spin", "spin ω₃", 0.5, 4.0, 0.05, 1.5, hint="About the symmetry axis."),
    ),
    shared=frozenset({Control.SPEED, Control.PLAYBACK}),
    readouts=(
        "drift rate M/((J₃−J)ω₃)",
        "drift across the torque",
        "nutation centre ω₁* = −M/((J₃−J)ω₃)",
        "ω from the attitude vs closed form",
        "attitude error estimate now",
        "nutation period 2π/|ν|",
    ),
    plots=(
        PlotSpec(
            "errors",
            "the integrated attitude (log scale)",
            "t",
            "log₁₀ error",
            (
                ("estimate (rad)", colors.PLOT_MEASURED),
                ("ω from attitude (rel.)", colors.PLOT_SECOND),
            ),
        ),
    ),
    build=build,
    draw=GyroDrawing,
    view=View(position=(2.3, -2.9, 2.5), look_at=(0.0, 0.0, 0.45)),
    speed=1.0,
    picture_time=12.0,
)
