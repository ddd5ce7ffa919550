"""Attitudes of the fixed-step methods: products of many small body-frame rotations.

A fixed-step method turns the body by one small rotation ``X_k`` per step, ``R_{k+1} = R_k X_k``.
The running product is sequential by nature; here it is formed for all requested step counts
at once by a product tree (vectorised, rounding ~log2(S) eps), chunk by chunk. Quaternions are
stored component-first, shape (4, n), so that each component is one contiguous array for the
products of :func:`poinsot.physics.core.rotations.hamilton`.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.spatial.transform import Rotation

from poinsot.physics.core.rotations import hamilton

__all__ = ["attitudes_at", "axis_products", "prefix_products"]


def _product(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Hamilton product of component-first (4, ...) stacks, so that R(p q) = R(p) R(q)."""
    return np.array(hamilton(p, q))


def _mul_axis(p: np.ndarray, axis: int, s: np.ndarray, c: np.ndarray) -> np.ndarray:
    """p X_axis, where X_axis = (sin(a/2) e_axis, cos(a/2)) is given by s = sin(a/2), c = cos(a/2).

    The general product with the two zero components dropped (8 products instead of 16).
    """
    j, k = (axis + 1) % 3, (axis + 2) % 3
    out = np.empty_like(p)
    out[axis] = p[3] * s + p[axis] * c
    out[j] = p[j] * c + p[k] * s
    out[k] = p[k] * c - p[j] * s
    out[3] = p[3] * c - p[axis] * s
    return out


def prefix_products(q: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """P_n = q_0 q_1 ... q_{n-1} for each n in ``counts``: (4, S) -> (4, len(counts)).

    The product is sequential by nature, and a Python loop over steps would cost as much as the
    integration. A product tree does it in O(S) vectorised work: level l holds the products of
    aligned runs of 2^l factors, and each prefix is the ordered product of the runs given by
    the binary digits of n (most significant first), gathered for all n at once. Rounding
    grows like log2(S) eps instead of S eps.
    """
    levels = [q]
    while levels[-1].shape[1] >= 2:
        top = levels[-1]
        pairs = top.shape[1] // 2
        levels.append(_product(top[:, 0 : 2 * pairs : 2], top[:, 1 : 2 * pairs : 2]))
    counts = np.asarray(counts, dtype=np.int64)
    acc = np.zeros((4, len(counts)))
    acc[3] = 1.0
    offset = np.zeros(len(counts), dtype=np.int64)
    for level in range(len(levels) - 1, -1, -1):
        take = (counts >> level) & 1 == 1
        if np.any(take):
            runs = levels[level][:, offset[take] >> level]
            acc[:, take] = _product(acc[:, take], runs)
            offset[take] += 1 << level
    return acc / np.linalg.norm(acc, axis=0)


#: Steps per chunk when turning per-step increments into attitudes: small enough that the
#: temporaries stay in cache and are reused (large fresh arrays cost page faults), large enough
#: that the numpy call overhead is negligible.
_CHUNK = 1 << 15


def attitudes_at(
    attitude0: Rotation,
    increments: Callable[[int, int], np.ndarray],
    total: int,
    counts: np.ndarray,
) -> Rotation:
    """Attitudes after ``counts[i]`` steps: R0 X_0 X_1 ... X_{counts[i]-1}.

    ``increments(lo, hi)`` returns the (4, hi - lo) body-frame step rotations X_lo ... X_{hi-1},
    component-first; ``total`` is the number of steps; ``counts``: (N,) integers in [0, total].
    Processed in chunks of :data:`_CHUNK` steps, carrying the running product across chunks.
    """
    counts = np.asarray(counts, dtype=np.int64)
    out = np.empty((4, len(counts)))
    running = attitude0.as_quat()[:, None]
    for lo in range(0, max(total, 1), _CHUNK):
        hi = min(lo + _CHUNK, total)
        chunk = increments(lo, hi)
        here = (counts >= lo) & (counts <= hi)
        ends = np.concatenate((counts[here] - lo, [hi - lo]))
        prefix = _product(running, prefix_products(chunk, ends))
        out[:, here] = prefix[:, :-1]
        running = prefix[:, -1:]
    return Rotation.from_quat(out.T)


def axis_products(angles: np.ndarray, axes: tuple[int, ...]) -> np.ndarray:
    """Quaternions of X_axes[0](a_0) X_axes[1](a_1) ..., rotations about body axes.

    angles: (C, S) [rad], one row per factor; returns (4, S), component-first.
    """
    half = 0.5 * angles
    s, c = np.sin(half), np.cos(half)
    result = np.zeros((4, angles.shape[1]))
    result[axes[0]] = s[0]
    result[3] = c[0]
    for row in range(1, len(axes)):
        result = _mul_axis(result, axes[row], s[row], c[row])
    return result
