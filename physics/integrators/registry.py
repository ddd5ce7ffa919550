"""The registry of numerical methods and the one entry point, :func:`integrate`.

Every method runs in units where the largest moment and the largest ``|ω0|`` component are
powers of two near 1 (:class:`Scaled`): exact scalings, so that ω ~ 1e200 (whose products
ω_j ω_k would overflow) or ~1e-200 (which would underflow) stays in range. The fixed-step
methods take the same steps bit for bit in any units. scipy's first step of the adaptive
pairs mixes the scales of ω and of its derivative, so their time is rescaled only where it
must be (``|ω0|`` outside ``[1e-100, 1e100]``): elsewhere they run exactly as in the caller's
units.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from scipy.spatial.transform import Rotation

from poinsot.physics.core.validation import (
    InputTypeError,
    check_attitude,
    check_count,
    check_inertia,
    check_moment_span,
    check_positive,
    check_time_array,
    check_vector,
)
from poinsot.physics.integrators.games import (
    run_gyro_explicit,
    run_gyro_implicit,
    run_jolt,
    run_no_gyro,
    run_rk4,
)
from poinsot.physics.integrators.interface import Integrator, Trajectory
from poinsot.physics.integrators.midpoint import run_midpoint
from poinsot.physics.integrators.runge_kutta import DEFAULT_MAX_STEPS, run_scipy, solve
from poinsot.physics.integrators.splitting import run_splitting

__all__ = ["GAME_STEPS", "INTEGRATORS", "METHODS", "Scaled", "integrate", "validated"]

#: The most steps a fixed-step run may take (the report's longest run takes ~10⁷).
MAX_STEPS = 50_000_000
#: The most radians of the fastest rotation an adaptive run may cover (a few steps each).
MAX_RADIANS = 1e8
#: scipy raises a smaller relative tolerance to 100 eps with a warning; above the largest the
#: steps are so long that the solution may run off to infinity.
MIN_RTOL, MAX_RTOL = 100.0 * float(np.finfo(float).eps), 1e-2

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

#: The steps of game physics engines (:mod:`.games`), at a game's frame step (1/60 s): what
#: most simulations people watch actually run. Not in :data:`INTEGRATORS` (the work-precision
#: study), which holds the methods a numerical analyst would compare.
GAME_STEPS: dict[str, Integrator] = {
    "no-gyro": Integrator(
        name="no-gyro",
        title="Game step without the gyroscopic term (GodotPhysics, brax, PhysX)",
        kind="fixed",
        order=0,
        default_setting=1.0 / 60.0,
        conserves_norm=False,
        run=run_no_gyro,
    ),
    "gyro-explicit": Integrator(
        name="gyro-explicit",
        title="Semi-implicit Euler with the explicit gyroscopic torque (Bullet explicit)",
        kind="fixed",
        order=1,
        default_setting=1.0 / 60.0,
        conserves_norm=False,
        run=run_gyro_explicit,
    ),
    "gyro-implicit": Integrator(
        name="gyro-implicit",
        title="Implicit gyroscopic step, one Newton step (Bullet implicit body, Catto 2015)",
        kind="fixed",
        order=1,
        default_setting=1.0 / 60.0,
        conserves_norm=False,
        run=run_gyro_implicit,
    ),
    "jolt": Integrator(
        name="jolt",
        title="Jolt's gyroscopic step, |L| kept (semi-implicit Euler)",
        kind="fixed",
        order=1,
        default_setting=1.0 / 60.0,
        conserves_norm=False,
        run=run_jolt,
    ),
    "rk4": Integrator(
        name="rk4",
        title="Fixed-step classical RK4, quaternion normalised (MuJoCo RK4)",
        kind="fixed",
        order=4,
        default_setting=1.0 / 60.0,
        conserves_norm=False,
        run=run_rk4,
    ),
}

#: Every method :func:`integrate` and :class:`~.propagation.Propagation` accept.
METHODS: dict[str, Integrator] = {**INTEGRATORS, **GAME_STEPS}


def integrate(
    method: str,
    inertia: np.typing.ArrayLike,
    omega0: np.typing.ArrayLike,
    attitude0: Rotation | None,
    t_eval: np.typing.ArrayLike,
    setting: float | None = None,
    max_steps: int | None = None,
) -> Trajectory:
    """Integrate the free rigid body numerically from t = 0 and sample it at ``t_eval``.

    Parameters
    ----------
    method
        A key of :data:`METHODS`: ``"RK45"``, ``"DOP853"``, ``"splitting"``, ``"midpoint"``
        (:data:`INTEGRATORS`) or a game engine's step (:data:`GAME_STEPS`).
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
    max_steps
        The most steps the run may take (fixed step: counted in advance; adaptive: counted as
        they are taken). Past it a ValueError says what to do instead (a looser tolerance or
        larger step, the exact solution, a stiff method). None: :data:`MAX_STEPS` for the
        fixed-step methods, ``DEFAULT_MAX_STEPS`` (1e4, about a second) for the adaptive pairs.

    Returns
    -------
    Trajectory
        ``omega`` (N, 3), ``attitude`` (stack of N rotations), ``cost`` (RHS evaluations or
        steps). Unpacks as a tuple ``omega, attitude, cost``.
    """
    integrator, inertia, omega0, attitude0, value = validated(
        method, inertia, omega0, attitude0, setting
    )
    t_eval = check_time_array(t_eval, "t_eval")
    if t_eval.size == 0:
        raise ValueError("t_eval must be a non-empty 1-D array of finite times")
    if t_eval[0] < 0.0 or np.any(t_eval[1:] < t_eval[:-1]):
        raise ValueError("t_eval must be non-negative and non-decreasing")
    budget = _budget(integrator, max_steps)
    units = Scaled.of(integrator, inertia, omega0)
    tau, h = units.time(t_eval), units.setting(integrator, value)
    units.check_cost(integrator, float(tau[-1]) if tau.size else 0.0, h, tau.size, budget)
    if integrator.kind == "adaptive":
        args = (units.inertia, units.omega0, attitude0, tau, h)
        run = solve(integrator.name, *args, budget)
    else:
        run = integrator.run(units.inertia, units.omega0, attitude0, tau, h)
    return Trajectory(units.omega(run.omega), run.attitude, run.cost)


def _budget(integrator: Integrator, max_steps: int | None) -> int:
    if max_steps is None:
        return MAX_STEPS if integrator.kind == "fixed" else DEFAULT_MAX_STEPS
    return check_count(max_steps, "max_steps", 1, 1 << 62)


def validated(
    method: str,
    inertia: np.typing.ArrayLike,
    omega0: np.typing.ArrayLike,
    attitude0: Rotation | None,
    setting: float | None,
) -> tuple[Integrator, np.ndarray, np.ndarray, Rotation, float]:
    """The checks shared by :func:`integrate` and :class:`Propagation` (readable ValueErrors)."""
    if not isinstance(method, str):
        raise InputTypeError(f"method must be a name, one of {sorted(METHODS)}; got {method!r}")
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r}; choose one of {sorted(METHODS)}")
    integrator = METHODS[method]
    inertia = check_inertia(inertia)
    check_moment_span(inertia)
    omega0 = check_vector(omega0, "omega0")
    attitude0 = check_attitude(attitude0)
    if setting is None:
        value = integrator.default_setting
    else:
        value = check_positive(setting, "setting")
    if integrator.kind == "adaptive" and not MIN_RTOL <= value <= MAX_RTOL:
        raise ValueError(
            f"setting, the relative tolerance of {method}, must lie between {MIN_RTOL:.3g} "
            f"(scipy's floor) and {MAX_RTOL:g}; got {setting!r}"
        )
    return integrator, inertia, omega0, attitude0, value


class Scaled(NamedTuple):
    """A problem in units where the largest moment and the largest ``|ω0|`` component are
    powers of two near 1: ``inertia = I/2^i``, ``omega0 = ω0/2^w``, times ``τ = t·2^w``.

    Euler's equations and the attitude kinematics keep their form (ω in rad per unit of τ);
    the moments enter only through their ratios.
    """

    inertia: np.ndarray
    omega0: np.ndarray
    w_exp: int

    @classmethod
    def of(cls, integrator: Integrator, inertia: np.ndarray, omega0: np.ndarray) -> Scaled:
        i_exp = math.frexp(float(inertia.max()))[1] - 1
        w_max = float(np.max(np.abs(omega0)))
        w_exp = math.frexp(w_max)[1] - 1 if w_max > 0.0 else 0
        if integrator.kind == "adaptive" and _SAFE_OMEGA[0] <= w_max <= _SAFE_OMEGA[1]:
            w_exp = 0  # see the module docstring
        return cls(np.ldexp(inertia, -i_exp), np.ldexp(omega0, -w_exp), w_exp)

    def time(self, t: np.ndarray) -> np.ndarray:
        """Caller's times -> τ (inf where beyond the range: refused by :meth:`check_cost`)."""
        with np.errstate(over="ignore"):
            return np.ldexp(t, self.w_exp)

    def setting(self, integrator: Integrator, value: float) -> float:
        """A fixed step in units of τ; a tolerance unchanged."""
        if integrator.kind == "adaptive":
            return value
        with np.errstate(over="ignore", under="ignore"):
            return float(np.ldexp(value, self.w_exp))

    def omega(self, w: np.ndarray) -> np.ndarray:
        """Scaled ω -> the caller's units."""
        with np.errstate(over="ignore"):
            out = np.ldexp(w, self.w_exp)
        if not np.all(np.isfinite(out)):
            raise ValueError(
                "the computed ω leaves the double-precision range in your units (the method "
                "diverged or ω grew beyond 1.8e308): use a smaller step or tolerance"
            )
        return out

    def check_cost(
        self, integrator: Integrator, span: float, h: float, outputs: int, budget: int = MAX_STEPS
    ) -> None:
        """Refuse a run that would never end: more than ``budget`` fixed steps (one at least
        per output time), or more than :data:`MAX_RADIANS` for an adaptive method."""
        if integrator.kind == "fixed":
            steps = span / h + outputs if h > 0.0 else math.inf
            if not steps <= budget:
                raise ValueError(
                    f"{integrator.name} would take {steps:.3g} steps (one at least per output "
                    f"time), more than max_steps = {budget:,}: {_ADVICE}"
                )
            return
        i = self.inertia
        spread = max(1.0, (float(i.max()) - float(i.min())) / float(i.min()))
        radians = math.hypot(*self.omega0.tolist()) * spread * span
        if not radians <= MAX_RADIANS:
            raise ValueError(
                f"the times span {radians:.3g} radians of the fastest rotation, more than "
                f"{MAX_RADIANS:g} for {integrator.name} (several steps each): "
                "use fewer or earlier times"
            )


_ADVICE = (
    "use a larger step or fewer, earlier output times, raise max_steps, or use the exact "
    "solution (FreeRigidBody)"
)
#: Where the adaptive pairs keep the caller's time unit.
_SAFE_OMEGA = (1e-100, 1e100)
