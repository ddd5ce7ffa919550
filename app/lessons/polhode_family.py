"""Scene "polhode-family": the energy ellipsoid carries a whole family of polhodes
[LL76 §37, Fig. 51; FM06 §7.8, Fig. 7.7; Pars65 §13.12].

What it shows: the polhodes of a 3 × 2 × 1 box for D = |L|²/2T evenly spread over [I₁, I₃],
drawn on its energy ellipsoid and coloured by family: closed curves around the minor axis
(D < I₂), closed curves around the major axis (D > I₂), and the separatrix (D = I₂), the two
ellipses crossing at ±e₂. The curves of the current D are highlighted, and the body runs on one
of them (Poinsot's construction: ellipsoid, plane, herpolhode). A D slider sweeps across
[I₁, I₃]; the highlighted curves and the body follow.

Beside it, Landau's view [LL76 §37]: in momentum space the sphere |m| = G cut by the ellipsoid
Σ mᵢ²/Iᵢ = 2T; their intersection is the polhode (mapped by m = I ω), and the point m(t) of the
moving body runs along it. A point of the sphere (pointed at by hand) is a start at |L| kept:
ω = I⁻¹L, and D follows from it (the setting :data:`START_KEY`, until the slider moves).

Physics: :func:`poinsot.physics.models.family.polhode_family` and :func:`~.polhode_curves` (the
curves, at the body's energy), :func:`~.momentum_view` (Landau's picture at the body's |L|),
:meth:`FreeRigidBody.from_energy` (the body on the polhode of D),
:func:`poinsot.physics.models.flip.measure_flips` (the period read off the motion).
"""

from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np

from poinsot.app.construction.geometry import POLHODE_INFLATE, Geometry
from poinsot.app.construction.palette import Entry
from poinsot.app.construction.sampled.batch import Frame
from poinsot.app.construction.view import View
from poinsot.app.lessons.momentum import (
    CURRENT_WIDTH_PX,
    KINDS,
    MomentumPicture,
    current_segments,
    extent,
    family_lines,
    family_segments,
    momentum_nodes,
    momentum_rows,
)
from poinsot.app.lessons.support import colors
from poinsot.app.lessons.support.base import CONSTRUCTION, PartsDrawing, SceneModel
from poinsot.app.lessons.support.spec import (
    START_KEY,
    Canvas,
    Model,
    Part,
    Readout,
    SceneSpec,
    Settings,
    Slider,
    number,
    parse_start,
)
from poinsot.app.model.elements import Control, Element, Solid
from poinsot.app.model.presets import preset_by_key
from poinsot.physics import FreeRigidBody, Regime
from poinsot.physics.models.axis_angles import measure_wobble, wobble_theory
from poinsot.physics.models.family import (
    MomentumView,
    PolhodeCurve,
    family_D_values,
    momentum_view,
    polhode_curves,
    polhode_family,
)
from poinsot.physics.models.flip import measure_flips
from poinsot.physics.models.pointing import body_from_start, omega_from_momentum

#: The body: the presets' homogeneous 3 × 2 × 1 box (its moments are checked against trimesh's
#: mass properties of the drawn mesh by tests/app/test_parts.py), sorted I₁ < I₂ < I₃.
BOX = preset_by_key("major")
INERTIA: tuple[float, float, float] = BOX.inertia
I1, I2, I3 = INERTIA
#: |ω₀| of the body on every polhode [rad/time].
OMEGA_NORM = 1.2
#: Curves per family on the ellipsoid (and the separatrix).
PER_FAMILY = 4
#: The D slider's step; a value within half a step of I₂ is the separatrix itself.
D_STEP = 0.005
#: Landau's picture stands this far to the side (space x, display units).
LANDAU_OFFSET = (2.75, 0.0, 0.1)
LANDAU_RADIUS = 0.62
LANDAU_TITLE = "Landau: |L| fixed  ∩  Σ Lᵢ²/Iᵢ = 2T"
ROOT = "/space"
FAMILY_ROOT = f"{ROOT}/body/family"
CURRENT_NODE = f"{ROOT}/body/current_polhode"
LANDAU_ROOT = f"{ROOT}/landau"
#: Samples of one period used to read the motion's D and its family.
CHECK_SAMPLES = 64
#: Tolerance of the readouts: every one is read off the exact motion (rounding only).
EXACT = 1e-12
#: The wobble is compared with its small-oscillation theory within this tilt of L from the
#: stable axis [rad] (20°), to the tilt squared (the theory's error is O(tilt²)).
NEAR_AXIS = math.radians(20.0)
WOBBLE = "wobble about the stable axis"
WOBBLE_FORMULAS = {0: "ω₁√((I₂−I₁)(I₃−I₁)/(I₂I₃))", 2: "ω₃√((I₃−I₁)(I₃−I₂)/(I₁I₂))"}


