"""The adaptive Runge-Kutta pairs RK45 [DP80] and DOP853 [HNW93 §II.5] (scipy's
``solve_ivp``) on Euler's equations [LL76 §36, Eq. 36.5] for the body angular velocity plus
the quaternion kinematics of the attitude. They conserve nothing exactly; their error grows
like t^2 over long times.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from poinsot.physics.integrators.interface import Run, Trajectory

__all__ = ["euler_quaternion_rhs", "run_scipy", "scipy_atol"]


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


def run_scipy(
    method: str,
) -> Run:
    def run(
        inertia: np.ndarray,
        omega0: np.ndarray,
        attitude0: Rotation,
        t_eval: np.ndarray,
        rtol: float,
    ) -> Trajectory:
        rhs = euler_quaternion_rhs(inertia)
        y0 = np.concatenate((omega0, attitude0.as_quat()))
        atol = scipy_atol(omega0, rtol)
        if t_eval[-1] == 0.0:
            ys = np.repeat(y0[:, None], len(t_eval), axis=1)
            nfev = 0
        else:
            # solve_ivp wants strictly increasing output times; repeated ones are copied back.
            times, where = np.unique(t_eval, return_inverse=True)
            with np.errstate(all="ignore"):  # a run that leaves the range is refused below
                sol = solve_ivp(
                    rhs,
                    (0.0, float(times[-1])),
                    y0,
                    method=method,
                    t_eval=times,
                    rtol=rtol,
                    atol=atol,
                )
            if sol.status != 0 or not np.all(np.isfinite(sol.y)):
                raise ValueError(
                    f"{method} failed ({sol.message}): use a smaller tolerance or earlier times"
                )
            ys, nfev = sol.y[:, where], int(sol.nfev)
        # The quaternion's norm drifts like any other error; from_quat normalises it.
        return Trajectory(ys[:3].T.copy(), Rotation.from_quat(ys[3:].T), nfev)

    return run
