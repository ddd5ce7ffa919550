"""Proper relabellings of the body axes: signed permutations with det +1.

The closed forms see one canonical body frame: the moments sorted ascending and, in the
minor-axis family, the axis the polhode circles (the *pole*) moved to the third place. An odd
permutation of the axes would turn a right-handed frame into a left-handed one, for which
Euler's equations change sign [LL76 §36, Eq. 36.5], so one axis is reversed to keep det = +1.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

__all__ = ["IDENTITY", "REVERSE", "AxisMap", "axis_map", "sorting_map"]


class AxisMap:
    """``x_internal = C @ x_user`` for a signed permutation ``C`` with det +1.

    Stored as ``index`` and ``sign`` so that ``x_internal[k] = sign[k] * x_user[index[k]]``.
    There are only 24 of them, so each is built once (:func:`axis_map`).

    Attributes:
        index, sign: (3,) the permutation and the signs.
        matrix: (3, 3) ``C``.
        quat: (4,) scalar-last quaternion of ``C``, the user -> internal map (it multiplies an
            internal attitude on the right).
        pairs, quat_tuple: plain-float copies for the single-time path.
        identity: True for the caller's own axes.
    """

    def __init__(self, index: tuple[int, ...], sign: tuple[float, ...]) -> None:
        self.index = np.asarray(index, dtype=int)
        self.sign = np.asarray(sign, dtype=float)
        self.matrix = np.zeros((3, 3))
        self.matrix[np.arange(3), self.index] = self.sign
        if round(np.linalg.det(self.matrix)) != 1:
            raise AssertionError("an axis relabelling must be a proper rotation")
        self.quat = Rotation.from_matrix(self.matrix).as_quat()
        self.pairs = tuple((int(i), float(x)) for i, x in zip(index, sign, strict=True))
        self.quat_tuple = tuple(float(x) for x in self.quat)
        self.identity = self.pairs == ((0, 1.0), (1, 1.0), (2, 1.0))

    def to_internal(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """(..., 3) user components -> internal components."""
        return self.sign * x[..., self.index]

    def to_internal_tuple(
        self, x: Sequence[float], signed: bool = True
    ) -> tuple[float, float, float]:
        """:meth:`to_internal` for one vector of plain floats (the same operations);
        ``signed=False`` only permutes (moments, which a reversed axis leaves as they are)."""
        (i0, s0), (i1, s1), (i2, s2) = self.pairs
        if not signed:
            return (x[i0], x[i1], x[i2])
        return (s0 * x[i0], s1 * x[i1], s2 * x[i2])

    def to_user_columns(self, cols: tuple[NDArray[np.float64], ...]) -> NDArray[np.float64]:
        """Stack internal components ``cols[k]`` (each (N,)) into user-order (N, 3)."""
        if self.identity:
            return np.stack(cols, axis=-1)
        out = np.empty((cols[0].shape[0], 3))
        for k in range(3):
            out[:, self.index[k]] = self.sign[k] * cols[k]
        return out

    def to_user_tuple(self, cols: tuple[float, ...]) -> list[float]:
        """:meth:`to_user_columns` for one sample of plain floats (a list in user order)."""
        out = [0.0, 0.0, 0.0]
        for (i, sign), col in zip(self.pairs, cols, strict=True):
            out[i] = sign * col
        return out

    def compose(self, other: AxisMap) -> AxisMap:
        """The map ``other ∘ self`` (apply self first)."""
        return _compose(self, other)


@functools.cache
def _compose(first: AxisMap, then: AxisMap) -> AxisMap:
    """``then ∘ first`` (the maps are singletons, so this table has at most 24² entries)."""
    return axis_map(
        tuple(int(i) for i in first.index[then.index]),
        tuple(float(x) for x in then.sign * first.sign[then.index]),
    )


@functools.cache
def axis_map(index: tuple[int, ...], sign: tuple[float, ...]) -> AxisMap:
    """The one :class:`AxisMap` with this permutation and these signs."""
    return AxisMap(index, sign)


def sorting_map(inertia: Sequence[float] | NDArray[np.float64]) -> AxisMap:
    """Proper relabelling that sorts the moments ascending (an odd permutation flips axis 1)."""
    values = inertia.tolist() if isinstance(inertia, np.ndarray) else list(inertia)
    order = tuple(sorted(range(3), key=values.__getitem__))  # stable, as argsort(kind="stable")
    inversions = sum(order[i] > order[j] for i in range(3) for j in range(i + 1, 3))
    parity = -1.0 if inversions % 2 else 1.0  # an odd permutation gets axis 1 reversed
    return axis_map(order, (parity, 1.0, 1.0))


#: The caller's own axes (the uniform motions work in them).
IDENTITY = axis_map((0, 1, 2), (1.0, 1.0, 1.0))
#: Reverse the sorted axes, pole = smallest moment becomes axis 3: ``x'' = (x3, x2, -x1)``.
REVERSE = axis_map((2, 1, 0), (1.0, 1.0, -1.0))
