"""Input checks: a readable ValueError, raised before anything is computed.

Every public entry point of :mod:`poinsot.physics` checks its arguments here once, so that the
core sees one canonical case (finite arrays of the right shape, positive moments) and a student
reads what is wrong and what to change.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

__all__ = [
    "check_attitude",
    "check_energy_parameter",
    "check_inertia",
    "check_moment_span",
    "check_positive",
    "check_times",
    "check_vector",
]

#: The moments may span at most this factor: beyond it a scaled moment leaves double precision.
MOMENT_SPAN = 1e300


def check_vector(value: ArrayLike, name: str) -> NDArray[np.float64]:
    """``value`` as a (3,) array of finite floats, else a ValueError naming ``name``."""
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be three real numbers, got {value!r}") from exc
    if arr.shape != (3,):
        raise ValueError(f"{name} must be three numbers (shape (3,)), got shape {arr.shape}")
    if not all(map(math.isfinite, arr.tolist())):
        raise ValueError(f"{name} must be finite, got {arr.tolist()}")
    return arr


def check_inertia(value: ArrayLike) -> NDArray[np.float64]:
    """Principal moments as a (3,) array of positive finite floats [kg m², any unit]."""
    inertia = check_vector(value, "the moments of inertia")
    if min(inertia.tolist()) <= 0.0:
        raise ValueError(
            f"the moments of inertia must be positive, got {inertia.tolist()} "
            "(a principal moment is a sum of m·r², never zero or negative)"
        )
    return inertia


def check_moment_span(inertia: NDArray[np.float64]) -> None:
    """Refuse moments more than :data:`MOMENT_SPAN` apart (checked moments, any order)."""
    i_min, i_max = min(inertia.tolist()), max(inertia.tolist())
    if i_max / MOMENT_SPAN > i_min:
        raise ValueError(
            "the moments of inertia span more than 300 decades "
            f"({i_min:g} to {i_max:g}): beyond double precision"
        )


def check_attitude(value: object) -> Rotation:
    """One scipy Rotation (body -> space); ``None`` is the identity."""
    if value is None:
        return Rotation.identity()
    if not isinstance(value, Rotation) or not value.single:
        raise ValueError("attitude0 must be one scipy Rotation (body -> space) or None")
    return value


def check_positive(value: object, name: str) -> float:
    """``value`` as a positive finite float, else a ValueError naming ``name``."""
    try:
        x = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be a positive number, got {value!r}") from exc
    if not (math.isfinite(x) and x > 0.0):
        raise ValueError(f"{name} must be positive and finite, got {x}")
    return x


def check_energy_parameter(D: object, inertia: NDArray[np.float64]) -> float:
    """``D = |L|²/2T`` as a float in ``[min I, max I]`` (same unit as the checked moments)."""
    try:
        d = float(D)  # type: ignore[arg-type]
    except (TypeError, ValueError) as exc:
        raise ValueError(f"D must be a finite number, got {D!r}") from exc
    if not math.isfinite(d):
        raise ValueError(f"D must be a finite number, got {d}")
    lo, hi = min(inertia.tolist()), max(inertia.tolist())
    if not (lo <= d <= hi):
        raise ValueError(
            "D = |L|²/2T must lie between the smallest and largest moments "
            f"[{lo:g}, {hi:g}], got {d:g}"
        )
    return d


def check_times(t: ArrayLike) -> float | NDArray[np.float64]:
    """The times as a float if the caller passed one number, else as a (N,) float array."""
    if isinstance(t, float):  # the common scalar (also numpy.float64): no array round trip
        if not math.isfinite(t):
            raise ValueError("time must be finite (got NaN or infinity)")
        return float(t)
    try:
        arr = np.asarray(t, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"time must be a number or a 1-D array of numbers, got {t!r}") from exc
    if arr.ndim > 1:
        raise ValueError(f"time must be a number or a 1-D array, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError("time must be finite (got NaN or infinity)")
    return float(arr) if arr.ndim == 0 else arr
