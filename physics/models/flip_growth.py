"""The growth of a perturbation off the intermediate axis, read from the motion [LL76 §37;
FM06 Theorem 7.3]: :func:`measure_growth_rate` (re-exported by :mod:`poinsot.physics.models.flip`).

``p(t) = |(ω1, ω3)|/|ω|`` is sampled on a grid until it has grown from its start to a given
amplitude, and a straight line is fitted to ``ln p`` on the exponential stretch between.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from poinsot.physics.core.free_body import FreeRigidBody
from poinsot.physics.core.validation import InputTypeError, check_positive

__all__ = ["STEPS_PER_RATE", "GrowthFit", "check_body", "fastest_rate", "measure_growth_rate"]

#: Grid steps per fastest time scale of Euler's equations (here and for the flips).
STEPS_PER_RATE = 10.0
#: measure_growth_rate gives up after this many grid samples.
_GROWTH_MAX_SAMPLES = 1 << 24
_GROWTH_CHUNK = 4096


def check_body(body: object, what: str) -> FreeRigidBody:
    """``body`` if it is a :class:`FreeRigidBody`, else an InputTypeError."""
    if not isinstance(body, FreeRigidBody):
        raise InputTypeError(f"{what} needs a FreeRigidBody, got {type(body).__name__}")
    return body


def fastest_rate(inertia: NDArray[np.float64], omega0: NDArray[np.float64]) -> float:
    """A bound on the rates of Euler's equations: ``|ω| max|Iⱼ - Iₖ|/Iᵢ`` (or ``|ω|``); inf
    where it leaves the double range."""
    spread = (float(inertia.max()) - float(inertia.min())) / float(inertia.min())
    return math.hypot(*omega0.tolist()) * max(1.0, spread)


@dataclass(frozen=True)
class GrowthFit:
    """A straight-line fit of ``ln |(ω1, ω3)|`` against t on the exponential stretch.

    Attributes:
        rate: the measured σ [1/time]. window: (t_start, t_stop) of the fit [time].
        e_folds: ``σ (t_stop - t_start)``, how long the stretch is.
        residual: the largest deviation of ``ln |(ω1, ω3)|`` from the line.
    """

    rate: float
    window: tuple[float, float]
    e_folds: float
    residual: float


def measure_growth_rate(
    body: FreeRigidBody,
    start_factor: float = math.exp(5.0),
    stop_amplitude: float = 1e-3,
    step: float | None = None,
) -> GrowthFit:
    """The growth rate of the perturbation off ``e2``, read from the motion (sorted moments).

    ``p(t) = |(ω1, ω3)|/|ω|`` grows like ``cosh``-type mixtures of ``e^{±σt}`` at first and
    bends over when it is no longer small. The fit window starts where ``p`` has grown by
    ``start_factor`` (the decaying mode has died down: its weight ~1/start_factor²) and stops
    where ``p`` reaches ``stop_amplitude`` (the nonlinear terms are O(p²) relative).

    Raises:
        ValueError: if there is less than two e-folds between the two (ω0 too far from e2 for
            an exponential stretch: use ``ε`` below ``stop_amplitude / (start_factor e²)``).
    """
    check_body(body, "measure_growth_rate")
    w0, (I1, I2, I3) = body.omega0, body.inertia.tolist()
    if not (I1 < I2 < I3 or I1 > I2 > I3):
        raise ValueError(
            f"e2 is not the intermediate axis of the moments {[I1, I2, I3]}: a perturbation off "
            "e2 grows only about the intermediate axis; give the moments with it second"
        )
    if not np.any(w0):
        raise ValueError("the body is at rest: there is no perturbation to grow")
    start_factor = check_positive(start_factor, "start_factor")
    hi = check_positive(stop_amplitude, "stop_amplitude")
    p0 = _off_axis(w0[None, :])[0]
    lo = p0 * start_factor
    if not (p0 > 0.0 and lo * math.e**2 < hi < 1.0):
        raise ValueError(
            f"no exponential stretch: the perturbation starts at {p0:.3g} of |ω|, it must grow "
            f"by {start_factor:.3g} and then by two e-folds before it reaches {hi:g}; "
            "start closer to the intermediate axis"
        )
    # A difference of logarithms: hi/p0 overflows for a subnormal start p0.
    step = _growth_step(body, step, math.log(hi) - math.log(p0))
    t, p = _walk_until(body, step, hi)
    first_hi = int(np.argmax(p >= hi))
    t, p = t[:first_hi], p[:first_hi]
    begin = int(np.argmax(p >= lo))
    return _fit_line(t[begin:], np.log(p[begin:]))


def _growth_step(body: FreeRigidBody, step: float | None, e_folds: float) -> float:
    """The grid step (default a tenth of the fastest time scale), refused where the growth by
    ``e_folds`` would take more than :data:`_GROWTH_MAX_SAMPLES` steps or the grid would leave
    the double range."""
    w0, (I1, I2, I3) = body.omega0, body.inertia.tolist()
    if step is None:
        step = 1.0 / (STEPS_PER_RATE * fastest_rate(body.inertia, w0))
    else:
        step = check_positive(step, "step")
    # It grows like e^{σt} [LL76 §37]: about ln(hi/p0)/σ to reach hi.
    sigma = abs(float(w0[1])) * math.sqrt(abs(I2 - I1) / I1) * math.sqrt(abs(I3 - I2) / I3)
    needed = e_folds / (sigma * step) if sigma * step > 0.0 else math.inf
    if not needed <= _GROWTH_MAX_SAMPLES:
        raise ValueError(
            f"the perturbation would take about {needed:.3g} grid steps to grow by "
            f"{e_folds:.3g} e-folds, more than {_GROWTH_MAX_SAMPLES}: use a larger step or a "
            "start closer to e2"
        )
    if not math.isfinite(step * (needed + 2 * _GROWTH_CHUNK)):
        raise ValueError(
            "the grid of this slow motion reaches beyond the double range in your time unit: "
            "use a longer time unit (then ω0 is a larger number)"
        )
    return step


def _walk_until(
    body: FreeRigidBody, step: float, hi: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Times and ``p(t)`` on the grid, chunk by chunk, until p passes hi (p grows
    monotonically on this stretch)."""
    times, amps = [], []
    for start in range(0, _GROWTH_MAX_SAMPLES, _GROWTH_CHUNK):
        t = step * np.arange(start, start + _GROWTH_CHUNK)
        p = _off_axis(body.omega(t))
        times.append(t)
        amps.append(p)
        if p.max() >= hi:
            return np.concatenate(times), np.concatenate(amps)
    raise ValueError(
        f"the perturbation did not reach {hi:g} of |ω| within {_GROWTH_MAX_SAMPLES} grid "
        "steps: this motion does not leave the intermediate axis (is e2 the intermediate axis?)"
    )