@dataclasses.dataclass(frozen=True)
class FamilyModel(SceneModel):
    """The body on the polhode of D, the family on its ellipsoid, and Landau's view."""

    D: float
    body: FreeRigidBody
    solid: Solid | None
    family: list[PolhodeCurve]
    current: list[PolhodeCurve]
    landau: MomentumView
    measured_period: float

    @functools.cached_property
    def rows(self) -> tuple[Readout, ...]:
        """The readouts (constant along the motion), computed once."""
        body, landau = self.body, self.landau
        J = np.asarray(INERTIA)
        w = body.omega(self._check_times())
        m = w * J
        D_motion = float(np.mean(np.sum(m * m, axis=1) / np.sum(m * w, axis=1)))
        on_sphere = max(
            float(np.abs(np.linalg.norm(c.momentum, axis=1) / landau.sphere_radius - 1).max())
            for c in landau.curves
        )
        on_ellipsoid = max(
            float(np.abs(np.sum(c.momentum**2 / J, axis=1) / landau.two_T - 1.0).max())
            for c in landau.curves
        )
        return (
            Readout.compare("D = |L|²/2T", self.D, D_motion, EXACT, "measured: |L|²/2T of ω(t)"),
            Readout("family", _family(body.regime), _kept_sign(w)),
            Readout("k²", number(body.parameter), "—"),
            _period(body.period, self.measured_period),
            _wobble(body),
            Readout(
                "|m| on Landau's curve",
                number(landau.sphere_radius),
                f"±{on_sphere:.0e} rel.",
                gap=on_sphere,
                tolerance=EXACT,
            ),
            Readout(
                "Σ mᵢ²/Iᵢ on Landau's curve",
                number(landau.two_T),
                f"±{on_ellipsoid:.0e} rel.",
                gap=on_ellipsoid,
                tolerance=EXACT,
            ),
        )

    def _check_times(self) -> np.ndarray:
        span = self.body.period if math.isfinite(self.body.period) else 20.0
        return np.linspace(0.0, span, CHECK_SAMPLES, endpoint=False)


def _period(theory: float, measured: float) -> Readout:
    """The period against the motion's, where the motion returns (else nothing to compare)."""
    note = "measured: twice the spacing of the zeros of ω₂"
    if math.isfinite(theory):
        return Readout.compare("period of ω (4K/λ)", theory, measured, EXACT, note)
    return Readout("period of ω (4K/λ)", number(theory), number(measured), note)


