"""The fitted model: parameters -> the exact solution's ω in the sensor's axes.

Parameter vector ``x`` (see :class:`Layout`):

- ``x[0:2]``: the moments, through the body's second moments of mass ``s = (sx, sy, sz)``
  (``sx = ∫ x² dm``, ...) as a direction on the unit sphere, ``(θ, φ) = x[0:2]``:
  ``s ∝ ((sin θ cos φ)², (sin θ sin φ)², cos² θ)``. The principal moments are then
  ``I = (sy + sz, sx + sz, sx + sy)``: positive and obeying the triangle inequality
  ``Ii + Ij >= Ik`` for every value of ``x``, as every real body's do, the flat and slender
  limits included at finite angles (a logarithm of ``s`` would put them at infinity, where the
  fit would stall); the common scale, which ω(t) cannot reveal, is fixed by ``|s| = 1``.
- ``x[2:5]``: ω0 [rad/s], the body's angular velocity at the first sample, principal axes.
- then, if fitted, the rotation vector [rad] of the rotation sensor -> principal axes,
- then, if fitted, the gyroscope's constant bias [rad/s] in the sensor's axes.

The measured ω is modelled as ``Rᵀ ω_body(t - t[0]) + bias``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from poinsot.physics.core.free_body import FreeRigidBody
from poinsot.physics.fit.omega import free_omega

#: Starting points keep each second moment at least this fraction of their sum (see angles).
START_FLOOR = 1e-2
#: The six orders of three axes (as index tuples).
ASSIGNMENTS = ((0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0))


@dataclass(frozen=True)
class Layout:
    """Which parameters a fit has: 5 always, 3 more for a rotation, 3 more for a bias."""

    rotation: bool
    bias: bool

    @property
    def size(self) -> int:
        return 5 + 3 * self.rotation + 3 * self.bias

    @property
    def rotation_slice(self) -> slice:
        return slice(5, 8) if self.rotation else slice(0, 0)

    @property
    def bias_slice(self) -> slice:
        start = 8 if self.rotation else 5
        return slice(start, start + 3) if self.bias else slice(0, 0)

    def pack(self, inertia, omega0, rotvec=None, bias=None) -> NDArray[np.float64]:
        """The starting parameter vector of moments (3,), ω0 (3,) and, as the layout has them,
        a rotation vector (3,) and a bias (3,) (``None``: zero). The moments are kept off the
        edge of the triangle inequality (see :func:`angles`)."""
        start = angles(np.asarray(inertia, dtype=float), START_FLOOR)
        parts = [start, np.asarray(omega0, dtype=float)]
        if self.rotation:
            parts.append(np.zeros(3) if rotvec is None else np.asarray(rotvec, dtype=float))
        if self.bias:
            parts.append(np.zeros(3) if bias is None else np.asarray(bias, dtype=float))
        return np.concatenate(parts)


def moments(x: NDArray[np.float64]) -> NDArray[np.float64]:
    """(3,) principal moments of the parameters ``x``, normalised so that the largest is 1."""
    theta, phi = float(x[0]), float(x[1])
    sin_t = np.sin(theta)
    s = np.array([(sin_t * np.cos(phi)) ** 2, (sin_t * np.sin(phi)) ** 2, np.cos(theta) ** 2])
    inertia = np.sum(s) - s  # (sy + sz, sx + sz, sx + sy)
    return inertia / np.max(inertia)


def angles(inertia: NDArray[np.float64], floor: float = 0.0) -> NDArray[np.float64]:
    """(2,) the parameters ``x[0:2]`` of positive moments (3,), any scale.

    Second moments below ``floor`` times their sum are raised to it: moments that break the
    triangle inequality (a noisy first estimate can) move onto admissible ones. A start needs
    ``floor > 0``: exactly on the edge (a second moment zero) the derivative with respect to
    the angle that would bring it back vanishes, and the fit could never leave the edge.
    """
    s = np.maximum(0.5 * np.sum(inertia) - inertia, 0.0)  # sx = (Iy + Iz - Ix) / 2, ...
    s = np.maximum(s / np.sum(s), floor)
    r = np.sqrt(s / np.sum(s))
    return np.array([np.arccos(np.clip(r[2], 0.0, 1.0)), np.arctan2(r[1], r[0])])


def rotation_matrix(x: NDArray[np.float64], layout: Layout) -> NDArray[np.float64] | None:
    """The 3×3 matrix sensor -> principal axes, or ``None`` if the layout fits none."""
    if not layout.rotation:
        return None
    return Rotation.from_rotvec(x[layout.rotation_slice]).as_matrix()


def nearest_axes(
    axes: NDArray[np.float64], values: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Rows ``axes`` (3, 3) (unit principal axes in sensor coordinates) reordered so that row k
    lies nearest sensor axis k, with signs making a proper rotation close to the identity;
    ``values`` (3,) (their moments) reordered alike."""
    best = max(ASSIGNMENTS, key=lambda p: sum(abs(axes[p[k], k]) for k in range(3)))
    matrix = axes[list(best)]
    matrix = matrix * np.where(np.diag(matrix) < 0.0, -1.0, 1.0)[:, None]
    if np.linalg.det(matrix) < 0.0:
        weakest = int(np.argmin(np.abs(np.diag(matrix))))
        matrix[weakest] = -matrix[weakest]
    return matrix, values[list(best)]


def relabelled(x: NDArray[np.float64], layout: Layout) -> NDArray[np.float64]:
    """The same fitted motion with its principal axes labelled after the nearest sensor axes.

    With a fitted rotation, relabelling the principal axes (and turning the rotation by the
    same signed permutation) leaves the modelled reading unchanged; this picks the labelling
    whose rotation is smallest, so that moment k belongs to the axis nearest sensor axis k.
    """
    matrix = rotation_matrix(x, layout)
    if matrix is None:
        return x
    nearest, _ = nearest_axes(matrix, np.zeros(3))
    signed = nearest @ matrix.T  # a signed permutation: new principal = signed @ old
    out = x.copy()
    out[:2] = angles(np.abs(signed) @ moments(x))
    out[2:5] = signed @ x[2:5]
    out[layout.rotation_slice] = Rotation.from_matrix(nearest).as_rotvec()
    return out


def body(x: NDArray[np.float64]) -> FreeRigidBody:
    """The free body of the parameters (moments normalised to a largest of 1, ω0 at τ = 0)."""
    return FreeRigidBody(moments(x), x[2:5])


def body_omega(x: NDArray[np.float64], tau: NDArray[np.float64]) -> NDArray[np.float64]:
    """(N, 3) the body's ω [rad/s], principal axes, at the times ``tau`` (N,) after the first
    (the fast evaluation of :func:`~poinsot.physics.fit.omega.free_omega`)."""
    return free_omega(moments(x), x[2:5], tau)


def separatrix_distance(inertia: NDArray[np.float64], omega0: NDArray[np.float64]) -> float:
    """``(D - I2) / (I3 - I1)`` of the body (moments (3,), ω0 (3,)), ``D = |L|²/2T`` (Pars' D,
    [Pars65 §13.12]) and ``I1 <= I2 <= I3`` the sorted moments.

    Positive in the major-axis family, negative in the minor-axis family, zero on the
    separatrix [LL76 §37]; 0 for a body at rest or with three equal moments.
    """
    m = inertia * omega0
    two_t = float(omega0 @ m)
    order = np.sort(inertia)
    span = float(order[2] - order[0])
    if two_t <= 0.0 or span <= 0.0:
        return 0.0
    return float((m @ m / two_t - order[1]) / span)
