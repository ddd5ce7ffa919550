"""Does a simulated rigid body flip, and does it stay on one polhode? The measures behind the
report's game-engine table and ``poinsot check-engine``.

A *flip* is a reversal of the intermediate axis (of the sorted moments) with respect to L:
``m_mid / |m|`` (``m = I ω``, body frame) passes from above ``+FLIP_LEVEL`` to below
``-FLIP_LEVEL`` or back [LL76 §37; ACC91]. The hysteresis is what makes it a flip: a body
spinning about its major or minor axis with a wobble also has ``ω_mid`` changing sign, but
its ``|m_mid| / |m|`` stays small, and that is no flip. The flip's time is where ``m_mid``
crosses zero between the two levels (linear interpolation between samples).

The drift of a quantity X is ``(X(t_end) / X(t_0) - 1) · 60 / (t_end - t_0)``: its relative
change per minute of simulated time (seconds). A free rigid body keeps the energy and |L|
exactly [LL76 §36].
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from poinsot.physics.core.free_body import FreeRigidBody
from poinsot.physics.integrators import GAME_STEPS, integrate

__all__ = [
    "FLIP_LEVEL",
    "FlipRun",
    "LogCheck",
    "check_log",
    "drift_per_minute",
    "exact_flip_times",
    "flip_times",
    "run_flips",
]

#: ``|m_mid| / |m|`` beyond which the intermediate axis counts as pointing along ±L.
FLIP_LEVEL = 0.5
#: Seconds per minute: drifts are quoted per simulated minute.
MINUTE = 60.0


def flip_times(inertia: NDArray, omega: NDArray, t: NDArray) -> NDArray[np.float64]:
    """The flip times (k,) of sampled body angular velocities ``omega`` (N, 3) [rad/s] at
    times ``t`` (N,) [s], for principal moments ``inertia`` (3,) in the same axes."""
    inertia = np.asarray(inertia, dtype=float)
    mid = int(np.argsort(inertia)[1])
    m = np.asarray(omega, dtype=float) * inertia
    size = np.linalg.norm(m, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        x = np.where(size > 0.0, m[:, mid] / size, 0.0)
    state = np.where(x > FLIP_LEVEL, 1, np.where(x < -FLIP_LEVEL, -1, 0))
    marked = np.flatnonzero(state)
    if marked.size < 2:
        return np.empty(0)
    turns = np.flatnonzero(state[marked[1:]] != state[marked[:-1]])
    out = np.empty(turns.size)
    for k, j in enumerate(turns):  # one root per flip: a loop over the flips
        a, b = int(marked[j]), int(marked[j + 1])
        seg = x[a : b + 1]
        i = a + int(np.argmax(np.sign(seg) != np.sign(seg[0]))) - 1
        x0, x1 = x[i], x[i + 1]
        frac = x0 / (x0 - x1) if x1 != x0 else 0.0
        out[k] = t[i] + frac * (t[i + 1] - t[i])
    return out


def exact_flip_times(body: FreeRigidBody, t: NDArray, start: float = 0.0) -> NDArray[np.float64]:
    """The flip times of the exact motion over the span of ``t`` [s] (``body`` starts at
    ``start``), measured as :func:`flip_times` does on a grid of at least 64 points per turn of
    the fastest rate of Euler's equations (and no coarser than ``t``)."""
    t = np.asarray(t, dtype=float)
    span = float(t[-1] - t[0]) if t.size else 0.0
    rate = float(np.linalg.norm(body.omega0)) * max(1.0, float(np.ptp(body.inertia)))
    n = max(t.size, int(np.ceil(span * rate * 64 / (2 * np.pi))) + 2)
    grid = np.linspace(float(t[0]), float(t[-1]), n) if t.size else t
    return flip_times(body.inertia, body.omega(grid - start), grid)


def drift_per_minute(x: NDArray, t: NDArray) -> float:
    """Relative change of ``x`` (N,) from the first to the last sample, per 60 s of ``t``."""
    span = float(t[-1] - t[0])
    if span <= 0.0 or x[0] == 0.0:
        return 0.0
    return float((x[-1] / x[0] - 1.0) * MINUTE / span)


@dataclass(frozen=True)
class FlipRun:
    """One game step (or the exact solution) from ω0 over ``duration`` seconds."""

    method: str
    step: float
    """Step size [s] (0 for the exact solution)."""
    flips: NDArray[np.float64]
    """Flip times [s]."""
    energy_drift: float
    """Kinetic energy drift per minute (relative)."""
    momentum_drift: float
    """|L| drift per minute (relative)."""
    blew_up: bool
    """ω left the double range (the step diverged)."""


