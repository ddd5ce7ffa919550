"""The sizes of Poinsot's construction on screen, computed once per body.

Everything is drawn in *display units*: the physical lengths times one factor
``scale = DISPLAY_RADIUS / max(semi_axes)``, so that the picture is the same size for any
|omega0| and any inertia scale. Scaling the whole construction by one factor keeps every
incidence (the ellipsoid touches the plane at the tip of omega).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import trimesh
from numpy.typing import ArrayLike

from poinsot.app.construction import meshes
from poinsot.app.construction.sampled.sampling import survey
from poinsot.app.model.elements import Solid
from poinsot.physics import FreeRigidBody, Regime

#: Largest semi-axis of the ellipsoid on screen [display units].
DISPLAY_RADIUS = 1.0
#: Radius of the plane disc and spacing of its grid [display units].
PLANE_RADIUS = 1.75
GRID_SPACING = 0.25
#: The L arrow reaches this far above the plane [display units].
L_OVERSHOOT = 0.65
#: Principal axes extend past the ellipsoid by this factor.
AXES_OVERSHOOT = 1.22
#: Lift of the herpolhode above the plane and growth of the polhode off the ellipsoid,
#: against z-fighting with the surfaces they lie on (drawing only; the contact point and
#: the omega arrow are exact).
HERPOLHODE_LIFT = 0.004
POLHODE_INFLATE = 1.004
#: Points of the whole closed polhode.
POLHODE_FULL_POINTS = 384
#: Radius of the contact point's marker [display units].
CONTACT_RADIUS = 0.035


@dataclasses.dataclass(frozen=True)
class ArrowShape:
    """Sizes of an arrow [display units] (the scene's and the GLB export's alike)."""

    shaft_radius: float
    head_radius: float
    head_length: float


#: omega is the thicker arrow and L the thinner one with the larger head: where they are
#: parallel (a sphere, a permanent rotation) omega shows round L up to the plane and L goes on
#: above it, instead of omega hiding inside L.
OMEGA_ARROW = ArrowShape(shaft_radius=0.024, head_radius=0.05, head_length=0.12)
L_ARROW = ArrowShape(shaft_radius=0.011, head_radius=0.055, head_length=0.16)


class SceneDataError(ValueError):
    """Physics returned something the scene must not draw (NaN or infinity)."""


def finite(name: str, value: ArrayLike) -> np.ndarray:
    """``value`` as a float array, or SceneDataError naming ``name`` if any entry is not finite."""
    arr = np.asarray(value, dtype=np.float64)
    if not np.all(np.isfinite(arr)):
        raise SceneDataError(f"{name} is not finite; the scene keeps the last valid state")
    return arr


def triple(values: ArrayLike) -> tuple[float, float, float]:
    """Three numbers as the plain-float triple viser takes for a node's scale."""
    x, y, z = (float(v) for v in np.asarray(values, dtype=np.float64).reshape(3))
    return x, y, z


@dataclasses.dataclass(frozen=True)
class Geometry:
    """Everything :meth:`PoinsotScene.load` sends, in display units, computed (and checked
    finite) before anything is sent, so that a failure leaves the previous scene intact."""

    scale: float
    semi_axes: np.ndarray  # (3,) display units
    plane_height: float  # h in display units
    polhode: np.ndarray  # (n, 3) body frame, display units
    polhode_closed: bool  # False on the separatrix: an open arc between the two poles
    solid_key: tuple | None  # equal keys share the mesh already sent
    solid_base: trimesh.Trimesh | None  # the mesh sent for the solid (a unit cube for boxes)
    solid_scale: np.ndarray | None  # node scale (3,) that makes solid_base the displayed solid
    trace_speed: float  # fastest trace point [display units per time unit]
    herpolhode_radius: float = 0.0  # the herpolhode's largest distance from L's axis
    #: :meth:`polhode_segments`, made once (a shared motion's geometry serves many views).
    _segments: list[np.ndarray] = dataclasses.field(
        default_factory=list, init=False, compare=False, repr=False
    )

    @classmethod
    def from_body(cls, body: FreeRigidBody, solid: Solid | None) -> Geometry:
        semi = finite("the semi-axes", body.semi_axes)
        if not np.all(semi > 0.0):
            raise SceneDataError("the body is at rest: there is no ellipsoid to draw")
        scale = DISPLAY_RADIUS / float(np.max(semi))
        h = float(finite("the plane distance", body.plane_distance))
        normal = finite("the plane normal", body.plane_normal)
        if not np.allclose(normal, (0.0, 0.0, 1.0), atol=1e-9):
            raise SceneDataError(f"L is not vertical (plane normal {normal}); use attitude0")
        polhode = finite("the polhode", body.polhode(POLHODE_FULL_POINTS)) * scale
        key = mesh = solid_scale = None
        if solid is not None:
            key, mesh, shape_scale = meshes.solid_shape(solid)
            vertices = np.asarray(mesh.vertices) * shape_scale
            solid_scale = shape_scale * meshes.fit_scale(vertices, semi * scale)
        closed = body.regime is not Regime.SEPARATRIX
        speed, radius = finite("the trace survey", survey(body, scale))
        return cls(
            scale,
            semi * scale,
            h * scale,
            polhode,
            closed,
            key,
            mesh,
            solid_scale,
            float(speed),
            float(radius),
        )

    @property
    def solid_mesh(self) -> trimesh.Trimesh | None:
        """The solid as displayed, in body coordinates and display units (for exports)."""
        if self.solid_base is None or self.solid_scale is None:
            return None
        mesh = self.solid_base.copy()
        mesh.apply_scale(self.solid_scale)
        return mesh

    def polhode_segments(self) -> np.ndarray:
        """The whole polhode as line segments (n, 2, 3) float32, closed unless on the
        separatrix."""
        if not self._segments:
            curve = self.polhode
            if self.polhode_closed:
                curve = np.concatenate([curve, curve[:1]])
            curve = curve.astype(np.float32)
            self._segments.append(np.stack([curve[:-1], curve[1:]], axis=1))
        return self._segments[0]

    def axis_ends(self) -> np.ndarray:
        """(3, 3): row i is the tip of principal axis i+1 as drawn (past the ellipsoid)."""
        return np.diag(self.semi_axes * AXES_OVERSHOOT)
