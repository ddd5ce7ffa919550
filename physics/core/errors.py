"""The one set of error measures: how far a motion is from a reference, and how well it keeps
the invariants. The ghost, the report and the tests all measure with these.

Shapes: ``omega`` is ``(..., 3)`` [rad/s] in the body frame, attitudes are scalar-last
quaternions ``(..., 4)`` or :class:`scipy.spatial.transform.Rotation` stacks, ``inertia`` is
``(3,)`` principal moments [kg m²] (any consistent unit).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from poinsot.physics.core.rotations import geodesic_angle

__all__ = [
    "angular_momentum_norm",
    "attitude_error",
    "energy",
    "omega_error",
    "relative_drift",
]


def energy(inertia: ArrayLike, omega: ArrayLike) -> NDArray[np.float64]:
    """Kinetic energy ``T = ½ Σ Iᵢ ωᵢ²`` [J] for each row of ``omega`` ``(..., 3)``."""
    i = np.asarray(inertia, dtype=float)
    w = np.asarray(omega, dtype=float)
    return 0.5 * np.sum(i * w * w, axis=-1)


def angular_momentum_norm(inertia: ArrayLike, omega: ArrayLike) -> NDArray[np.float64]:
    """``G = |I ω|`` [kg m²/s] for each row of ``omega`` ``(..., 3)`` (``hypot``: no overflow
    of the squares)."""
    m = np.asarray(inertia, dtype=float) * np.asarray(omega, dtype=float)
    return np.hypot(np.hypot(m[..., 0], m[..., 1]), m[..., 2])


def omega_error(omega: ArrayLike, reference: ArrayLike) -> NDArray[np.float64]:
    """Relative error ``|ω - ω_ref| / |ω_ref|`` per row of ``(..., 3)`` arrays."""
    w = np.asarray(omega, dtype=float)
    ref = np.asarray(reference, dtype=float)
    return np.linalg.norm(w - ref, axis=-1) / np.linalg.norm(ref, axis=-1)


def _quat(attitude: Rotation | ArrayLike) -> NDArray[np.float64]:
    if isinstance(attitude, Rotation):
        return np.asarray(attitude.as_quat(), dtype=float)
    return np.asarray(attitude, dtype=float)


def attitude_error(attitude: Rotation | ArrayLike, reference: Rotation | ArrayLike) -> NDArray:
    """Geodesic angle [rad] between attitudes (quaternions ``(..., 4)`` or ``Rotation``s),
    accurate near 0 (:func:`poinsot.physics.core.rotations.geodesic_angle`)."""
    return geodesic_angle(_quat(attitude), _quat(reference))


def relative_drift(values: ArrayLike, initial: float) -> NDArray[np.float64]:
    """``|x - x₀| / |x₀|`` of an invariant's values against its initial value."""
    return np.abs(np.asarray(values, dtype=float) - initial) / abs(initial)
