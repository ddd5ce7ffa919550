"""The one place where an attitude becomes a viser orientation, and back.

scipy's ``Rotation.as_quat()`` and :mod:`poinsot.physics.core.rotations` are scalar-last
(x, y, z, w); viser's ``wxyz`` is scalar-first. Every pose the app sends goes through
:func:`wxyz`; every pose read back from the scene goes through :func:`rotation_from_wxyz` or
:func:`xyzw_from_wxyz`; nothing else in the app touches a quaternion's component order.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

#: Index order taking (x, y, z, w) to (w, x, y, z), and back.
_WXYZ_FROM_XYZW = [3, 0, 1, 2]
_XYZW_FROM_WXYZ = [1, 2, 3, 0]


def wxyz(rotation: Rotation) -> np.ndarray:
    """Viser orientation (w, x, y, z), w >= 0: shape (4,) for a single rotation, (N, 4) for a
    stack."""
    return wxyz_from_xyzw(rotation.as_quat())


def wxyz_from_xyzw(xyzw: np.ndarray) -> np.ndarray:
    """The same for quaternions already taken out of scipy (``Rotation.as_quat()``, scalar
    last), (4,) or (N, 4)."""
    q = np.asarray(xyzw, dtype=np.float64)[..., _WXYZ_FROM_XYZW]
    if q.ndim == 1:
        return -q if q[0] < 0.0 else q
    return np.where(q[:, :1] < 0.0, -q, q)


def xyzw_from_wxyz(q: np.ndarray) -> np.ndarray:
    """A viser orientation (w, x, y, z) as a scalar-last quaternion, (4,) or (N, 4)."""
    return np.asarray(q, dtype=np.float64)[..., _XYZW_FROM_WXYZ]


def rotation_from_wxyz(q: np.ndarray) -> Rotation:
    """Inverse of :func:`wxyz` for one orientation (the ghost's start, the ride-along camera)."""
    return Rotation.from_quat(xyzw_from_wxyz(q))
