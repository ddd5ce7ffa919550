"""How the report writes numbers: one place, so that the tables and the verdicts agree."""

from __future__ import annotations

import math
from collections.abc import Sequence

__all__ = ["csv_float", "exp", "sig", "vector"]


def sig(x: float, digits: int = 3) -> str:
    """``x`` to ``digits`` significant digits (``nan``, ``inf`` as such)."""
    return f"{x:.{digits}g}" if math.isfinite(x) else str(x)


def exp(x: float) -> str:
    """``x`` in exponent form with three significant digits: ``1.23e-04``."""
    return f"{x:.2e}" if math.isfinite(x) else str(x)


def vector(values: Sequence[float]) -> str:
    """``(13, 10, 5)``: a triple to ten significant digits."""
    return "(" + ", ".join(f"{v:.10g}" for v in values) + ")"


def csv_float(x: float) -> str:
    """A CSV cell: seven significant digits, ``nan`` for anything not finite."""
    return f"{x:.6e}" if math.isfinite(x) else "nan"
