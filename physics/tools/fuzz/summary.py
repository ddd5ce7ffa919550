"""The fuzz's benchmark on the command line (``python -m poinsot.physics.tools.fuzz``): a run of
cases, the count of each outcome per target, the kinds of refusal and the unclean cases."""

from __future__ import annotations

import argparse
import time
from collections import Counter, defaultdict
from collections.abc import Sequence

from poinsot.physics.tools.fuzz import checks
from poinsot.physics.tools.fuzz.harness import CLEAN, Outcome
from poinsot.physics.tools.fuzz.registry import TARGETS, case, run

DESCRIPTION = """A fuzz of the whole public API of poinsot.physics: odd input must end cleanly.

Every call ends in a ValueError or TypeError raised by the package with a sentence that says what
to change, or in a finite result that keeps the invariants of the motion. This prints the count
of each outcome per target and shows the unclean ones by kind; the exit status is 1 if any case
ended uncleanly."""

__all__ = ["main", "template"]


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
    parser = argparse.ArgumentParser(
        prog="python -m poinsot.physics.tools.fuzz",
        description=DESCRIPTION,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
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
        f"largest relative errors (tolerance {checks.TOL:g}): "
        + ", ".join(f"{k} {v:.1e}" for k, v in sorted(checks.worst.items()))
    )
    if args.messages:
        _print_messages(outcomes)
    _print_unclean(outcomes, args.examples)
    return 1 if any(not o.clean for o in outcomes) else 0
