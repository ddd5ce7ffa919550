"""The parameters a user edits, and how they become a :class:`physics.FreeRigidBody`.

The app never integrates or solves anything: the initial omega comes from
:func:`physics.omega_from_energy` and the attitude that puts L along +z from
:func:`physics.attitude_with_L_along_z`.
"""

from __future__ import annotations

import dataclasses
import math

from poinsot.app.presets import Preset
from poinsot.physics import (
    FreeRigidBody,
    attitude_with_L_along_z,
    check_real_body,
    omega_from_energy,
)

#: Slider ranges.
INERTIA_RANGE = (0.1, 5.0)
OMEGA_NORM_RANGE = (0.2, 4.0)
SPEED_RANGE = (0.05, 4.0)
TRAIL_RANGE = (100, 6000)


@dataclasses.dataclass(frozen=True)
class Parameters:
    """Moments (caller order), D = |L|²/2T, which polhode, and |omega0|.

    ``omega0``: an exact initial omega given by a preset (data), used instead of
    :func:`physics.omega_from_energy`; any edit drops it (the sliders then speak).
    """

    inertia: tuple[float, float, float]
    D: float
    pole_sign: int = 1
    omega_norm: float = 1.0
    omega0: tuple[float, float, float] | None = None

    @classmethod
    def from_preset(cls, preset: Preset) -> Parameters:
        return cls(
            tuple(float(i) for i in preset.inertia),  # type: ignore[arg-type]
            float(preset.D),
            int(preset.pole_sign),
            float(preset.omega_norm),
            None if preset.omega0 is None else tuple(float(w) for w in preset.omega0),  # type: ignore[arg-type]
        )

    @property
    def D_range(self) -> tuple[float, float]:
        return min(self.inertia), max(self.inertia)

    @property
    def intermediate(self) -> float:
        return sorted(self.inertia)[1]

    def with_inertia(self, index: int, value: float) -> Parameters:
        """Change one moment; D is clamped into the new [min I, max I]."""
        inertia = list(self.inertia)
        inertia[index] = float(value)
        lo, hi = min(inertia), max(inertia)
        return dataclasses.replace(
            self,
            inertia=tuple(inertia),
            D=min(max(self.D, lo), hi),  # type: ignore[arg-type]
            omega0=None,
        )

    def mirrored(self, side: str) -> Parameters:
        """Move D to the ``side`` ("minor" or "major") of the separatrix D = I2, keeping its
        relative position in that side's interval; unchanged if it is already there."""
        lo, hi = self.D_range
        mid = self.intermediate
        if side == "major" and self.D < mid and mid > lo:
            frac = (mid - self.D) / (mid - lo)
            return dataclasses.replace(self, D=mid + frac * (hi - mid), omega0=None)
        if side == "minor" and self.D > mid and hi > mid:
            frac = (self.D - mid) / (hi - mid)
            return dataclasses.replace(self, D=mid - frac * (mid - lo), omega0=None)
        return self

    def side(self) -> str:
        return "major" if self.D >= self.intermediate else "minor"

    def check(self) -> None:
        """Raise ValueError, with a message for the GUI, if no real body has these values
        (:func:`physics.check_real_body`: the triangle inequality I_i <= I_j + I_k)."""
        check_real_body(self.inertia)
        if not (math.isfinite(self.omega_norm) and self.omega_norm > 0):
            raise ValueError("|ω₀| must be positive")

    def build(self) -> FreeRigidBody:
        """The body, with L along +z at t = 0. Raises ValueError with a readable message."""
        self.check()
        if self.omega0 is not None:
            omega0 = self.omega0
        else:
            omega0 = omega_from_energy(self.inertia, self.D, self.omega_norm, self.pole_sign)
        attitude0 = attitude_with_L_along_z(self.inertia, omega0)
        return FreeRigidBody(self.inertia, omega0, attitude0)

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
