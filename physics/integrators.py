"""Numerical integrators of the free rigid body, to measure the exact solution against.

Four methods share one interface, :func:`integrate`, and one registry, :data:`INTEGRATORS`,
which the tests and the work-precision report loop over:

- ``RK45`` and ``DOP853``: scipy's adaptive Runge-Kutta pairs (Dormand-Prince 5(4) and 8(5,3))
  on Euler's equations for the body angular velocity plus the quaternion kinematics of the
  attitude. They conserve nothing exactly; their error grows like t^2 over long times.
- ``splitting``: the explicit symplectic splitting of Dullweber, Leimkuhler and McLachlan,
  J. Chem. Phys. 107 (1997) 5840 (after McLachlan, SIAM J. Sci. Comput. 16 (1995) 151).
  The kinetic energy is split as T = T1 + T2 + T3, Ti = m_i^2 / (2 I_i); each piece is a rotation
  about one principal axis that is solved exactly, and the symmetric Strang composition
  1(h/2) 2(h/2) 3(h) 2(h/2) 1(h/2) is second order. |m| = |L| is kept to rounding (every
  sub-step is a rotation of m); the energy error stays bounded (backward error analysis).
- ``midpoint``: the implicit midpoint rule on (m, R). It keeps every quadratic invariant of the
  coupled system exactly (up to the nonlinear solve): |m|^2, 2T = m . I^-1 m, R^T R = 1 and the
  space angular momentum L = R m. For R' = R [w]x the midpoint rule is R1 = R0 cay(h [w_mid]x),
  the Cayley transform, a rotation by 2 atan(h |w_mid| / 2) about w_mid.

:class:`Propagation` advances the same methods piece by piece, carrying their whole state
(scipy's stepper for the adaptive pairs, the grid state for the fixed-step methods): what an
animation needs to show a method's solution frame by frame without restarting it.

Conventions (as in :mod:`physics`): ``omega`` is the body-frame angular velocity, ``m = I omega``
the body angular momentum, the attitude ``R`` maps body to space coordinates and obeys
``R' = R [omega]x``; quaternions are scipy's, scalar last ``(x, y, z, w)``. The principal moments
are used in the caller's order: Euler's equations and the splitting hold in any labelling.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal, NamedTuple

import numpy as np
from scipy.integrate import DOP853, RK45, OdeSolver, solve_ivp
from scipy.spatial.transform import Rotation

__all__ = ["INTEGRATORS", "Integrator", "Propagation", "State", "Trajectory", "integrate"]

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


class Trajectory(NamedTuple):
    """Samples of a numerical solution at the requested times ``t_eval`` (N of them)."""

    omega: np.ndarray
    """(N, 3) body-frame angular velocity [rad / time unit], caller's axes."""
    attitude: Rotation
    """Stack of N rotations, body -> space."""
    cost: int
    """Right-hand-side evaluations (adaptive methods) or steps taken (fixed-step methods)."""


@dataclass(frozen=True)
class Integrator:
    """One registered method, with what a caller needs to drive it."""

    name: str
    """Registry key, e.g. ``"DOP853"``."""
    title: str
    """Human-readable name with its reference."""
    kind: Literal["fixed", "adaptive"]
    """``fixed``: the setting is the (maximum) step size [time units]; ``adaptive``: it is the
    relative tolerance (the absolute tolerance is scaled from it, see :func:`integrate`)."""
    order: int
    """Classical order of accuracy (global error ~ h^order)."""
    default_setting: float
    """Step size or relative tolerance used when the caller gives none."""
    conserves_norm: bool
    """True if |L| is conserved to rounding (geometric methods)."""
    run: Callable[[np.ndarray, np.ndarray, Rotation, np.ndarray, float], Trajectory]
    """``run(inertia, omega0, attitude0, t_eval, setting)`` on validated inputs."""


# --------------------------------------------------------------------------------------------
# Quaternion helpers (scalar last). Internally quaternions are stored component-first,
# shape (4, n), so that each component is one contiguous array for the vectorised products.


