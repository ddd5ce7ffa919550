"""The adaptive Runge-Kutta pairs RK45 [DP80] and DOP853 [HNW93 §II.5] (scipy's steppers, driven
step by step as ``solve_ivp`` does, within a step budget) on Euler's equations [LL76 §36,
Eq. 36.5] for the body angular velocity plus the quaternion kinematics of the attitude. They
conserve nothing exactly; their error grows like t^2 over long times.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.integrate import DOP853, RK45, OdeSolver
from scipy.spatial.transform import Rotation

from poinsot.physics.integrators.interface import Run, Trajectory

__all__ = [
    "DEFAULT_MAX_STEPS",
    "SCIPY_STEPPERS",
    "euler_quaternion_rhs",
    "run_scipy",
    "scipy_atol",
    "solve",
    "too_many_steps",
]

#: scipy's stepper classes behind the adaptive entries of the registry.
SCIPY_STEPPERS: dict[str, type[OdeSolver]] = {"RK45": RK45, "DOP853": DOP853}
#: Steps an adaptive run may take unless the caller says otherwise (:func:`solve`): about a
#: second of work on an idle machine (DOP853 takes 0.1-0.3 ms a step, RK45 ~0.06 ms). A longer
#: run is a choice the caller makes with ``max_steps``: the report's most accurate DOP853 run
#: (rtol 1e-13 to t = 1e4 on the generic box, ~5e4 steps) passes its own budget.
DEFAULT_MAX_STEPS = 10_000


def euler_quaternion_rhs(inertia: np.ndarray) -> Callable[[float, np.ndarray], np.ndarray]:
    """Right-hand side of the adaptive pairs: Euler's equations for omega and the quaternion
    kinematics of the attitude, state y = (omega1, omega2, omega3, x, y, z, w)."""
    i1, i2, i3 = (float(v) for v in inertia)
    # Euler's equations I1 w1' = (I2 - I3) w2 w3 and cyclic [LL76 §36, Eq. 36.5].
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


def scipy_atol(omega0: np.ndarray, rtol: float) -> np.ndarray:
    """Absolute tolerance of the adaptive pairs: rtol * max|omega0| on omega, rtol on the unit
    quaternion (a relative tolerance alone would be meaningless where a component crosses 0)."""
    scale = max(float(np.max(np.abs(omega0))), np.finfo(float).tiny)
    return rtol * np.array([scale, scale, scale, 1.0, 1.0, 1.0, 1.0])


def run_scipy(method: str) -> Run:
    """The registry's run of ``method`` with the default step budget (:func:`solve`)."""

    def run(
        inertia: np.ndarray,
        omega0: np.ndarray,
        attitude0: Rotation,
        t_eval: np.ndarray,
        rtol: float,
    ) -> Trajectory:
        return solve(method, inertia, omega0, attitude0, t_eval, rtol, DEFAULT_MAX_STEPS)

    return run


def solve(
    method: str,
    inertia: np.ndarray,
    omega0: np.ndarray,
    attitude0: Rotation,
    t_eval: np.ndarray,
    rtol: float,
    max_steps: int,
) -> Trajectory:
    """scipy's stepper of ``method`` from 0 to ``t_eval[-1]``, sampled at ``t_eval`` from its
    dense output, as ``solve_ivp`` does, but with the steps counted: past ``max_steps`` steps
    a ValueError says what to do instead."""
    y0 = np.concatenate((omega0, attitude0.as_quat()))
    if t_eval[-1] == 0.0:
        ys = np.repeat(y0[:, None], len(t_eval), axis=1)
        return Trajectory(ys[:3].T.copy(), Rotation.from_quat(ys[3:].T), 0)
    # Repeated output times are computed once and copied back.
    times, where = np.unique(t_eval, return_inverse=True)
    out = np.empty((7, len(times)))
    done = int(np.searchsorted(times, 0.0, side="right"))
    out[:, :done] = y0[:, None]
    with np.errstate(all="ignore"):  # a run that leaves the range is refused below
        solver = SCIPY_STEPPERS[method](
            euler_quaternion_rhs(inertia),
            0.0,
            y0,
            t_bound=float(times[-1]),
            rtol=rtol,
            atol=scipy_atol(omega0, rtol),
        )
        steps = 0
        while solver.status == "running":
            if steps >= max_steps:
                raise ValueError(too_many_steps(method, max_steps, float(solver.t), times[-1]))
            message = solver.step()
            steps += 1
            if solver.status == "failed" or not np.all(np.isfinite(solver.y)):
                raise ValueError(
                    f"{method} failed ({message}): use a smaller tolerance or earlier times"
                )
            reached = int(np.searchsorted(times, solver.t, side="right"))
            if reached > done:
                out[:, done:reached] = solver.dense_output()(times[done:reached])
                done = reached
    if not np.all(np.isfinite(out)):
        raise ValueError(f"{method} failed (non-finite output): use a smaller tolerance")
    ys = out[:, where]
    # The quaternion's norm drifts like any other error; from_quat normalises it.
    return Trajectory(ys[:3].T.copy(), Rotation.from_quat(ys[3:].T), int(solver.nfev))


def too_many_steps(method: str, max_steps: int, reached: float, end: float) -> str:
    """The message of a run stopped by its step budget: what to do instead."""
    return (
        f"{method} took {max_steps:,} steps (the max_steps budget) and reached only "
        f"t = {reached:.3g} of {end:.3g}: this motion is stiff for it (rates far apart); "
        "loosen the tolerance, raise max_steps, use the exact solution (FreeRigidBody), "
        "or a stiff method (scipy's Radau or BDF)"
    )
