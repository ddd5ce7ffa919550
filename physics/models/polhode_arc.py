"""The progress of the contact point along its polhode: arc length and fraction of a circuit
[FM06 Remark 7.5]. Re-exported by :mod:`poinsot.physics.models.family`.

The speed along the polhode is ``|dω/dt|`` (Euler's equations on the exact ω(t)); it is
periodic with the period of ω, so its Fourier series over one circuit, integrated term by term,
gives the arc length at any time. Everything is computed in units where the largest moment and
the largest ``|ω0|`` component are powers of two near 1, as the body itself works: the squares
of ω ~ 1e200 would overflow, those of ω ~ 1e-200 underflow.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import special

from poinsot.physics.core.exact import ldexp, pow2_below
from poinsot.physics.core.free_body import FreeRigidBody
from poinsot.physics.core.regime import Regime
from poinsot.physics.core.validation import check_time_array

__all__ = ["PolhodeArc", "polhode_progress"]

_EPS = float(np.finfo(float).eps)
#: Fourier samples of |dω/dt| per circuit: start, and the most before giving up.
_ARC_SAMPLES_MIN, _ARC_SAMPLES_MAX = 64, 1 << 21
#: The series of |dω/dt| is converged when its coefficients in the upper quarter of the
#: spectrum fall below this fraction of the mean, or below the rounding noise of the samples,
#: _ARC_NOISE_EPS · eps · max|dω/dt| (a bursty speed, next to the separatrix, has a mean far
#: below its peak; a noise-level term adds < 1e-13 of a circuit to the arc).
_ARC_TAIL = 1e-15
_ARC_NOISE_EPS = 16.0


def _omega_dot_norm(inertia: NDArray[np.float64], w: NDArray[np.float64]) -> NDArray[np.float64]:
    """``|dω/dt|`` from Euler's equations ``I1 ω1' = (I2 - I3) ω2 ω3`` and cyclic [LL76 §36,
    Eq. 36.5], for rows of ``w`` (N, 3)."""
    I1, I2, I3 = inertia
    d1 = (I2 - I3) / I1 * w[:, 1] * w[:, 2]
    d2 = (I3 - I1) / I2 * w[:, 2] * w[:, 0]
    d3 = (I1 - I2) / I3 * w[:, 0] * w[:, 1]
    return np.hypot(np.hypot(d1, d2), d3)


class PolhodeArc:
    """The arc length travelled by the tip of ω along its polhode (in the body frame).

    Args:
        body: any :class:`FreeRigidBody`.

    The samples of the speed are doubled until the upper quarter of the spectrum is below
    ``1e-15`` of the mean; as a function of time the speed is analytic in a strip of width
    O(1/λ), so even next to the separatrix (1 - m = 1e-24) a few thousand samples reach
    rounding: ``s(t) = c0 t + Σ_k 2 Re(F_k (e^{ikwt} - 1)/(ikw))``.

    The separatrix is not periodic: there ``ω = (s1 A1 cos φ, A2 sin φ, s3 A3 cos φ)`` with
    ``sin φ = tanh u``, an arc of an ellipse, whose length is the incomplete elliptic integral
    ``∫ sqrt(a² sin²φ + A2² cos²φ) dφ = A2 E(φ | 1 - a²/A2²)``, ``a² = A1² + A3²``.
    A constant ω (permanent rotation, sphere, rest) travels nothing.

    Raises:
        ValueError: ``body`` is not a FreeRigidBody, or (from :meth:`arc_length`) an arc
            length beyond the double range.
    """

    def __init__(self, body: FreeRigidBody):
        if not isinstance(body, FreeRigidBody):
            raise ValueError(f"PolhodeArc needs a FreeRigidBody, got {type(body).__name__}")
        self.body = body
        self.circuit_time = float(body.period)
        """Time of one circuit of the polhode, the period of ω [time] (inf if none)."""
        # Scaled units: moments and ω over exact powers of two.
        inertia = np.asarray(body.inertia, dtype=float)
        self._inertia = inertia / pow2_below(float(inertia.max()))
        w_max = float(np.max(np.abs(body.omega0)))
        self._w_exp = math.frexp(w_max)[1] - 1 if w_max > 0.0 else 0
        self._coef = np.zeros(0, dtype=complex)
        # Arc lengths are kept scaled: s = s_scaled · 2^_exp in the caller's units.
        self._exp = self._w_exp
        self._mean = 0.0
        self._w = 0.0  # 2π / period
        self._sep: tuple[float, float, float] | None = None
        self._sep_axes = (0, 1, 2)
        if body.regime is Regime.SEPARATRIX:
            self._init_separatrix()
        elif math.isfinite(self.circuit_time):
            self._init_series()
        self.circuit_length = float(self._in_units(self._circuit_length_scaled(), "one circuit"))
        """Length of one circuit [rad/time] (of the whole arc ``-e2 → +e2`` on the separatrix;
        0 for a constant ω)."""

    def _omega_scaled(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.ldexp(self.body.omega(t), -self._w_exp)

    def _in_units(self, x: NDArray[np.float64] | float, what: str) -> NDArray[np.float64]:
        """Scaled arc lengths in the caller's units, or a ValueError."""
        with np.errstate(over="ignore"):
            out = np.ldexp(x, self._exp) if np.ndim(x) else np.float64(ldexp(float(x), self._exp))
        if not np.all(np.isfinite(out)):
            raise ValueError(
                f"the arc length of {what} is beyond the double-precision range (1.8e308): "
                "use a shorter time span, or a shorter time unit (then ω is a smaller number)"
            )
        return np.asarray(out, dtype=float)

    def _init_series(self) -> None:
        """The series of ``g = |dω/dt| / ω_ref²`` (Euler's equations on the scaled ω) over
        one circuit in the caller's time: the arc length is ``ω_ref² ∫ g dt``."""
        P = self.circuit_time
        M = _ARC_SAMPLES_MIN
        self._exp = 2 * self._w_exp
        while True:
            t = np.arange(M, dtype=np.float64) * (P / M)
            with np.errstate(over="ignore", invalid="ignore"):
                f = _omega_dot_norm(self._inertia, self._omega_scaled(t))
            if not np.all(np.isfinite(f)):
                raise ValueError(
                    "the speed of ω along this polhode leaves the double-precision range (the "
                    "moments are too far apart for it): express them closer together"
                )
            F = np.fft.rfft(f) / M
            mean = float(F[0].real)
            tail = np.abs(F[3 * (M // 8) : M // 2])
            floor = max(_ARC_TAIL * mean, _ARC_NOISE_EPS * _EPS * float(f.max()))
            if mean == 0.0 or float(tail.max()) <= floor:
                break
            if M >= _ARC_SAMPLES_MAX:
                raise ValueError(
                    "the speed along this polhode does not resolve with "
                    f"{_ARC_SAMPLES_MAX} samples per circuit (the motion lies too close to the "
                    "separatrix for its arc length to be tabulated)"
                )
            M *= 2
        self._mean = mean
        coef = 2.0 * F[1 : M // 2]
        keep = np.flatnonzero(np.abs(coef) > 0.1 * floor)
        self._coef = coef[: int(keep[-1]) + 1] if keep.size else coef[:0]
        self._w = 2.0 * math.pi / P

    def _init_separatrix(self) -> None:
        order = np.argsort(self._inertia, kind="stable")  # caller's indices of I1, I2, I3
        Is = self._inertia[order]
        ws = np.ldexp(self.body.omega0.astype(float), -self._w_exp)[order]
        two_T = float(np.sum(Is * ws * ws))
        A1sq = two_T * (Is[2] - Is[1]) / (Is[0] * (Is[2] - Is[0]))
        A3sq = two_T * (Is[1] - Is[0]) / (Is[2] * (Is[2] - Is[0]))
        A2 = math.sqrt(two_T / Is[1])
        self._sep = (A2, math.sqrt(A1sq + A3sq), 1.0 - (A1sq + A3sq) / (A2 * A2))
        self._sep_axes = (int(order[0]), int(order[1]), int(order[2]))

    def _separatrix_arc(self, w: NDArray[np.float64]) -> NDArray[np.float64]:
        """Signed arc length (scaled units) from the arc's midpoint (φ = 0) to the scaled
        points ``w`` (N, 3)."""
        assert self._sep is not None
        A2, a, m = self._sep
        k1, k2, k3 = self._sep_axes
        # sin φ = ω2/A2, cos φ = hypot(ω1, ω3)/a >= 0: atan2 keeps the digits of both.
        phi = np.arctan2(w[:, k2] / A2, np.hypot(w[:, k1], w[:, k3]) / a)
        return A2 * special.ellipeinc(phi, m)

    def _circuit_length_scaled(self) -> float:
        if self._sep is not None:
            A2, _, m = self._sep
            return float(2.0 * A2 * special.ellipe(m))
        if not math.isfinite(self.circuit_time) or self._mean == 0.0:
            return 0.0
        return self._mean * self.circuit_time

    def _series(self, r: NDArray[np.float64]) -> NDArray[np.float64]:
        """``∫₀^r g dt`` for ``0 <= r < P`` (N,), from the integrated Fourier series:
        ``Σ_k b_k (z^k - 1)`` with ``z = e^{iwr}``, ``b_k = c_k/(ikw)``, summed by Horner's
        scheme (one complex multiply-add per term and time; ``|z| = 1`` keeps it stable)."""
        out = self._mean * r
        if self._coef.size == 0:
            return out
        kw = np.arange(1, self._coef.size + 1) * self._w
        b = self._coef / (1j * kw)
        z = np.exp(1j * self._w * r)
        acc = np.full(r.shape, b[-1], dtype=complex)
        for bk in b[-2::-1]:  # a loop over the series' terms, each step vectorised over times
            acc = acc * z + bk
        return out + (acc * z).real - float(b.sum().real)

    def arc_length(self, t: ArrayLike) -> NDArray[np.float64]:
        """Arc length [rad/time] travelled along the polhode from ``t = 0`` to ``t`` (N,),
        whole circuits included (negative for ``t < 0``)."""
        tt = check_time_array(t)
        if self._sep is not None:
            # The tip runs monotonically from one pole to the other: the arc travelled is the
            # distance along the arc, signed like t.
            moved = self._separatrix_arc(self._omega_scaled(tt))
            start = np.ldexp(self.body.omega0[None, :].astype(float), -self._w_exp)
            moved = moved - self._separatrix_arc(start)
            return self._in_units(np.copysign(np.abs(moved), tt), "this span of time")
        if self.circuit_length == 0.0:
            return np.zeros_like(tt)
        P = self.circuit_time
        with np.errstate(over="ignore", invalid="ignore"):
            turns = np.floor(tt / P)
            r = np.clip(tt - turns * P, 0.0, P)
            scaled = turns * self._circuit_length_scaled() + self._series(r)
        return self._in_units(scaled, "this span of time")

    def fraction(self, t: ArrayLike) -> NDArray[np.float64]:
        """The fraction in ``[0, 1)`` of one circuit travelled since ``t = 0``, modulo whole
        circuits (N,). On the separatrix: the arc travelled over the whole arc's length
        (``-e2 → +e2``), in ``(-1, 1)``. 0 for a constant ω."""
        s = self.arc_length(t)
        if self.circuit_length == 0.0:
            return s
        if self._sep is not None:
            return s / self.circuit_length
        frac = np.mod(s / self.circuit_length, 1.0)
        return np.where(frac >= 1.0, 0.0, frac)


def polhode_progress(body: FreeRigidBody, t: ArrayLike) -> tuple[NDArray[np.float64], float]:
    """``(fraction (N,), circuit_time)``: :meth:`PolhodeArc.fraction` at the times ``t`` and the
    time one circuit of the polhode takes (the period of ω; ``inf`` if it never closes)."""
    arc = PolhodeArc(body)
    return arc.fraction(t), arc.circuit_time
