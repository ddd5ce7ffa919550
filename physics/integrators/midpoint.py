"""The implicit midpoint rule on (m, R) [HNW93 §II.10], [HLW06 §IX].

It keeps every quadratic invariant of the coupled system exactly (up to the nonlinear solve):
|m|^2, 2T = m . I^-1 m, R^T R = 1 and the space angular momentum L = R m. For R' = R [w]x the
midpoint rule is R1 = R0 cay(h [w_mid]x), the Cayley transform, a rotation by
2 atan(h |w_mid| / 2) about w_mid.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial.transform import Rotation

from poinsot.physics.integrators.attitudes import attitudes_at
from poinsot.physics.integrators.interface import Trajectory, steps_per_interval

__all__ = ["run_midpoint"]

_EPS = np.finfo(float).eps

#: The fixed-point iteration of the midpoint rule stops when an update changes the midpoint by
#: less than this many units of |m| * eps: below that the change is rounding noise, and the
#: quadratic invariants are then kept to rounding.
_MIDPOINT_STOP_ULPS = 4.0
#: With a very small moment, rounding in m_i is amplified by 1/I_i and the updates stall at a
#: floor above that; an update that no longer shrinks while already below this fraction of |m|
#: is that floor, and the iteration stops there too.
_MIDPOINT_FLOOR = 1e-12
#: ... and gives up after this many iterations: the iteration contracts by about h |omega| per
#: sweep, so needing more means the step is far too large for the method to be meaningful.
_MIDPOINT_MAX_ITERATIONS = 60


def run_midpoint(
    inertia: np.ndarray, omega0: np.ndarray, attitude0: Rotation, t_eval: np.ndarray, h: float
) -> Trajectory:
    j1, j2, j3 = (1.0 / float(v) for v in inertia)
    m1, m2, m3 = (float(v) for v in inertia * omega0)
    n_steps = steps_per_interval(t_eval, h)
    dts = np.diff(t_eval, prepend=0.0)
    size = math.sqrt(m1 * m1 + m2 * m2 + m3 * m3)
    stop, floor = _MIDPOINT_STOP_ULPS * _EPS * size, _MIDPOINT_FLOOR * size
    mids: list[float] = []  # h * omega_mid per step, flat
    keep = mids.extend
    m_out = np.empty((len(t_eval), 3))
    for k, (n, dt) in enumerate(zip(n_steps.tolist(), dts.tolist(), strict=True)):
        if n:
            hh = 0.5 * dt / n
            for _ in range(n):
                # Midpoint x = (m0 + m1)/2 solves x = m0 + (h/2) x x (I^-1 x). Start from the
                # explicit half step (error O(h^2)); each sweep gains a factor ~ h |omega|.
                w1, w2, w3 = j1 * m1, j2 * m2, j3 * m3
                x1 = m1 + hh * (m2 * w3 - m3 * w2)
                x2 = m2 + hh * (m3 * w1 - m1 * w3)
                x3 = m3 + hh * (m1 * w2 - m2 * w1)
                previous = math.inf
                for _it in range(_MIDPOINT_MAX_ITERATIONS):
                    w1, w2, w3 = j1 * x1, j2 * x2, j3 * x3
                    y1 = m1 + hh * (x2 * w3 - x3 * w2)
                    y2 = m2 + hh * (x3 * w1 - x1 * w3)
                    y3 = m3 + hh * (x1 * w2 - x2 * w1)
                    change = abs(y1 - x1) + abs(y2 - x2) + abs(y3 - x3)
                    x1, x2, x3 = y1, y2, y3
                    if change <= stop or (change >= previous and change <= floor):
                        break
                    previous = change
                else:
                    raise ValueError(
                        f"implicit midpoint: the fixed-point iteration did not converge with "
                        f"step {2 * hh:g}; use a smaller step"
                    )
                m1, m2, m3 = 2.0 * x1 - m1, 2.0 * x2 - m2, 2.0 * x3 - m3
                # h * omega_mid, for the Cayley attitude update.
                keep((2.0 * hh * j1 * x1, 2.0 * hh * j2 * x2, 2.0 * hh * j3 * x3))
        m_out[k] = (m1, m2, m3)

    def increments(lo: int, hi: int) -> np.ndarray:
        # cay(h [w]x) = rotation about w by 2 atan(h |w| / 2): quaternion ∝ (h w / 2, 1).
        q = np.empty((4, hi - lo))
        q[:3] = 0.5 * np.array(mids[3 * lo : 3 * hi], dtype=float).reshape(hi - lo, 3).T
        q[3] = 1.0
        return q / np.linalg.norm(q, axis=0)

    total = len(mids) // 3
    attitude = attitudes_at(attitude0, increments, total, np.cumsum(n_steps))
    return Trajectory(m_out / inertia, attitude, total)
