"""The body's figures in the caller's units, from the exact scaled values that
:class:`~poinsot.physics.core.free_body.FreeRigidBody` keeps.

The body computes in units where the largest moment and the largest |ω0| component are powers
of two near 1; a figure read in the caller's units is ``scaled · 2^exp2``. For extreme units
that may leave the double range (ω0 ~ 1e200 with moments ~ 1e100 has an energy ~ 1e500): the
functions here then raise a ValueError that says how large the figure is and which unit to
change, while the motion itself, ω(t) and R(t), stays available.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from poinsot.physics.core.exact import ldexp

__all__ = ["FASTER", "LARGER", "SLOWER", "in_units", "time_in_units", "vector_in_units"]

# Rate [1/time] and time are inverse: in a shorter time unit (ms for s) ω0 is a smaller number
# and a time a larger one.
SLOWER = "use a shorter time unit (then ω0 and the rates are smaller numbers, the times larger)"
FASTER = "use a longer time unit (then ω0 and the rates are larger numbers, the times smaller)"
LARGER = "express the moments or ω0 in larger units"


def in_units(
    scaled: float,
    exp2: int,
    what: str,
    advice: str = LARGER,
    log10_scaled: Callable[[], float] | None = None,
    units: str = " in your units",
) -> float:
    """``scaled · 2^exp2``, or a ValueError if that overflows.

    The scaled value is exact and finite; only its size in the caller's units may exceed the
    double range: reading it then raises a ValueError that says so instead of returning inf,
    while the motion itself, ω(t) and R(t), stays available. ``log10_scaled()`` gives the size
    of a scaled value that itself overflowed (a period ~1e320 of a spin ~1e-320).
    """
    value = ldexp(scaled, exp2)
    if math.isfinite(value):
        return value
    size = math.log10(abs(scaled)) if log10_scaled is None else log10_scaled()
    raise _too_large(size, exp2, what, advice, units)


def time_in_units(scaled: float, exp2: int, what: str, log10_scaled: float) -> float:
    """:func:`in_units` for a period: refused also where it underflows to 0 (a spin ~1e306
    about a body with moments 1e66 apart turns in 1e-372 time units), since a period of 0
    would divide by zero wherever it is used."""
    value = in_units(scaled, exp2, what, FASTER, lambda: log10_scaled)
    if value != 0.0 or scaled == 0.0:
        return value
    decades = log10_scaled + exp2 * math.log10(2.0)
    raise ValueError(
        f"{what} of this body is about 1e{decades:.0f} in your units, below the smallest "
        f"double-precision number (5e-324): {SLOWER} (omega(t) and attitude(t) are still "
        "available)"
    )


def vector_in_units(scaled: NDArray[np.float64], exp2: int, what: str) -> NDArray[np.float64]:
    """:func:`in_units` for each entry of a (3,) array."""
    value = np.array([ldexp(x, exp2) for x in scaled.tolist()])
    if all(map(math.isfinite, value.tolist())):
        return value
    size = math.log10(float(np.max(np.abs(scaled))))
    raise _too_large(size, exp2, what, LARGER, " in your units")


def _too_large(size: float, exp2: int, what: str, advice: str, units: str) -> ValueError:
    decades = size + exp2 * math.log10(2.0)
    return ValueError(
        f"{what} of this body is about 1e{decades:.0f}{units}, beyond the largest "
        f"double-precision number (1.8e308): {advice} (omega(t) and attitude(t) are "
        "still available)"
    )
