"""Scene "long-cylinder": a spin that looks stable for a long time [FM06 Remark 7.5;
FM06 Theorem 7.3].

What it shows: a long homogeneous cylinder whose cross-section is very slightly elliptic
(semi-axes 1 % apart), so that its two diametral moments differ a little (I₂ < I₃, both far
above the axial I₁). It is spun about the intermediate diametral axis e₂ with a small error
(1° towards its own axis). Rotation about e₂ is unstable, and the polhode is a long curve: in
the body, ω runs all the way round the cylinder's waist, through e₃, −e₂ and −e₃. But the
herpolhode is tiny beside it: in space ω stays within a few degrees of L, so the body seems to
spin steadily about a fixed diametral axis, while it slowly turns about its own long axis (which
a nearly round cylinder hides). One circuit of the polhode takes many spins, so a time-lapse
control reaches long times.

Readouts: how far the contact point has moved along its polhode (the fraction of a circuit from
the arc length, against the chord length of ω(t) sampled), the circuits done, the time one
circuit takes (4K/λ against the zeros of ω₂), and the sizes of the herpolhode and the polhode.

Physics: :class:`poinsot.physics.models.family.PolhodeArc` (arc length along the polhode, circuit
time and length), :class:`FreeRigidBody`, :func:`poinsot.physics.models.flip.measure_flips`; the
moments of the drawn mesh by trimesh (:func:`poinsot.app.model.bodies.body_from_mesh`).
"""

from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np
import trimesh

from poinsot.app.lessons.support import colors
from poinsot.app.lessons.support.base import CONSTRUCTION, OwnSolid, SceneModel, riding_mesh
from poinsot.app.lessons.support.spec import Choice, Part, Readout, SceneSpec, Settings, number
from poinsot.app.model.bodies import MeshBody, body_from_mesh
from poinsot.app.model.elements import Control, Element
from poinsot.physics import FreeRigidBody, attitude_with_L_along_z
from poinsot.physics.models.family import PolhodeArc
from poinsot.physics.models.flip import measure_flips

#: The cylinder: length, and the semi-axes of its elliptic cross-section (1 % apart).
LENGTH = 2.4
SEMI_AXES = (0.2512, 0.2488)
#: |ω₀| [rad/time] and the error of the spin axis from e₂, towards e₁ [rad].
SPIN = 2.0
ERROR = math.radians(1.0)
#: Time lapse: simulation time per second.
LAPSES = ("×1", "×3", "×10", "×30", "×100")
LAPSE_VALUES = (1.0, 3.0, 10.0, 30.0, 100.0)
#: Samples of one circuit for the chord length of ω(t), and for the herpolhode's size.
CHORD_SAMPLES = 4096
SIZE_SAMPLES = 2048
CYLINDER_NODE = "/space/body/cylinder"
CYLINDER = Part("cylinder", "the cylinder", (CYLINDER_NODE,), surface=colors.SOLID)
#: Tolerances of the readouts: the chord of CHORD_SAMPLES points falls short of the arc by
#: about (its step's angle)²/24 at the sharpest bend, a fraction of a circuit; the zeros of ω₂
#: are refined to a few ulps of t.
CHORD = 1e-3
EXACT = 1e-12


@functools.cache
def cylinder() -> MeshBody:
    """The elliptic cylinder along x, measured by trimesh in its principal frame (x its axis,
    I₁ < I₂ < I₃)."""
    mesh = trimesh.creation.cylinder(radius=1.0, height=LENGTH, sections=128)
    mesh.apply_scale((SEMI_AXES[0], SEMI_AXES[1], 1.0))
    mesh.apply_transform(trimesh.transformations.rotation_matrix(math.pi / 2, (0.0, 1.0, 0.0)))
    return body_from_mesh(mesh, "long elliptic cylinder")


