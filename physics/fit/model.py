"""The fitted model: parameters -> the exact solution's ω in the sensor's axes.

Parameter vector ``x`` (see :class:`Layout`):

- ``x[0:2]``: the moments, through the body's second moments of mass ``s = (sx, sy, sz)``
  (``sx = ∫ x² dm``, ...), ``log s = (q0, q1, -q0 - q1)``. The principal moments are then
  ``I = (sy + sz, sx + sz, sx + sy)``: positive and obeying the triangle inequality
  ``Ii + Ij >= Ik`` for every value of ``x``, as every real body's do; the common scale, which
  ω(t) cannot reveal, is fixed by the sum of the logs.
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

from poinsot.physics import FreeRigidBody
from poinsot.physics.fit.omega import free_omega

#: |log| of a second moment relative to their geometric mean is kept below this: a flat or
#: slender body (one second moment e^-25 ~ 1e-11 of the others) is still described.
LOG_LIMIT = 25.0
#: Second moments below this fraction of the largest are raised to it when converting moments
#: that break the triangle inequality (a noisy first estimate) into parameters.
SECOND_MOMENT_FLOOR = 1e-3
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
        """The parameter vector of moments (3,), ω0 (3,) and, as the layout has them, a rotation
        vector (3,) and a bias (3,) (``None``: zero)."""
        parts = [log_ratios(np.asarray(inertia, dtype=float)), np.asarray(omega0, dtype=float)]
        if self.rotation:
            parts.append(np.zeros(3) if rotvec is None else np.asarray(rotvec, dtype=float))
        if self.bias:
            parts.append(np.zeros(3) if bias is None else np.asarray(bias, dtype=float))
        return np.concatenate(parts)


def moments(x: NDArray[np.float64]) -> NDArray[np.float64]:
    """(3,) principal moments of the parameters ``x``, normalised so that the largest is 1."""
    q = np.clip([x[0], x[1], -x[0] - x[1]], -LOG_LIMIT, LOG_LIMIT)
    s = np.exp(q - np.max(q))
    inertia = np.array([s[1] + s[2], s[0] + s[2], s[0] + s[1]])
    return inertia / np.max(inertia)


def log_ratios(inertia: NDArray[np.float64]) -> NDArray[np.float64]:
    """(2,) the parameters ``x[0:2]`` of positive moments (3,), any scale.

    Moments that break the triangle inequality (possible for a noisy estimate) are moved onto
    the nearest admissible ones by raising the negative second moments to a small floor.
    """
    s = 0.5 * np.sum(inertia) - inertia  # sx = (Iy + Iz - Ix) / 2, ...
    s = np.maximum(s, SECOND_MOMENT_FLOOR * np.max(s))
    q = np.log(s)
    q -= np.mean(q)
    return q[:2]


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
    order = np.abs(signed) @ np.arange(3.0)
    q = np.array([x[0], x[1], -x[0] - x[1]])[order.round().astype(int)]
    out = x.copy()
    out[:2] = q[:2]
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


def predict(x: NDArray[np.float64], layout: Layout, tau: NDArray[np.float64]) -> NDArray:
    """(N, 3) the modelled sensor reading [rad/s] at the times ``tau`` (N,) after the first."""
    w = body_omega(x, tau)
    matrix = rotation_matrix(x, layout)
    if matrix is not None:
        w = w @ matrix  # row form of Rᵀ ω: the principal components back in sensor axes
    if layout.bias:
        w = w + x[layout.bias_slice]
    return w


def separatrix_distance(x: NDArray[np.float64]) -> float:
    """``(D - I2) / (I3 - I1)`` for the parameters, ``D = |L|²/2T`` (Pars' D, [Pars65 §13.12]).

    Positive in the major-axis family, negative in the minor-axis family, zero on the
    separatrix [LL76 §37]; the sorted moments ``I1 <= I2 <= I3`` are meant.
    """
    inertia = moments(x)
    w = x[2:5]
    m = inertia * w
    two_t = float(w @ m)
    if two_t <= 0.0:
        return 0.0
    order = np.sort(inertia)
    span = float(order[2] - order[0])
    if span <= 0.0:
        return 0.0
    return float((m @ m / two_t - order[1]) / span)