def _quat_mul(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Hamilton product p q of (4, ...) arrays, scalar last, so that R(p q) = R(p) R(q)."""
    px, py, pz, pw = p
    qx, qy, qz, qw = q
    return np.array(
        (
            pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx,
            pw * qz + px * qy - py * qx + pz * qw,
            pw * qw - px * qx - py * qy - pz * qz,
        )
    )


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


def _prefix_products(q: np.ndarray, counts: np.ndarray) -> np.ndarray:
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
        levels.append(_quat_mul(top[:, 0 : 2 * pairs : 2], top[:, 1 : 2 * pairs : 2]))
    counts = np.asarray(counts, dtype=np.int64)
    acc = np.zeros((4, len(counts)))
    acc[3] = 1.0
    offset = np.zeros(len(counts), dtype=np.int64)
    for level in range(len(levels) - 1, -1, -1):
        take = (counts >> level) & 1 == 1
        if np.any(take):
            runs = levels[level][:, offset[take] >> level]
            acc[:, take] = _quat_mul(acc[:, take], runs)
            offset[take] += 1 << level
    return acc / np.linalg.norm(acc, axis=0)


#: Steps per chunk when turning per-step increments into attitudes: small enough that the
#: temporaries stay in cache and are reused (large fresh arrays cost page faults), large enough
#: that the numpy call overhead is negligible.
_CHUNK = 1 << 15


def _attitudes_at(
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
        prefix = _quat_mul(running, _prefix_products(chunk, ends))
        out[:, here] = prefix[:, :-1]
        running = prefix[:, -1:]
    return Rotation.from_quat(out.T)


def _axis_products(angles: np.ndarray, axes: tuple[int, ...]) -> np.ndarray:
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


# --------------------------------------------------------------------------------------------
# Fixed-step grid


def _steps_per_interval(t_eval: np.ndarray, h: float) -> np.ndarray:
    """Number of equal steps between consecutive output times (the first from t = 0).

    Each interval dt is cut into ceil(dt / h) equal steps of size <= h; the 1e-9 slack keeps an
    interval that is an integer multiple of h (up to rounding) at exactly that multiple.
    """
    dt = np.diff(t_eval, prepend=0.0)
    n = np.ceil(dt / h - 1e-9).astype(np.int64)
    return np.where(dt > 0.0, np.maximum(n, 1), 0)


# --------------------------------------------------------------------------------------------
# Adaptive Runge-Kutta (scipy)


def _euler_quaternion_rhs(inertia: np.ndarray) -> Callable[[float, np.ndarray], np.ndarray]:
    """Right-hand side of the adaptive pairs: Euler's equations for omega and the quaternion
    kinematics of the attitude, state y = (omega1, omega2, omega3, x, y, z, w)."""
    i1, i2, i3 = (float(v) for v in inertia)
    # Euler's equations I1 w1' = (I2 - I3) w2 w3 and cyclic (Landau 36.5).
    a1, a2, a3 = (i2 - i3) / i1, (i3 - i1) / i2, (i1 - i2) / i3

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        # Plain floats: a 7-vector is far cheaper as Python scalars than as numpy ops.
        w1, w2, w3, x, yq, z, w = y.tolist()
        return np.array(
            (
                a1 * w2 * w3,
                a2 * w3 * w1,
                a3 * w1 * w2,
                # q' = q (omega, 0) / 2, i.e. R' = R [omega]x (body angular velocity).
                0.5 * (w * w1 + yq * w3 - z * w2),
                0.5 * (w * w2 + z * w1 - x * w3),
                0.5 * (w * w3 + x * w2 - yq * w1),
                -0.5 * (x * w1 + yq * w2 + z * w3),
            )
        )

    return rhs


def _scipy_atol(omega0: np.ndarray, rtol: float) -> np.ndarray:
    """Absolute tolerance of the adaptive pairs: rtol * max|omega0| on omega, rtol on the unit
    quaternion (a relative tolerance alone would be meaningless where a component crosses 0)."""
    scale = max(float(np.max(np.abs(omega0))), np.finfo(float).tiny)
    return rtol * np.array([scale, scale, scale, 1.0, 1.0, 1.0, 1.0])


def _run_scipy(
    method: str,
) -> Callable[[np.ndarray, np.ndarray, Rotation, np.ndarray, float], Trajectory]:
    def run(
        inertia: np.ndarray,
        omega0: np.ndarray,
        attitude0: Rotation,
        t_eval: np.ndarray,
        rtol: float,
    ) -> Trajectory:
        rhs = _euler_quaternion_rhs(inertia)
        y0 = np.concatenate((omega0, attitude0.as_quat()))
        atol = _scipy_atol(omega0, rtol)
        if t_eval[-1] == 0.0:
            ys = np.repeat(y0[:, None], len(t_eval), axis=1)
            nfev = 0
        else:
            # solve_ivp wants strictly increasing output times; repeated ones are copied back.
            times, where = np.unique(t_eval, return_inverse=True)
            sol = solve_ivp(
                rhs,
                (0.0, float(times[-1])),
                y0,
                method=method,
                t_eval=times,
                rtol=rtol,
                atol=atol,
            )
            if sol.status != 0:
                raise RuntimeError(f"{method} failed: {sol.message}")
            ys, nfev = sol.y[:, where], int(sol.nfev)
        # The quaternion's norm drifts like any other error; from_quat normalises it.
        return Trajectory(ys[:3].T.copy(), Rotation.from_quat(ys[3:].T), nfev)

    return run


# --------------------------------------------------------------------------------------------
# Dullweber-Leimkuhler-McLachlan splitting


def _run_splitting(
    inertia: np.ndarray, omega0: np.ndarray, attitude0: Rotation, t_eval: np.ndarray, h: float
) -> Trajectory:
    i1, i2, i3 = (float(v) for v in inertia)
    m1, m2, m3 = (float(v) for v in inertia * omega0)
    n_steps = _steps_per_interval(t_eval, h)
    dts = np.diff(t_eval, prepend=0.0)
    cos, sin = math.cos, math.sin
    angles: list[float] = []  # five sub-step angles per step, flat
    keep = angles.extend
    m_out = np.empty((len(t_eval), 3))
    # The sequential part is a scalar recurrence on three floats: plain Python floats cost
    # ~1 us per step here, an order of magnitude less than small numpy arrays would.
    for k, (n, dt) in enumerate(zip(n_steps.tolist(), dts.tolist(), strict=True)):
        if n:
            step = dt / n
            # Flow of T_i = m_i^2 / (2 I_i) for time tau: m_i fixed, m turns about e_i by
            # -tau m_i / I_i (m' = m x omega_i), R turns by +tau m_i / I_i (R' = R [omega_i]x).
            half1, half2, full3 = 0.5 * step / i1, 0.5 * step / i2, step / i3
            for _ in range(n):
                a = half1 * m1
                c, s = cos(a), sin(a)
                m2, m3 = c * m2 + s * m3, c * m3 - s * m2
                b = half2 * m2
                c, s = cos(b), sin(b)
                m3, m1 = c * m3 + s * m1, c * m1 - s * m3
                g = full3 * m3
                c, s = cos(g), sin(g)
                m1, m2 = c * m1 + s * m2, c * m2 - s * m1
                d = half2 * m2
                c, s = cos(d), sin(d)
                m3, m1 = c * m3 + s * m1, c * m1 - s * m3
                e = half1 * m1
                c, s = cos(e), sin(e)
                m2, m3 = c * m2 + s * m3, c * m3 - s * m2
                keep((a, b, g, d, e))
        m_out[k] = (m1, m2, m3)

    def increments(lo: int, hi: int) -> np.ndarray:
        per_step = np.array(angles[5 * lo : 5 * hi], dtype=float).reshape(hi - lo, 5).T
        # R_{n+1} = R_n X1(a) X2(b) X3(g) X2(d) X1(e), the composition of the m sub-steps.
        return _axis_products(per_step, (0, 1, 2, 1, 0))

    total = len(angles) // 5
    attitude = _attitudes_at(attitude0, increments, total, np.cumsum(n_steps))
    return Trajectory(m_out / inertia, attitude, total)


# --------------------------------------------------------------------------------------------
# Implicit midpoint


def _run_midpoint(
    inertia: np.ndarray, omega0: np.ndarray, attitude0: Rotation, t_eval: np.ndarray, h: float
) -> Trajectory:
    j1, j2, j3 = (1.0 / float(v) for v in inertia)
    m1, m2, m3 = (float(v) for v in inertia * omega0)
    n_steps = _steps_per_interval(t_eval, h)
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
    attitude = _attitudes_at(attitude0, increments, total, np.cumsum(n_steps))
    return Trajectory(m_out / inertia, attitude, total)


# --------------------------------------------------------------------------------------------
# Registry and entry point

INTEGRATORS: dict[str, Integrator] = {
    "RK45": Integrator(
        name="RK45",
        title="Dormand-Prince 5(4), scipy solve_ivp (Euler + quaternion)",
        kind="adaptive",
        order=5,
        default_setting=1e-8,
        conserves_norm=False,
        run=_run_scipy("RK45"),
    ),
    "DOP853": Integrator(
        name="DOP853",
        title="Dormand-Prince 8(5,3), scipy solve_ivp (Euler + quaternion)",
        kind="adaptive",
        order=8,
        default_setting=1e-10,
        conserves_norm=False,
        run=_run_scipy("DOP853"),
    ),
    "splitting": Integrator(
        name="splitting",
        title="Symplectic splitting, Dullweber-Leimkuhler-McLachlan 1997 (Strang, 1-2-3-2-1)",
        kind="fixed",
        order=2,
        default_setting=1e-2,
        conserves_norm=True,
        run=_run_splitting,
    ),
    "midpoint": Integrator(
        name="midpoint",
        title="Implicit midpoint rule on (m, R) (Cayley attitude update)",
        kind="fixed",
        order=2,
        default_setting=1e-2,
        conserves_norm=True,
        run=_run_midpoint,
    ),
}


def integrate(
    method: str,
    inertia: np.typing.ArrayLike,
    omega0: np.typing.ArrayLike,
    attitude0: Rotation | None,
    t_eval: np.typing.ArrayLike,
    setting: float | None = None,
) -> Trajectory:
    """Integrate the free rigid body numerically from t = 0 and sample it at ``t_eval``.

    Parameters
    ----------
    method
        A key of :data:`INTEGRATORS`: ``"RK45"``, ``"DOP853"``, ``"splitting"``, ``"midpoint"``.
    inertia
        (3,) positive finite principal moments, any order (the caller's body axes).
    omega0
        (3,) body-frame angular velocity at t = 0 [rad / time unit].
    attitude0
        Single scipy Rotation, body -> space at t = 0; None means the identity.
    t_eval
        (N,) output times [time units], finite, >= 0, non-decreasing; N >= 1.
    setting
        Fixed-step methods: the largest step [time units]; every interval between consecutive
        output times (and from 0 to the first) is cut into equal steps no longer than this.
        Adaptive methods: the relative tolerance ``rtol``; the absolute tolerance is
        ``rtol * max|omega0|`` on omega and ``rtol`` on the unit quaternion.
        None: the method's ``default_setting``.

    Returns
    -------
    Trajectory
        ``omega`` (N, 3), ``attitude`` (stack of N rotations), ``cost`` (RHS evaluations or
        steps). Unpacks as a tuple ``omega, attitude, cost``.
    """
    integrator, inertia, omega0, attitude0, value = _validated(
        method, inertia, omega0, attitude0, setting
    )
    t_eval = np.atleast_1d(np.asarray(t_eval, dtype=float))
    if t_eval.ndim != 1 or len(t_eval) == 0 or not np.all(np.isfinite(t_eval)):
        raise ValueError("t_eval must be a non-empty 1-D array of finite times")
    if t_eval[0] < 0.0 or np.any(np.diff(t_eval) < 0.0):
        raise ValueError("t_eval must be non-negative and non-decreasing")
    return integrator.run(inertia, omega0, attitude0, t_eval, value)


def _validated(
    method: str,
    inertia: np.typing.ArrayLike,
    omega0: np.typing.ArrayLike,
    attitude0: Rotation | None,
    setting: float | None,
) -> tuple[Integrator, np.ndarray, np.ndarray, Rotation, float]:
    """The checks shared by :func:`integrate` and :class:`Propagation` (readable ValueErrors)."""
    if method not in INTEGRATORS:
        raise ValueError(f"unknown method {method!r}; choose one of {sorted(INTEGRATORS)}")
    integrator = INTEGRATORS[method]
    inertia = np.asarray(inertia, dtype=float)
    omega0 = np.asarray(omega0, dtype=float)
    if inertia.shape != (3,) or not np.all(np.isfinite(inertia)) or np.any(inertia <= 0.0):
        raise ValueError(f"inertia must be three positive finite numbers, got {inertia!r}")
    if omega0.shape != (3,) or not np.all(np.isfinite(omega0)):
        raise ValueError(f"omega0 must be three finite numbers, got {omega0!r}")
    if attitude0 is None:
        attitude0 = Rotation.identity()
    elif not isinstance(attitude0, Rotation) or not attitude0.single:
        raise ValueError("attitude0 must be a single scipy Rotation or None")
    value = integrator.default_setting if setting is None else float(setting)
    if not (math.isfinite(value) and value > 0.0):
        raise ValueError(f"setting must be a positive finite number, got {setting!r}")
    return integrator, inertia, omega0, attitude0, value


# --------------------------------------------------------------------------------------------
# Piecewise propagation (an animation advances the solution a little at every frame)

#: scipy's stepper classes behind the adaptive entries of the registry.
_SCIPY_STEPPERS: dict[str, type[OdeSolver]] = {"RK45": RK45, "DOP853": DOP853}
#: A requested time within this many steps' rounding of a grid time counts as that grid time
#: (the same slack as :func:`_steps_per_interval`).
_GRID_SLACK = 1e-9


class State(NamedTuple):
    """A numerical solution at one time."""

    t: float
    """The time of this state [time units] (behind the requested time if the work ran out)."""
    omega: np.ndarray
    """(3,) body-frame angular velocity [rad / time unit], caller's axes."""
    attitude: Rotation
    """Single rotation, body -> space."""
    cost: int
    """Total work since the start: RHS evaluations (adaptive) or steps (fixed-step)."""


class Propagation:
    """One numerical solution started at ``t0``, advanced piece by piece with the integrator's
    whole state carried from call to call.

    :func:`integrate` solves from t = 0 to the last requested time in one call. An animation
    needs the solution a little further at every frame, without redoing the past and without
    changing it: restarting a method at each frame would, for the adaptive pairs, throw away
    the step-size control and force at least one step per frame, a far more accurate run than
    the method at that tolerance really is (RK45 at rtol 1e-3 takes steps of about one time
    unit here; a frame is 1/60 of one). So this class keeps

    - for the adaptive pairs, scipy's stepper object (its step size and error history
      included); a time between two steps is read from the stepper's dense output, which is
      how ``solve_ivp`` computes its ``t_eval`` samples. The steps are those of one
      ``integrate`` call with the same tolerance (up to the last one, which ``solve_ivp``
      shortens to land on its final output time);
    - for the fixed-step methods, the state on the grid ``t0 + k h``; a time between grid
      points is reached by one shorter step from the grid state that is not carried, so the
      trajectory does not depend on when, or how often, it is looked at.

    ``advance(t, max_cost)`` bounds the work of one call (an animation frame must not stall on
    a tiny step or a tight tolerance); the state it returns then lies behind ``t``, and the
    next call continues from there.
    """

    def __init__(
        self,
        method: str,
        inertia: np.typing.ArrayLike,
        omega0: np.typing.ArrayLike,
        attitude0: Rotation | None = None,
        setting: float | None = None,
        t0: float = 0.0,
    ) -> None:
        """Arguments as for :func:`integrate`; ``omega0`` and ``attitude0`` hold at ``t0``."""
        integrator, inertia, omega0, attitude0, value = _validated(
            method, inertia, omega0, attitude0, setting
        )
        if not math.isfinite(t0):
            raise ValueError(f"t0 must be finite, got {t0!r}")
        self.integrator, self.setting, self.t0 = integrator, value, float(t0)
        self._inertia = inertia
        self._omega, self._attitude = omega0.copy(), attitude0
        self._steps = 0  # fixed-step: grid steps taken, the carried state is at t0 + steps h
        self._cost = 0
        self._stepper: OdeSolver | None = None
        self._dense: Callable[[float], np.ndarray] | None = None
        if integrator.kind == "adaptive":
            self._stepper = _SCIPY_STEPPERS[method](
                _euler_quaternion_rhs(inertia),
                self.t0,
                np.concatenate((omega0, attitude0.as_quat())),
                t_bound=math.inf,
                rtol=value,
                atol=_scipy_atol(omega0, value),
            )

    @property
    def method(self) -> str:
        return self.integrator.name

    @property
    def t(self) -> float:
        """Time of the carried state: the last step's end (adaptive), the grid time (fixed)."""
        if self._stepper is not None:
            return float(self._stepper.t)
        return self.t0 + self._steps * self.setting

    @property
    def cost(self) -> int:
        return self._cost

    def advance(self, t: float, max_cost: int | None = None) -> State:
        """The solution at time ``t``, or at the furthest time reached when ``max_cost``
        (RHS evaluations or steps in this call) runs out first. ``t`` may not lie before the
        start of the last step taken (ValueError): the past is not kept."""
        t = float(t)
        if not math.isfinite(t):
            raise ValueError(f"t must be finite, got {t!r}")
        if max_cost is not None and max_cost < 1:
            raise ValueError(f"max_cost must be at least 1, got {max_cost!r}")
        if self._stepper is not None:
            return self._advance_adaptive(t, max_cost)
        return self._advance_fixed(t, max_cost)

    def _advance_adaptive(self, t: float, max_cost: int | None) -> State:
        stepper = self._stepper
        assert stepper is not None
        start = self.t0 if self._dense is None else float(stepper.t_old)
        if t < start:
            raise ValueError(f"t = {t:g} lies before this propagation's last step ({start:g})")
        nfev0 = stepper.nfev
        stepped = False
        while stepper.t < t and (max_cost is None or stepper.nfev - nfev0 < max_cost):
            message = stepper.step()
            if stepper.status == "failed":
                raise RuntimeError(f"{self.method} failed: {message}")
            stepped = True
        if stepped:
            self._dense = stepper.dense_output()
        self._cost = int(stepper.nfev)
        reached = min(t, float(stepper.t))
        if reached == stepper.t or self._dense is None:
            y = np.asarray(stepper.y, dtype=float)
        else:
            y = np.asarray(self._dense(reached), dtype=float)
        # The quaternion's norm drifts like any other error; from_quat normalises it.
        return State(reached, y[:3].copy(), Rotation.from_quat(y[3:]), self._cost)

    def _advance_fixed(self, t: float, max_cost: int | None) -> State:
        h, grid = self.setting, self.t
        if t < grid - _GRID_SLACK * h:
            raise ValueError(f"t = {t:g} lies before this propagation's grid time {grid:g}")
        whole = max(int(math.floor((t - grid) / h + _GRID_SLACK)), 0)
        if max_cost is not None and whole >= max_cost:
            whole, rest = max_cost, 0.0
        else:
            rest = max(t - (grid + whole * h), 0.0)
        if whole == 0 and rest == 0.0:
            return State(grid, self._omega.copy(), self._attitude, self._cost)
        # Two outputs from the carried grid state: after ``whole`` steps of exactly h (the new
        # grid state) and one shorter step further (the requested time, not carried).
        run = self.integrator.run(
            self._inertia, self._omega, self._attitude, np.array([whole * h, whole * h + rest]), h
        )
        self._omega, self._attitude = run.omega[0].copy(), run.attitude[0]
        self._steps += whole
        self._cost += whole
        if rest == 0.0:
            return State(self.t, self._omega.copy(), self._attitude, self._cost)
        return State(t, run.omega[1].copy(), run.attitude[1], self._cost + 1)
