"""The fuzz's registry: every target by name, one case, a run of cases (see the package's
docstring)."""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Sequence

import numpy as np

from poinsot.physics.tools.fuzz import free_body, textbook, tools
from poinsot.physics.tools.fuzz.harness import Call, Outcome, build, run_case
from poinsot.physics.tools.fuzz.values import RandomSource, Source

__all__ = ["TARGETS", "case", "run"]

#: Every target by name: the public API, one entry a kind of call.
TARGETS: dict[str, Callable[[Source], Call]] = {
    **free_body.TARGETS,
    **textbook.TARGETS,
    **tools.TARGETS,
}


def case(index: int, seed: int, names: Sequence[str]) -> Outcome:
    """Case ``index`` of a run over the targets ``names``."""
    name = names[index % len(names)]
    src = RandomSource(np.random.default_rng([seed, index]))
    return run_case(name, build(TARGETS[name], src))


def run(cases: int, seed: int, names: Sequence[str], progress: bool = False) -> list[Outcome]:
    outcomes = []
    start = time.perf_counter()
    for i in range(cases):
        outcomes.append(case(i, seed, names))
        if progress and (i + 1) % 5000 == 0:
            bad = sum(not o.clean for o in outcomes)
            rate = (i + 1) / (time.perf_counter() - start)
            print(f"  {i + 1} cases, {bad} unclean, {rate:.0f}/s", file=sys.stderr, flush=True)
    return outcomes
