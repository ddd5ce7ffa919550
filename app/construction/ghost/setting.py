"""The ghost's settings: which integrator, at which tolerance, step or game-engine rate.

The choices offered in the panel (:data:`TOLERANCES`, :data:`DIVISIONS`,
:data:`GAME_STEP_RATES`), their labels, and :class:`GhostConfig`, what the controls ask for:
an adaptive pair's relative tolerance, a fixed step h = T/n of the body's time scale T
(:func:`time_scale`), or a game engine's frame step 1/rate s.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from poinsot.physics import FreeRigidBody
from poinsot.physics.integrators import GAME_STEPS, METHODS

#: Relative tolerances offered for the adaptive pairs (log scale).
TOLERANCES: tuple[float, ...] = tuple(10.0**-k for k in range(3, 11))
#: Fixed steps offered, as divisions of the time scale T: h = T / n.
DIVISIONS: tuple[int, ...] = (20, 50, 100, 200, 500, 1000, 2000)
#: Defaults: RK45 at a loose tolerance drifts visibly within a minute at speed 1 (energy error
#: 1e-4 at t = 10, 2e-2 at t = 60 on the default preset); T/50 shows the splitting's bounded
#: wobble (energy error ~ 5e-4, flat).
DEFAULT_METHOD = "RK45"
DEFAULT_TOLERANCE = 1e-3
DEFAULT_DIVISIONS = 50
#: A game engine's step (:data:`GAME_STEPS`) runs at a frame rate in seconds, as in a game, not
#: at a fraction of T: 1/60 s is the usual physics tick (Godot, Unity, Jolt's samples), 1/240 s
#: a fine one; on the T-handle at its preset's 2 rad/s both show the step's verdict within a
#: minute (no flip without the gyroscopic term, energy gained or lost with it).
GAME_STEP_RATES: tuple[int, ...] = (30, 60, 120, 240)
DEFAULT_GAME_RATE = 60


def tolerance_label(tol: float) -> str:
    return f"1e-{round(-math.log10(tol))}"


def division_label(n: int) -> str:
    return f"T/{n}"


def game_step_label(rate: int) -> str:
    return f"1/{rate} s"


def time_scale(body: FreeRigidBody) -> float:
    """T of the step choices h = T/n: the period of ω, or where ω does not return (separatrix,
    sphere, permanent rotation) the time of one turn, 2π/|ω₀|."""
    if math.isfinite(body.period) and body.period > 0.0:
        return float(body.period)
    return 2.0 * math.pi / float(np.linalg.norm(body.omega0))


@dataclasses.dataclass(frozen=True)
class GhostConfig:
    """What the controls ask for. Each kind of method keeps its own setting."""

    enabled: bool = False
    method: str = DEFAULT_METHOD
    tolerance: float = DEFAULT_TOLERANCE
    divisions: int = DEFAULT_DIVISIONS
    game_rate: int = DEFAULT_GAME_RATE

    @property
    def adaptive(self) -> bool:
        return METHODS[self.method].kind == "adaptive"

    @property
    def game(self) -> bool:
        """A game engine's step: its setting is a frame step h = 1/rate s."""
        return self.method in GAME_STEPS

    def setting(self, body: FreeRigidBody) -> float:
        """The integrator's setting: the tolerance, the game step 1/rate, or h = T/n."""
        if self.adaptive:
            return self.tolerance
        if self.game:
            return 1.0 / self.game_rate
        return time_scale(body) / self.divisions

    def setting_text(self, body: FreeRigidBody) -> str:
        if self.game:
            return f"h = {game_step_label(self.game_rate)}"
        if self.adaptive:
            return f"tol {tolerance_label(self.tolerance)}"
        return f"h = T/{self.divisions} = {self.setting(body):.3g}"
