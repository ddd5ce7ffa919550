"""Today's benchmarks against another git revision, as ratios in one run.

``python -m poinsot.app.devtools.compare --against REV [--rounds 4] [--physics] [--app]`` (or
``make bench-compare AGAINST=REV``).

The other revision is checked out into a temporary ``git worktree`` (removed afterwards). Each
round runs the physics benchmark and/or the app's benchmark of today's working tree and of that
revision one after the other, each side first in every other round (new, old, old, new, ...:
both see the same machine load, and neither is always the first of a pair), each in a fresh
Python of this environment. ``--against HEAD`` compares the tree with itself: its ratios show
how far the machine's noise alone moves them. The tool parses the figures each benchmark prints and
shows, per figure, the ratio new/old: the median over the rounds and the min–max. A cost
(time, bytes) has not regressed when the median ratio is <= 1.10, a rate (frames per second)
when it is >= 0.90. Controls (bare ``ellipj``, the bare viser server: no Poinsot code) are
shown, not judged: their ratio tells how steady the machine was. Exits 1 when a figure missed.

Both layouts run: the folders ``physics/`` and ``app/`` imported as top-level packages (older
revisions) or through ``poinsot.`` (today). For the latter a temporary folder ``poinsot/`` of
links to the revision's folders goes first on ``PYTHONPATH``, so that the revision's code, not
the installed one, is measured. Figures are read from the text the benchmarks print, the same
parser for both sides, so that a ratio compares figures rounded the same way.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import pathlib
import re
import statistics
import subprocess
import sys
import tempfile
from collections.abc import Iterator, Sequence
from contextlib import contextmanager

#: "No regression": the median ratio new/old of a cost at most this, of a rate at least that.
COST_LIMIT = 1.10
RATE_LIMIT = 0.90

COST, RATE, CONTROL = "cost", "rate", "control"
BENCHMARKS = ("physics", "app")

_NUM = r"([-+]?(?:\d+(?:\.\d*)?(?:e[-+]?\d+)?|nan|inf))"


def _pattern(template: str) -> re.Pattern[str]:
    """A line pattern where each ``#`` stands for a printed number."""
    return re.compile(template.replace("#", _NUM))


# Each line the benchmarks print that carries figures: its pattern, then (name, kind) for
# each number in it. ``{}`` in a name is the case (physics) or the number of clients (app).
_PHYSICS_LINES = [
    (
        _pattern(r"^(.+?)\s+#ns\s+#ns\s+#x\s+#ns\s+#x\s+#us\s*$"),
        [
            ("{} ellipj [ns/point]", CONTROL),
            ("{} omega [ns/point]", COST),
            ("{} omega / ellipj", COST),
            ("{} attitude [ns/point]", COST),
            ("{} attitude / ellipj", COST),
            ("{} construction [us]", COST),
        ],
    ),
    (
        _pattern(r"^construct \+ one evaluation at t=1e4: # ms"),
        [("single time: construct + evaluate [ms]", COST)],
    ),
    (
        _pattern(r"construction # ms, evaluation # ms"),
        [("single time: construct [ms]", COST), ("single time: evaluate [ms]", COST)],
    ),
]
_APP_LINES = [
    (
        _pattern(r"server time per client-frame:\s*# ms CPU .*\(mean; p95 # ms\)"),
        [("{} frame CPU, session thread, mean [ms]", COST), ("{} frame CPU p95 [ms]", COST)],
    ),
    (
        _pattern(r"whole process per client-frame:\s*# ms CPU"),
        [("{} whole process CPU per client-frame [ms]", COST)],
    ),
    (
        _pattern(r"frame in session thread\s*: median # ms, p95 # ms"),
        [("{} frame wall median [ms]", COST), ("{} frame wall p95 [ms]", COST)],
    ),
    (
        _pattern(r"frames per second per client:\s*#"),
        [("{} frames per second per client", RATE)],
    ),
    (  # scene bytes only, the GUI's apart (older revisions)
        _pattern(r"bytes sent per frame\s*:\s*# B .*GUI # kB/s"),
        [("{} scene bytes per frame [B]", COST), ("{} GUI traffic [kB/s]", COST)],
    ),
    (  # everything one client receives (one websocket message per frame)
        _pattern(r"bytes sent per frame\s*:\s*# B\s+\(everything"),
        [("{} all bytes per frame [B]", COST)],
    ),
    (
        _pattern(r"messages per frame\s*:\s*#\s+\(scene #"),
        [("{} viser messages per frame", COST), ("{} scene messages per frame", COST)],
    ),
    (
        _pattern(r"slider-to-redraw\s*: median # ms, p95 # ms"),
        [("{} slider-to-redraw median [ms]", COST), ("{} slider-to-redraw p95 [ms]", COST)],
    ),
    (
        _pattern(r"server rebuild alone\s*: median # ms, p95 # ms"),
        [("{} rebuild median [ms]", COST), ("{} rebuild p95 [ms]", COST)],
    ),
    (
        _pattern(r"^viser floor: .* costs # ms CPU"),
        [("viser floor: bare viser CPU per frame [ms]", CONTROL)],
    ),
]
_APP_CLIENTS = re.compile(r"^clients: (\d+)\s*$")