def run_flips(inertia: NDArray, omega0: NDArray, duration: float, method: str, h: float) -> FlipRun:
    """Run ``method`` (a key of :data:`GAME_STEPS`, or ``"exact"``) at step ``h`` [s] for
    ``duration`` [s] and measure its flips and drifts, sampled at every step."""
    inertia = np.asarray(inertia, dtype=float)
    n = max(int(round(duration / h)), 1)
    t = np.arange(n + 1) * h
    if method == "exact":
        omega = FreeRigidBody(inertia, omega0).omega(t)
    else:
        if method not in GAME_STEPS:
            raise ValueError(f"unknown game step {method!r}; choose one of {sorted(GAME_STEPS)}")
        try:
            omega = integrate(method, inertia, omega0, None, t, h).omega
        except ValueError:
            return FlipRun(method, h, np.empty(0), np.inf, np.inf, True)
    m = omega * inertia
    energy = 0.5 * np.sum(m * omega, axis=1)
    size = np.linalg.norm(m, axis=1)
    flips = flip_times(inertia, omega, t)
    return FlipRun(method, h, flips, drift_per_minute(energy, t), drift_per_minute(size, t), False)


@dataclass(frozen=True)
class LogCheck:
    """What a log of a simulated free body shows (see :func:`check_log`)."""

    duration: float
    step: float
    """Median sample interval [s]."""
    energy_drift: float
    momentum_drift: float
    space_drift: float | None
    """Largest |L(t) - L(0)| / |L(0)| in space over the log (None without an attitude)."""
    measured_flips: NDArray[np.float64]
    predicted_flips: NDArray[np.float64]
    flip_tolerance: float
    """Largest allowed |measured - predicted| flip time [s]."""
    likeness: dict[str, float]
    """RMS of |ω_log - ω_method| / |ω0| for the exact solution and each game step."""

    @property
    def flips_agree(self) -> bool:
        if self.measured_flips.size != self.predicted_flips.size:
            return False
        diff = np.abs(self.measured_flips - self.predicted_flips)
        return bool(np.all(diff <= self.flip_tolerance))

    @property
    def looks_like(self) -> str:
        return min(self.likeness, key=lambda k: self.likeness[k])


def check_log(
    t: NDArray, omega: NDArray, inertia: NDArray, quaternion: NDArray | None = None
) -> LogCheck:
    """Measure a log: times ``t`` (N,) [s], body angular velocity ``omega`` (N, 3) [rad/s],
    principal moments ``inertia`` (3,) in the log's axes, optionally the attitude (N, 4) as
    scalar-last quaternions, body -> space. The exact motion starts from the first sample."""
    t = np.asarray(t, dtype=float)
    omega = np.asarray(omega, dtype=float)
    inertia = np.asarray(inertia, dtype=float)
    body = FreeRigidBody(inertia, omega[0])  # validates the moments and the first sample
    m = omega * inertia
    energy = 0.5 * np.sum(m * omega, axis=1)
    size = np.linalg.norm(m, axis=1)
    space = None
    if quaternion is not None:
        ls = Rotation.from_quat(quaternion).apply(m)
        space = float(np.max(np.linalg.norm(ls - ls[0], axis=1)) / size[0])
    step = float(np.median(np.diff(t)))
    tau = t - t[0]
    predicted = exact_flip_times(body, tau) + t[0]
    measured = flip_times(inertia, omega, t)
    tolerance = 2.0 * step + 0.01 * float(tau[-1])
    return LogCheck(
        float(tau[-1]),
        step,
        drift_per_minute(energy, t),
        drift_per_minute(size, t),
        space,
        measured,
        predicted,
        tolerance,
        _likeness(inertia, omega, tau, step, body),
    )


def _likeness(
    inertia: NDArray, omega: NDArray, tau: NDArray, step: float, body: FreeRigidBody
) -> dict[str, float]:
    scale = float(np.linalg.norm(omega[0])) or 1.0

    def rms(w: NDArray) -> float:
        return float(np.sqrt(np.mean(np.sum((w - omega) ** 2, axis=1)))) / scale

    out = {"exact": rms(body.omega(tau))}
    for name in GAME_STEPS:
        try:
            w = integrate(name, inertia, omega[0], None, tau, step).omega
        except ValueError:
            out[name] = np.inf
            continue
        out[name] = rms(w)
    return out
