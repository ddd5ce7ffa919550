"""Fuzz targets of the helpers around the body: initial states, real bodies, the fit's input
checks and the numerical integrators."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from poinsot.physics.core.initial_state import attitude_with_L_along_z, omega_from_energy
from poinsot.physics.fit import fit_angular_velocity, synthetic_toss
from poinsot.physics.integrators import METHODS, Propagation, integrate
from poinsot.physics.models.solids import box_dimensions, check_real_body
from poinsot.physics.tools.fuzz import values
from poinsot.physics.tools.fuzz.checks import Invariants, finite, require, rotation
from poinsot.physics.tools.fuzz.free_body import energy_parameter, short
from poinsot.physics.tools.fuzz.harness import Call
from poinsot.physics.tools.fuzz.values import Source, pick

__all__ = ["TARGETS"]


def _omega_from_energy(src: Source) -> Call:
    inertia = values.moments(src)
    D = energy_parameter(src, inertia)
    args = [inertia, D]
    if src.index(2):
        args.append(values.positive(src))
        if src.index(2):
            args.append(pick(src, [1.0, -1.0, 1, -1, 0.0, math.nan, "a", None, True, 1j]))

    def check(w: Any) -> None:
        finite(w, (3,), "omega0")
        if len(args) > 2:
            # Halved (exactly): |ω0| asked as 1.8e308 may round one ulp above the largest double.
            want, got = 0.5 * float(args[2]), math.hypot(*(0.5 * w).tolist())
            ok = abs(got - want) <= 1e-12 * want + 4 * 5e-324  # a few subnormal spacings
            require(ok, f"|omega0| = {got}, asked {want}")

    return Call(f"omega_from_energy{short(*args)}", lambda: omega_from_energy(*args), check)


def _attitude_with_L_along_z(src: Source) -> Call:
    inertia, w = values.moments(src), values.omega(src)

    def check(R: Any) -> None:
        rotation(R, None)
        moments, w0 = np.asarray(inertia, dtype=float), np.asarray(w, dtype=float)
        inv = Invariants(moments, w0, R)
        if inv.G > 0.0:
            require(bool(np.allclose(inv.L / inv.G, [0, 0, 1], atol=1e-12)), "L is not along +z")

    return Call(
        f"attitude_with_L_along_z{short(inertia, w)}",
        lambda: attitude_with_L_along_z(inertia, w),
        check,
    )


def _solids(src: Source) -> Call:
    inertia = values.moments(src)
    if src.index(3) == 0:
        return Call(
            f"check_real_body{short(inertia)}",
            lambda: check_real_body(inertia),
            lambda r: require(r is None, "check_real_body returns None"),
        )
    args = (inertia,) if src.index(2) else (inertia, values.positive(src))

    def check(sides: Any) -> None:
        finite(sides, (3,), "box sides")
        require(bool(np.all(sides >= 0.0)), "negative side")

    return Call(f"box_dimensions{short(*args)}", lambda: box_dimensions(*args), check)


_TOSS = synthetic_toss((1.0, 1.9, 2.7), (12.0, 1.0, 1.0), seed=1)


def _fit_input(src: Source) -> Call:
    """Recordings that are wrong in at least one way (a valid one would start a whole fit)."""
    t, w = _TOSS[0].copy(), _TOSS[1].copy()
    kind = src.index(9)
    if kind == 0:
        w[src.index(len(w)), src.index(3)] = pick(src, [math.nan, math.inf])
    elif kind == 1:
        t[src.index(len(t) - 1) + 1] = t[0]
    elif kind == 2:
        t, w = t[: src.index(20)], w[: src.index(20)]
    elif kind == 3:
        w = w * 1e-3
    elif kind == 4:
        w = pick(src, [w.T, w[:, :2], w.astype(complex), w.astype(str), w[:-1], w.ravel()])
    elif kind == 5:
        t = pick(src, [t[:, None], t.astype(complex), None, "t", t.tolist() + ["x"]])
    elif kind == 6:
        w = np.tile(w[:1], (len(w), 1))  # a constant ω: no wobble
    elif kind == 7:
        t, w = values.times(src), values.odd_vector(src, values.number)
    else:
        t, w = t * pick(src, [math.inf, math.nan, -1.0]), w
    flags = {k: pick(src, [False, True, "yes", None, 1]) for k in ("fit_rotation", "fit_bias")}
    if src.index(2):
        flags = {}
    return Call(
        f"fit_angular_velocity{short(t, w, **flags)}",
        lambda: fit_angular_velocity(t, w, **flags),
        lambda r: require(False, "a wrong recording was fitted"),
    )


def _time_scale(inertia: Any, w0: Any) -> float:
    """1/(the fastest rate) of these arguments, if they are numbers (a valid run then covers
    a few radians: the fuzz looks for unclean ends, not for long runs)."""
    try:
        i, w = np.abs(np.asarray(inertia, dtype=float)), np.asarray(w0, dtype=float)
        rate = float(np.max(np.abs(w))) * max(1.0, float(i.max() / i.min()))
    except (TypeError, ValueError, OverflowError, ZeroDivisionError):
        return 1.0
    return 1.0 / rate if 0.0 < rate < math.inf and math.isfinite(1.0 / rate) else 1.0


def _integrator_args(src: Source) -> tuple[Any, ...]:
    method = pick(src, [*METHODS, "euler", None, 3])
    inertia = values.moments(src) if src.index(3) == 0 else (1.0, 2.0, src.real(2.5, 3.5))
    w0 = values.omega(src) if src.index(3) == 0 else (src.real(-2, 2), src.real(-2, 2), 1.0)
    attitude0 = values.attitude(src)
    scale = _time_scale(inertia, w0)
    kind = src.index(4)
    if kind <= 1:
        setting = None if method in ("RK45", "DOP853") else 0.05 * scale
    elif kind == 2:
        setting = pick(src, [1e-3, 1e-6, 1e-10]) if method in ("RK45", "DOP853") else 0.01 * scale
    else:
        setting = values.one_of(src, values.positive, values.odd_scalar)
    return method, inertia, w0, attitude0, setting, scale


def _integrate(src: Source) -> Call:
    method, inertia, w0, attitude0, setting, scale = _integrator_args(src)
    if src.index(3) == 0:
        t_eval = values.times(src)
    else:
        t_eval = np.sort(np.abs([src.real(0, 3) * scale for _ in range(src.index(5) + 1)]))
    args = (method, inertia, w0, attitude0, t_eval, setting)

    def check(run: Any) -> None:
        w = finite(run.omega, None, "omega")
        rotation(run.attitude, len(w))

    return Call(f"integrate{short(*args)}", lambda: integrate(*args), check)


def _propagation(src: Source) -> Call:
    method, inertia, w0, attitude0, setting, scale = _integrator_args(src)
    t0 = 0.0 if src.index(2) else values.times(src)
    steps = [src.real(0.0, 2.0) * scale if src.index(3) else values.times(src) for _ in range(2)]
    steps.sort(key=_order)
    max_cost = pick(src, [None, None, 1, 10, 0, -1, 2.5, "5", 10**30])
    text = f"Propagation{short(method, inertia, w0, attitude0, setting, t0)}.advance{short(*steps)}"

    def run() -> Any:
        p = Propagation(method, inertia, w0, attitude0, setting, t0)
        return [p.advance(t, max_cost) for t in steps]

    def check(states: Any) -> None:
        for s in states:
            finite(s.omega, (3,), "omega")
            rotation(s.attitude, None)
            require(isinstance(s.t, float) and math.isfinite(s.t), "t")

    return Call(f"{text} max_cost={max_cost!r}", run, check)


def _order(x: Any) -> float:
    try:
        return float(x)
    except (TypeError, ValueError, OverflowError):
        return 0.0


TARGETS: dict[str, Callable[[Source], Call]] = {
    "omega_from_energy": _omega_from_energy,
    "attitude_with_L_along_z": _attitude_with_L_along_z,
    "box_dimensions/check_real_body": _solids,
    "fit.fit_angular_velocity (input checks)": _fit_input,
    "integrators.integrate": _integrate,
    "integrators.Propagation": _propagation,
}
