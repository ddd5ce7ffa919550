"""Fuzz targets of :class:`~poinsot.physics.FreeRigidBody`: the constructors, every method and
every property, on bodies of every regime and scale."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from poinsot.physics.core.free_body import FreeRigidBody
from poinsot.physics.core.regime import Regime
from poinsot.physics.tools.fuzz import values
from poinsot.physics.tools.fuzz.checks import Invariants, finite, number, require, rotation
from poinsot.physics.tools.fuzz.harness import Call
from poinsot.physics.tools.fuzz.values import Source, pick

__all__ = ["TARGETS", "body_maker", "short"]

PROPERTIES = (
    "energy",
    "angular_momentum",
    "semi_axes",
    "frequency",
    "mean_precession_rate",
    "period",
    "precession_per_period",
    "second_period",
    "D",
    "plane_distance",
    "plane_normal",
    "parameter",
    "complementary_parameter",
    "regime",
    "repr",
)


def short(*args: Any, **kwargs: Any) -> str:
    """The arguments of a call as text, each cut to a readable length."""
    parts = [_cut(repr(a)) for a in args] + [f"{k}={_cut(repr(v))}" for k, v in kwargs.items()]
    return "(" + ", ".join(parts) + ")"


def _cut(text: str) -> str:
    text = " ".join(text.split())
    return text if len(text) <= 160 else text[:150] + " …" + text[-8:]


def energy_parameter(src: Source, inertia: Any) -> Any:
    """A D for these moments: in range, at an end, exactly I2, just outside, or anything."""
    try:
        lo, mid, hi = sorted(float(x) for x in np.asarray(inertia, dtype=float).tolist())
    except (TypeError, ValueError, OverflowError):
        return values.one_of(src, values.number, values.odd_scalar)
    kind = src.index(7)
    if kind <= 2:
        return lo + src.real(0.0, 1.0) * (hi - lo)
    if kind == 3:
        return pick(src, [lo, mid, hi])
    if kind == 4:
        return pick(src, [math.nextafter(lo, -math.inf), math.nextafter(hi, math.inf), 2 * hi])
    return values.one_of(src, values.number, values.odd_scalar)


def _pole_sign(src: Source) -> Any:
    return pick(src, [1, -1, 1.0, -1.0, np.int64(-1), 0, 2.5, math.nan, "a", None, True, 1j])


def body_maker(src: Source) -> tuple[Callable[[], FreeRigidBody], str]:
    """A thunk that builds a body of valid-looking input (every regime, every scale)."""
    inertia = values.moments(src) if src.index(8) == 0 else _valid_moments(src)
    if src.index(4) == 0:
        D = energy_parameter(src, inertia)
        norm = values.real(src)
        return (
            lambda: FreeRigidBody.from_energy(inertia, D, omega_norm=norm),
            "FreeRigidBody.from_energy" + short(inertia, D, omega_norm=norm),
        )
    omega0 = values.omega(src)
    attitude0 = values.attitude(src) if src.index(4) == 0 else None
    return (
        lambda: FreeRigidBody(inertia, omega0, attitude0),
        "FreeRigidBody" + short(inertia, omega0, attitude0),
    )


def _valid_moments(src: Source) -> Any:
    vals = values._scale_pattern(src, 3)
    return tuple(vals[k] for k in pick(src, [(0, 1, 2), (2, 1, 0), (1, 0, 2)]))


def check_body(body: Any) -> None:
    require(isinstance(body, FreeRigidBody), f"got a {type(body).__name__}")
    require(isinstance(body.regime, Regime), "regime")
    inv = Invariants.of(body)
    if body.regime is not Regime.REST:
        lo, hi = (
            math.ldexp(float(np.min(inv.I)), inv.e_I),
            math.ldexp(float(np.max(inv.I)), inv.e_I),
        )
        d = number(body.D, "D")
        require(lo * (1 - 1e-15) <= d <= hi * (1 + 1e-15), f"D = {d} outside [{lo}, {hi}]")


def construct(src: Source) -> Call:
    inertia, omega0, attitude0 = values.moments(src), values.omega(src), values.attitude(src)
    return Call(
        "FreeRigidBody" + short(inertia, omega0, attitude0),
        lambda: FreeRigidBody(inertia, omega0, attitude0),
        check_body,
    )


def from_energy(src: Source) -> Call:
    inertia = values.moments(src)
    D = energy_parameter(src, inertia)
    kwargs: dict[str, Any] = {}
    if src.index(3) == 0:
        kwargs["omega_norm"] = values.positive(src)
    if src.index(3) == 0:
        kwargs["momentum_norm"] = values.positive(src)
    if src.index(3) == 0:
        kwargs["pole_sign"] = _pole_sign(src)
    if src.index(4) == 0:
        kwargs["attitude0"] = values.attitude(src)

    def check(body: Any) -> None:
        check_body(body)
        if kwargs.get("omega_norm") is not None:  # None: the default |ω0|, nothing to check
            want, got = float(kwargs["omega_norm"]), math.hypot(*body.omega0.tolist())
            require(abs(got - want) <= 1e-12 * want + _SUBNORMAL, f"|omega0| {got} != {want}")

    return Call(
        "FreeRigidBody.from_energy" + short(inertia, D, **kwargs),
        lambda: FreeRigidBody.from_energy(inertia, D, **kwargs),
        check,
    )


def _rows(out: Any) -> int | None:
    return None if np.ndim(out) == 1 else int(np.shape(out)[0])


def _check_omega(body: FreeRigidBody, t: Any, out: Any) -> None:
    require(np.ndim(out) in (1, 2) and np.shape(out)[-1] == 3, f"omega shape {np.shape(out)}")
    Invariants.of(body).omega(out)


def _check_state(body: FreeRigidBody, t: Any, out: Any) -> None:
    w, R = out
    inv = Invariants.of(body)
    ws = inv.omega(w)
    inv.attitude(ws, rotation(R, _rows(w)))


def _check_attitude(body: FreeRigidBody, t: Any, out: Any) -> None:
    _check_state(body, t, (body.omega(t), out))


def _check_sample(body: FreeRigidBody, t: Any, out: Any) -> None:
    w, R, c = out
    inv = Invariants.of(body)
    ws = inv.omega(w)
    q = rotation(R, _rows(w))
    inv.attitude(ws, q)
    require(np.shape(c) == np.shape(w), f"contact shape {np.shape(c)}")
    inv.contact(c, ws, q)


def _check_contact(body: FreeRigidBody, t: Any, out: Any) -> None:
    w, R, c = body.sample(t)
    require(np.array_equal(out, c), "contact_point differs from sample()[2]")
    _check_sample(body, t, (w, R, c))


_METHODS: dict[str, Callable[[FreeRigidBody, Any, Any], None]] = {
    "omega": _check_omega,
    "attitude": _check_attitude,
    "state": _check_state,
    "sample": _check_sample,
    "contact_point": _check_contact,
    "herpolhode": _check_contact,
}


def _method(name: str) -> Callable[[Source], Call]:
    def target(src: Source) -> Call:
        make, text = body_maker(src)
        t = values.times(src)

        def run() -> tuple[FreeRigidBody, Any]:
            body = make()
            return body, getattr(body, name)(t)

        return Call(
            f"{text}.{name}({short(t)[1:-1]})", run, lambda r: _METHODS[name](r[0], t, r[1])
        )

    target.__name__ = name
    return target


def polhode(src: Source) -> Call:
    make, text = body_maker(src)
    n = values.count(src) if src.index(3) else pick(src, [2, 3, 16, 256])

    def run() -> tuple[FreeRigidBody, Any]:
        body = make()
        return body, body.polhode(n)

    def check(result: tuple[FreeRigidBody, Any]) -> None:
        body, points = result
        finite(points, (int(n), 3), "polhode")
        Invariants.of(body).omega(points, "polhode")

    return Call(f"{text}.polhode({n!r})", run, check)


def properties(src: Source) -> Call:
    make, text = body_maker(src)
    name = pick(src, PROPERTIES)

    def run() -> tuple[FreeRigidBody, Any]:
        body = make()
        return body, repr(body) if name == "repr" else getattr(body, name)

    return Call(f"{text}.{name}", run, lambda r: _check_property(name, *r))


def _check_property(name: str, body: FreeRigidBody, value: Any) -> None:
    inv = Invariants.of(body)
    if name == "repr":
        require(isinstance(value, str), "repr")
    elif name == "regime":
        require(isinstance(value, Regime), "regime")
    elif name in ("angular_momentum", "plane_normal", "semi_axes"):
        _check_vector_property(name, inv, finite(value, (3,), name))
    elif name == "period":
        require(number(value, name, allow_inf=True) > 0.0, f"{name} = {value}")
    elif name == "second_period":  # 2π/ν: the sign of the precession, never 0
        require(abs(number(value, name, allow_inf=True)) > 0.0, f"{name} = {value}")
    elif name in ("parameter", "complementary_parameter"):
        require(0.0 <= number(value, name) <= 1.0, f"{name} = {value}")
    elif name == "energy":
        want = _in_caller_units(0.5 * inv.two_T, inv.e_I + 2 * inv.e_w)
        got = number(value, name)
        require(abs(got - want) <= 1e-12 * want + _SUBNORMAL, f"energy {got} != {want}")
    else:
        number(value, name)


#: A few subnormal spacings: a value that underflows keeps only the digits a subnormal has.
_SUBNORMAL = 4 * 5e-324


def _in_caller_units(x: float, e: int) -> float:
    try:
        return math.ldexp(x, e)
    except OverflowError:
        return math.copysign(math.inf, x)


def _check_vector_property(name: str, inv: Invariants, value: np.ndarray) -> None:
    if name == "plane_normal":
        require(abs(float(np.linalg.norm(value)) - 1.0) < 1e-12, "plane_normal is not a unit")
    elif name == "angular_momentum":
        e = inv.e_I + inv.e_w
        want = np.array([_in_caller_units(x, e) for x in inv.L.tolist()])
        atol = 1e-12 * _in_caller_units(inv.G, e) + _SUBNORMAL
        require(bool(np.allclose(value, want, rtol=0, atol=atol)), f"L = {value}, not {want}")
    else:  # sqrt(2T/I_i), compared in the caller's units (it may be subnormal there)
        want = np.array([_in_caller_units(x, inv.e_w) for x in np.sqrt(inv.two_T / inv.I)])
        ok = np.allclose(value, want, rtol=1e-12, atol=_SUBNORMAL)
        require(bool(ok), f"semi-axes {value} != {want}")


TARGETS: dict[str, Callable[[Source], Call]] = {
    "FreeRigidBody": construct,
    "FreeRigidBody.from_energy": from_energy,
    "FreeRigidBody.polhode": polhode,
    "FreeRigidBody.<property>": properties,
    **{f"FreeRigidBody.{m}": _method(m) for m in _METHODS},
}
