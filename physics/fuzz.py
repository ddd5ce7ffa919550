"""A fuzz of the whole public API of :mod:`poinsot.physics`: odd input must end cleanly.

    python -m poinsot.physics.fuzz --cases 100000

Every call ends in a ``ValueError`` or ``TypeError`` raised by the package with a sentence
that says what to change, or in a finite result that keeps the invariants of the motion
(:mod:`~poinsot.physics.fuzz_checks`). The benchmark prints the count of each outcome per
target and shows the unclean ones by kind; its exit status is 1 if any case ended uncleanly.
Case ``i`` draws its choices from ``numpy.random.default_rng([seed, i])`` and calls target
``i mod (number of targets)``: any case can be replayed alone (``--replay i``).

Rooms: :mod:`~.fuzz_values` (odd arguments from a source of choices), :mod:`~.fuzz_harness`
(one case and its outcome), :mod:`~.fuzz_checks` (the invariants), :mod:`~.fuzz_free_body`,
:mod:`~.fuzz_textbook` and :mod:`~.fuzz_tools` (the targets), this module (the registry and
the benchmark). The tests drive the same targets from hypothesis
(``tests/physics/test_fuzz.py``). Only numpy, scipy and the standard library: the choices come
from numpy's Generator here.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections import Counter, defaultdict
from collections.abc import Callable, Sequence

import numpy as np

from poinsot.physics import fuzz_checks, fuzz_free_body, fuzz_textbook, fuzz_tools
from poinsot.physics.fuzz_harness import CLEAN, Call, Outcome, build, run_case
from poinsot.physics.fuzz_values import RandomSource, Source

__all__ = ["CLEAN", "TARGETS", "Call", "Outcome", "case", "main", "run", "template"]

#: Every target by name: the public API, one entry a kind of call.
TARGETS: dict[str, Callable[[Source], Call]] = {
    **fuzz_free_body.TARGETS,
    **fuzz_textbook.TARGETS,
    **fuzz_tools.TARGETS,
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


def template(text: str) -> str:
    """The first line of a message with its numbers blanked: one line per kind of outcome."""
    line = text.splitlines()[0] if text else ""
    out, i = [], 0
    while i < len(line):
        j = _number_end(line, i)
        out.append("#" if j > i else line[i])
        i = max(j, i + 1)
    return "".join(out)[:200]


def _number_end(line: str, i: int) -> int:
    """The end of a number (``-1.5e+07``, ``nan``, ``inf``) starting at ``i``, or ``i``."""
    for word in ("nan", "inf"):
        end = i + len(word)
        alone = not (i and line[i - 1].isalpha()) and not line[end : end + 1].isalpha()
        if line.startswith(word, i) and alone:
            return end
    j = i + 1 if line[i] in "+-" and i + 1 < len(line) else i
    start = j
    while j < len(line) and (line[j].isdigit() or line[j] == "."):
        j += 1
    if j == start or not any(c.isdigit() for c in line[start:j]):
        return i
    if j + 1 < len(line) and line[j] in "eE":
        k = j + 2 if line[j + 1] in "+-" else j + 1
        if k < len(line) and line[k].isdigit():
            j = k
            while j < len(line) and line[j].isdigit():
                j += 1
    return j


def _print_counts(outcomes: list[Outcome], seconds: float) -> None:
    total = Counter(o.kind for o in outcomes)
    print(
        f"{len(outcomes)} cases in {seconds:.0f} s over {len({o.target for o in outcomes})} targets"
    )
    for kind in (*CLEAN, "UNCLEAN"):
        label = {"finite": "finite result, invariants held"}.get(kind, kind)
        print(f"  {label:<34} {total.get(kind, 0):>8}")
    by_target: dict[str, Counter[str]] = defaultdict(Counter)
    for o in outcomes:
        by_target[o.target][o.kind] += 1
    print(f"\n  {'target':<44}" + "".join(f"{k:>11}" for k in (*CLEAN, "UNCLEAN")))
    for name in sorted(by_target):
        row = by_target[name]
        print(f"  {name:<44}" + "".join(f"{row.get(k, 0):>11}" for k in (*CLEAN, "UNCLEAN")))


def _print_unclean(outcomes: list[Outcome], examples: int) -> None:
    groups: dict[tuple[str, str], list[Outcome]] = defaultdict(list)
    for o in outcomes:
        if not o.clean:
            groups[(o.target, template(o.detail))].append(o)
    if not groups:
        return
    print(f"\nUNCLEAN: {len(groups)} kinds")
    ranked = sorted(groups.items(), key=lambda kv: -len(kv[1]))
    for (target, _), group in ranked[:examples]:
        first = group[0]
        print(f"- {len(group)} x {target}: {first.detail[:400]}\n    e.g. {first.call[:400]}")


def _print_messages(outcomes: list[Outcome]) -> None:
    messages = Counter(template(o.detail) for o in outcomes if o.kind in CLEAN[:2])
    print(f"\n{len(messages)} kinds of refusal:")
    for text, n in messages.most_common():
        print(f"  {n:>7}  {text}")


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m poinsot.physics.fuzz", description=__doc__)
    parser.add_argument("--cases", type=int, default=100_000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--only", default="", help="targets whose name contains this text")
    parser.add_argument("--examples", type=int, default=40, help="kinds of unclean shown")
    parser.add_argument("--messages", action="store_true", help="list the kinds of refusal")
    parser.add_argument("--replay", type=int, help="run case REPLAY alone and show it")
    args = parser.parse_args(argv)
    names = [n for n in TARGETS if args.only in n]
    if not names:
        parser.error(f"no target matches {args.only!r}; targets: {', '.join(TARGETS)}")
    if args.replay is not None:
        o = case(args.replay, args.seed, names)
        print(f"{o.target}: {o.kind} in {o.seconds:.3f} s\n  {o.call}\n  {o.detail}")
        return 0 if o.clean else 1
    start = time.perf_counter()
    outcomes = run(args.cases, args.seed, names, progress=True)
    _print_counts(outcomes, time.perf_counter() - start)
    slowest = max(outcomes, key=lambda o: o.seconds)
    print(f"\nslowest case: {slowest.seconds:.2f} s, {slowest.target}: {slowest.call[:200]}")
    print(
        f"largest relative errors (tolerance {fuzz_checks.TOL:g}): "
        + ", ".join(f"{k} {v:.1e}" for k, v in sorted(fuzz_checks.worst.items()))
    )
    if args.messages:
        _print_messages(outcomes)
    _print_unclean(outcomes, args.examples)
    return 1 if any(not o.clean for o in outcomes) else 0


if __name__ == "__main__":
    sys.exit(main())
