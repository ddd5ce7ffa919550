"""The report's game-engine table: does the body flip, and when, under the rotation steps that
games run (:data:`poinsot.physics.integrators.GAME_STEPS`) at 1/60 s and 1/240 s?

Two starts of the T-handle, each followed for one simulated minute: the preset as the app
shows it (|ω| = 2 rad/s, on a polhode near the separatrix), and the same body flicked at
12 rad/s (about two turns a second) 0.05 rad from its middle axis, the rate of a thrown
wing nut. The measures (flip times, drifts per minute) are
:mod:`poinsot.physics.integrators.engine_check`'s; the exact flip times are measured the same way on
the exact solution sampled finely.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from poinsot.app.model.parameters import Parameters
from poinsot.app.model.presets import preset_by_key
from poinsot.physics import FreeRigidBody
from poinsot.physics.integrators import GAME_STEPS
from poinsot.physics.integrators.engine_check import FlipRun, exact_flip_times, run_flips

__all__ = ["GAME_STEP_SIZES", "GameCase", "GameRow", "game_rows", "games_section", "write_csv"]

#: The frame steps of games [s].
GAME_STEP_SIZES = (1.0 / 60.0, 1.0 / 240.0)
#: Simulated time of each run [s].
DURATION = 60.0
#: The flips count as damped when the last one comes this many exact intervals before the end.
DAMPED_INTERVALS = 3.0


@dataclass(frozen=True)
class GameCase:
    name: str
    inertia: tuple[float, float, float]
    omega0: tuple[float, float, float]


def game_cases() -> list[GameCase]:
    body = Parameters.from_preset(preset_by_key("t_handle")).build()
    i1, i2, i3 = (float(v) for v in body.inertia)
    w1, w2, w3 = (float(v) for v in body.omega0)
    off = 0.05
    return [
        GameCase("T-handle preset, 2 rad/s", (i1, i2, i3), (w1, w2, w3)),
        GameCase(
            "T-handle flicked, 12 rad/s, 0.05 rad off",
            (i1, i2, i3),
            (12.0 * math.sin(off), 12.0 * math.cos(off), 0.0),
        ),
    ]


@dataclass(frozen=True)
class GameRow:
    case: str
    method: str
    step: str
    verdict: str
    flips: int
    exact_flips: int
    first_error: float
    """|first flip time - the exact one| [s] (nan without a flip)."""
    energy_drift: float
    momentum_drift: float


def game_rows() -> list[GameRow]:
    """Every game step at every step size on every case, after the exact row of each case."""
    rows = []
    for case in game_cases():
        exact = exact_flip_times(
            FreeRigidBody(case.inertia, case.omega0), np.array([0.0, DURATION])
        )
        rows.append(GameRow(case.name, "exact", "-", "yes", exact.size, exact.size, 0.0, 0, 0))
        for h in GAME_STEP_SIZES:
            for name in GAME_STEPS:
                run = run_flips(np.array(case.inertia), np.array(case.omega0), DURATION, name, h)
                rows.append(_row(case.name, run, exact))
    return rows


def _row(case: str, run: FlipRun, exact: np.ndarray) -> GameRow:
    step = f"1/{round(1.0 / run.step)} s"
    if run.blew_up:
        return GameRow(
            case, run.method, step, "blows up", 0, exact.size, math.nan, math.inf, math.inf
        )
    first = abs(run.flips[0] - exact[0]) if run.flips.size and exact.size else math.nan
    return GameRow(
        case,
        run.method,
        step,
        flip_verdict(run.flips, exact),
        run.flips.size,
        exact.size,
        float(first),
        run.energy_drift,
        run.momentum_drift,
    )


def flip_verdict(flips: np.ndarray, exact: np.ndarray) -> str:
    """``never``, ``damped: stops at t = …``, ``yes`` (as many as the exact motion), or
    ``fewer`` / ``more``."""
    if exact.size == 0:
        return "no (nor the exact)" if flips.size == 0 else "yes (the exact does not)"
    if flips.size == 0:
        return "never"
    interval = float(np.mean(np.diff(exact))) if exact.size > 1 else float(exact[0])
    if flips[-1] < DURATION - DAMPED_INTERVALS * interval:
        return f"damped: stops at t = {flips[-1]:.1f} s"
    if flips.size == exact.size:
        return "yes"
    return "fewer (slower clock)" if flips.size < exact.size else "more (faster clock)"


def games_section(rows: list[GameRow]) -> list[str]:
    lines = [
        "## Game-engine steps: does the body flip?",
        "",
        f"Each step from {len({r.case for r in rows})} starts of the T-handle for "
        f"{DURATION:g} s of simulated time, at 1/60 s and 1/240 s. A flip is the middle axis "
        "reversing against L (|m_mid|/|L| from above 1/2 to below -1/2); the first flip's "
        "error is against the exact solution's; drifts are relative changes per simulated "
        "minute. " + ", ".join(f"`{k}`: {i.title}" for k, i in GAME_STEPS.items()) + ".",
        "",
        "| start | step | h | flips? | flips in 60 s (exact) | first flip error [s] "
        "| energy drift / min | abs(L) drift / min |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        first = "-" if math.isnan(r.first_error) else f"{r.first_error:.2g}"
        lines.append(
            f"| {r.case} | {r.method} | {r.step} | {r.verdict} | {r.flips} ({r.exact_flips}) "
            f"| {first} | {_drift(r.energy_drift)} | {_drift(r.momentum_drift)} |"
        )
    return [*lines, ""]


def _drift(x: float) -> str:
    if not math.isfinite(x):
        return "diverges"
    return "0" if x == 0.0 else f"{x:+.1e}"


def write_csv(out: Path, rows: list[GameRow]) -> None:
    """``game_steps.csv``: one row per game step, step size and start."""
    with (out / "game_steps.csv").open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(
            [
                "case",
                "method",
                "step",
                "verdict",
                "flips",
                "exact_flips",
                "first_flip_error",
                "energy_drift_per_min",
                "momentum_drift_per_min",
            ]
        )
        for r in rows:
            w.writerow(
                [
                    r.case,
                    r.method,
                    r.step,
                    r.verdict,
                    r.flips,
                    r.exact_flips,
                    r.first_error,
                    r.energy_drift,
                    r.momentum_drift,
                ]
            )