def _fit_line(t: NDArray[np.float64], logp: NDArray[np.float64]) -> GrowthFit:
    """The straight line through ``ln p(t)`` on the exponential stretch."""
    if t.size < 3:
        raise ValueError(
            f"only {t.size} grid samples on the exponential stretch: use a smaller step"
        )
    # The line in the time since the window's start over its length, x in [0, 1]: the squares
    # of times ~1e-300 would underflow in the fit.
    span = float(t[-1] - t[0])
    x = (t - t[0]) / span
    slope, offset = np.polyfit(x, logp, 1)
    residual = float(np.abs(logp - (slope * x + offset)).max())
    rate = float(slope) / span
    if not math.isfinite(rate):
        raise ValueError(
            f"the growth rate is beyond the double-precision range in your units ({slope:.3g} "
            f"e-folds in {span:.3g}): use a time unit closer to 1/|ω0|"
        )
    return GrowthFit(rate, (float(t[0]), float(t[-1])), float(slope), residual)


def _off_axis(w: NDArray[np.float64]) -> NDArray[np.float64]:
    """``|(ω1, ω3)|/|ω|`` for rows of ``w`` (hypot: no overflow of the squares)."""
    side = np.hypot(w[:, 0], w[:, 2])
    return side / np.hypot(side, w[:, 1])
