"""What a result of the public API must satisfy: finite numbers and the invariants of the motion.

The invariants of torque-free motion are checked in units where the largest moment and the
largest ``|ω0|`` component are powers of two near 1 (exact scalings, as the body itself works):
``2T = ω·Iω`` and ``G = |Iω|`` along ω(t); ``L = R(t) I ω(t)`` fixed in space; the contact point
``R(t) ω(t)`` on the invariable plane at ``2T/G`` from the origin; unit quaternions. Each holds
to :data:`TOL` relative to its scale, plus a few subnormal spacings of the caller's numbers
(a motion at ω ~ 1e-320 carries only the digits a subnormal has).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

__all__ = ["TOL", "InvariantError", "Invariants", "finite", "require", "rotation", "worst"]

#: Relative tolerance of every invariant.
TOL = 1e-10
#: The largest relative error met per invariant (filled as the checks run; the report prints it).
worst: dict[str, float] = {}

Array = NDArray[np.float64]


class InvariantError(AssertionError):
    """A result that is not finite, has the wrong shape, or breaks an invariant."""


def require(condition: bool, message: str) -> None:
    if not condition:
        raise InvariantError(message)


def finite(value: Any, shape: tuple[int, ...] | None = None, what: str = "result") -> Array:
    """``value`` as a float64 array of finite numbers (of ``shape`` if given)."""
    require(isinstance(value, np.ndarray), f"{what} is a {type(value).__name__}, not an array")
    require(value.dtype == np.float64, f"{what} has dtype {value.dtype}")
    require(shape is None or value.shape == shape, f"{what} has shape {value.shape}, not {shape}")
    require(bool(np.all(np.isfinite(value))), f"{what} is not finite: {value!r}"[:300])
    return value


def number(value: Any, what: str, *, allow_inf: bool = False) -> float:
    """``value`` as a float: finite (or +inf if allowed)."""
    require(isinstance(value, float), f"{what} is a {type(value).__name__}, not a float")
    ok = math.isfinite(value) or (allow_inf and value == math.inf)
    require(ok, f"{what} = {value}")
    return float(value)


def rotation(value: Any, n: int | None, what: str = "attitude") -> Array:
    """The quaternions (n, 4) (or (4,) for n None) of a Rotation: finite and of unit norm."""
    require(isinstance(value, Rotation), f"{what} is a {type(value).__name__}, not a Rotation")
    require(value.single == (n is None), f"{what}: single is {value.single}")
    q = finite(value.as_quat(), (4,) if n is None else (n, 4), what)
    err = float(np.max(np.abs(np.linalg.norm(q, axis=-1) - 1.0), initial=0.0))
    _measure("|q| = 1", err)
    require(err <= TOL, f"{what}: quaternion norms off by {err:.2e}")
    return q


def _measure(name: str, err: float) -> None:
    if err > worst.get(name, 0.0):
        worst[name] = err


def _close(name: str, got: Array | float, want: Array | float, scale: float, slack: float) -> None:
    """``|got - want| <= TOL scale + slack`` everywhere; the relative error is recorded."""
    diff = float(np.max(np.abs(np.asarray(got) - np.asarray(want)), initial=0.0))
    if scale > 0.0:
        _measure(name, max(diff - slack, 0.0) / scale)
    require(diff <= TOL * scale + slack, f"{name}: off by {diff:.3e} at scale {scale:.3e}")


class Invariants:
    """The invariants of a body, from its checked input, in exactly scaled units.

    Args:
        inertia, omega0: (3,) the body's moments and initial ω (as the body stores them).
        attitude0: ``R(0)``.
    """

    def __init__(self, inertia: Array, omega0: Array, attitude0: Rotation) -> None:
        self.e_I = math.frexp(float(np.max(inertia)))[1]
        w_max = float(np.max(np.abs(omega0)))
        self.e_w = math.frexp(w_max)[1] if w_max > 0.0 else 0
        self.I = np.ldexp(inertia, -self.e_I)
        w0 = np.ldexp(omega0, -self.e_w)
        m0 = self.I * w0
        self.G = math.hypot(*m0.tolist())
        self.two_T = float(np.sum(m0 * w0))
        self.L = attitude0.apply(m0)
        # A few subnormal spacings of the caller's ω, in these units.
        self.q = 8.0 * math.ldexp(5e-324, -self.e_w)

    @classmethod
    def of(cls, body: Any) -> Invariants:
        return cls(body.inertia, body.omega0, body.attitude0)

    def omega(self, w: Array, what: str = "omega") -> Array:
        """ω rows (..., 3) in the caller's units: 2T and G as at t = 0. Returns them scaled."""
        ws = np.ldexp(finite(w, None, what), -self.e_w).reshape(-1, 3)
        m = self.I * ws
        G = np.hypot(np.hypot(m[:, 0], m[:, 1]), m[:, 2])
        _close("G = |I ω|", G, self.G, self.G, 3.0 * self.q)
        _close("2T = ω·I ω", np.sum(m * ws, axis=1), self.two_T, self.two_T, 3.0 * self.G * self.q)
        return ws

    def attitude(self, w_scaled: Array, q: Array) -> None:
        """L = R(t) I ω(t) fixed in space, for scaled ω rows and quaternions (N, 4)."""
        m = self.I * w_scaled
        L = Rotation.from_quat(q.reshape(-1, 4)).apply(m)
        _close("L fixed in space", L, self.L, self.G, 3.0 * self.q)

    def contact(self, c: Array, w_scaled: Array, q: Array) -> None:
        """The contact point ``R ω`` (rows, caller's units) on the invariable plane."""
        cs = np.ldexp(finite(c, None, "contact point"), -self.e_w).reshape(-1, 3)
        rotated = Rotation.from_quat(q.reshape(-1, 4)).apply(w_scaled)
        size = float(np.max(np.abs(w_scaled), initial=0.0))
        _close("contact = R ω", cs, rotated, size, 3.0 * self.q)
        if self.G > 0.0:
            height = cs @ (self.L / self.G)
            _close("plane distance 2T/G", height, self.two_T / self.G, size, 3.0 * self.q)

    def scaled(self, x: float, e: int) -> float:
        return math.ldexp(x, -e)