#: A parsed run: figure name -> (value, kind).
Figures = dict[str, tuple[float, str]]


def parse_physics(text: str) -> Figures:
    """The figures of one ``physics.benchmark`` run, from its printed text."""
    figures: Figures = {}
    for line in text.splitlines():
        for pattern, names in _PHYSICS_LINES:
            match = pattern.search(line)
            if match is None:
                continue
            groups = match.groups()
            context = ""
            if len(groups) > len(names):  # a table row: the case label comes first
                context, groups = "physics " + groups[0].strip(), groups[1:]
            for (name, kind), value in zip(names, groups, strict=True):
                label = name.format(context) if "{}" in name else "physics " + name
                figures[label] = (float(value), kind)
            break
    return figures


def parse_app(text: str) -> Figures:
    """The figures of one app benchmark run, from its printed text."""
    figures: Figures = {}
    clients = "app"
    for line in text.splitlines():
        heading = _APP_CLIENTS.match(line)
        if heading is not None:
            clients = f"app {heading.group(1)} client(s):"
            continue
        for pattern, names in _APP_LINES:
            match = pattern.search(line)
            if match is None:
                continue
            for (name, kind), value in zip(names, match.groups(), strict=True):
                label = name.format(clients) if "{}" in name else "app " + name
                figures[label] = (float(value), kind)
            break
    return figures


# -- ratios ------------------------------------------------------------------------------------
@dataclasses.dataclass(frozen=True)
class Ratio:
    """One figure's ratio new/old over the rounds."""

    name: str
    kind: str
    ratios: tuple[float, ...]

    @property
    def median(self) -> float:
        return statistics.median(self.ratios) if self.ratios else float("nan")

    @property
    def verdict(self) -> str:
        if self.kind == CONTROL:
            return "control"
        if not self.ratios or self.median != self.median:
            return "n/a"
        ok = self.median <= COST_LIMIT if self.kind == COST else self.median >= RATE_LIMIT
        return "met" if ok else "MISSED"


def ratios(new_runs: Sequence[Figures], old_runs: Sequence[Figures]) -> list[Ratio]:
    """Per figure present on both sides, the ratio new/old of each round (paired by round).

    A round where either side lacks the figure, or the old value is zero or not finite, gives
    no ratio for it.
    """
    names: list[str] = []
    for run in [*new_runs, *old_runs]:
        names += [n for n in run if n not in names]
    result = []
    for name in names:
        values = []
        kind = ""
        for new, old in zip(new_runs, old_runs, strict=True):
            if name in new and name in old:
                kind = new[name][1]
                a, b = new[name][0], old[name][0]
                if b != 0 and abs(b) != float("inf") and b == b and a == a:
                    values.append(a / b)
        if kind:
            result.append(Ratio(name, kind, tuple(values)))
    return result


def one_sided(new_runs: Sequence[Figures], old_runs: Sequence[Figures]) -> list[str]:
    """Figures only one side printed (a benchmark that gained or changed a line): not
    compared, but named, so that nothing is dropped silently."""
    new = {name for run in new_runs for name in run}
    old = {name for run in old_runs for name in run}
    return [f"{name} (new only)" for name in sorted(new - old)] + [
        f"{name} (old only)" for name in sorted(old - new)
    ]


def format_ratios(rows: Sequence[Ratio], header: str, unpaired: Sequence[str] = ()) -> str:
    """The table of ratios with the limits they are judged against, and a one-line tally."""
    width = max([len(r.name) for r in rows] + [30])
    lines = [
        header,
        f"no regression: median ratio new/old <= {COST_LIMIT:.2f} for a cost (time, bytes), "
        f">= {RATE_LIMIT:.2f} for a rate (frames per second); controls are not judged",
        f"{'figure':{width}s}  {'median':>7s}  {'min-max':>13s}  verdict",
    ]
    for r in rows:
        low, high = (min(r.ratios), max(r.ratios)) if r.ratios else (float("nan"),) * 2
        lines.append(f"{r.name:{width}s}  {r.median:7.3f}  {low:6.3f}-{high:<6.3f}  {r.verdict}")
    lines += [f"not compared, printed by one side only: {name}" for name in unpaired]
    missed = [r.name for r in rows if r.verdict == "MISSED"]
    judged = [r for r in rows if r.verdict in ("met", "MISSED")]
    lines.append(
        f"no regression: {len(judged) - len(missed)} of {len(judged)} figures met"
        + (f"; MISSED: {', '.join(missed)}" if missed else "")
    )
    return "\n".join(lines)


