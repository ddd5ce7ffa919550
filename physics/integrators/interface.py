"""What every numerical method provides: its registry record and its sampled trajectory.

Conventions (as in :mod:`poinsot.physics`): ``omega`` is the body-frame angular velocity,
``m = I omega`` the body angular momentum, the attitude ``R`` maps body to space coordinates and
obeys ``R' = R [omega]x``; quaternions are scalar last ``(x, y, z, w)``
(:mod:`poinsot.physics.core.rotations`). The principal moments are used in the caller's order:
Euler's equations and the splitting hold in any labelling.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal, NamedTuple

import numpy as np
from scipy.spatial.transform import Rotation

__all__ = ["Integrator", "Run", "Trajectory", "steps_per_interval"]


class Trajectory(NamedTuple):
    """Samples of a numerical solution at the requested times ``t_eval`` (N of them)."""

    omega: np.ndarray
    """(N, 3) body-frame angular velocity [rad / time unit], caller's axes."""
    attitude: Rotation
    """Stack of N rotations, body -> space."""
    cost: int
    """Right-hand-side evaluations (adaptive methods) or steps taken (fixed-step methods)."""


#: ``run(inertia, omega0, attitude0, t_eval, setting)`` on validated inputs.
Run = Callable[[np.ndarray, np.ndarray, Rotation, np.ndarray, float], "Trajectory"]


@dataclass(frozen=True)
class Integrator:
    """One registered method, with what a caller needs to drive it."""

    name: str
    """Registry key, e.g. ``"DOP853"``."""
    title: str
    """Human-readable name with its reference."""
    kind: Literal["fixed", "adaptive"]
    """``fixed``: the setting is the (maximum) step size [time units]; ``adaptive``: it is the
    relative tolerance (the absolute tolerance is scaled from it, see :func:`integrate`)."""
    order: int
    """Classical order of accuracy (global error ~ h^order)."""
    default_setting: float
    """Step size or relative tolerance used when the caller gives none."""
    conserves_norm: bool
    """True if |L| is conserved to rounding (geometric methods)."""
    run: Run
    """``run(inertia, omega0, attitude0, t_eval, setting)`` on validated inputs."""


def steps_per_interval(t_eval: np.ndarray, h: float) -> np.ndarray:
    """Number of equal steps between consecutive output times (the first from t = 0).

    Each interval dt is cut into ceil(dt / h) equal steps of size <= h; the 1e-9 slack keeps an
    interval that is an integer multiple of h (up to rounding) at exactly that multiple.
    """
    dt = np.diff(t_eval, prepend=0.0)
    n = np.ceil(dt / h - 1e-9).astype(np.int64)
    return np.where(dt > 0.0, np.maximum(n, 1), 0)
