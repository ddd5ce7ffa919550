"""Starting points of the fit: Euler's equations solved as a linear problem for the moments.

Once ω and dω/dt are known at every sample, Euler's equations ``I dω/dt + ω × (I ω) = 0``
[LL76 §36, Eq. 36.5] are linear and homogeneous in the inertia tensor ``I``: stacking them over
the samples gives ``A vec(I) = 0``, solved up to scale by the right singular vector of ``A``
with the smallest singular value. With the three diagonal entries as unknowns this gives the
moments in the sensor's axes; with all six entries of the symmetric tensor, its eigenvectors
also give the principal axes in the sensor's frame.

The nonlinear fit is then started from this estimate and from variants of it: each assignment
of the smallest, intermediate and largest moment to the three axes, each placed on either side
of the separatrix so that both families are tried [LL76 §37].
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from poinsot.physics.fit.model import ASSIGNMENTS, nearest_axes

# Symmetric basis matrices of the inertia tensor: the diagonal entries, then xy, xz, yz.
_BASIS = np.zeros((6, 3, 3))
_BASIS[0, 0, 0] = _BASIS[1, 1, 1] = _BASIS[2, 2, 2] = 1.0
_BASIS[3, 0, 1] = _BASIS[3, 1, 0] = 1.0
_BASIS[4, 0, 2] = _BASIS[4, 2, 0] = 1.0
_BASIS[5, 1, 2] = _BASIS[5, 2, 1] = 1.0
# A start is placed at least this fraction of I3 - I1 away from the separatrix value of I2.
_FAMILY_MARGIN = 0.05


def euler_estimate(
    omega: NDArray[np.float64], domega: NDArray[np.float64], full_tensor: bool
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Moments and principal axes from Euler's equations, linear least squares.

    Args:
        omega: (N, 3) smoothed ω [rad/s], sensor axes.
        domega: (N, 3) its time derivative [rad/s²].
        full_tensor: fit the six entries of the inertia tensor (principal axes turned away from
            the sensor's) rather than the three diagonal ones.

    Returns:
        ``(inertia (3,), matrix (3, 3))``: the moments, largest 1 (an entry may be negative when
        the data are poor), and the rotation matrix sensor -> principal axes, whose row ``k``
        is the principal axis closest to sensor axis ``k`` (the identity if not ``full_tensor``).
    """
    basis = _BASIS if full_tensor else _BASIS[:3]
    # Column j: B_j dω/dt + ω × (B_j ω), the equations' coefficient of the j-th entry.
    columns = [domega @ b.T + np.cross(omega, omega @ b.T) for b in basis]
    a = np.stack([c.ravel() for c in columns], axis=1)
    vec = np.linalg.svd(a, full_matrices=False)[2][-1]
    if np.sum(vec[:3]) < 0.0:
        vec = -vec
    tensor = np.einsum("j,jkl->kl", vec, basis)
    if not full_tensor:
        inertia = np.diag(tensor).copy()
        return inertia / np.max(np.abs(inertia)), np.eye(3)
    values, vectors = np.linalg.eigh(tensor)
    matrix, inertia = nearest_axes(vectors.T, values)
    return inertia / np.max(np.abs(inertia)), matrix


@dataclass(frozen=True)
class Start:
    """One starting point: moments (3,) in the principal axes' order, and ``steady``, the axis
    whose component keeps its sign in the family this start lies in (``dn`` in [LL76 §37, Eq.
    37.10]): the largest moment's axis in the major-axis family, the smallest's in the
    minor-axis family.
    """

    inertia: NDArray[np.float64]
    steady: int


def family_starts(inertia: NDArray[np.float64], omega0: NDArray[np.float64]) -> list[Start]:
    """Up to 12 starts: every assignment of the sorted moments to the axes, in both families.

    The first is the estimate itself (kept 5 % of ``v3 - v1`` from the separatrix), the second
    the same axes in the other family. For the
    axes ``(a1, a2, a3)`` of the smallest, intermediate and largest moment ``(v1, v2, v3)``, the
    separatrix value of ``I2`` for this ω0 is ``I2* = (v1² ω1² + v3² ω3²) / (v1 ω1² + v3 ω3²)``
    (``Δ2 = G² - 2T I2 = 0``, [LL76 §37]); ``I2 < I2*`` is the major-axis family. Each start
    puts ``I2`` on one side of ``I2*``, as far from it as the estimate's own ``v2`` (at least
    5 % of ``v3 - v1``); a family this ω0 cannot have (``I2*`` at an end) is skipped.
    """
    values = np.sort(np.abs(inertia))
    if values[0] <= 0.0 or values[2] - values[0] <= 1e-9 * values[2]:
        values = np.array([0.5, 0.75, 1.0])  # no usable estimate: a generic body
    own = tuple(int(k) for k in np.argsort(np.abs(inertia)))
    order = [own] + [a for a in ASSIGNMENTS if a != own]
    starts: list[Start] = []
    for a1, a2, a3 in order:
        v1, v2, v3 = values
        w1, w3 = omega0[a1] ** 2, omega0[a3] ** 2
        if w1 + w3 == 0.0:
            continue
        star = (v1 * v1 * w1 + v3 * v3 * w3) / (v1 * w1 + v3 * w3)
        span = v3 - v1
        gap = max(abs(v2 - star), _FAMILY_MARGIN * span)
        natural = 1.0 if v2 <= star else -1.0  # +1: the major-axis side
        for side in (natural, -natural):
            i2 = star - side * gap
            lo, hi = v1 + 0.02 * span, v3 - 0.02 * span
            if not lo < star - side * _FAMILY_MARGIN * span < hi:
                continue
            moments = np.empty(3)
            moments[[a1, a2, a3]] = v1, float(np.clip(i2, lo, hi)), v3
            starts.append(Start(moments, a3 if side > 0 else a1))
    return starts
