"""The report's game-engine table (:mod:`poinsot.app.report.measure.games`)."""

from __future__ import annotations

import numpy as np

from poinsot.app.report.measure.games import flip_verdict, game_rows, games_section
from poinsot.physics.integrators import GAME_STEPS


def test_flip_verdict_words():
    exact = np.arange(1.0, 60.0, 2.0)
    assert flip_verdict(np.empty(0), exact) == "never"
    assert flip_verdict(exact, exact) == "yes"
    assert flip_verdict(exact[:10], exact).startswith("damped: stops at t = 19.0 s")
    assert flip_verdict(exact[::2] * 1.9, exact).startswith("fewer")


def test_the_table_has_every_step_at_both_sizes_and_the_verdicts():
    rows = game_rows()
    assert len(rows) == 2 * (1 + 2 * len(GAME_STEPS))
    by = {(r.case.split(",")[0] + r.case[-8:], r.method, r.step): r for r in rows}
    verdicts = {(k[1], k[2]): r.verdict for k, r in by.items() if "flicked" in k[0]}
    assert verdicts["no-gyro", "1/60 s"] == "never"
    assert verdicts["gyro-implicit", "1/60 s"].startswith("damped")
    assert verdicts["rk4", "1/240 s"] == "yes"
    assert verdicts["gyro-explicit", "1/60 s"] == "blows up"
    text = "\n".join(games_section(rows))
    assert text.count("\n| T-handle") == len(rows)
    assert all(line.count("|") == 9 for line in text.splitlines() if line.startswith("| T"))
