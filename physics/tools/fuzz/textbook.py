"""Fuzz targets of the textbook modules: the polhode family, the flip, the symmetric top, the
gyroscope, the dissipating body, the geometric phase's solid angle and the racket's twist."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from poinsot.physics.core.free_body import FreeRigidBody
from poinsot.physics.models import (
    dissipation,
    family,
    flip,
    geometric_phase,
    gyroscope,
    racket,
    symmetric,
)
from poinsot.physics.tools.fuzz import values
from poinsot.physics.tools.fuzz.checks import finite, number, require, rotation
from poinsot.physics.tools.fuzz.free_body import body_maker, energy_parameter, short
from poinsot.physics.tools.fuzz.harness import Call
from poinsot.physics.tools.fuzz.values import Source, pick

__all__ = ["TARGETS"]


def sorted_moments(src: Source) -> Any:
    """Mostly ``I1 < I2 < I3``, else any moments."""
    if src.index(4) == 0:
        return values.moments(src)
    vals = sorted(values._scale_pattern(src, 3))
    return pick(src, [tuple, list, np.array])(vals)


def small_time(src: Source) -> Any:
    """A time of a few units, or any time."""
    return (
        src.real(0.1, 20.0) if src.index(3) else values.one_of(src, values.positive, values.times)
    )


def _energy_kwargs(src: Source) -> dict[str, Any]:
    kind = src.index(4)
    if kind == 1:
        return {"energy": values.positive(src)}
    if kind == 2:
        return {"momentum": values.positive(src)}
    if kind == 3:
        return {"energy": values.positive(src), "momentum": values.positive(src)}
    return {}


def _curves_ok(curves: Any) -> None:
    require(isinstance(curves, list), "not a list of curves")
    for c in curves:
        w, m = finite(c.omega, None, "curve omega"), finite(c.momentum, None, "curve momentum")
        number(c.two_T, "2T")
        number(c.G, "G")
        require(w.shape == m.shape, "omega and momentum shapes differ")


def _family_call(name: str, fn: Callable[..., Any], check: Callable[[Any], object]) -> Callable:
    """A target calling ``fn`` with arguments drawn per parameter."""

    def target(src: Source) -> Call:
        inertia = sorted_moments(src)
        args: tuple[Any, ...]
        kwargs: dict[str, Any] = {}
        if name == "sorted_moments":
            args = (inertia,)
        elif name == "family_D_values":
            args = (inertia, values.count(src) if src.index(3) == 0 else 4)
        elif name == "polhode_points":
            phi = values.times(src)
            signs = pick(src, [(1, 1, 1), (-1, 1, -1), (1, -1, 1), (2, 1, 1), "abc", None])
            args, kwargs = (
                (inertia, energy_parameter(src, inertia), phi, signs),
                _energy_kwargs(src),
            )
        elif name == "polhode_family":
            D = None if src.index(2) else values.times(src)
            args, kwargs = (inertia, D), _energy_kwargs(src)
        elif name == "momentum_view":
            args = (inertia, energy_parameter(src, inertia), values.positive(src))
        else:
            args, kwargs = (inertia, energy_parameter(src, inertia)), _energy_kwargs(src)
        if name in ("polhode_curves", "polhode_family", "momentum_view") and src.index(3) == 0:
            kwargs["n"] = values.count(src)
        return Call(f"family.{name}{short(*args, **kwargs)}", lambda: fn(*args, **kwargs), check)

    return target


def _arc(src: Source) -> Call:
    make, text = body_maker(src)
    t = values.times(src)
    method = pick(src, ["arc_length", "fraction", "progress"])

    def run() -> Any:
        body = make()
        if method == "progress":
            return family.polhode_progress(body, t)
        return getattr(family.PolhodeArc(body), method)(t)

    def check(out: Any) -> None:
        if method == "progress":
            finite(out[0], None, "fraction")
            require(number(out[1], "circuit time", allow_inf=True) > 0, "circuit time")
        else:
            finite(out, None, method)

    return Call(f"family.PolhodeArc({text}).{method}({short(t)[1:-1]})", run, check)


def _flip_omega(src: Source) -> Call:
    args = (
        values.positive(src),
        values.positive(src),
        values.one_of(src, values.number, values.odd_scalar),
    )
    return Call(
        f"flip.flip_initial_omega{short(*args)}",
        lambda: flip.flip_initial_omega(*args),
        lambda w: finite(w, (3,), "omega0"),
    )


def _flip_theory(src: Source) -> Call:
    inertia, w = sorted_moments(src), values.omega(src)

    def check(th: Any) -> None:
        for field in ("K", "frequency", "time_between_flips", "first_flip_time", "growth_rate"):
            number(getattr(th, field), field)

    return Call(f"flip.flip_theory{short(inertia, w)}", lambda: flip.flip_theory(inertia, w), check)


def _measure(src: Source) -> Call:
    kind = pick(src, ["flips", "growth", "precession", "spin"])
    inertia = sorted_moments(src)
    if kind in ("precession", "spin"):
        top = [values.real(src)] * 2 + [values.real(src)]
        inertia = tuple(top[k] for k in pick(src, [(0, 1, 2), (0, 2, 1), (2, 0, 1)]))
    eps = 10.0 ** src.real(-12.0, -0.5)
    w0 = flip.flip_initial_omega(eps, values.real(src), pick(src, [0.0, 1.5, 0.7]))
    if src.index(3) == 0:
        w0 = values.omega(src)
    t_end = small_time(src)
    step = None if src.index(3) else values.positive(src)
    text = f"{kind}: FreeRigidBody{short(inertia, w0)}, t_end/step {short(t_end, step)}"

    def run() -> Any:
        body = FreeRigidBody(inertia, w0)
        if kind == "flips":
            return flip.measure_flips(body, t_end, step=step)
        if kind == "growth":
            return flip.measure_growth_rate(body, step=step)
        if kind == "precession":
            return symmetric.measure_precession_rate(body, t_end)
        return symmetric.measure_spin_rate(body, t_end)

    def check(out: Any) -> None:
        if kind == "flips":
            finite(out, None, "flip times")
        elif kind == "growth":
            number(out.rate, "growth rate")
        else:
            number(out, "rate")

    return Call(text, run, check)


def _integrated_flips(src: Source) -> Call:
    inertia, w0 = sorted_moments(src), values.omega(src)
    t_end, rtol = small_time(src), pick(src, [1e-12, 1e-6, 1e-300, 0.5, 1e10, math.nan, "x"])
    args = (inertia, w0, t_end, rtol)
    return Call(
        f"flip.integrated_flip_times{short(*args)}",
        lambda: flip.integrated_flip_times(*args),
        lambda r: finite(r, None, "flip times"),
    )


def _symmetric_top(src: Source) -> Call:
    args = (values.positive(src), values.positive(src), values.omega(src), values.attitude(src))
    part = pick(src, ["top", "body", "body_cone", "space_cone"])
    n = values.count(src) if src.index(3) == 0 else 16
    length = None if src.index(2) else values.positive(src)

    def run() -> Any:
        top = symmetric.symmetric_top(*args)
        if part == "top":
            return top
        if part == "body":
            return top.body().omega(1.0)
        return getattr(top, part)(n, length)

    def check(out: Any) -> None:
        if part == "top":
            for field in (
                "precession_rate",
                "spin_rate",
                "body_cone_half_angle",
                "space_cone_half_angle",
                "nutation_angle",
                "omega_norm",
            ):
                number(getattr(out, field), field)
            finite(out.angular_momentum, (3,), "L")
        else:
            finite(out, None, part)

    return Call(f"symmetric.symmetric_top{short(*args)}.{part}{short(n, length)}", run, check)


def _gyroscope(src: Source) -> Call:
    args = (
        values.positive(src),
        values.positive(src),
        values.one_of(src, values.number, values.odd_scalar),
        values.omega(src),
        values.attitude(src),
    )
    part = pick(src, ["gyro", "omega", "attitude", "axis_and_torque", "measure_drift"])
    span = src.real(0.1, 20.0) * _gyro_time_scale(args)
    t = values.times(src) if src.index(3) == 0 else np.linspace(0.0, span, 5)
    step = None if src.index(3) else values.positive(src)
    drift = (
        pick(src, [1, 2, 0, -1, 2.5, None, "4"]),
        pick(src, [None, 16, 64, 3, 10**9, 1e9]),
        values.times(src) if src.index(3) == 0 else 0.0,
    )

    def run() -> Any:
        gyro = gyroscope.Gyroscope(*args)
        if part == "gyro":
            return gyro
        if part == "attitude":
            return gyro.attitude(t, step)
        if part == "measure_drift":
            return gyro.measure_drift(*drift)
        return getattr(gyro, part)(t)

    def check(out: Any) -> None:
        if part == "gyro":
            for field in (
                "nutation_center",
                "nutation_rate",
                "amplitude",
                "phase",
                "drift_rate",
                "nutation_period",
            ):
                number(getattr(out, field), field)
        elif part == "attitude":
            rotation(out.attitude, len(out.quaternions))
            finite(out.error_estimate, None, "error estimate")
        elif part == "axis_and_torque":
            finite(out[0], None, "axis")
            finite(out[1], None, "torque")
        elif part == "measure_drift":
            number(out.along_torque, "drift")
            number(out.across, "across")
        else:
            finite(out, None, "omega")

    extra = {"omega": t, "attitude": (t, step), "axis_and_torque": t, "measure_drift": drift}
    return Call(f"gyroscope.Gyroscope{short(*args)}.{part}{short(extra.get(part))}", run, check)


def _gyro_time_scale(args: tuple[Any, ...]) -> float:
    """1/(the fastest rotation) of a gyroscope, if these arguments make one (a valid run then
    covers a few turns: the fuzz looks for unclean ends, not for long runs)."""
    try:
        g = gyroscope.Gyroscope(*args)
    except Exception:  # a heuristic only: the call itself is judged later
        return 1.0
    fastest = max(
        abs(g.nutation_center) + g.amplitude, abs(float(g.omega0[2])), abs(g.nutation_rate)
    )
    return 1.0 / fastest if 0.0 < fastest < math.inf and 1.0 / fastest < math.inf else 1.0


def _default_window(kappa: Any, w0: Any) -> float:
    """EnergySink's default window for these arguments, if they are numbers (else 1)."""
    try:
        spin = math.hypot(*(float(x) for x in w0))
        window = min(0.01 / float(kappa), 0.5 / spin)
    except Exception:  # a heuristic only: the call itself is judged later
        return 1.0
    return window if 0.0 < window < math.inf else 1.0


