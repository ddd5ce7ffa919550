"""A high-precision reference motion for the report: Taylor series at >= 30 digits.

The work-precision report (:mod:`poinsot.app.report`) measures the integrators against the exact
solution :class:`physics.FreeRigidBody`, and measures the exact solution itself against this
reference. To be a check and not a copy, the reference shares no formula with the closed form:
it integrates Euler's equations plus the quaternion kinematics ``q' = q (omega, 0) / 2`` by the
Taylor-series method, with the Taylor coefficients computed exactly by the recurrences of the
polynomial right-hand side (Cauchy products). The only errors are the truncation of each series
(held below ``10**-digits`` relative to the state) and rounding at ``digits + GUARD_DIGITS``
digits.

Arithmetic. The series, the steps and Newton's iteration run in binary fixed point on Python
integers (a number is ``n * 2**-bits``): after scaling omega and time by a power of two near
``|omega0|`` (exact) every quantity is O(1), so fixed point loses nothing against floating point
and a product of two 150-bit integers costs ~50 ns, against ~3 us for an mpmath product. mpmath
(at the same precision) does the rest: the conversions, the trigonometry of the folding below,
and the error measures in :meth:`TaylorReference.compare`.

Long times use the periodicity of omega instead of integrating through every period: if
``omega(P) = omega(0)`` then ``R(t + P) = C R(t)`` with ``C = R(P) R(0)^T`` (both sides solve
``R' = R [omega]x``), so ``R(k P + tau) = C^k R(tau)``; C is a rotation about L and its k-th power
is taken in closed form from its axis and angle. The period P is found by Newton's method on
the Taylor polynomials, started from a float guess (e.g. ``FreeRigidBody.period``), and accepted
only if it matches the guess and *all three* components of omega return to omega(0) to the
reference's accuracy. The digits lost to ``k`` are ``log10(k)``: 4 of them at 1e4 periods.

mpmath is an optional dependency (the ``test`` extra); import this module lazily.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Iterable
from dataclasses import dataclass
from operator import mul
from typing import Any

import mpmath

from poinsot.physics.core.rotations import conjugate, hamilton

#: Significant digits the reference is accurate to: >= 30, so that errors of the closed form
#: near 1e-16 are measured with ~14 digits to spare.
DIGITS = 32
#: Extra working digits: cover the rounding of ~1e4 Taylor steps (4 digits), the log10(k) digits
#: lost to folding k periods at 1e4 periods (4 digits), and a margin.
GUARD_DIGITS = 12
#: Taylor order. The cost per step grows like ORDER^2 and the step like 10^(-DIGITS/ORDER), so
#: the cost per unit time is flat for orders between ~25 and ~60; 30 sits in that valley.
ORDER = 30
#: Give up integrating directly beyond this many Taylor steps.
MAX_STEPS = 200_000
#: The period found by Newton must match the float guess to this: the closed form's period is
#: good to ~1e-14, and any other root of omega_j(t) = omega_j(0) lies a fraction of a period away.
PERIOD_MATCH_RTOL = 1e-8


@dataclass(frozen=True)
class Comparison:
    """Errors of a float solution against the reference at one time."""

    t: float
    omega_error: float
    """|omega - omega_ref| / |omega_ref|."""
    attitude_error: float
    """Geodesic angle between the two attitudes [rad]."""


class TaylorReference:
    """The free rigid body integrated by Taylor series, evaluated at any t >= 0.

    Args:
        inertia: (3,) principal moments (floats, any order, the caller's axes).
        omega0: (3,) body angular velocity at t = 0 [rad / time unit].
        quat0: (4,) scalar-last quaternion of the attitude at t = 0 (body -> space); it is
            normalised at high precision.
        digits: accuracy target in significant digits (>= 30).
    """

    def __init__(
        self,
        inertia: Iterable[float],
        omega0: Iterable[float],
        quat0: Iterable[float] = (0.0, 0.0, 0.0, 1.0),
        digits: int = DIGITS,
    ) -> None:
        if digits < 30:
            raise ValueError("the reference must carry at least 30 digits")
        self.digits = digits
        self.ctx = ctx = mpmath.MPContext()
        ctx.dps = digits + GUARD_DIGITS
        self._bits = math.ceil((digits + GUARD_DIGITS) * math.log2(10)) + 8
        moments = [float(v) for v in inertia]
        omega = [float(v) for v in omega0]
        if min(moments) <= 0.0:
            raise ValueError("the moments of inertia must be positive")
        self._moments = tuple(ctx.mpf(v) for v in moments)
        # Scale omega and time by a power of two near |omega0| (exact in binary): omega/nu0 and
        # q are O(1), which is what fixed point needs.
        top = max(abs(v) for v in omega)
        self._nu0 = 2.0 ** math.frexp(top)[1] if top > 0.0 else 1.0
        i1, i2, i3 = self._moments
        # Euler's equations I1 w1' = (I2 - I3) w2 w3, cyclic [LL76 §36, Eq. 36.5].
        self._a = tuple(self._fix(x) for x in ((i2 - i3) / i1, (i3 - i1) / i2, (i1 - i2) / i3))
        w = [self._fix(ctx.mpf(v) / self._nu0) for v in omega]
        q = [ctx.mpf(float(v)) for v in quat0]
        norm = ctx.sqrt(ctx.fsum(x * x for x in q))
        q = [self._fix(x / norm) for x in q]
        # The scale of the omega coefficients: |omega0| (in units of nu0). |omega| varies along
        # the motion by a modest factor; the looser bound |L| / I_min would let the truncation
        # error of a needle (I_min / I_max = 1e-4) grow to ~1e-30.
        self._omega_scale = max(math.hypot(*omega) / self._nu0, 2.0**-900)
        # Per-step truncation 1000x below the target: the errors of ~1e3 steps (a period of the
        # near-separatrix cases, or a horizon integrated directly) then still add up to < 1 unit.
        self._tol = 10.0 ** (-(digits + 3))
        self._state0 = w + q
        self._starts: list[int] = [0]
        self._coeffs: list[list[list[int]]] = []
        self._end_state = list(self._state0)
        self._period: int | None = None
        # The quaternion C = q(P) q(0)^-1 (space frame), mpf components.
        self._per_period: tuple[Any, Any, Any, Any] | None = None

    # -- fixed point ------------------------------------------------------------------------------

    def _fix(self, x: Any) -> int:
        """mpf (or float) -> fixed-point integer, rounded to nearest."""
        return int(self.ctx.nint(self.ctx.ldexp(self.ctx.mpf(x), self._bits)))

    def _mp(self, n: int) -> Any:
        """Fixed-point integer -> mpf (exact)."""
        return self.ctx.ldexp(self.ctx.mpf(n), -self._bits)

    def _float(self, n: int) -> float:
        """Fixed-point integer -> float, without overflow for huge integers."""
        shift = max(n.bit_length() - 64, 0)
        return math.ldexp(float(n >> shift), shift - self._bits)

    def _time_fix(self, t: float) -> int:
        """Float time -> fixed-point scaled time s = nu0 t (exact: both are binary scalings)."""
        return int(math.ldexp(float(t) * self._nu0, self._bits))

    # -- Taylor series ----------------------------------------------------------------------------

    def _series(self, state: list[int]) -> list[list[int]]:
        """Taylor coefficients y_0..y_ORDER of (w1, w2, w3, qx, qy, qz, qw) about ``state``.

        The right-hand side is quadratic, so y_{k+1} = F_k / (k + 1) where F_k is the k-th
        coefficient of F(y), a sum of Cauchy products of the coefficients already known.
        Fixed point: a product of two numbers carries 2 * bits fraction bits, hence ``>> bits``.
        """
        bits = self._bits
        a1, a2, a3 = self._a
        w1, w2, w3, x, y, z, s = ([v] for v in state)

        def conv(p: list[int], r: list[int]) -> int:
            return sum(map(mul, p, r))

        for k in range(ORDER):
            r1, r2, r3 = w1[::-1], w2[::-1], w3[::-1]
            n = k + 1
            w1.append(((a1 * (conv(w2, r3) >> bits)) >> bits) // n)
            w2.append(((a2 * (conv(w3, r1) >> bits)) >> bits) // n)
            w3.append(((a3 * (conv(w1[:-1], r2) >> bits)) >> bits) // n)
            # q' = q (omega, 0) / 2 = ((s omega + v x omega) / 2, -(v . omega) / 2).
            dx = conv(s, r1) + conv(y, r3) - conv(z, r2)
            dy = conv(s, r2) + conv(z, r1) - conv(x, r3)
            dz = conv(s, r3) + conv(x, r2) - conv(y, r1)
            ds = -(conv(x, r1) + conv(y, r2) + conv(z, r3))
            x.append((dx >> (bits + 1)) // n)
            y.append((dy >> (bits + 1)) // n)
            z.append((dz >> (bits + 1)) // n)
            s.append((ds >> (bits + 1)) // n)
        return [w1, w2, w3, x, y, z, s]

    def _step_size(self, series: list[list[int]]) -> int:
        """Largest h with |y_k| h^k <= tol for k = ORDER - 1, ORDER [JZ05]."""
        h = math.inf
        for k in (ORDER - 1, ORDER):
            size = max(
                self._float(max(abs(c[k]) for c in series[:3])) / self._omega_scale,
                self._float(max(abs(c[k]) for c in series[3:])),
            )
            if size > 0:
                h = min(h, (self._tol / size) ** (1.0 / k))
        if h == math.inf:  # every coefficient vanishes: the state is at rest
            h = 1.0
        return int(math.ldexp(h, self._bits))

    def _horner(self, coeffs: list[int], tau: int) -> int:
        bits = self._bits
        value = coeffs[-1]
        for c in reversed(coeffs[:-1]):
            value = ((value * tau) >> bits) + c
        return value

    def _extend_to(self, t: int) -> None:
        while self._starts[-1] <= t:
            if len(self._coeffs) >= MAX_STEPS:
                raise RuntimeError(f"the Taylor reference would need over {MAX_STEPS} steps")
            series = self._series(self._end_state)
            h = self._step_size(series)
            self._coeffs.append(series)
            self._end_state = [self._horner(c, h) for c in series]
            self._starts.append(self._starts[-1] + h)

    def _segment(self, t: int) -> tuple[list[list[int]], int]:
        self._extend_to(t)
        i = bisect.bisect_right(self._starts, t) - 1
        return self._coeffs[i], t - self._starts[i]

    def _direct(self, t: int) -> list[int]:
        series, tau = self._segment(t)
        return [self._horner(c, tau) for c in series]

    # -- periodicity ------------------------------------------------------------------------------

    def find_period(self, guess: float) -> bool:
        """Refine a float guess of the period of omega to full precision; True if confirmed.

        Newton's method on the component of omega that moves fastest at t = 0, then two checks:
        the root lies within PERIOD_MATCH_RTOL of the guess (so this also checks the closed
        form's period), and the whole of omega returns to omega(0) to the reference's accuracy
        (a root that is only a crossing of that one component fails).
        """
        if not (math.isfinite(guess) and guess > 0.0):
            return False
        bits = self._bits
        w0 = self._state0[:3]
        a1, a2, a3 = self._a
        rates = [a1 * w0[1] * w0[2], a2 * w0[2] * w0[0], a3 * w0[0] * w0[1]]
        j = max(range(3), key=lambda i: abs(rates[i]))
        if rates[j] == 0:
            return False
        start = self._time_fix(guess)
        t = start
        close = max(t // 10 ** (self.digits + 4), 2)
        for _ in range(50):
            series, tau = self._segment(t)
            value = self._horner(series[j], tau) - w0[j]
            slope = self._horner([k * c for k, c in enumerate(series[j])][1:], tau)
            if slope == 0:
                return False
            delta = (value << bits) // slope
            t -= delta
            if abs(delta) <= close:
                break
        if not abs(t - start) <= PERIOD_MATCH_RTOL * start:
            return False
        state = self._direct(t)
        mismatch = max(abs(state[i] - w0[i]) for i in range(3))
        if self._float(mismatch) > 10.0 ** (-(self.digits - 4)) * self._omega_scale:
            return False
        self._period = t
        # C = q(P) q(0)^-1: the quaternion of R(P) R(0)^T.
        q_p = [self._mp(v) for v in state[3:]]
        q_0 = [self._mp(v) for v in self._state0[3:]]
        self._per_period = hamilton(q_p, conjugate(q_0))
        return True

    @property
    def period(self) -> Any:
        """The period of omega [time units] as an mpf, once :meth:`find_period` confirmed it."""
        if self._period is None:
            return None
        return self._mp(self._period) / self._nu0

    # -- evaluation ------------------------------------------------------------------------------

    def state(self, t: float) -> tuple[list[Any], list[Any]]:
        """(omega (3 mpf), quaternion (4 mpf, scalar last)) at time t >= 0 (a float, exact)."""
        if t < 0:
            raise ValueError("the reference runs forward from t = 0")
        ctx = self.ctx
        fixed = self._time_fix(t)
        c = self._per_period  # set together with the period by find_period
        if self._period is None or c is None or fixed <= self._period:
            y = [self._mp(v) for v in self._direct(fixed)]
            return [v * self._nu0 for v in y[:3]], y[3:]
        k, tau = divmod(fixed, self._period)
        y = [self._mp(v) for v in self._direct(tau)]
        omega = [v * self._nu0 for v in y[:3]]
        vec = ctx.sqrt(c[0] ** 2 + c[1] ** 2 + c[2] ** 2)
        if vec == 0:
            return omega, y[3:]
        half = ctx.atan2(vec, c[3])  # C is a rotation by 2 * half about c[:3] / vec
        sk, ck = ctx.sin(k * half), ctx.cos(k * half)
        power = [sk * c[0] / vec, sk * c[1] / vec, sk * c[2] / vec, ck]
        return omega, list(hamilton(power, y[3:]))

    def compare(self, t: float, omega: Iterable[float], quat: Iterable[float]) -> Comparison:
        """Errors of a float solution (omega (3,), scalar-last quaternion (4,)) at time t."""
        ctx = self.ctx
        w_ref, q_ref = self.state(t)
        w = [ctx.mpf(float(v)) for v in omega]
        q = [ctx.mpf(float(v)) for v in quat]
        norm = ctx.sqrt(ctx.fsum(v * v for v in q))
        q = [v / norm for v in q]
        diff = ctx.sqrt(ctx.fsum((a - b) ** 2 for a, b in zip(w, w_ref, strict=True)))
        size = ctx.sqrt(ctx.fsum(b * b for b in w_ref))
        rel = diff / size if size > 0 else diff
        r = hamilton(conjugate(q_ref), q)
        angle = 2 * ctx.atan2(ctx.sqrt(r[0] ** 2 + r[1] ** 2 + r[2] ** 2), abs(r[3]))
        return Comparison(float(t), float(rel), float(angle))

    def invariants(self, t: float) -> tuple[Any, Any, tuple[Any, ...]]:
        """(2T, |m|^2, L in space (3 mpf)) at time t: for the reference's own self-checks."""
        ctx = self.ctx
        w, q = self.state(t)
        m = [i * x for i, x in zip(self._moments, w, strict=True)]
        two_t = ctx.fsum(i * x * x for i, x in zip(self._moments, w, strict=True))
        g2 = ctx.fsum(x * x for x in m)
        space = hamilton(hamilton(q, [m[0], m[1], m[2], ctx.mpf(0)]), conjugate(q))
        return two_t, g2, space[:3]

    @property
    def steps(self) -> int:
        """Taylor steps taken so far."""
        return len(self._coeffs)
