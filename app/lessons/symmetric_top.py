"""Scene "symmetric-top": the free symmetric top, its body cone rolling on the space cone
[GPS02 §5.6; FM06 §7.11].

What it shows: a homogeneous disc (oblate, J > I) or rod (prolate, J < I) in Poinsot's
construction, with the two cones of the instantaneous axis: the body cone (ω about the symmetry
axis e₃, fixed in the body, drawn riding with it) and the space cone (ω about L, fixed in
space). They touch along ω and the body cone rolls on the space cone without slipping: around
its outside for a prolate body, around it with the space cone inside for an oblate one. The
axis precesses about L at p = G/I while the body spins relative to it at s = ((I − J)/I) ω₃.
No separatrix here: a symmetric body has none, so there is no such control.

Readouts: p and s predicted against the rates measured from the motion (the azimuth of the axis
about L, and of ω about e₃), and the cones' half-angles and the nutation angle against the angles
read from the motion.

Physics: :func:`poinsot.physics.models.symmetric.symmetric_top` (rates, cones, the body),
:func:`~.measure_precession_rate`, :func:`~.measure_spin_rate`. The bodies are the presets' disc
and rod (their moments checked against trimesh by tests/app/test_parts.py).
"""

from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np
import viser

from poinsot.app.construction.geometry import Geometry
from poinsot.app.construction.palette import Entry
from poinsot.app.lessons.support import colors
from poinsot.app.lessons.support.base import CONSTRUCTION, PartsDrawing, SceneModel
from poinsot.app.lessons.support.drawing import cone_mesh, segments
from poinsot.app.lessons.support.spec import (
    Canvas,
    Choice,
    Model,
    Part,
    Readout,
    SceneSpec,
    Settings,
    Slider,
)
from poinsot.app.model.elements import Control, Element, Solid
from poinsot.app.model.presets import preset_by_key
from poinsot.physics import FreeRigidBody, attitude_with_L_along_z
from poinsot.physics.models.symmetric import (
    SymmetricTop,
    measure_precession_rate,
    measure_spin_rate,
    symmetric_top,
)

#: The two bodies: the presets' disc and rod (I₁ = I₂ = I transverse, I₃ = J axial).
SHAPES = {"oblate (a disc)": preset_by_key("oblate"), "prolate (a rod)": preset_by_key("prolate")}
#: |ω₀| [rad/time].
SPIN = 1.2
#: Sections of the drawn cones, and the generators drawn as lines.
CONE_SECTIONS = 96
GENERATORS = 12
#: The rates are measured over this many precession periods.
MEASURE_TURNS = 3.0
#: Samples of the motion used to read the cones' angles.
ANGLE_SAMPLES = 256
BODY_CONE = "/space/body/body_cone"
SPACE_CONE = "/space/space_cone"
#: Tolerance of the readouts: the rates are slopes of unwrapped azimuths of the exact motion,
#: the angles means over its samples (rounding only).
EXACT = 1e-9


@dataclasses.dataclass(frozen=True)
class TopModel(SceneModel):
    shape: str
    tilt: float  # angle of ω₀ from e₃ [rad]
    top: SymmetricTop
    body: FreeRigidBody
    solid: Solid | None

    @functools.cached_property
    def rows(self) -> tuple[Readout, ...]:
        top, body = self.top, self.body
        span = MEASURE_TURNS * 2.0 * math.pi / top.precession_rate
        p = measure_precession_rate(body, span)
        s = measure_spin_rate(body, span)
        alpha_b, alpha_s, theta = self.measured_angles()
        return (
            Readout("shape", top.shape, "J > I" if body.inertia[2] > body.inertia[0] else "J < I"),
            Readout.compare(
                "precession p = G/I",
                top.precession_rate,
                p,
                EXACT,
                "measured: azimuth of the axis about L",
                digits=9,
            ),
            Readout.compare(
                "spin s = ((I − J)/I) ω₃",
                top.spin_rate,
                s,
                EXACT,
                "measured: azimuth of ω about e₃",
                digits=9,
            ),
            _angles("body cone α_b (ω to e₃)", top.body_cone_half_angle, alpha_b),
            _angles("space cone α_s (ω to L)", top.space_cone_half_angle, alpha_s),
            _angles("nutation θ (e₃ to L)", top.nutation_angle, theta),
        )

    def measured_angles(self) -> tuple[float, float, float]:
        """The mean angles (ω, e₃), (ω, L) and (e₃, L) over one precession period of the motion."""
        body = self.body
        t = np.linspace(0.0, 2.0 * math.pi / self.top.precession_rate, ANGLE_SAMPLES)
        w, R, _ = body.sample(t)
        L = np.asarray(body.angular_momentum, dtype=float)
        Lhat = L / np.linalg.norm(L)
        e3 = np.array([0.0, 0.0, 1.0])
        w_space = R.apply(w)
        return (
            float(np.mean(_angle(w, e3))),
            float(np.mean(_angle(w_space, Lhat))),
            float(np.mean(_angle(R.apply(e3), Lhat))),
        )


