"""The parameters a user edits, and how they become a :class:`poinsot.physics.FreeRigidBody`.

The app never integrates or solves anything: the body comes from one call into physics
(:func:`_body`: :meth:`FreeRigidBody.from_energy` builds the initial ω from D, |ω₀| and the
pole, and the attitude that puts L along +z).
"""

from __future__ import annotations

import dataclasses
import math

from poinsot.app.model.elements import Solid
from poinsot.app.model.presets import Preset
from poinsot.physics import (
    FreeRigidBody,
    attitude_with_L_along_z,
    box_dimensions,
    check_real_body,
)
from poinsot.physics.models.pointing import body_from_start, energy_parameter

#: Slider ranges.
INERTIA_RANGE = (0.1, 5.0)
OMEGA_NORM_RANGE = (0.2, 4.0)
SPEED_RANGE = (0.05, 4.0)
TRAIL_RANGE = (100, 6000)


def clamp(value: float, bounds: tuple[float, float]) -> float:
    """``value`` within ``bounds`` (low, high): the one clamp of a value asked for by code (a
    link, the lead's state, a script) into a range declared here; a browser's value is clamped
    into its widget's range by :func:`poinsot.app.live.panel.widgets.checked` instead."""
    low, high = bounds
    return min(max(value, low), high)


Vector = tuple[float, float, float]


def _vector(values: tuple[float, ...] | list[float]) -> Vector:
    x, y, z = (float(v) for v in values)
    return x, y, z


