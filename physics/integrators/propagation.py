"""Piecewise propagation: a numerical method advanced a little at every animation frame."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NamedTuple

import numpy as np
from scipy.integrate import DOP853, RK45, OdeSolver
from scipy.spatial.transform import Rotation

from poinsot.physics.integrators.registry import validated
from poinsot.physics.integrators.runge_kutta import euler_quaternion_rhs, scipy_atol

__all__ = ["Propagation", "State"]

#: scipy's stepper classes behind the adaptive entries of the registry.
_SCIPY_STEPPERS: dict[str, type[OdeSolver]] = {"RK45": RK45, "DOP853": DOP853}
#: A requested time within this many steps' rounding of a grid time counts as that grid time
#: (the same slack as :func:`~poinsot.physics.integrators.interface.steps_per_interval`).
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
        integrator, inertia, omega0, attitude0, value = validated(
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
                euler_quaternion_rhs(inertia),
                self.t0,
                np.concatenate((omega0, attitude0.as_quat())),
                t_bound=math.inf,
                rtol=value,
                atol=scipy_atol(omega0, value),
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
