"""A periodic odd function as a short sine series, summed by Clenshaw's recurrence.

The precession wobble of the triaxial forms is analytic and 2K-periodic, so away from the
separatrix its sine coefficients decay geometrically (with the nome q [DLMF 22.2]) and a few
terms reproduce the direct Carlson evaluation to rounding at a fraction of its cost.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

__all__ = ["MIN_POINTS", "clenshaw_sine", "sine_series"]

# A wobble is represented by its sine series when this many terms or fewer reach the rounding
# floor of its samples (|b_k| <= _TOL_EPS · eps · max|f|: below that the FFT coefficients are
# noise); _SAMPLES >= 12 × the terms kept leaves aliasing negligible.
_MAX_TERMS = 40
_SAMPLES = 512
_TOL_EPS = 4.0
#: Below this many times, two Carlson calls per point cost less than a Clenshaw sum of ~25
#: steps on tiny arrays (both agree to rounding).
MIN_POINTS = 256


def sine_series(
    f: Callable[[NDArray[np.float64]], NDArray[np.float64]], K: float
) -> NDArray[np.float64] | None:
    """Sine coefficients ``b_1..b_n`` of an odd 2K-periodic ``f(u) = Σ b_k sin(kπu/K)``.

    Returns None when more than ``_MAX_TERMS`` terms stand above the rounding floor (or the
    samples show ``f`` is not odd to rounding), so the caller evaluates ``f`` directly.
    """
    theta = 2.0 * math.pi * np.arange(_SAMPLES) / _SAMPLES
    values = f(theta * (K / math.pi))
    spectrum = np.fft.rfft(values)
    b = -2.0 * spectrum.imag / _SAMPLES
    scale = float(np.abs(values).max())
    tol = _TOL_EPS * np.finfo(float).eps * scale
    if np.abs(spectrum.real).max() / _SAMPLES > 100.0 * tol:
        return None  # not odd to rounding: evaluate directly
    big = np.flatnonzero(np.abs(b[1:]) > tol)
    n = int(big[-1]) + 1 if big.size else 0
    if n > _MAX_TERMS:
        return None
    return b[1 : n + 1].copy()


def clenshaw_sine(b: NDArray[np.float64], theta: NDArray[np.float64]) -> NDArray[np.float64]:
    """``Σ_k b_k sin(k θ)`` by Clenshaw's recurrence (k = 1..len(b)), θ of shape (N,)."""
    if b.size == 0:
        return np.zeros_like(theta)
    two_cos = 2.0 * np.cos(theta)
    y1 = np.full_like(theta, b[-1])
    y2 = np.zeros_like(theta)
    for bk in b[-2::-1]:
        y1, y2 = bk + two_cos * y1 - y2, y1
    return y1 * np.sin(theta)