def _odd_time(src: Source) -> Any:
    """A duration that is refused: not a number, not positive, or of 1e300 windows."""
    return values.one_of(src, values.odd_scalar, lambda s: -values.real(s), lambda s: 1e300)


def _energy_sink(src: Source) -> Call:
    inertia = sorted_moments(src)
    w0 = values.omega(src) if src.index(3) == 0 else (1.0, 0.15, 0.1)
    kappa = src.real(0.05, 2.0) if src.index(3) else values.positive(src)
    # Mostly a few dozen windows of the default length (each is one exact body), or a length
    # that is refused: a valid run stays short.
    t_end = src.real(0.1, 30.0) * _default_window(kappa, w0) if src.index(3) else _odd_time(src)
    if src.index(3):
        window = None
    elif src.index(2) and isinstance(t_end, float) and t_end < math.inf:
        window = t_end / src.real(1.0, 40.0)  # a few dozen windows: each is one exact body
    else:
        window = values.positive(src)
    attitude0 = values.attitude(src)
    part = pick(src, ["sink", "state", "D", "window_D", "body_at"])
    t: Any = values.times(src) if src.index(3) == 0 else np.array([0.0, 0.05])
    args = (inertia, w0, kappa, t_end, window, attitude0)

    def run() -> Any:
        sink = dissipation.EnergySink(*args)
        if part == "sink":
            return sink
        if part == "body_at":
            return sink.body_at(t).omega(0.0)
        if part == "state":
            return sink.state(t)[0]
        return getattr(sink, part)(t)

    def check(out: Any) -> None:
        if part == "sink":
            number(out.G, "G")
            number(out.crossing_time, "crossing time")
            finite(out.jumps, None, "jumps")
        else:  # D and two_T keep the shape of t: a number for a number
            finite(np.asarray(out, dtype=np.float64), None, part)

    return Call(f"dissipation.EnergySink{short(*args)}.{part}({short(t)[1:-1]})", run, check)