def _wobble(body: FreeRigidBody) -> Readout:
    """The wobble's frequency read off the angle between L and a transverse axis, against
    the small-oscillation theory about the axis the polhode circles (none on the separatrix)."""
    axis = {Regime.MINOR_AXIS: 0, Regime.MAJOR_AXIS: 2}.get(body.regime)
    if axis is None:
        return Readout(WOBBLE, "—", "—", "no stable axis circled")
    G = float(np.linalg.norm(body.angular_momentum))
    theory = float(wobble_theory(INERTIA, axis, G / INERTIA[axis]))
    fit = measure_wobble(body, axis)
    e = "₁₂₃"[axis]
    formula = WOBBLE_FORMULAS[axis] + " [rad/time]"
    tilt = f"tilt of L from e{e} ≤ {math.degrees(fit.amplitude):.1f}°"
    if fit.amplitude > NEAR_AXIS:
        return Readout(
            WOBBLE,
            number(theory),
            number(fit.frequency),
            f"the small-oscillation theory {formula} holds near the axis only, and L "
            f"is far from it here ({tilt}, beyond {math.degrees(NEAR_AXIS):.0f}°)",
            applies=False,
        )
    note = f"{formula}; measured: the angle between L and a transverse axis ({tilt})"
    return Readout.compare(WOBBLE, theory, fit.frequency, max(fit.amplitude**2, EXACT), note)


def _family(regime: Regime) -> str:
    return {
        Regime.MINOR_AXIS: "around the minor axis",
        Regime.MAJOR_AXIS: "around the major axis",
        Regime.SEPARATRIX: "separatrix",
        Regime.PERMANENT_ROTATION: "permanent rotation",
    }.get(regime, regime.value)


def _kept_sign(w: np.ndarray) -> str:
    """Which components of ω keep their sign over the samples (the axis the polhode circles)."""
    kept = [f"ω{'₁₂₃'[i]}" for i in range(3) if np.all(w[:, i] > 0) or np.all(w[:, i] < 0)]
    if not kept:
        return "every component changes sign"
    return ", ".join(kept) + (" keeps its sign" if len(kept) == 1 else " keep their signs")


def snapped_D(value: float) -> float:
    """The slider's D, inside [I₁, I₃]; within half a step of I₂ it is I₂ exactly."""
    D = min(max(float(value), I1), I3)
    return I2 if abs(D - I2) <= 0.5 * D_STEP else D


def pointed_body(text: str) -> FreeRigidBody:
    """The body started from a point of Landau's sphere (:data:`START_KEY`'s setting): body-frame
    L, ω = I⁻¹L, the exact separatrix if it was snapped onto it (ValueError if it is no start)."""
    momentum, separatrix = parse_start(text)
    return body_from_start(INERTIA, omega_from_momentum(INERTIA, momentum), separatrix=separatrix)


def build(settings: Settings) -> FamilyModel:
    start = settings.get(START_KEY)
    if isinstance(start, str):  # pointed at on Landau's sphere: D follows from the point
        body = pointed_body(start)
        D = body.D
    else:
        D = snapped_D(float(settings["D"]))
        body = FreeRigidBody.from_energy(INERTIA, D, omega_norm=OMEGA_NORM)
    T = body.energy
    G = math.sqrt(2.0 * T * body.D)
    family = polhode_family(INERTIA, family_D_values(INERTIA, PER_FAMILY), energy=T)
    current = polhode_curves(INERTIA, body.D, energy=T)
    landau = momentum_view(INERTIA, body.D, momentum=G)
    measured = math.nan
    if body.regime in (Regime.MINOR_AXIS, Regime.MAJOR_AXIS):
        zeros = measure_flips(body, 2.2 * body.period, axis=1)
        if len(zeros) >= 2:
            measured = 2.0 * float(np.mean(np.diff(zeros)))
    return FamilyModel(D, body, BOX.solid, family, current, landau, measured)


