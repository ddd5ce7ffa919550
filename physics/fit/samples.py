"""Recorded angular velocities: checks, local polynomial smoothing, sign changes, synthetic tosses.

Shapes and units: ``t`` is ``(N,)`` [s], strictly increasing; ``omega`` is ``(N, 3)`` [rad/s]
in the sensor's axes (one row ``(ωx, ωy, ωz)`` per time).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from poinsot.physics.core.free_body import FreeRigidBody
from poinsot.physics.core.validation import real_array

#: Fewest samples a fit accepts: 5 to 11 parameters need several times as many data.
MIN_SAMPLES = 20
#: Below this median |ω| [rad/s] the body is not spinning (a phone at rest reads ~0.01 rad/s).
MIN_RATE = 0.5
#: A component changes sign only when it goes from above +h to below -h (or back), with
#: ``h = SIGN_THRESHOLD · max |ω|``: noise and bias near zero never count as a sign change.
SIGN_THRESHOLD = 0.1


def check_samples(
    t: ArrayLike, omega: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(t, omega)`` as float arrays, or a ValueError that says what is wrong with them.

    Checks the shapes ``(N,)`` and ``(N, 3)``, at least :data:`MIN_SAMPLES` rows, finite values,
    strictly increasing times and a body that turns (median |ω| at least :data:`MIN_RATE`).
    """
    t_arr = real_array(t, "t", "an array of times in seconds")
    w_arr = real_array(omega, "omega", "an array of angular velocities in rad/s")
    if t_arr.ndim != 1:
        raise ValueError(f"t must be a 1-D array of N times in seconds; got shape {t_arr.shape}")
    if w_arr.ndim != 2 or w_arr.shape[1] != 3:
        hint = " (transpose it: omega.T)" if w_arr.ndim == 2 and w_arr.shape[0] == 3 else ""
        raise ValueError(
            "omega must have shape (N, 3), one row (ωx, ωy, ωz) in rad/s per time; "
            f"got {w_arr.shape}{hint}"
        )
    if w_arr.shape[0] != t_arr.shape[0]:
        raise ValueError(f"t has {t_arr.shape[0]} times but omega has {w_arr.shape[0]} rows")
    n = t_arr.shape[0]
    if n < MIN_SAMPLES:
        raise ValueError(
            f"too few samples: {n}, a fit needs at least {MIN_SAMPLES} "
            "(record a longer flight or at a higher rate)"
        )
    bad = ~(np.isfinite(t_arr) & np.isfinite(w_arr).all(axis=1))
    if bad.any():
        rows = np.flatnonzero(bad)
        raise ValueError(
            f"{rows.size} rows hold NaN or infinite values (the first is row {rows[0]}): "
            "remove them before fitting"
        )
    steps = np.diff(t_arr)
    if (steps <= 0.0).any():
        i = int(np.flatnonzero(steps <= 0.0)[0])
        raise ValueError(
            f"the times must increase strictly: t[{i + 1}] = {t_arr[i + 1]:g} s follows "
            f"t[{i}] = {t_arr[i]:g} s"
        )
    speed = float(np.median(np.linalg.norm(w_arr, axis=1)))
    if speed < MIN_RATE:
        raise ValueError(
            f"the body hardly turns: the median |ω| is {speed:.3g} rad/s, below {MIN_RATE} rad/s "
            "(a thrown body spins at several rad/s; are the values in rad/s, and is this a flight?)"
        )
    return t_arr, w_arr


@dataclass(frozen=True)
class Smoothed:
    """Local cubic least-squares fits around each sample (see :func:`smooth`).

    Attributes:
        value: (N, K) smoothed samples (ω [rad/s]) at the sample times.
        derivative: (N, K) their time derivative (dω/dt [rad/s²]).
        noise: estimated standard deviation of the noise of one component [rad/s].
    """

    value: NDArray[np.float64]
    derivative: NDArray[np.float64]
    noise: float


