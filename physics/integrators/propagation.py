"""Piecewise propagation: a numerical method advanced a little at every animation frame."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NamedTuple

import numpy as np
from scipy.integrate import OdeSolver
from scipy.spatial.transform import Rotation

from poinsot.physics.core.validation import check_count, check_number
from poinsot.physics.integrators.registry import MAX_STEPS, Scaled, validated
from poinsot.physics.integrators.runge_kutta import (
    DEFAULT_MAX_STEPS,
    SCIPY_STEPPERS,
    euler_quaternion_rhs,
    scipy_atol,
    too_many_steps,
)

__all__ = ["Propagation", "State"]

#: scipy's stepper classes behind the adaptive entries of the registry (shared with
#: :func:`~.runge_kutta.solve`).
_SCIPY_STEPPERS = SCIPY_STEPPERS
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
        t0 = check_number(t0, "t0")
        self.integrator, self.setting, self.t0 = integrator, value, t0
        # The run is carried in the scaled units of the registry (exact powers of two).
        self._units = units = Scaled.of(integrator, inertia, omega0)
        self._h = units.setting(integrator, value)
        if not (math.isfinite(self._h) and self._h > 0.0):
            raise ValueError(
                f"the step {value:g} leaves the double-precision range in the units of this "
                "motion (ω0 in your units times the step): use a step closer to 1/|ω0|"
            )
        self._inertia = units.inertia
        self._omega, self._attitude = units.omega0.copy(), attitude0
        self._steps = 0  # fixed-step: grid steps taken, the carried state is at t0 + steps h
        self._cost = 0
        self._stepper: OdeSolver | None = None
        self._dense: Callable[[float], np.ndarray] | None = None
        if integrator.kind == "adaptive":
            tau0 = float(units.time(np.array(t0)))
            if not math.isfinite(tau0):
                raise ValueError(f"t0 = {t0:g} is too far for this motion in double precision")
            with np.errstate(all="ignore"):
                self._stepper = _SCIPY_STEPPERS[method](
                    euler_quaternion_rhs(units.inertia),
                    tau0,
                    np.concatenate((units.omega0, attitude0.as_quat())),
                    t_bound=math.inf,
                    rtol=value,
                    atol=scipy_atol(units.omega0, value),
                )

    @property
    def method(self) -> str:
        return self.integrator.name

    @property
    def t(self) -> float:
        """Time of the carried state: the last step's end (adaptive), the grid time (fixed)."""
        if self._stepper is not None:
            return self._caller_time(float(self._stepper.t))
        return self.t0 + self._steps * self.setting

    def _caller_time(self, tau: float) -> float:
        return math.ldexp(tau, -self._units.w_exp)

    @property
    def cost(self) -> int:
        return self._cost

    def advance(self, t: float, max_cost: int | None = None) -> State:
        """The solution at time ``t``, or at the furthest time reached when ``max_cost``
        (RHS evaluations or steps in this call) runs out first; without ``max_cost`` an
        adaptive pair raises a ValueError past ``DEFAULT_MAX_STEPS`` steps in one call (a stiff
        motion: what to do instead is in the message). ``t`` may not lie before the
        start of the last step taken (ValueError): the past is not kept."""
        t = check_number(t, "t")
        if max_cost is not None:
            max_cost = check_count(max_cost, "max_cost", 1, 1 << 62)
        if self._stepper is not None:
            return self._advance_adaptive(t, max_cost)
        return self._advance_fixed(t, max_cost)

    def _advance_adaptive(self, t: float, max_cost: int | None) -> State:
        stepper = self._stepper
        assert stepper is not None
        start = self.t0 if self._dense is None else self._caller_time(float(stepper.t_old))
        if t < start:
            raise ValueError(f"t = {t:g} lies before this propagation's last step ({start:g})")
        tau = float(self._units.time(np.array(t)))
        self._units.check_cost(self.integrator, tau - float(stepper.t), 0.0, 0)
        nfev0 = stepper.nfev
        stepped = False
        steps = 0
        with np.errstate(all="ignore"):  # a run that leaves the range is refused below
            while stepper.t < tau and (max_cost is None or stepper.nfev - nfev0 < max_cost):
                if max_cost is None and steps >= DEFAULT_MAX_STEPS:
                    reached = self._caller_time(float(stepper.t))
                    raise ValueError(too_many_steps(self.method, steps, reached, t))
                steps += 1
                message = stepper.step()
                if stepper.status == "failed":
                    raise ValueError(f"{self.method} failed ({message}): use a smaller tolerance")
                stepped = True
            if stepped:
                self._dense = stepper.dense_output()
        self._cost = int(stepper.nfev)
        reached = min(tau, float(stepper.t))
        if reached == stepper.t or self._dense is None:
            y = np.asarray(stepper.y, dtype=float)
        else:
            y = np.asarray(self._dense(reached), dtype=float)
        if not np.all(np.isfinite(y)):
            raise ValueError(f"{self.method} diverged: use a smaller tolerance")
        # The quaternion's norm drifts like any other error; from_quat normalises it.
        when = t if reached == tau else self._caller_time(reached)
        return State(when, self._units.omega(y[:3]), Rotation.from_quat(y[3:]), self._cost)

    def _advance_fixed(self, t: float, max_cost: int | None) -> State:
        h, grid = self.setting, self.t
        if t < grid - _GRID_SLACK * h:
            raise ValueError(f"t = {t:g} lies before this propagation's grid time {grid:g}")
        steps = (t - grid) / h + _GRID_SLACK
        if max_cost is not None and not steps < max_cost:
            whole, rest = max_cost, 0.0
        else:
            whole = max(int(math.floor(steps)), 0) if math.isfinite(steps) else MAX_STEPS + 1
            rest = max(t - (grid + whole * h), 0.0)
        if whole > MAX_STEPS:
            raise ValueError(
                f"t = {t:g} lies {steps:.3g} steps of {h:g} ahead, more than {MAX_STEPS:,} in one "
                "call: advance in smaller pieces or give max_cost"
            )
        if whole == 0 and rest == 0.0:
            return State(grid, self._units.omega(self._omega), self._attitude, self._cost)
        # Two outputs from the carried grid state: after ``whole`` steps of exactly h (the new
        # grid state) and one shorter step further (the requested time, not carried). In the
        # scaled units: h and the times times 2^w, exactly.
        hs, rest_s = self._h, float(self._units.time(np.array(rest)))
        times = np.array([whole * hs, whole * hs + rest_s])
        run = self.integrator.run(self._inertia, self._omega, self._attitude, times, hs)
        self._omega, self._attitude = run.omega[0].copy(), run.attitude[0]
        self._steps += whole
        self._cost += whole
        if rest == 0.0:
            return State(self.t, self._units.omega(self._omega), self._attitude, self._cost)
        return State(t, self._units.omega(run.omega[1]), run.attitude[1], self._cost + 1)
