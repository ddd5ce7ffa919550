"""The one quaternion algebra of the project: Hamilton product, conjugate, rotation of vectors,
axis-angle quaternions and the geodesic angle between attitudes.

Quaternions are **scalar-last**, ``(x, y, z, w)``, as in ``scipy.spatial.transform.Rotation``
(``as_quat``). viser's scalar-first ``wxyz`` is converted in exactly one place, the app's
:mod:`poinsot.app.construction.sampled.frames`.

The component functions (:func:`hamilton`, :func:`rotate_vector`, :func:`conjugate`,
:func:`axis_angle`) take quaternions as 4-sequences of *anything that has + and ×*: Python
floats (the scalar paths, bit-identical to the array paths because they perform the same
operations in the same order), numpy arrays of any shape (one component per entry, e.g. the rows
of a ``(4, n)`` array), or high-precision numbers (mpmath's ``mpf`` in the report's Taylor
reference). :func:`multiply` and :func:`rotate` wrap them for stacked ``(..., 4)`` arrays.
"""

from __future__ import annotations

from typing import Any, TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "axis_angle",
    "conjugate",
    "geodesic_angle",
    "hamilton",
    "multiply",
    "rotate",
    "rotate_vector",
]

#: One quaternion component: a float, an array of them, or a high-precision number.
C = TypeVar("C")


def hamilton(p: Any, q: Any) -> tuple[Any, Any, Any, Any]:
    """Hamilton product ``p ⊗ q`` of scalar-last quaternions given as 4-sequences of components,
    so that ``R(p ⊗ q) = R(p) R(q)``. Returns the four components ``(x, y, z, w)``."""
    px, py, pz, pw = p
    qx, qy, qz, qw = q
    return (
        pw * qx + px * qw + py * qz - pz * qy,
        pw * qy - px * qz + py * qw + pz * qx,
        pw * qz + px * qy - py * qx + pz * qw,
        pw * qw - px * qx - py * qy - pz * qz,
    )


def conjugate(q: Any) -> tuple[Any, Any, Any, Any]:
    """``(-x, -y, -z, w)``: the inverse of a unit quaternion."""
    x, y, z, w = q
    return (-x, -y, -z, w)


def rotate_vector(q: Any, v: Any) -> tuple[Any, Any, Any]:
    """``R(q) v`` for a unit quaternion ``q`` (4 components) and a vector ``v`` (3 components):
    ``v + 2 u × (u × v + w v)`` with ``u = (x, y, z)``, written out (``np.cross`` costs tens of
    µs per call)."""
    x, y, z, w = q
    vx, vy, vz = v
    tx = y * vz - z * vy + w * vx
    ty = z * vx - x * vz + w * vy
    tz = x * vy - y * vx + w * vz
    return (
        vx + 2.0 * (y * tz - z * ty),
        vy + 2.0 * (z * tx - x * tz),
        vz + 2.0 * (x * ty - y * tx),
    )


def axis_angle(axis: Any, angle: Any, *, sin: Any = np.sin, cos: Any = np.cos) -> tuple[Any, ...]:
    """The quaternion of a rotation by ``angle`` [rad] about the unit ``axis`` (3 components).
    ``sin``/``cos`` default to numpy's; pass ``math.sin``/``math.cos`` for plain floats."""
    half = 0.5 * angle
    s = sin(half)
    return (axis[0] * s, axis[1] * s, axis[2] * s, cos(half))


def multiply(p: ArrayLike, q: ArrayLike) -> NDArray[np.float64]:
    """:func:`hamilton` for stacks: ``p``, ``q`` of shape ``(..., 4)`` (broadcasting), scalar
    last; returns ``(..., 4)``."""
    pa = np.asarray(p, dtype=float)
    qa = np.asarray(q, dtype=float)
    return np.stack(hamilton(np.moveaxis(pa, -1, 0), np.moveaxis(qa, -1, 0)), axis=-1)


def rotate(q: ArrayLike, v: ArrayLike) -> NDArray[np.float64]:
    """:func:`rotate_vector` for stacks: unit ``q`` ``(..., 4)`` and ``v`` ``(..., 3)``
    (broadcasting); returns ``(..., 3)``."""
    qa = np.asarray(q, dtype=float)
    va = np.asarray(v, dtype=float)
    return np.stack(rotate_vector(np.moveaxis(qa, -1, 0), np.moveaxis(va, -1, 0)), axis=-1)


def geodesic_angle(p: ArrayLike, q: ArrayLike) -> NDArray[np.float64]:
    """Angle [rad] in ``[0, π]`` of the rotation taking attitude ``q`` to attitude ``p``, from
    scalar-last quaternions ``(..., 4)`` (broadcasting; need not be normalised).

    The 4-vectors ``p`` and ``±q`` (sign chosen so that ``p·q >= 0``) make an angle ``a``, and the
    rotation angle is ``2a = 4 atan2(|p̂ - q̂|, |p̂ + q̂|)``. This keeps full relative accuracy at
    every angle; ``2 acos(|p·q|)`` loses half the digits near 0, where the errors we measure live.
    """
    pa = np.asarray(p, dtype=float)
    qa = np.asarray(q, dtype=float)
    pa = pa / np.linalg.norm(pa, axis=-1, keepdims=True)
    qa = qa / np.linalg.norm(qa, axis=-1, keepdims=True)
    sign = np.where(np.sum(pa * qa, axis=-1, keepdims=True) >= 0.0, 1.0, -1.0)
    diff = np.linalg.norm(pa - sign * qa, axis=-1)
    total = np.linalg.norm(pa + sign * qa, axis=-1)
    return 4.0 * np.arctan2(diff, total)
