"""Speed of :func:`~poinsot.physics.fit.fit_angular_velocity` on one-second tosses.

Run it as ``python -m poinsot.physics.fit.benchmark`` (or call :func:`benchmark_fit`).

Each toss is a synthetic phone recording of a T-handle-like body ``I = (1, 1.9, 2.7)``: 1 s
at 100 Hz with jittered time stamps, 0.02 rad/s of noise and a gyroscope bias. Printed: the
median wall time of one fit over ``repeat`` seeds, for the bias-only fit and the fit with a
rotation as well. Target: well under a second per toss.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import dataclass

import numpy as np

from poinsot.physics.fit.samples import synthetic_toss
from poinsot.physics.fit.solve import fit_angular_velocity

#: (label, ω0 [rad/s]) of the timed tosses, all with I = (1, 1.9, 2.7).
TOSSES = (
    ("major-axis family", (1.0, 2.0, 8.0)),
    ("minor-axis family", (12.0, 1.0, 1.0)),
    ("near the separatrix", (3.06, 10.0, 2.0)),
)
INERTIA = (1.0, 1.9, 2.7)
BIAS = (0.03, -0.02, 0.01)


@dataclass(frozen=True)
class FitTiming:
    """Wall time of one kind of fit [s] over the seeds."""

    toss: str
    fitted: str
    samples: int
    median: float
    worst: float


def benchmark_fit(repeat: int = 5) -> list[FitTiming]:
    """Time the fits of each toss (bias, then bias and rotation) and print a table."""
    rows = []
    for label, omega0 in TOSSES:
        for rotation in (False, True):
            times = []
            for seed in range(repeat):
                t, w = synthetic_toss(INERTIA, omega0, bias=BIAS, seed=seed)
                start = time.perf_counter()
                fit_angular_velocity(t, w, fit_bias=True, fit_rotation=rotation)
                times.append(time.perf_counter() - start)
            fitted = "bias + rotation" if rotation else "bias"
            rows.append(FitTiming(label, fitted, int(t.size), float(np.median(times)), max(times)))
    print(f"fit_angular_velocity: median of {repeat} one-second tosses (100 Hz)")
    print(f"{'toss':<22}{'fitted':<18}{'samples':>8}{'median':>10}{'max':>10}")
    for r in rows:
        print(
            f"{r.toss:<22}{r.fitted:<18}{r.samples:>8}"
            f"{1e3 * r.median:>8.0f}ms{1e3 * r.worst:>8.0f}ms"
        )
    overall = float(np.median([r.median for r in rows]))
    print(f"median over all tosses: {1e3 * overall:.0f} ms per fit")
    return rows


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="seeds per toss (default 5)")
    benchmark_fit(parser.parse_args(argv).repeat)


if __name__ == "__main__":
    main()