def smooth(t: NDArray[np.float64], y: NDArray[np.float64], half_width: int) -> Smoothed:
    """Savitzky–Golay smoothing and differentiation on the actual (irregular) sample times.

    Around each sample a cubic is fitted by least squares to the ``2 half_width + 1`` nearest
    samples (windows shifted inwards at the ends); its value and slope at the sample are the
    smoothed value and derivative. On uniform times this is exactly
    ``scipy.signal.savgol_filter(y, 2 half_width + 1, 3, mode="interp")`` (and ``deriv=1``); on
    a phone's jittered time stamps it stays exact, where resampling first would not. The noise
    is estimated from the residuals and the weight ``h`` of each sample in its own fit:
    ``σ² = Σ r² / Σ (1 - h)``, averaged over the components.

    Args:
        t: (N,) strictly increasing times [s], N >= 2.
        y: (N, K) samples.
        half_width: samples on each side (the window is clipped to N).
    """
    n = t.shape[0]
    width = min(2 * half_width + 1, n)
    first = np.clip(np.arange(n) - width // 2, 0, n - width)
    index = first[:, None] + np.arange(width)
    tau = t[index] - t[:, None]
    scale = np.maximum(np.max(np.abs(tau), axis=1), np.finfo(float).tiny)
    basis = (tau / scale[:, None])[..., None] ** np.arange(4)  # (N, width, 4)
    pinv = np.linalg.pinv(basis)  # (N, 4, width)
    coef = pinv @ y[index]  # (N, 4, 3)
    own = pinv[np.arange(n), 0, np.arange(n) - first]  # weight of each sample in its own fit
    value = coef[:, 0, :]
    residual = y - value
    dof = max(float(np.sum(1.0 - own)), 1.0)
    noise = float(np.sqrt(np.sum(residual**2) / (y.shape[1] * dof)))
    return Smoothed(value, coef[:, 1, :] / scale[:, None], noise)


def half_width_for(t: NDArray[np.float64], omega: NDArray[np.float64]) -> int:
    """Samples on each side of the smoothing window: the window spans about ``1/max|ω|``.

    The motion changes on the time scale ``1/|ω|`` (Euler's equations give ``|dω/dt| ≲ |ω|²``
    for a real body), so a cubic over ``±0.5/|ω|`` follows it while averaging the noise.
    """
    step = float(np.median(np.diff(t)))
    fastest = float(np.max(np.linalg.norm(omega, axis=1)))
    return int(np.clip(round(0.5 / (fastest * step)), 3, 25))


def sign_changes(t: NDArray[np.float64], x: NDArray[np.float64], threshold: float) -> NDArray:
    """Times [s] at which ``x`` changes sign, with hysteresis.

    A change is counted when ``x`` goes from above ``+threshold`` to below ``-threshold`` (or
    back); its time is where the chord between the last sample beyond the old side and the first
    beyond the new side crosses zero. Returns a (K,) array, empty if ``x`` keeps its sign.
    """
    state = np.where(x > threshold, 1, np.where(x < -threshold, -1, 0))
    known = np.flatnonzero(state)
    if known.size < 2:
        return np.empty(0)
    flips = np.flatnonzero(state[known[1:]] != state[known[:-1]])
    i, j = known[flips], known[flips + 1]
    return t[i] + (t[j] - t[i]) * x[i] / (x[i] - x[j])


def sign_change_counts(t: NDArray[np.float64], w: NDArray[np.float64], threshold: float) -> NDArray:
    """(3,) number of sign changes of each component of ``w`` (N, 3) (see :func:`sign_changes`)."""
    return np.array([sign_changes(t, w[:, k], threshold).size for k in range(3)])


def synthetic_toss(
    inertia: ArrayLike,
    omega0: ArrayLike,
    *,
    duration: float = 1.0,
    rate: float = 100.0,
    noise: float = 0.02,
    bias: ArrayLike = (0.0, 0.0, 0.0),
    rotation: Rotation | None = None,
    jitter: float = 0.3,
    start: float = 0.0,
    seed: int | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A gyroscope recording of a free flight, from the exact solution: ``(t (N,), omega (N, 3))``.

    The sensor samples at ``rate`` [Hz] with time stamps jittered by up to ``± jitter / 2``
    of a step (the stamps are the true sample times, as a phone's are), adds a constant
    ``bias`` (3,) [rad/s] and white Gaussian ``noise`` [rad/s] to each component. ``rotation``
    (sensor -> principal axes) turns the body's ω into the sensor's axes; the body's ω equals
    ``omega0`` (principal axes, rad/s) at ``t = start``.
    """
    rng = np.random.default_rng(seed)
    n = int(round(duration * rate)) + 1
    t = start + (np.arange(n) + jitter * (rng.random(n) - 0.5)) / rate
    t[0] = start
    w = FreeRigidBody(inertia, omega0).omega(t - start)
    if rotation is not None:
        w = rotation.inv().apply(w)
    w = w + np.asarray(bias, dtype=float) + noise * rng.standard_normal(w.shape)
    return t, w
