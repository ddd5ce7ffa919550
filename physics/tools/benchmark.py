"""Speed of the closed form against bare ``scipy.special.ellipj``.

Run it as ``python -m poinsot.physics.tools.benchmark``.

Prints, for 10⁶ times measured in this one run (so the ratios are meaningful on a noisy
machine), the nanoseconds per point of ``omega(t)`` and ``attitude(t)`` next to bare
``ellipj`` on arguments of the same range (``u = λ t``, the body's own parameter m), and the
construction cost of a ``FreeRigidBody``. Targets: omega ≤ 1.5× ellipj, attitude ≤ 4× ellipj.

Then the single-time figure of the report's speed-up study: constructing the generic body of
``poinsot report`` and evaluating ω and the attitude at the one time t = 1e4
(``FreeRigidBody(I, ω0).state(1e4)``), median of many runs. Target ≤ 0.3 ms.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from scipy import special

from poinsot.physics.core.free_body import FreeRigidBody

# Cases timed: (label, inertia, omega0). Bare ellipj is run on the very same (u, m).
CASES = (
    ("generic (1,2,3)", (1.0, 2.0, 3.0), (1.0, 0.1, 0.5)),
    ("near separatrix 1-m~1e-10", (2.0, 3.0, 6.0), (3.0, 0.25, 1.0 + 2e-11)),
    ("extreme (1,10,1000)", (1.0, 10.0, 1000.0), (1.0, 0.1, 0.5)),
)


def _best(fn: Callable[[], object], repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def run(n: int = 1_000_000, repeat: int = 5) -> list[dict[str, Any]]:
    """Time the cases; returns one dict of figures per case (ns per point, ratios, µs)."""
    rows = []
    for label, inertia, omega0 in CASES:
        body = FreeRigidBody(inertia, omega0)
        t = np.linspace(0.0, 100.0 * body.period, n)
        u = body.frequency * t  # the range of the elliptic argument u0 + λ t
        m = body.parameter
        t_ellipj = _best(lambda: special.ellipj(u, m), repeat)  # noqa: B023
        t_omega = _best(lambda: body.omega(t), repeat)  # noqa: B023
        t_att = _best(lambda: body.attitude(t), repeat)  # noqa: B023
        n_build = 2000
        t0 = time.perf_counter()
        for _ in range(n_build):
            FreeRigidBody(inertia, omega0)
        t_build = (time.perf_counter() - t0) / n_build
        rows.append(
            {
                "case": label,
                "regime": body.regime.value,
                "ellipj_ns": t_ellipj / n * 1e9,
                "omega_ns": t_omega / n * 1e9,
                "attitude_ns": t_att / n * 1e9,
                "omega_ratio": t_omega / t_ellipj,
                "attitude_ratio": t_att / t_ellipj,
                "construct_us": t_build * 1e6,
            }
        )
    return rows


# The generic body of the report's speed-up study (app.report.GENERIC) and its time.
SINGLE_TIME_CASE = ((13.0, 10.0, 5.0), (0.3, 0.6, 0.9))
SINGLE_TIME = 1e4


def _median(fn: Callable[[], object], n: int) -> float:
    samples = []
    for _ in range(n):
        t0 = time.perf_counter()
        fn()
        samples.append(time.perf_counter() - t0)
    return float(np.median(samples))


def single_time(n: int = 1000) -> dict[str, float]:
    """Medians [s] of construction, one ``state(t)`` and both together, at t = 1e4."""
    inertia, omega0 = (np.array(v) for v in SINGLE_TIME_CASE)
    body = FreeRigidBody(inertia, omega0)
    for _ in range(20):  # warm up
        FreeRigidBody(inertia, omega0).state(SINGLE_TIME)
    return {
        "n": n,
        "construct": _median(lambda: FreeRigidBody(inertia, omega0), n),
        "evaluate": _median(lambda: body.state(SINGLE_TIME), n),
        "both": _median(lambda: FreeRigidBody(inertia, omega0).state(SINGLE_TIME), n),
    }


#: Targets the figures are printed against (met or missed).
OMEGA_TARGET = 1.5
ATTITUDE_TARGET = 4.0
SINGLE_TARGET_MS = 0.3
#: "Well under a second" for a one-second toss: the median, and the slowest kind of fit.
FIT_MEDIAN_TARGET_S = 0.25
FIT_TARGET_S = 1.0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m poinsot.physics.tools.benchmark", description=__doc__
    )
    parser.add_argument("-n", type=int, default=1_000_000, help="times per evaluation")
    parser.add_argument("--repeat", type=int, default=5, help="best of this many runs")
    parser.add_argument("--no-fit", dest="fit", action="store_false", help="skip the fit timing")
    args = parser.parse_args(argv)
    rows = run(args.n, args.repeat)
    _print_speed(rows, args.n, args.repeat)
    _print_single_time()
    if args.fit:
        _print_fit(args.repeat)
    return 0


def _met(ok: bool) -> str:
    return "met" if ok else "MISSED"


def _print_speed(rows: list[dict], n: int, repeat: int) -> None:
    print(f"FreeRigidBody speed, {n:,} times per call, best of {repeat}")
    header = (
        f"{'case':28s} {'ellipj':>9s} {'omega':>9s} {'ratio':>6s} "
        f"{'attitude':>9s} {'ratio':>6s} {'build':>9s}"
    )
    print(header)
    print("-" * len(header))
    for r in rows:
        print(
            f"{r['case']:28s} {r['ellipj_ns']:7.1f}ns {r['omega_ns']:7.1f}ns "
            f"{r['omega_ratio']:5.2f}x "
            f"{r['attitude_ns']:7.1f}ns {r['attitude_ratio']:5.2f}x {r['construct_us']:7.1f}us"
        )
    fine = [r for r in rows if "1-m" not in r["case"] or "1e-06" in r["case"]]
    omega_ok = all(r["omega_ratio"] <= OMEGA_TARGET for r in fine)
    attitude_ok = all(r["attitude_ratio"] <= ATTITUDE_TARGET for r in fine)
    print(
        f"targets: omega <= {OMEGA_TARGET}x ellipj ({_met(omega_ok)}), "
        f"attitude <= {ATTITUDE_TARGET}x ellipj ({_met(attitude_ok)})"
    )
    print(
        "note: for 1-m < 1e-9 bare ellipj takes a first-order tanh/sech shortcut that is wrong\n"
        "      for u beyond ~1, so that row's ratio compares against a wrong answer."
    )


def _print_single_time() -> None:
    one = single_time()
    print(
        f"construct + one evaluation at t=1e4: {one['both'] * 1e3:.3f} ms "
        f"(median of {one['n']}; target <= {SINGLE_TARGET_MS} ms: "
        f"{_met(one['both'] * 1e3 <= SINGLE_TARGET_MS)})"
    )
    print(
        f"  FreeRigidBody(I, omega0).state(1e4), I = {SINGLE_TIME_CASE[0]}, "
        f"omega0 = {SINGLE_TIME_CASE[1]}: construction {one['construct'] * 1e3:.3f} ms, "
        f"evaluation {one['evaluate'] * 1e3:.3f} ms"
    )


def _print_fit(repeat: int) -> None:
    """The fit of a one-second toss (100 samples) to the exact solution."""
    from poinsot.physics.fit.benchmark import benchmark_fit

    rows = benchmark_fit(repeat)
    worst = max((r.worst for r in rows), default=0.0)
    median = float(np.median([r.median for r in rows])) if rows else 0.0
    ok = median <= FIT_MEDIAN_TARGET_S and worst <= FIT_TARGET_S
    print(
        f"targets: median fit <= {FIT_MEDIAN_TARGET_S} s, every fit <= {FIT_TARGET_S} s "
        f"({_met(ok)}; median {median:.3f} s, worst {worst:.3f} s)"
    )


if __name__ == "__main__":
    raise SystemExit(main())