@dataclasses.dataclass(frozen=True)
class CylinderModel(OwnSolid, SceneModel):
    body: FreeRigidBody
    arc: PolhodeArc
    measured_period: float

    def readouts(self, t: float) -> tuple[Readout, ...]:
        arc = self.arc
        fraction = float(arc.fraction(t)[0])
        circuits = math.floor(float(arc.arc_length(t)[0]) / arc.circuit_length)
        chord = self.chord_fraction(t)
        return (
            Readout.compare(
                "travelled along the polhode",
                fraction,
                chord,
                CHORD,
                "theory: arc length (PolhodeArc); measured: chord length of ω(t) sampled",
                scale=1.0,  # a fraction of the circuit
                text=(f"{100.0 * fraction:.2f} %", f"{100.0 * chord:.2f} %"),
            ),
            Readout("circuits of the polhode done", str(circuits), "—"),
            *self.rows,
        )

    @functools.cached_property
    def rows(self) -> tuple[Readout, ...]:
        arc = self.arc
        herpolhode, polhode = self.sizes()
        return (
            Readout.compare(
                "one circuit, 4K/λ",
                arc.circuit_time,
                self.measured_period,
                EXACT,
                "measured: twice the spacing of the zeros of ω₂",
            ),
            Readout(
                "… in spins (|ω| t/2π)", number(arc.circuit_time * SPIN / (2 * math.pi), 4), "—"
            ),
            Readout("herpolhode radius / polhode radius", "—", f"{herpolhode / polhode:.3f}"),
            Readout("largest angle of ω from L", "—", f"{math.degrees(self.cone_angle()):.2f}°"),
        )

    def _circuit(self, samples: int) -> np.ndarray:
        return np.linspace(0.0, self.arc.circuit_time, samples + 1)

    def chord_fraction(self, t: float) -> float:
        """The fraction of the circuit's chord length ω(t) has covered by ``t`` (mod a circuit)."""
        w = self.body.omega(np.linspace(0.0, t % self.arc.circuit_time, CHORD_SAMPLES + 1))
        return _chord(w) / self.circuit_chord

    @functools.cached_property
    def circuit_chord(self) -> float:
        return _chord(self.body.omega(self._circuit(CHORD_SAMPLES)))

    def sizes(self) -> tuple[float, float]:
        """The herpolhode's radius (contact point from the foot of L) and the polhode's (ω from
        the body axis e₁ it circles), over one circuit."""
        omega, _, contact = self.body.sample(self._circuit(SIZE_SAMPLES))
        return float(np.hypot(contact[:, 0], contact[:, 1]).max()), float(
            np.hypot(omega[:, 1], omega[:, 2]).max()
        )

    def cone_angle(self) -> float:
        """The largest angle between ω (in space) and L over one circuit."""
        _, _, contact = self.body.sample(self._circuit(SIZE_SAMPLES))
        return float(np.max(np.arctan2(np.hypot(contact[:, 0], contact[:, 1]), contact[:, 2])))


def _chord(points: np.ndarray) -> float:
    """The length of the polyline through ``points`` (N, 3)."""
    return float(np.sum(np.linalg.norm(np.diff(points, axis=0), axis=1)))


def build(settings: Settings) -> CylinderModel:
    J = np.asarray(cylinder().ratios, dtype=float)
    w0 = SPIN * np.array([math.sin(ERROR), math.cos(ERROR), 0.0])
    body = FreeRigidBody(J, w0, attitude_with_L_along_z(J, w0))
    arc = PolhodeArc(body)
    zeros = measure_flips(body, 2.2 * arc.circuit_time, axis=1)
    measured = 2.0 * float(np.mean(np.diff(zeros))) if len(zeros) >= 2 else math.nan
    return CylinderModel(body, arc, measured)


SPEC = SceneSpec(
    name="long-cylinder",
    label="Scene: long cylinder, stable-looking spin",
    source=(
        "[FM06 Remark 7.5; FM06 Theorem 7.3]: a long, slightly asymmetric cylinder spun about a "
        "diametral axis seems to spin steadily for a long time: the herpolhode is tiny beside "
        "the polhode, so ω hardly moves in space while it slowly runs round the body."
    ),
    body="a homogeneous cylinder 2.4 long with an elliptic section of semi-axes 0.2512 and "
    "0.2488, moments by trimesh, normalised to I₃ = 1",
    motion="FreeRigidBody(I, |ω₀| = 2 at 1° from e₂ towards e₁); PolhodeArc",
    elements=CONSTRUCTION | {Element.POLHODE, Element.POLHODE_FULL},
    parts=(CYLINDER,),
    controls=(
        Choice(
            "lapse",
            "Time lapse",
            LAPSES,
            "×10",
            hint="Simulation time per second: a circuit of the polhode takes many spins.",
            values=LAPSE_VALUES,
            speed=True,
        ),
    ),
    shared=frozenset({Control.PLAYBACK, Control.TRAIL, Control.VISIBILITY}),
    readouts=(
        "travelled along the polhode",
        "circuits of the polhode done",
        "one circuit, 4K/λ",
        "… in spins (|ω| t/2π)",
        "herpolhode radius / polhode radius",
        "largest angle of ω from L",
    ),
    plots=(),
    build=build,
    draw=riding_mesh(CYLINDER, lambda: cylinder().mesh),
    speed_range=(0.05, 100.0),
    trail_points=3000,
    picture_time=40.0,
)