def _angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angles [rad] between the rows of ``a`` and the vector ``b`` (atan2: exact at 0)."""
    return np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), a @ b)


def _angles(quantity: str, theory: float, measured: float) -> Readout:
    """A row of two angles [rad], shown in degrees."""
    text = tuple(f"{math.degrees(a):.6f}°" for a in (theory, measured))
    return Readout.compare(quantity, theory, measured, EXACT, text=(text[0], text[1]))


def build(settings: Settings) -> TopModel:
    shape = str(settings["shape"])
    preset = SHAPES[shape]
    tilt = math.radians(float(settings["tilt"]))
    transverse, _, axial = preset.inertia
    w0 = SPIN * np.array([math.sin(tilt), 0.0, math.cos(tilt)])
    R0 = attitude_with_L_along_z(preset.inertia, w0)
    top = symmetric_top(transverse, axial, w0, R0)
    return TopModel(shape, tilt, top, top.body(), preset.solid)


class ConesDrawing(PartsDrawing):
    """The body cone (body frame) and the space cone (space frame), to the tip of ω."""

    def __init__(self, canvas: Canvas) -> None:
        super().__init__(canvas)
        self.cones: dict[str, tuple[viser.MeshHandle, viser.LineSegmentsHandle]] = {}
        for part, name, color in (
            ("body_cone", BODY_CONE, colors.BODY_CONE),
            ("space_cone", SPACE_CONE, colors.SPACE_CONE),
        ):
            surface = self.parts.surface(
                part, name, cone_mesh(np.eye(3)), color, colors.CONE_OPACITY
            )
            rim = self.parts.lines(part, f"{name}_rim", color, 2.5)
            self.cones[part] = (surface, rim)

    def fit(self, model: Model, geometry: Geometry | None) -> None:
        assert isinstance(model, TopModel)
        top, scale = model.top, self.geometry(geometry).scale
        # Generators of length |ω|: both rims pass through the tip of ω, on the plane.
        rims = {
            "body_cone": top.body_cone(CONE_SECTIONS, top.omega_norm) * scale,
            "space_cone": top.space_cone(CONE_SECTIONS, top.omega_norm) * scale,
        }
        for part, rim in rims.items():
            surface, line = self.cones[part]
            vertices, faces = cone_mesh(rim)
            surface.vertices = vertices.astype(np.float32)
            surface.faces = faces.astype(np.uint32)
            generators = np.zeros((GENERATORS, 2, 3), np.float32)
            generators[:, 1] = rim[:: CONE_SECTIONS // GENERATORS]
            line.points = np.concatenate([segments(rim, closed=True), generators])


SPEC = SceneSpec(
    name="symmetric-top",
    label="Scene: symmetric top, body cone on space cone",
    source=(
        "[GPS02 §5.6; FM06 §7.11]: I₁ = I₂ = I, I₃ = J. The axis precesses about L at p = G/I, "
        "the body spins relative to it at s = ((I − J)/I) ω₃; the body cone (ω about e₃) rolls "
        "without slipping on the space cone (ω about L)."
    ),
    body="the presets' homogeneous disc (r 1, thickness 0.25) or rod (r 0.35, length 2)",
    motion="symmetric_top(I, J, ω₀, R₀ with L along z).body(); measure_precession_rate, "
    "measure_spin_rate",
    elements=CONSTRUCTION | {Element.POLHODE, Element.SOLID},
    parts=(
        Part(
            "body_cone",
            "body cone (rides with the body)",
            (BODY_CONE, f"{BODY_CONE}_rim"),
            (colors.BODY_CONE,),
            legend=(Entry("body cone (moves)", (colors.BODY_CONE,), "line"),),
        ),
        Part(
            "space_cone",
            "space cone (fixed)",
            (SPACE_CONE, f"{SPACE_CONE}_rim"),
            (colors.SPACE_CONE,),
        ),
    ),
    controls=(
        Choice("shape", "Body", tuple(SHAPES), "prolate (a rod)", buttons=True),
        Slider(
            "tilt",
            "angle of ω₀ from the axis (°)",
            5.0,
            75.0,
            1.0,
            30.0,
            hint="The angle between ω and the symmetry axis e₃ (the body cone's half-angle).",
        ),
    ),
    shared=frozenset({Control.SPEED, Control.PLAYBACK, Control.TRAIL, Control.VISIBILITY}),
    readouts=(
        "shape",
        "precession p = G/I",
        "spin s = ((I − J)/I) ω₃",
        "body cone α_b (ω to e₃)",
        "space cone α_s (ω to L)",
        "nutation θ (e₃ to L)",
    ),
    plots=(),
    build=build,
    draw=ConesDrawing,
    speed=1.0,
    picture_time=4.0,
    table_settings=({}, {"shape": "oblate (a disc)"}),
)
