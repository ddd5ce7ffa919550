"""Where the suite's time goes: each xdist group's seconds and the slowest tests, read from a
JUnit XML report (``make test-times`` writes one with the parallel stage and prints this).

    python tests/durations.py REPORT.xml [--slowest N]

The parallel stage of ``make test`` lasts at least as long as its longest group (a group runs
on one worker, its tests one after another: :func:`tests.conftest.xdist_group`), and at least
the sum of all groups over the workers: the two figures this prints first.
"""

from __future__ import annotations

import argparse
import collections
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tests.conftest import xdist_group  # noqa: E402


def node_ids(report: Path) -> list[tuple[str, float]]:
    """(node id, seconds) of every test case in the JUnit XML ``report``."""
    cases = []
    for case in ET.parse(report).iter("testcase"):
        path = str(case.get("classname", "")).replace(".", "/") + ".py"
        cases.append((f"{path}::{case.get('name')}", float(case.get("time", 0.0))))
    return cases


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("report", type=Path, help="a JUnit XML report (pytest --junitxml)")
    parser.add_argument("--slowest", type=int, default=20, help="tests listed (20)")
    parser.add_argument("--workers", type=int, default=4, help="xdist workers (4, as make test)")
    args = parser.parse_args(argv)
    cases = node_ids(args.report)
    seconds: collections.Counter[str] = collections.Counter()
    counts: collections.Counter[str] = collections.Counter()
    for node, time in cases:
        seconds[xdist_group(node)] += time
        counts[xdist_group(node)] += 1
    total = sum(seconds.values())
    longest = max(seconds.values(), default=0.0)
    print(f"{len(cases)} tests, {total:.0f} s of test time in all")
    print(f"the parallel stage lasts at least {max(total / args.workers, longest):.0f} s:")
    spread = total / args.workers
    print(f"  {spread:.0f} s on {args.workers} workers, {longest:.0f} s the longest group")
    print("\n seconds  tests  group")
    for group, time in seconds.most_common(15):
        print(f"{time:8.1f} {counts[group]:6d}  {group}")
    print(f"\n seconds  the {args.slowest} slowest tests")
    for node, time in sorted(cases, key=lambda c: -c[1])[: args.slowest]:
        print(f"{time:8.1f}  {node}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