# -- running a revision's benchmark ------------------------------------------------------------
@dataclasses.dataclass(frozen=True)
class Tree:
    """A checkout to run: its root, and whether its code imports through ``poinsot.``."""

    root: pathlib.Path
    namespaced: bool
    pythonpath: pathlib.Path

    def module(self, benchmark: str) -> str:
        dotted = f"{benchmark}.{_place(self.root, benchmark).replace('/', '.')}"
        return f"poinsot.{dotted}" if self.namespaced else dotted

    def supports(self, benchmark: str, option: str) -> bool:
        return option in _source(self.root, benchmark).read_text()


#: Where a package's benchmark module sits, the newest layout first (physics/ keeps it among
#: its tools since it was grouped into rooms, app/ among its developer tools since it was).
PLACES = {"physics": ("tools/benchmark", "benchmark"), "app": ("devtools/benchmark", "benchmark")}


def _place(root: pathlib.Path, benchmark: str) -> str:
    places = PLACES[benchmark]
    return next((p for p in places if (root / benchmark / f"{p}.py").is_file()), places[-1])


def _source(root: pathlib.Path, benchmark: str) -> pathlib.Path:
    return root / benchmark / f"{_place(root, benchmark)}.py"


def _imports_through_poinsot(root: pathlib.Path) -> bool:
    text = _source(root, "physics").read_text()
    return re.search(r"^\s*(from|import) poinsot\.", text, re.MULTILINE) is not None


def prepare(root: pathlib.Path, scratch: pathlib.Path) -> Tree:
    """How to run the checkout at ``root``: for the ``poinsot.`` layout, a folder of links
    ``scratch/poinsot/{physics,app}`` to put on ``PYTHONPATH``; else ``root`` itself."""
    if not _source(root, "physics").is_file():
        raise ValueError(f"{root} has no physics benchmark: not a Poinsot checkout")
    if not _imports_through_poinsot(root):
        return Tree(root, False, root)
    (scratch / "poinsot").mkdir(parents=True, exist_ok=True)
    for package in ("physics", "app"):
        (scratch / "poinsot" / package).symlink_to(root / package, target_is_directory=True)
    return Tree(root, True, scratch)


def environment(tree: Tree) -> dict[str, str]:
    """This process's environment with ``tree``'s import path."""
    return {**os.environ, "PYTHONPATH": str(tree.pythonpath), "PYTHONDONTWRITEBYTECODE": "1"}


def benchmark_command(tree: Tree, benchmark: str, options: argparse.Namespace) -> list[str]:
    """The command line of one benchmark run of ``tree`` (the fit timing is skipped: older
    revisions do not have it)."""
    command = [sys.executable, "-m", tree.module(benchmark)]
    if benchmark == "physics":
        command += ["-n", str(options.n), "--repeat", str(options.repeat)]
        if tree.supports("physics", "--no-fit"):
            command.append("--no-fit")
    else:
        command += ["--clients", *map(str, options.clients), "--seconds", str(options.seconds)]
        command += ["--redraws", str(options.redraws)]
    return command


def run_benchmark(tree: Tree, benchmark: str, options: argparse.Namespace) -> Figures:
    """Run one benchmark of ``tree`` in a fresh interpreter and parse what it prints."""
    done = subprocess.run(
        benchmark_command(tree, benchmark, options),
        cwd=tree.root,  # `python -m` puts the working folder first on sys.path
        env=environment(tree),
        capture_output=True,
        text=True,
        check=False,
    )
    if done.returncode != 0:
        tail = "\n".join(done.stderr.strip().splitlines()[-5:])
        raise RuntimeError(f"{benchmark} benchmark of {tree.root} failed:\n{tail}")
    figures = (parse_physics if benchmark == "physics" else parse_app)(done.stdout)
    if not figures:
        raise RuntimeError(f"no figures in the {benchmark} benchmark output of {tree.root}")
    return figures


