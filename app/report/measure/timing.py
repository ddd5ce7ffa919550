"""Wall-clock timing of the runs: medians of repeated calls, more repeats for cheaper calls."""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable
from typing import TypeVar

__all__ = ["median_seconds", "repeats", "repeats_text", "timed"]

T = TypeVar("T")


def timed(fn: Callable[[], T], quick: bool) -> tuple[float, T, int]:
    """Median wall time of repeated calls: (seconds, last result, repeats).

    Cheap calls are repeated more (see :func:`repeats`); longer runs are timed once (their
    spread is a few percent).
    """
    start = time.perf_counter()
    result = fn()
    times = [time.perf_counter() - start]
    for _ in range(repeats(times[0], quick) - 1):
        start = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times), result, len(times)


def median_seconds(fn: Callable[[], object], count: int) -> float:
    """Median wall time of ``count`` calls (for sub-millisecond calls, where the median of
    many is what is stable)."""
    samples = []
    for _ in range(count):
        start = time.perf_counter()
        fn()
        samples.append(time.perf_counter() - start)
    return statistics.median(samples)


def repeats(first: float, quick: bool) -> int:
    """How many timed calls in all, given the first call's duration [s]."""
    # Many repeats for millisecond calls: on a loaded machine a few of them lose a whole
    # scheduler slice (~5 ms), and the median must not be one of those.
    if quick:
        return 15 if first < 0.01 else 3 if first < 0.1 else 1
    return 21 if first < 0.01 else 5 if first < 0.1 else 3 if first < 1.0 else 1


def repeats_text(quick: bool) -> str:
    """:func:`repeats` in words, for the report."""
    if quick:
        return "15 under 10 ms, 3 under 0.1 s, else one run"
    return "21 under 10 ms, 5 under 0.1 s, 3 under 1 s, else one run"