@dataclasses.dataclass(frozen=True)
class Parameters:
    """Moments (caller order), D = |L|²/2T, which polhode, and |omega0|.

    ``omega0``: an exact initial omega given by a preset (data), used instead of the one built
    from D, |ω₀| and the pole; any edit drops it (the sliders then speak).

    ``D_asked``: the D the user chose, while the moments keep it out of [min I, max I] (then
    ``D`` is clamped); None when ``D`` is the user's own. A moment passing through a value
    that narrows the range (even an impossible body) therefore does not move the user's D for
    good: once the range holds it again, D is back.
    """

    inertia: Vector
    D: float
    pole_sign: int = 1
    omega_norm: float = 1.0
    omega0: Vector | None = None
    D_asked: float | None = None
    separatrix: bool = False

    @classmethod
    def from_preset(cls, preset: Preset) -> Parameters:
        return cls(
            _vector(preset.inertia),
            float(preset.D),
            int(preset.pole_sign),
            float(preset.omega_norm),
            None if preset.omega0 is None else _vector(preset.omega0),
        )

    @property
    def D_range(self) -> tuple[float, float]:
        return min(self.inertia), max(self.inertia)

    @property
    def intermediate(self) -> float:
        return sorted(self.inertia)[1]

    # -- edits (each drops a preset's exact omega0) ----------------------------------------
    def with_inertia(self, index: int, value: float) -> Parameters:
        """Change one moment; the user's D is clamped into the new [min I, max I] (and kept
        in ``D_asked`` for when the range holds it again)."""
        moments = list(self.inertia)
        moments[index] = float(value)
        inertia = _vector(moments)
        asked = self.D if self.D_asked is None else self.D_asked
        D = min(max(asked, min(inertia)), max(inertia))
        return dataclasses.replace(
            self,
            inertia=inertia,
            D=D,
            omega0=None,
            separatrix=False,
            D_asked=None if D == asked else asked,
        )

    def with_D(self, D: float, snap: float = 0.0) -> Parameters:
        """D, clamped into [min I, max I]; within ``snap`` of the intermediate moment it is
        that moment exactly, the separatrix (a slider's value is only near I₂: D = 2.000 on
        the slider arrived as 1.9999999999999996, a polhode of period 151 around the minor
        axis instead of the separatrix)."""
        D = clamp(float(D), self.D_range)
        if self.has_separatrix and abs(D - self.intermediate) <= snap:
            D = self.intermediate
        return dataclasses.replace(self, D=D, omega0=None, separatrix=False, D_asked=None)

    @property
    def has_separatrix(self) -> bool:
        """Three distinct moments: a triaxial body, whose D = I₂ separates two families."""
        lo, hi = self.D_range
        return lo < self.intermediate < hi

    def with_pole(self, sign: int) -> Parameters:
        return dataclasses.replace(
            self, pole_sign=1 if sign >= 0 else -1, omega0=None, separatrix=False
        )

    def with_omega_norm(self, value: float) -> Parameters:
        """|ω₀|; a value that is not a positive number changes nothing."""
        if not (math.isfinite(value) and value > 0):
            return self
        return dataclasses.replace(self, omega_norm=float(value), omega0=None, separatrix=False)

    def mirrored(self, side: str) -> Parameters:
        """Move D to the ``side`` ("minor" or "major") of the separatrix D = I2, keeping its
        relative position in that side's interval; unchanged if it is already there."""
        lo, hi = self.D_range
        mid = self.intermediate
        if side == "major" and self.D < mid and mid > lo:
            frac = (mid - self.D) / (mid - lo)
            D = mid + frac * (hi - mid)
        elif side == "minor" and self.D > mid and hi > mid:
            frac = (self.D - mid) / (hi - mid)
            D = mid - frac * (mid - lo)
        else:
            return self
        return dataclasses.replace(self, D=D, omega0=None, separatrix=False, D_asked=None)

    def with_start(self, omega0: Vector, separatrix: bool = False) -> Parameters:
        """Start at ``omega0`` (a point of the energy ellipsoid pointed at): D follows from it
        (I₂ exactly when it was snapped onto the ``separatrix``), |ω₀| is its length."""
        w = _vector(omega0)
        D = self.intermediate if separatrix else float(energy_parameter(self.inertia, w))
        norm = math.sqrt(sum(x * x for x in w))
        if not (math.isfinite(D) and norm > 0.0):
            return self
        return dataclasses.replace(
            self,
            D=clamp(D, self.D_range),
            omega_norm=norm,
            omega0=w,
            D_asked=None,
            separatrix=separatrix and self.has_separatrix,
        )

    def side(self) -> str:
        return "major" if self.D >= self.intermediate else "minor"

    # -- the body --------------------------------------------------------------------------
    def check(self) -> None:
        """Raise ValueError, with a message for the GUI, if no real body has these values
        (:func:`poinsot.physics.check_real_body`: the triangle inequality I_i <= I_j + I_k).
        Every other check of the input is the physics' own, once, as it builds the body
        (:mod:`poinsot.physics.core.validation`)."""
        check_real_body(self.inertia)

    def build(self) -> FreeRigidBody:
        """The body, with L along +z at t = 0. Raises ValueError with a readable message."""
        self.check()
        return _body(self)

    def matches(self, preset: Preset, rel: float = 1e-9) -> bool:
        """True while these are still the preset's values (within slider rounding)."""
        other = Parameters.from_preset(preset)
        return (
            all(
                math.isclose(a, b, rel_tol=rel)
                for a, b in zip(self.inertia, other.inertia, strict=True)
            )
            and math.isclose(self.D, other.D, rel_tol=rel)
            and self.pole_sign == other.pole_sign
            and math.isclose(self.omega_norm, other.omega_norm, rel_tol=rel)
            and self.omega0 == other.omega0
        )


def _body(p: Parameters) -> FreeRigidBody:
    """The one place the app asks physics for a body, L along +z: from D, |ω₀| and the pole
    (:meth:`FreeRigidBody.from_energy`, which checks its input once), or from a preset's exact
    ω₀."""
    if p.separatrix and p.omega0 is not None:  # a start snapped onto the separatrix
        return body_from_start(p.inertia, p.omega0, separatrix=True)
    if p.omega0 is None:
        return FreeRigidBody.from_energy(
            p.inertia, p.D, omega_norm=p.omega_norm, pole_sign=p.pole_sign
        )
    return FreeRigidBody(p.inertia, p.omega0, attitude_with_L_along_z(p.inertia, p.omega0))


def drawn_solid(inertia: Vector, base: Preset, base_inertia: Vector) -> Solid | None:
    """The solid drawn for the moments ``inertia``: the preset ``base``'s own solid while they
    are still its moments (``base_inertia``), otherwise the homogeneous box with the same
    moments (:func:`poinsot.physics.box_dimensions`); a flat lamina is drawn with a thin (2 %)
    side."""
    if base.solid is not None and inertia == base_inertia:
        return base.solid
    sides = box_dimensions(inertia)
    return Solid("box", tuple(float(max(a, 0.02 * sides.max())) for a in sides))
