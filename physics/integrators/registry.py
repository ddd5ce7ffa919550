"""The registry of numerical methods and the one entry point, :func:`integrate`."""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial.transform import Rotation

from poinsot.physics.integrators.interface import Integrator, Trajectory
from poinsot.physics.integrators.midpoint import run_midpoint
from poinsot.physics.integrators.runge_kutta import run_scipy
from poinsot.physics.integrators.splitting import run_splitting

__all__ = ["INTEGRATORS", "integrate", "validated"]

INTEGRATORS: dict[str, Integrator] = {
    "RK45": Integrator(
        name="RK45",
        title="Dormand-Prince 5(4), scipy solve_ivp (Euler + quaternion)",
        kind="adaptive",
        order=5,
        default_setting=1e-8,
        conserves_norm=False,
        run=run_scipy("RK45"),
    ),
    "DOP853": Integrator(
        name="DOP853",
        title="Dormand-Prince 8(5,3), scipy solve_ivp (Euler + quaternion)",
        kind="adaptive",
        order=8,
        default_setting=1e-10,
        conserves_norm=False,
        run=run_scipy("DOP853"),
    ),
    "splitting": Integrator(
        name="splitting",
        title="Symplectic splitting, Dullweber-Leimkuhler-McLachlan 1997 (Strang, 1-2-3-2-1)",
        kind="fixed",
        order=2,
        default_setting=1e-2,
        conserves_norm=True,
        run=run_splitting,
    ),
    "midpoint": Integrator(
        name="midpoint",
        title="Implicit midpoint rule on (m, R) (Cayley attitude update)",
        kind="fixed",
        order=2,
        default_setting=1e-2,
        conserves_norm=True,
        run=run_midpoint,
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
    integrator, inertia, omega0, attitude0, value = validated(
        method, inertia, omega0, attitude0, setting
    )
    t_eval = np.atleast_1d(np.asarray(t_eval, dtype=float))
    if t_eval.ndim != 1 or len(t_eval) == 0 or not np.all(np.isfinite(t_eval)):
        raise ValueError("t_eval must be a non-empty 1-D array of finite times")
    if t_eval[0] < 0.0 or np.any(np.diff(t_eval) < 0.0):
        raise ValueError("t_eval must be non-negative and non-decreasing")
    return integrator.run(inertia, omega0, attitude0, t_eval, value)


def validated(
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
