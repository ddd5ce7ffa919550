"""A fuzz of the whole public API of :mod:`poinsot.physics`: odd input must end cleanly.

    python -m poinsot.physics.tools.fuzz --cases 100000

Every call ends in a ``ValueError`` or ``TypeError`` raised by the package with a sentence
that says what to change, or in a finite result that keeps the invariants of the motion
(:mod:`~poinsot.physics.tools.fuzz.checks`). The benchmark prints the count of each outcome per
target and shows the unclean ones by kind; its exit status is 1 if any case ended uncleanly.
Case ``i`` draws its choices from ``numpy.random.default_rng([seed, i])`` and calls target
``i mod (number of targets)``: any case can be replayed alone (``--replay i``).

Rooms: :mod:`~.values` (odd arguments from a source of choices), :mod:`~.harness`
(one case and its outcome), :mod:`~.checks` (the invariants), :mod:`~.free_body`,
:mod:`~.textbook` and :mod:`~.tools` (the targets), :mod:`~.registry` (every target by
name, one case, a run), :mod:`~.summary` (the benchmark's command line and its counts). The
tests drive the same targets from hypothesis (``tests/physics/test_fuzz.py``). Only numpy,
scipy and the standard library: the choices come from numpy's Generator here.
"""

from __future__ import annotations

from poinsot.physics.tools.fuzz.harness import CLEAN, Call, Outcome
from poinsot.physics.tools.fuzz.registry import TARGETS, case, run
from poinsot.physics.tools.fuzz.summary import main, template

__all__ = ["CLEAN", "TARGETS", "Call", "Outcome", "case", "main", "run", "template"]