def _solid_angle(src: Source) -> Call:
    inertia = sorted_moments(src)
    D = energy_parameter(src, inertia) if src.index(3) else [energy_parameter(src, inertia)] * 3

    def check(omega: Any) -> None:
        out = finite(omega, None, "solid angle")
        require(bool(np.all(np.abs(out) <= 2.0 * math.pi)), "|Ω| beyond 2π")

    return Call(
        f"geometric_phase.solid_angle{short(inertia, D)}",
        lambda: geometric_phase.solid_angle(inertia, D),
        check,
    )


def _separatrix_twist(src: Source) -> Call:
    inertia = sorted_moments(src)

    def check(th: Any) -> None:
        for field in ("ratio", "tau", "twist", "defect", "defect_low", "defect_high"):
            finite(getattr(th, field), None, field)
        require(bool(np.all(th.defect_low <= th.defect)), "defect below its lower bound")
        require(bool(np.all(th.defect <= th.defect_high)), "defect above its upper bound")

    return Call(
        f"racket.separatrix_twist{short(inertia)}",
        lambda: racket.separatrix_twist(inertia),
        check,
    )


TARGETS: dict[str, Callable[[Source], Call]] = {
    **{
        f"family.{name}": _family_call(name, getattr(family, name), check)
        for name, check in (
            ("sorted_moments", lambda r: require(len(r) == 3, "three moments")),
            ("family_D_values", lambda r: finite(r, None, "D values")),
            ("polhode_curves", _curves_ok),
            ("polhode_points", lambda r: finite(r, None, "points")),
            ("polhode_family", _curves_ok),
            ("momentum_view", lambda r: _curves_ok(r.curves)),
        )
    },
    "family.PolhodeArc": _arc,
    "flip.flip_initial_omega": _flip_omega,
    "flip.flip_theory": _flip_theory,
    "flip/symmetric.measure_*": _measure,
    "flip.integrated_flip_times": _integrated_flips,
    "symmetric.symmetric_top": _symmetric_top,
    "gyroscope.Gyroscope": _gyroscope,
    "dissipation.EnergySink": _energy_sink,
    "geometric_phase.solid_angle": _solid_angle,
    "racket.separatrix_twist": _separatrix_twist,
}
