"""The gyroscope under a constant torque fixed in the body [FM06 §7.11, Eqs. 7.85-7.98].

A symmetric body, ``I1 = I2 = J`` (transverse), ``I3 = J3`` (axial), carries a torque of
constant size ``M`` along its own axis ``x2``: ``M = (0, M, 0)`` in the body frame. Euler's
equations with the torque [LL76 §36, Eq. 36.5] read

    ``J ω1' = (J - J3) ω2 ω3``,   ``J ω2' = (J3 - J) ω3 ω1 + M``,   ``J3 ω3' = 0``,

so ω3 is constant and, with ``ν = ((J3 - J)/J) ω3`` and ``ω1* = -M/((J3 - J) ω3)`` [FM06 Eq.
7.91], ``(ω1 - ω1*, ω2)`` turns uniformly on a circle [FM06 Eqs. 7.90-7.95]:

    ``ω1 = ω1* + C cos(ν t + α)``,   ``ω2 = C sin(ν t + α)``,
    ``C = hypot(ω1(0) - ω1*, ω2(0))``,   ``α = atan2(ω2(0), ω1(0) - ω1*)``

(check: ``ω1' = -ν ω2``, ``ω2' = ν (ω1 - ω1*) = ν ω1 + M/J``). The attitude has no closed form:
:meth:`Gyroscope.attitude` integrates ``R' = R [ω]×`` with this ω(t) by the fourth-order Magnus
method [HLW06 §IV.7] (two Gauss points, ``c = ½ ∓ √3/6``): each step is the exact rotation by
``θ = (h/2)(ω_a + ω_b) + (√3/12) h² ω_a × ω_b`` in the body frame, so the quaternion keeps unit
norm to rounding. All step rotations are formed at once and composed by a parallel prefix
product (log₂ N vectorised sweeps), and the result carries an error estimate from a run with
twice the steps (Richardson: the error of the finer run is ``|q_h - q_{h/2}|/15``).

*Tendency to parallelism* [FM06 Eq. 7.98]: the axis moves with ``de3/dt = ω × e3``, in body
components ``(ω2, -ω1, 0)``; over whole periods ``2π/|ν|`` of the nutation the average of ω2 is
0 and that of ω1 is ω1*, so the axis moves on average towards the current direction of the
torque, ``R x2``, at the rate ``M/((J3 - J) ω3)`` (for an oblate body spun with ω3 > 0 and
M > 0, towards the torque; the sign reverses for a prolate body, J3 < J, or ω3 < 0). Because
the torque turns with the body, this is a drift *relative to the torque*, not towards a fixed
direction in space.
:meth:`Gyroscope.measure_drift` reads it off the integrated attitude.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from poinsot.physics.core import rotations
from poinsot.physics.core.validation import (
    MAX_SAMPLES,
    check_attitude,
    check_count,
    check_number,
    check_positive,
    check_time_array,
    check_times,
    check_vector,
    grid_size,
)

__all__ = ["AttitudeRun", "DriftMeasurement", "Gyroscope"]

_SQRT3 = math.sqrt(3.0)
#: Default Magnus steps per turn of the fastest rotation (|ω| or ν): ~1e-11 rad per turn.
_STEPS_PER_TURN = 256
#: Samples for the drift measurement: at least this many per nutation period, and per turn of
#: the fastest rotation (4th-order differences: relative error ~(2π/1024)^4/30 ~ 5e-11).
_DRIFT_SAMPLES = 512
_DRIFT_SAMPLES_PER_TURN = 1024


@dataclass(frozen=True)
class AttitudeRun:
    """The integrated attitude on the requested times.

    Attributes:
        attitude: N rotations, body -> space. quaternions: (N, 4) scalar-last, unit norm.
        error_estimate: (N,) estimated error [rad] (geodesic angle) of ``attitude``.
        steps: Magnus steps of the returned run.
    """

    attitude: Rotation
    quaternions: NDArray[np.float64]
    error_estimate: NDArray[np.float64]
    steps: int


@dataclass(frozen=True)
class DriftMeasurement:
    """The mean velocity of the axis over whole nutation periods, read from the attitude.

    Attributes:
        along_torque: mean of ``de3/dt · (R x2)`` [rad/time], the drift towards the torque.
        across: mean of ``de3/dt · (R x1)`` [rad/time] (0 in theory).
        periods: whole nutation periods averaged. window: (t_start, t_end) [time].
    """

    along_torque: float
    across: float
    periods: int
    window: tuple[float, float]


#: The most nutation periods measure_drift averages over.
_MAX_PERIODS = 10_000


class Gyroscope:
    """A symmetric body with a constant torque ``(0, M, 0)`` fixed in the body.

    Args:
        transverse: J = I1 = I2 [moment]. axial: J3 [moment], different from J.
        torque: M [moment × rad/time²], along body x2 (any sign, 0 allowed).
        omega0: (3,) body-frame ω at t = 0 [rad/time], ``ω3 ≠ 0``.
        attitude0: R(0), body -> space (identity if None).

    Raises:
        ValueError: ``J3 = J`` (no gyroscopic term: ω1 grows without bound, there is no nutation
            circle), ``ω3 = 0`` (no spin), or values that are not finite/positive.
    """

    def __init__(
        self,
        transverse: float,
        axial: float,
        torque: float,
        omega0: ArrayLike,
        attitude0: Rotation | None = None,
    ):
        J = check_positive(transverse, "the transverse moment J")
        J3 = check_positive(axial, "the axial moment J3")
        M = check_number(torque, "the torque M")
        w = check_vector(omega0, "omega0")
        if J3 == J:
            raise ValueError(
                "J3 = J: with equal moments the torque meets no gyroscopic resistance "
                "(ω1* = -M/((J3 - J) ω3) is infinite); choose an axial moment J3 ≠ J"
            )
        if w[2] == 0.0:
            raise ValueError(
                "ω3 = 0: a gyroscope must spin about its symmetry axis (ω1* = -M/((J3 - J) ω3) "
                "is infinite); give omega0 a non-zero third component"
            )
        attitude0 = check_attitude(attitude0)
        self.transverse, self.axial, self.torque = J, J3, M
        self.omega0 = w.copy()
        self.attitude0 = attitude0
        w3 = float(w[2])
        if (J3 - J) * w3 == 0.0:  # (J3 - J) ω3 underflowed: ω1* is beyond the range
            raise ValueError(
                f"(J3 - J) ω3 = ({J3:g} - {J:g}) · {w3:g} underflows: ω1* = -M/((J3 - J) ω3) is "
                "beyond the double-precision range; express the moments and ω0 in other units"
            )
        self.nutation_center = -M / ((J3 - J) * w3)
        """ω1* [rad/time], the centre of the nutation circle [FM06 Eq. 7.91]."""
        self.nutation_rate = (J3 - J) / J * w3
        """ν [rad/time], the rate at which (ω1 - ω1*, ω2) turns [FM06 Eq. 7.88]."""
        self.amplitude = math.hypot(float(w[0]) - self.nutation_center, float(w[1]))
        """C [rad/time], the radius of the nutation circle [FM06 Eq. 7.94]."""
        self.phase = math.atan2(float(w[1]), float(w[0]) - self.nutation_center)
        """α [rad]: the phase on the nutation circle [FM06 Eq. 7.95]."""
        self.drift_rate = M / ((J3 - J) * w3)
        """The mean rate [rad/time] of the axis towards the torque [FM06 Eq. 7.98]."""
        self.nutation_period = (
            2.0 * math.pi / abs(self.nutation_rate) if self.nutation_rate else math.inf
        )
        """2π/|ν| [time]."""
        self._check_range()

    def _check_range(self) -> None:
        """Refuse a gyroscope whose constants leave the double range (moments 1e-300 apart, a
        torque of 1e300, a spin of 1e-300: ω1* or ν overflow or underflow)."""
        values = (
            self.nutation_center,
            self.nutation_rate,
            self.amplitude,
            self.drift_rate,
            self.nutation_period,
            self._fastest_rate(),
        )
        if all(map(math.isfinite, values)) and self.nutation_rate != 0.0:
            return
        raise ValueError(
            "the nutation of this gyroscope lies beyond the double-precision range "
            f"(ω1* = {self.nutation_center:g}, ν = {self.nutation_rate:g} in your units): "
            "express the moments, the torque and ω0 in units closer to each other"
        )

    @property
    def inertia(self) -> NDArray[np.float64]:
        """(3,) ``(J, J, J3)``."""
        return np.array([self.transverse, self.transverse, self.axial])

    def omega(self, t: ArrayLike) -> NDArray[np.float64]:
        """Body-frame ω(t) [rad/time] in closed form: (3,) for a number, (N, 3) for (N,)."""
        tt = np.asarray(check_times(t, "t"), dtype=float)
        with np.errstate(over="ignore"):
            angle = self.nutation_rate * tt + self.phase
        if not np.all(np.isfinite(angle)):
            raise ValueError(
                "t is too far for this gyroscope: its nutation phase ν t passes the "
                "double-precision range (1.8e308 rad); use smaller times"
            )
        w1 = self.nutation_center + self.amplitude * np.cos(angle)
        w2 = self.amplitude * np.sin(angle)
        return np.stack([w1, w2, np.full_like(w1, self.omega0[2])], axis=-1)

    def _fastest_rate(self) -> float:
        """The fastest rotation [rad/time]: the largest |ω| on the circle, or ν."""
        largest = math.hypot(abs(self.nutation_center) + self.amplitude, float(self.omega0[2]))
        return max(largest, abs(self.nutation_rate))

    def _default_step(self) -> float:
        return 2.0 * math.pi / (_STEPS_PER_TURN * self._fastest_rate())

    def _magnus(self, t_eval: NDArray[np.float64], h: float) -> tuple[NDArray, int]:
        """Quaternions (N, 4) at ``t_eval`` by Magnus-4 steps no longer than ``h``."""
        edges = np.concatenate([[0.0], t_eval])
        counts = np.ceil(np.diff(edges) / h - 1e-12).astype(np.int64)
        counts = np.maximum(counts, np.where(np.diff(edges) > 0.0, 1, 0))
        total = int(counts.sum())
        if total == 0:  # every output time is t = 0
            return np.tile(self.attitude0.as_quat(), (t_eval.size, 1)), 0
        # Every step's start and length, interval by interval (each interval cut evenly).
        interval = np.repeat(np.arange(counts.size), counts)
        first = np.cumsum(counts) - counts
        k = np.arange(total) - first[interval]
        length = (np.diff(edges) / np.maximum(counts, 1))[interval]
        start = edges[interval] + k * length
        wa = self.omega(start + (0.5 - _SQRT3 / 6.0) * length)
        wb = self.omega(start + (0.5 + _SQRT3 / 6.0) * length)
        # h ω_a × h ω_b rather than h² (ω_a × ω_b): the angles, not ω² (which overflows for
        # ω ~ 1e200 however short the step).
        ha, hb = length[:, None] * wa, length[:, None] * wb
        theta = 0.5 * (ha + hb) + (_SQRT3 / 12.0) * np.cross(ha, hb)
        angle = np.linalg.norm(theta, axis=1)
        half_sinc = 0.5 * np.sinc(angle / (2.0 * math.pi))  # sin(a/2)/a, finite at a = 0
        steps = np.concatenate([theta * half_sinc[:, None], np.cos(0.5 * angle)[:, None]], axis=1)
        prefix = _prefix_products(steps)
        q0 = self.attitude0.as_quat()
        reached = np.cumsum(counts)  # steps taken up to each output time
        composed = np.where(
            (reached > 0)[:, None], prefix[np.maximum(reached - 1, 0)], [0.0, 0.0, 0.0, 1.0]
        )
        q = rotations.multiply(q0, composed)
        return q / np.linalg.norm(q, axis=1, keepdims=True), total

    def attitude(self, t: ArrayLike, step: float | None = None) -> AttitudeRun:
        """R(t) on the times ``t`` (N,) ``>= 0`` non-decreasing, by Magnus-4 with steps of at most
        ``step/2`` [time] (default: 1/512 of the fastest turn), with its error estimate from the
        run with steps of at most ``step``."""
        tt = check_time_array(t)
        if tt.size == 0:
            raise ValueError("t must be a non-empty 1-D array of finite times")
        if tt[0] < 0.0 or np.any(tt[1:] < tt[:-1]):
            raise ValueError("t must be non-negative and non-decreasing (the run starts at 0)")
        h = self._default_step() if step is None else check_positive(step, "the step")
        turn = h * self._fastest_rate()
        if not turn <= math.pi:
            raise ValueError(
                f"a step of {h:g} turns the body by up to {turn:.3g} rad, more than half a turn: "
                f"too long for Magnus-4; use a step below {h * math.pi / turn:.3g}"
            )
        steps = grid_size(
            float(tt[-1]), 0.5 * h, "the Magnus run up to t", "use a larger step or shorter t"
        )
        if steps + tt.size > MAX_SAMPLES:
            raise ValueError(
                f"{tt.size} output times need as many Magnus steps, with {steps} more to reach "
                f"t: at most {MAX_SAMPLES:,} in all; ask for fewer times"
            )
        coarse, _ = self._magnus(tt, h)
        fine, steps = self._magnus(tt, 0.5 * h)
        error = rotations.geodesic_angle(coarse, fine) / 15.0
        return AttitudeRun(Rotation.from_quat(fine), fine, error, steps)

    def axis_and_torque(self, t: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The symmetry axis ``R e3`` and the torque direction ``R x2`` in space, (N, 3) each,
        from :meth:`attitude`: what the scene draws."""
        R = self.attitude(t).attitude
        return R.apply([0.0, 0.0, 1.0]), R.apply([0.0, 1.0, 0.0])

    def measure_drift(
        self, periods: int = 4, samples: int | None = None, t_start: float = 0.0
    ) -> DriftMeasurement:
        """The mean velocity of the axis, relative to the torque, read off the integrated
        attitude over ``periods`` whole nutation periods from ``t_start``.

        ``e3(t) = R(t) e3`` is sampled ``samples`` times per period (default: 512, or 1024 per
        turn of the fastest rotation if that is more; plus two on each side), its
        velocity taken by fourth-order central differences, projected on the torque direction
        ``R x2`` (and on ``R x1``), and averaged over the whole periods (a mean over a uniform
        grid of whole periods is exact for the periodic components of the velocity).
        """
        count = check_count(periods, "periods", 1, _MAX_PERIODS)
        if samples is None:
            turns = self.nutation_period * self._fastest_rate() / (2.0 * math.pi)
            needed = max(_DRIFT_SAMPLES, _DRIFT_SAMPLES_PER_TURN * turns)
            if not needed * count <= MAX_SAMPLES:
                raise ValueError(
                    f"this gyroscope turns {turns:.3g} times per nutation period: measuring its "
                    f"drift over {count} periods would take more than {MAX_SAMPLES:,} samples; "
                    "give fewer periods or a number of samples"
                )
            samples = math.ceil(needed)
        n_per = check_count(samples, "samples (per period)", 16, MAX_SAMPLES // count)
        t_start = check_number(t_start, "t_start")
        if t_start < 0.0:
            raise ValueError(f"t_start must be a finite time >= 0, got {t_start!r}")
        dt = self.nutation_period / n_per
        n = count * n_per
        t = t_start + dt * np.arange(-2, n + 3)
        if t[0] < 0.0:
            t = t - t[0]
        R = self.attitude(t).attitude
        e3 = R.apply([0.0, 0.0, 1.0])
        vel = (e3[:-4] - 8.0 * e3[1:-3] + 8.0 * e3[3:-1] - e3[4:]) / (12.0 * dt)
        inner = R[2:-2]
        along = np.sum(vel * inner.apply([0.0, 1.0, 0.0]), axis=1)[:n]
        across = np.sum(vel * inner.apply([1.0, 0.0, 0.0]), axis=1)[:n]
        return DriftMeasurement(
            float(along.mean()), float(across.mean()), count, (float(t[2]), float(t[2 + n]))
        )


def _prefix_products(q: NDArray[np.float64]) -> NDArray[np.float64]:
    """Inclusive prefix products ``q[0] ⊗ q[1] ⊗ … ⊗ q[i]`` (N, 4), in order (the quaternion
    product is associative, not commutative), by log₂ N doubling sweeps (Hillis-Steele)."""
    out = q.copy()
    d = 1
    while d < out.shape[0]:
        out[d:] = rotations.multiply(out[:-d], out[d:])
        d *= 2
    return out


def _demo() -> None:  # pragma: no cover - a printout for the report
    print("gyroscope with a body-fixed torque: drift of the axis towards the torque")
    print(
        f"{'J':>4} {'J3':>4} {'M':>5} {'ω3':>5} {'M/((J3-J)ω3)':>13} {'measured':>13} "
        f"{'rel.err':>8} {'across':>8} {'attitude err. est.':>18}"
    )
    for J, J3, M, w0 in [
        (1.0, 2.0, 0.3, (0.2, -0.1, 5.0)),
        (2.0, 0.5, -0.4, (0.1, 0.3, -4.0)),
        (1.0, 1.5, 2.0, (0.0, 0.0, 3.0)),
    ]:
        gyro = Gyroscope(J, J3, M, w0)
        drift = gyro.measure_drift(periods=4)
        est = float(gyro.attitude(np.linspace(0.0, 20.0, 5)).error_estimate.max())
        print(
            f"{J:4g} {J3:4g} {M:5g} {w0[2]:5g} {gyro.drift_rate:13.9f} {drift.along_torque:13.9f}"
            f" {drift.along_torque / gyro.drift_rate - 1:8.0e} {drift.across:8.0e} {est:18.1e}"
        )


if __name__ == "__main__":  # pragma: no cover
    _demo()