@contextmanager
def checkout(repo: pathlib.Path, revision: str) -> Iterator[pathlib.Path]:
    """A temporary detached ``git worktree`` of ``revision``, removed on the way out."""
    with tempfile.TemporaryDirectory(prefix="poinsot-compare-") as scratch:
        path = pathlib.Path(scratch) / "tree"
        subprocess.run(
            ["git", "-C", str(repo), "worktree", "add", "--detach", str(path), revision],
            check=True,
            capture_output=True,
            text=True,
        )
        try:
            yield path
        finally:
            subprocess.run(
                ["git", "-C", str(repo), "worktree", "remove", "--force", str(path)],
                check=False,
                capture_output=True,
            )
            subprocess.run(["git", "-C", str(repo), "worktree", "prune"], check=False)


def _order(
    k: int, new: Tree, old: Tree, new_runs: list[Figures], old_runs: list[Figures]
) -> tuple[tuple[str, Tree, list[Figures]], ...]:
    """Round ``k``'s two runs: new first in even rounds, old first in odd ones. The first run
    of a pair was measured slower than the second, the same tree on both sides (up to 1.14 in
    every round of three), so each side goes first as often as the other."""
    pair = (("new", new, new_runs), ("old", old, old_runs))
    return pair if k % 2 == 0 else pair[::-1]


def compare(
    new: Tree, old: Tree, benchmarks: Sequence[str], options: argparse.Namespace
) -> tuple[list[Ratio], list[str]]:
    """Alternate the runs (new, old, old, new, new, old, ...: :func:`_order`) for
    ``options.rounds`` rounds; the ratios, and the figures only one side printed."""
    rows: list[Ratio] = []
    unpaired: list[str] = []
    for benchmark in benchmarks:
        new_runs: list[Figures] = []
        old_runs: list[Figures] = []
        for k in range(options.rounds):
            for label, tree, runs in _order(k, new, old, new_runs, old_runs):
                print(f"  round {k + 1}/{options.rounds}: {benchmark} {label}", file=sys.stderr)
                runs.append(run_benchmark(tree, benchmark, options))
        rows += ratios(new_runs, old_runs)
        unpaired += one_sided(new_runs, old_runs)
    return rows, unpaired


def run_comparison(
    repo: pathlib.Path, against: str, benchmarks: Sequence[str], options: argparse.Namespace
) -> tuple[list[Ratio], list[str]]:
    """The working tree at ``repo`` against revision ``against`` of the same repository: the
    ratios, and the figures only one side printed."""
    with checkout(repo, against) as other, tempfile.TemporaryDirectory() as scratch:
        new = prepare(repo, pathlib.Path(scratch) / "new")
        old = prepare(other, pathlib.Path(scratch) / "old")
        return compare(new, old, benchmarks, options)


# -- command line ------------------------------------------------------------------------------
def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m poinsot.app.devtools.compare", description=__doc__.split("\n\n")[0]
    )
    parser.add_argument("--against", required=True, metavar="REV", help="git revision to beat")
    parser.add_argument("--rounds", type=int, default=4, help="alternating runs of each side")
    parser.add_argument("--physics", action="store_true", help="the physics benchmark")
    parser.add_argument("--app", action="store_true", help="the app benchmark")
    parser.add_argument("-n", type=int, default=1_000_000, help="physics: times per call")
    parser.add_argument("--repeat", type=int, default=5, help="physics: best of this many")
    parser.add_argument("--clients", type=int, nargs="+", default=[1, 10], help="app: browsers")
    parser.add_argument("--seconds", type=float, default=4.0, help="app: steady-state window")
    parser.add_argument("--redraws", type=int, default=30, help="app: slider moves per run")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Compare; 0 when every judged figure met "no regression", 1 when one missed, 2 on a
    bad revision."""
    options = build_parser().parse_args(argv)
    if options.rounds < 1:
        print("compare: --rounds must be at least 1", file=sys.stderr)
        return 2
    benchmarks = [b for b in BENCHMARKS if getattr(options, b)] or list(BENCHMARKS)
    repo = pathlib.Path(__file__).resolve().parents[2]
    load0 = os.getloadavg()[0]
    try:
        rows, unpaired = run_comparison(repo, options.against, benchmarks, options)
    except subprocess.CalledProcessError as error:
        print(
            f"compare: git cannot check out {options.against!r}: {error.stderr.strip()}",
            file=sys.stderr,
        )
        return 2
    except (RuntimeError, ValueError) as error:
        print(f"compare: {error}", file=sys.stderr)
        return 2
    header = (
        f"ratio new/old: this working tree against {options.against} ({', '.join(benchmarks)}), "
        f"{options.rounds} alternating round(s), {os.cpu_count()} CPUs, load average "
        f"{load0:.1f} at start, {os.getloadavg()[0]:.1f} at end"
    )
    print(format_ratios(rows, header, unpaired))
    return 1 if any(r.verdict == "MISSED" for r in rows) else 0


if __name__ == "__main__":
    raise SystemExit(main())
