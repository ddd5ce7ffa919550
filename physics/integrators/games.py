"""The rotation steps of game physics engines, at the step sizes games use (1/60 s, 1/240 s).

Every engine below stores ω in space, steps it with the torques of one frame ("velocity
step"), then turns the attitude quaternion by the exact rotation ``h ω`` about the new ω and
normalises it ("position step", semi-implicit Euler). In the body frame that is
``R_{n+1} = R_n exp(h [ω_{n+1}]x)``: a space rotation ``exp(h [R ω]x) R = R exp(h [ω]x)``.
They differ only in the velocity step of a free body, the gyroscopic term ``-ω × I ω`` of
Euler's equations [LL76 §36, Eq. 36.5]:

- ``no-gyro``: none. ω in space is kept, so the body turns about one fixed axis for ever and
  ω in the body is constant: no flip, ever. GodotPhysics3D [GOD21], brax [BRAX22], PhysX and
  Bullet unless a gyroscopic flag is set [BT15].
- ``gyro-explicit``: the torque ``-ω_n × I ω_n`` applied explicitly (Bullet's
  ``BT_ENABLE_GYROSCOPIC_FORCE_EXPLICIT`` [BT15]; avian before its fix [AVIAN24]). Each step
  adds ``h² |ω × I ω|²`` to ``|L|²``: energy and |L| grow, and a large step blows up.
- ``gyro-implicit``: backward Euler on ``I ω' = -ω × I ω`` in the body frame, solved by one
  Newton step from ω_n (``btRigidBody::computeGyroscopicImpulseImplicit_Body``, Bullet's
  ``BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_BODY`` [BT15]; [CAT15]). Backward Euler proper takes
  ``|L|`` and the energy down at every step (``|m_n|² = |m_{n+1}|² + |m_n - m_{n+1}|²``); its
  one Newton step does too at game steps (the tests measure it): a fast flip is damped out.
- ``jolt``: the explicit step of the body angular momentum, rescaled to its old length
  (``MotionProperties::ApplyGyroscopicForceInternal`` [JOLT24]; avian since [AVIAN24]): |L| kept
  to rounding, the energy not.
- ``rk4``: the classical fourth-order Runge-Kutta step [HNW93 §II.1] on Euler's equations and
  ``q' = q (ω, 0) / 2``, the quaternion normalised after each step (MuJoCo's ``RK4`` [MJ22]).

The sequential part is a scalar recurrence on three floats (plain Python floats, as in
:mod:`.splitting`); the attitudes are assembled afterwards by :func:`.attitudes.attitudes_at`.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from scipy.spatial.transform import Rotation

from poinsot.physics.core.rotations import hamilton
from poinsot.physics.integrators.attitudes import attitudes_at
from poinsot.physics.integrators.interface import Trajectory, steps_per_interval

__all__ = [
    "run_gyro_explicit",
    "run_gyro_implicit",
    "run_jolt",
    "run_no_gyro",
    "run_rk4",
]

#: ``step(w1, w2, w3, h) -> (w1, w2, w3)``: one velocity step of a free body.
Step = Callable[[float, float, float, float], tuple[float, float, float]]


def _velocity_steps(
    make: Callable[[float, float, float], Step],
    inertia: np.ndarray,
    omega0: np.ndarray,
    t_eval: np.ndarray,
    h: float,
) -> tuple[np.ndarray, list[float], np.ndarray]:
    """Run a velocity step over the grid of :func:`steps_per_interval`.

    Returns ω at the output times (N, 3), ``h ω_{n+1}`` of every step (flat, 3 per step: the
    rotation vector of the position step) and the cumulative step counts (N,).
    """
    step = make(*(float(v) for v in inertia))
    w1, w2, w3 = (float(v) for v in omega0)
    n_steps = steps_per_interval(t_eval, h)
    dts = np.diff(t_eval, prepend=0.0)
    turns: list[float] = []
    keep = turns.extend
    w_out = np.empty((len(t_eval), 3))
    for k, (n, dt) in enumerate(zip(n_steps.tolist(), dts.tolist(), strict=True)):
        if n:
            size = dt / n
            for _ in range(n):
                w1, w2, w3 = step(w1, w2, w3, size)
                keep((size * w1, size * w2, size * w3))
        w_out[k] = (w1, w2, w3)
    if not np.all(np.isfinite(w_out)):
        raise ValueError("the game step blew up (ω left the double range): use a smaller step")
    return w_out, turns, np.cumsum(n_steps)


def _exact_turns(turns: list[float], lo: int, hi: int) -> np.ndarray:
    """Quaternions (4, hi - lo) of the rotations by the rotation vectors ``turns[lo:hi]``."""
    v = np.array(turns[3 * lo : 3 * hi], dtype=float).reshape(hi - lo, 3).T
    angle = np.sqrt(np.sum(v * v, axis=0))
    # sin(a/2)/a, with its series below 1e-4 (as the engines do near 0): no 0/0.
    safe = np.where(angle > 1e-4, angle, 1.0)
    half = np.where(angle > 1e-4, np.sin(0.5 * safe) / safe, 0.5 - angle * angle / 48.0)
    q = np.empty((4, hi - lo))
    q[:3] = v * half
    q[3] = np.cos(0.5 * angle)
    return q


def _semi_implicit(make: Callable[[float, float, float], Step]):
    """A :data:`~.interface.Run`: the velocity step ``make``, then the exact position step."""

    def run(
        inertia: np.ndarray, omega0: np.ndarray, attitude0: Rotation, t_eval: np.ndarray, h: float
    ) -> Trajectory:
        w_out, turns, counts = _velocity_steps(make, inertia, omega0, t_eval, h)
        total = len(turns) // 3
        attitude = attitudes_at(
            attitude0, lambda lo, hi: _exact_turns(turns, lo, hi), total, counts
        )
        return Trajectory(w_out, attitude, total)

    return run


def _no_gyro(i1: float, i2: float, i3: float) -> Step:
    def step(w1: float, w2: float, w3: float, h: float) -> tuple[float, float, float]:
        # ω in space is kept; the position step turns the body about it, so ω in the body
        # (R^T ω_space, with R turned about ω_space itself) is kept too.
        return w1, w2, w3

    return step


def _gyro_explicit(i1: float, i2: float, i3: float) -> Step:
    a1, a2, a3 = (i2 - i3) / i1, (i3 - i1) / i2, (i1 - i2) / i3

    def step(w1: float, w2: float, w3: float, h: float) -> tuple[float, float, float]:
        # ω += h I^-1 (-ω × I ω), Euler's equations component by component.
        return w1 + h * a1 * w2 * w3, w2 + h * a2 * w3 * w1, w3 + h * a3 * w1 * w2

    return step


def _gyro_implicit(i1: float, i2: float, i3: float) -> Step:
    def step(w1: float, w2: float, w3: float, h: float) -> tuple[float, float, float]:
        # Backward Euler F(x) = I (x - ω) + h x × I x = 0; one Newton step from x = ω:
        # x = ω - J^-1 F(ω), F(ω) = h ω × I ω, J = I + h ([ω]x I - [I ω]x).
        m1, m2, m3 = i1 * w1, i2 * w2, i3 * w3
        f1, f2, f3 = h * (w2 * m3 - w3 * m2), h * (w3 * m1 - w1 * m3), h * (w1 * m2 - w2 * m1)
        j11, j12, j13 = i1, h * (m3 - w3 * i2), h * (w2 * i3 - m2)
        j21, j22, j23 = h * (w3 * i1 - m3), i2, h * (m1 - w1 * i3)
        j31, j32, j33 = h * (m2 - w2 * i1), h * (w1 * i2 - m1), i3
        # Cramer's rule on the 3 x 3 system (as Bullet's solve33).
        c11, c12, c13 = j22 * j33 - j23 * j32, j23 * j31 - j21 * j33, j21 * j32 - j22 * j31
        det = j11 * c11 + j12 * c12 + j13 * c13
        d1 = (f1 * c11 + j12 * (j23 * f3 - f2 * j33) + j13 * (f2 * j32 - j22 * f3)) / det
        d2 = (j11 * (f2 * j33 - j23 * f3) + f1 * c12 + j13 * (j21 * f3 - f2 * j31)) / det
        d3 = (j11 * (j22 * f3 - f2 * j32) + j12 * (f2 * j31 - j21 * f3) + f1 * c13) / det
        return w1 - d1, w2 - d2, w3 - d3

    return step


def _jolt(i1: float, i2: float, i3: float) -> Step:
    def step(w1: float, w2: float, w3: float, h: float) -> tuple[float, float, float]:
        m1, m2, m3 = i1 * w1, i2 * w2, i3 * w3
        # L_new = L - h ω × L, then scaled back to |L| (no energy from the Euler step).
        n1, n2, n3 = (
            m1 - h * (w2 * m3 - w3 * m2),
            m2 - h * (w3 * m1 - w1 * m3),
            m3 - h * (w1 * m2 - w2 * m1),
        )
        new = n1 * n1 + n2 * n2 + n3 * n3
        if new == 0.0:
            return 0.0, 0.0, 0.0
        s = math.sqrt((m1 * m1 + m2 * m2 + m3 * m3) / new)
        return s * n1 / i1, s * n2 / i2, s * n3 / i3

    return step


run_no_gyro = _semi_implicit(_no_gyro)
run_gyro_explicit = _semi_implicit(_gyro_explicit)
run_gyro_implicit = _semi_implicit(_gyro_implicit)
run_jolt = _semi_implicit(_jolt)


def run_rk4(
    inertia: np.ndarray, omega0: np.ndarray, attitude0: Rotation, t_eval: np.ndarray, h: float
) -> Trajectory:
    """Classical RK4 on (ω, q). ``q' = q ⊗ (ω, 0)/2`` is linear in q with the body rate on the
    right, so one RK4 step is ``q_{n+1} = q_n ⊗ Φ_n``, Φ_n a polynomial in the stage rates, and
    normalising ``q_{n+1}`` is normalising Φ_n: the attitudes are products of the Φ_n/|Φ_n|."""
    i1, i2, i3 = (float(v) for v in inertia)
    a1, a2, a3 = (i2 - i3) / i1, (i3 - i1) / i2, (i1 - i2) / i3
    w1, w2, w3 = (float(v) for v in omega0)
    n_steps = steps_per_interval(t_eval, h)
    dts = np.diff(t_eval, prepend=0.0)
    stages: list[float] = []  # h times the four stage rates, 12 per step
    keep = stages.extend
    w_out = np.empty((len(t_eval), 3))
    for k, (n, dt) in enumerate(zip(n_steps.tolist(), dts.tolist(), strict=True)):
        if n:
            s = dt / n
            for _ in range(n):
                k11, k12, k13 = a1 * w2 * w3, a2 * w3 * w1, a3 * w1 * w2
                x1, x2, x3 = w1 + 0.5 * s * k11, w2 + 0.5 * s * k12, w3 + 0.5 * s * k13
                k21, k22, k23 = a1 * x2 * x3, a2 * x3 * x1, a3 * x1 * x2
                y1, y2, y3 = w1 + 0.5 * s * k21, w2 + 0.5 * s * k22, w3 + 0.5 * s * k23
                k31, k32, k33 = a1 * y2 * y3, a2 * y3 * y1, a3 * y1 * y2
                z1, z2, z3 = w1 + s * k31, w2 + s * k32, w3 + s * k33
                k41, k42, k43 = a1 * z2 * z3, a2 * z3 * z1, a3 * z1 * z2
                keep((s * w1, s * w2, s * w3, s * x1, s * x2, s * x3))
                keep((s * y1, s * y2, s * y3, s * z1, s * z2, s * z3))
                w1 += s / 6.0 * (k11 + 2.0 * k21 + 2.0 * k31 + k41)
                w2 += s / 6.0 * (k12 + 2.0 * k22 + 2.0 * k32 + k42)
                w3 += s / 6.0 * (k13 + 2.0 * k23 + 2.0 * k33 + k43)
        w_out[k] = (w1, w2, w3)
    if not np.all(np.isfinite(w_out)):
        raise ValueError("RK4 blew up (ω left the double range): use a smaller step")
    total = len(stages) // 12

    def increments(lo: int, hi: int) -> np.ndarray:
        hw = np.array(stages[12 * lo : 12 * hi], dtype=float).reshape(hi - lo, 4, 3)
        return _rk4_factor(hw)

    attitude = attitudes_at(attitude0, increments, total, np.cumsum(n_steps))
    return Trajectory(w_out, attitude, total)


def _rk4_factor(hw: np.ndarray) -> np.ndarray:
    """Φ/|Φ| (4, S) for the stage rotation vectors ``hw`` (S, 4, 3) = h × the stage rates.

    With ``a_i = (h ω_i, 0)/2``: ``k1 = a1``, ``k2 = (1 + k1/2) a2``, ``k3 = (1 + k2/2) a3``,
    ``k4 = (1 + k3) a4`` and ``Φ = 1 + (k1 + 2 k2 + 2 k3 + k4)/6`` (each k times h already).
    """
    s = hw.shape[0]
    one = np.zeros((4, s))
    one[3] = 1.0
    a = [np.vstack((0.5 * hw[:, i, :].T, np.zeros((1, s)))) for i in range(4)]
    k1 = a[0]
    k2 = np.array(hamilton(one + 0.5 * k1, a[1]))
    k3 = np.array(hamilton(one + 0.5 * k2, a[2]))
    k4 = np.array(hamilton(one + k3, a[3]))
    phi = one + (k1 + 2.0 * k2 + 2.0 * k3 + k4) / 6.0
    return phi / np.linalg.norm(phi, axis=0)