class FamilyDrawing(PartsDrawing):
    """The family and the current curves on the ellipsoid (body frame), and Landau's view."""

    def __init__(self, canvas: Canvas) -> None:
        super().__init__(canvas)
        self.parts.frame("family", FAMILY_ROOT)
        self.family = family_lines(self.parts, "family", FAMILY_ROOT)
        self.current = self.parts.lines("current", CURRENT_NODE, colors.CURRENT, CURRENT_WIDTH_PX)
        self.landau = MomentumPicture(
            self.parts,
            "landau",
            LANDAU_ROOT,
            LANDAU_OFFSET,
            title=LANDAU_TITLE,
            current=True,
            radius=LANDAU_RADIUS,
        )
        #: Landau's sphere takes a start pointed at (app/live/pointing/sphere_pointer.py).
        self.pointable = self.landau
        self.model: FamilyModel | None = None

    def fit(self, model: Model, geometry: Geometry | None) -> None:
        assert isinstance(model, FamilyModel)
        scale = self.geometry(geometry).scale * POLHODE_INFLATE
        family = family_segments(model.family, scale)
        current = current_segments(model.current, scale, momentum=False)
        for kind, segs in family.items():
            self.family[kind].points = segs
        self.current.points = current
        view = model.landau
        self.landau.fit(view.sphere_radius, view.curves, view.ellipsoid_semi_axes)
        self.model = model

    def advance(self, t: float, frame: Frame | None) -> Frame:
        frame = super().advance(t, frame)
        self.landau.show_m(np.asarray(INERTIA) * frame.omega)
        return frame


SPEC = SceneSpec(
    name="polhode-family",
    label="Scene: the polhode family",
    source=(
        "[LL76 §37, Fig. 51; FM06 §7.8, Fig. 7.7; Pars65 §13.12]: the polhodes of one body fill "
        "its energy ellipsoid, closed around the minor and the major axis, split by the "
        "separatrix through ±e₂. Landau's view: the sphere of fixed |L| meets the ellipsoid "
        "Σ Lᵢ²/Iᵢ = 2T along the polhode."
    ),
    body="the presets' homogeneous 3 × 2 × 1 box, I = (1, 2, 2.6)",
    motion="FreeRigidBody.from_energy(I, D, |ω₀| = 1.2); polhode_family, momentum_view",
    elements=CONSTRUCTION | {Element.SOLID},
    parts=(
        Part(
            "family",
            "polhode family (by kind)",
            (FAMILY_ROOT, *(f"{FAMILY_ROOT}/{kind}" for kind in KINDS)),
            tuple(color for _, color in KINDS.values()),
            legend=(
                Entry("minor-axis polhodes", (colors.MINOR_FAMILY,), "line"),
                Entry("major-axis polhodes", (colors.MAJOR_FAMILY,), "line"),
                Entry("separatrix", (colors.SEPARATRIX,), "line", "thick"),
            ),
        ),
        Part(
            "current",
            "polhodes of this D",
            (CURRENT_NODE,),
            (colors.CURRENT,),
            legend=(Entry("this D's polhodes", (colors.CURRENT,), "line", "thick"),),
        ),
        Part(
            "landau",
            "Landau's view (momentum space)",
            momentum_nodes(LANDAU_ROOT, family=False, current=True, trace=False),
            (colors.CURRENT,),
            surface=colors.SPHERE,
            legend=momentum_rows(family=False, current=True, trace=False),
        ),
    ),
    controls=(
        Slider(
            "D",
            "D = |L|²/2T",
            I1,
            I3,
            D_STEP,
            1.6,
            hint="Which polhode: D < I₂ circles the minor axis, D > I₂ the major axis, "
            "D = I₂ is the separatrix.",
            marks=((I1, "I₁"), (I2, "I₂"), (I3, "I₃")),
        ),
    ),
    shared=frozenset({Control.SPEED, Control.PLAYBACK, Control.TRAIL, Control.VISIBILITY}),
    readouts=(
        "D = |L|²/2T",
        "family",
        "k²",
        "period of ω (4K/λ)",
        WOBBLE,
        "|m| on Landau's curve",
        "Σ mᵢ²/Iᵢ on Landau's curve",
    ),
    plots=(),
    build=build,
    draw=FamilyDrawing,
    view=View(position=(2.8, -6.2, 2.95), look_at=(1.35, 0.0, 0.3)),
    beside=(extent(LANDAU_OFFSET, LANDAU_TITLE, LANDAU_RADIUS),),
    speed=1.0,
    trail_points=1600,
    picture_time=6.0,
    table_settings=({}, {"D": 2.3}, {"D": I2}, {"D": 1.005}, {"D": 2.595}),
)
