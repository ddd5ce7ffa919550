"""``python -m poinsot.app.devtools.compare``: parsing the benchmarks' text, the ratios and their
verdicts, and running two revisions of a repository from a temporary git worktree.

Everything but the last test runs on canned outputs or on a tiny git repository whose
"benchmarks" print canned text: no timing is asserted anywhere.
"""

from __future__ import annotations

import math
import subprocess
import textwrap
from pathlib import Path

import pytest

from poinsot.app.devtools import benchmark as app_benchmark
from poinsot.app.devtools import compare
from poinsot.app.devtools.compare import COST, RATE, Ratio
from poinsot.physics.tools import benchmark as physics_benchmark

REPO = Path(compare.__file__).resolve().parents[2]


def physics_text(omega_ns: float = 25.0, construct_ms: float = 0.050) -> str:
    """What physics.benchmark prints (the old revision's wording: no met/missed, no fit)."""
    return textwrap.dedent(
        f"""\
        FreeRigidBody speed, 1,000,000 times per call, best of 5
        case                            ellipj     omega  ratio  attitude  ratio     build
        ---------------------------------------------------------------------------------
        generic (1,2,3)                 20.0ns    {omega_ns:4.1f}ns  1.25x    60.0ns  3.00x    40.0us
        near separatrix 1-m~1e-10       10.0ns    30.0ns  3.00x    70.0ns  7.00x    50.0us
        extreme (1,10,1000)             20.0ns    22.0ns  1.10x    50.0ns  2.50x    45.0us
        targets: omega <= 1.5x ellipj, attitude <= 4x ellipj
        note: for 1-m < 1e-9 bare ellipj takes a first-order tanh/sech shortcut that is wrong
              for u beyond ~1, so that row's ratio compares against a wrong answer.
        construct + one evaluation at t=1e4: 0.120 ms (median of 1000; target <= 0.3 ms)
          FreeRigidBody(I, omega0).state(1e4), I = (13.0, 10.0, 5.0), omega0 = (0.3, 0.6, 0.9): construction {construct_ms:.3f} ms, evaluation 0.070 ms
        """  # noqa: E501
    )


def app_text(fps: float = 59.8, redraw_ms: float = 12.5) -> str:
    """What app.benchmark prints for one and ten clients."""
    blocks = []
    for clients in (1, 10):
        blocks.append(
            textwrap.dedent(
                f"""\
                clients: {clients}
                  server time per client-frame:   0.400 ms CPU in the session thread (mean; p95 0.900 ms)   (target <= 1 ms)
                  whole process per client-frame: 0.700 ms CPU (the above plus viser's transport thread)
                  frame in session thread     : median 0.350 ms, p95 1.200 ms (wall)
                  frames per second per client:    {fps:.1f}        (cap 60)
                  bytes sent per frame        :     612 B  (poses + trail increments) + GUI 3.4 kB/s (plot 10 Hz, time 5 Hz)
                  slider-to-redraw            : median {redraw_ms:.1f} ms, p95 nan ms   (target <= 30 ms)
                  server rebuild alone        : median 2.10 ms, p95 3.50 ms"""  # noqa: E501
            )
        )
    head = "Poinsot app benchmark (python 3.11.7, 2 CPUs, load average 4.2)"
    tail = "viser floor: a bare viser server sending one pose per frame costs 0.150 ms CPU per client-frame here (no Poinsot code)"  # noqa: E501
    return "\n".join([head, *blocks, tail]) + "\n"


# -- parsing ------------------------------------------------------------------------------------
def test_the_physics_figures_are_read_per_case_with_their_kind():
    figures = compare.parse_physics(physics_text())
    assert len(figures) == 3 * 6 + 3
    assert figures["physics generic (1,2,3) omega [ns/point]"] == (25.0, COST)
    assert figures["physics near separatrix 1-m~1e-10 attitude / ellipj"] == (7.0, COST)
    assert figures["physics extreme (1,10,1000) construction [us]"] == (45.0, COST)
    assert figures["physics extreme (1,10,1000) ellipj [ns/point]"][1] == compare.CONTROL
    assert figures["physics single time: construct + evaluate [ms]"] == (0.12, COST)
    assert figures["physics single time: construct [ms]"] == (0.05, COST)
    assert figures["physics single time: evaluate [ms]"] == (0.07, COST)


def test_the_app_figures_are_read_per_number_of_clients():
    figures = compare.parse_app(app_text())
    assert len(figures) == 2 * 12 + 1
    assert figures["app 10 client(s): frames per second per client"] == (59.8, RATE)
    assert figures["app 1 client(s): scene bytes per frame [B]"] == (612.0, COST)
    assert figures["app 1 client(s): GUI traffic [kB/s]"] == (3.4, COST)
    assert figures["app 10 client(s): slider-to-redraw median [ms]"] == (12.5, COST)
    assert math.isnan(figures["app 10 client(s): slider-to-redraw p95 [ms]"][0])
    assert figures["app viser floor: bare viser CPU per frame [ms]"] == (0.15, compare.CONTROL)


def test_todays_physics_printers_print_what_the_parser_reads(capsys, monkeypatch):
    rows = [
        {
            "case": label,
            "regime": "rotation",
            "ellipj_ns": 20.0,
            "omega_ns": 25.0,
            "attitude_ns": 60.0,
            "omega_ratio": 1.25,
            "attitude_ratio": 3.0,
            "construct_us": 40.0,
        }
        for label, _, _ in physics_benchmark.CASES
    ]
    canned = {"n": 1000, "construct": 5e-5, "evaluate": 7e-5, "both": 1.2e-4}
    monkeypatch.setattr(physics_benchmark, "single_time", lambda: canned)
    physics_benchmark._print_speed(rows, 1000, 1)
    physics_benchmark._print_single_time()
    figures = compare.parse_physics(capsys.readouterr().out)
    assert figures.keys() == compare.parse_physics(physics_text()).keys()
    assert figures["physics extreme (1,10,1000) attitude / ellipj"] == (3.0, COST)
    assert figures["physics single time: evaluate [ms]"] == (0.07, COST)


def test_todays_app_printer_prints_what_the_parser_reads():
    """Every figure today's benchmark prints is read back with its value and kind."""
    result = app_benchmark.Result(
        clients=1,
        cpu_per_client_frame_ms=0.7,
        frame_cpu_mean_ms=0.4,
        frame_cpu_p95_ms=0.9,
        frame_wall_median_ms=0.35,
        frame_wall_p95_ms=1.2,
        frames_per_second_per_client=59.8,
        skipped_per_second_per_client=1.5,
        bytes_per_frame=612,
        messages_per_frame=5.0,
        scene_messages_per_frame=3.0,
        redraw_median_ms=12.5,
        redraw_p95_ms=20,
        rebuild_median_ms=2.1,
        rebuild_p95_ms=3.5,
    )
    figures = compare.parse_app(app_benchmark.format_result(result))
    expected = {
        "frame CPU, session thread, mean [ms]": 0.4,
        "frame CPU p95 [ms]": 0.9,
        "whole process CPU per client-frame [ms]": 0.7,
        "frame wall median [ms]": 0.35,
        "frame wall p95 [ms]": 1.2,
        "all bytes per frame [B]": 612.0,
        "viser messages per frame": 5.0,
        "scene messages per frame": 3.0,
        "slider-to-redraw median [ms]": 12.5,
        "slider-to-redraw p95 [ms]": 20.0,
        "rebuild median [ms]": 2.1,
        "rebuild p95 [ms]": 3.5,
    }
    want = {f"app 1 client(s): {k}": (v, COST) for k, v in expected.items()}
    want["app 1 client(s): frames per second per client"] = (59.8, RATE)
    assert figures == want


# -- ratios and verdicts ------------------------------------------------------------------------
def test_ratios_pair_the_rounds_and_take_the_median_with_its_range():
    new = [compare.parse_physics(physics_text(omega_ns=w)) for w in (20.0, 30.0, 22.0)]
    old = [compare.parse_physics(physics_text()) for _ in range(3)]  # 25 ns each
    rows = {r.name: r for r in compare.ratios(new, old)}
    omega = rows["physics generic (1,2,3) omega [ns/point]"]
    assert omega.ratios == pytest.approx((0.8, 1.2, 0.88))
    assert omega.median == pytest.approx(0.88)
    assert omega.verdict == "met"
    assert rows["physics extreme (1,10,1000) attitude [ns/point]"].median == 1.0


def test_a_cost_regresses_above_the_limit_and_a_rate_below_it():
    assert Ratio("c", COST, (1.10,)).verdict == "met"
    assert Ratio("c", COST, (1.2, 1.11, 0.5)).verdict == "MISSED"
    assert Ratio("r", RATE, (0.90,)).verdict == "met"
    assert Ratio("r", RATE, (0.95, 0.89, 0.8)).verdict == "MISSED"
    assert Ratio("k", compare.CONTROL, (3.0,)).verdict == "control"
    assert Ratio("c", COST, ()).verdict == "n/a"


def test_a_figure_missing_on_one_side_or_unmeasured_is_not_judged():
    new = [compare.parse_app(app_text(redraw_ms=10.0))]
    old = [{k: v for k, v in compare.parse_app(app_text()).items() if "10 client" not in k}]
    rows = {r.name: r for r in compare.ratios(new, old)}
    assert not any("10 client" in name for name in rows)  # only the new side has them
    assert rows["app 1 client(s): slider-to-redraw median [ms]"].ratios == (0.8,)
    assert rows["app 1 client(s): slider-to-redraw p95 [ms]"].verdict == "n/a"  # nan


def test_a_benchmark_line_that_changed_is_named_not_compared():
    """The app benchmark that counts every byte of a frame (one websocket message) and its
    viser messages, against one that counted the scene's bytes and the GUI's apart."""
    changed = app_text().replace(
        "612 B  (poses + trail increments) + GUI 3.4 kB/s (plot 10 Hz, time 5 Hz)",
        "1210 B  (everything: poses, traces, labels, plot 10 Hz, time 5 Hz)   (target <= 2 kB)\n"
        "  messages per frame          :    4.30    (scene 3.25: 3 poses + a trace increment)",
    )
    new, old = [compare.parse_app(changed)], [compare.parse_app(app_text())]
    assert new[0]["app 1 client(s): all bytes per frame [B]"] == (1210.0, COST)
    assert new[0]["app 10 client(s): scene messages per frame"] == (3.25, COST)
    unpaired = compare.one_sided(new, old)
    assert "app 1 client(s): viser messages per frame (new only)" in unpaired
    assert "app 10 client(s): GUI traffic [kB/s] (old only)" in unpaired
    names = {r.name for r in compare.ratios(new, old)}
    assert "app 1 client(s): frames per second per client" in names
    assert not any("bytes" in name for name in names)
    table = compare.format_ratios(compare.ratios(new, old), "header", unpaired)
    assert "printed by one side only: app 1 client(s): all bytes per frame [B] (new only)" in table


def test_the_table_states_the_limits_and_names_what_missed():
    rows = [Ratio("fast", COST, (0.9, 1.0, 1.05)), Ratio("fps", RATE, (0.5, 0.6, 0.7))]
    table = compare.format_ratios(rows, "header")
    assert "<= 1.10 for a cost" in table and ">= 0.90 for a rate" in table
    assert "1 of 2 figures met; MISSED: fps" in table
    assert "0.900-1.050" in table


# -- running revisions from a git worktree ------------------------------------------------------
def _git(repo: Path, *args: str) -> str:
    done = subprocess.run(["git", "-C", str(repo), *args], check=True, capture_output=True)
    return done.stdout.decode()


def _worktree_paths(repo: Path) -> set[str]:
    listing = _git(repo, "worktree", "list", "--porcelain").splitlines()
    return {line.split(" ", 1)[1] for line in listing if line.startswith("worktree ")}


def _write_layout(repo: Path, namespaced: bool, physics: str, app: str) -> None:
    """Fake benchmarks printing canned text, importing it as that layout's code does."""
    prefix = "poinsot." if namespaced else ""
    for package, text in (("physics", physics), ("app", app)):
        (repo / package).mkdir(exist_ok=True)
        (repo / package / "__init__.py").write_text("")
        (repo / package / "canned.py").write_text(f"TEXT = {text!r}\n")
        (repo / package / "benchmark.py").write_text(
            f"from {prefix}{package}.canned import TEXT\n\nprint(TEXT)\n"
        )


@pytest.mark.server  # it starts a process of its own
def test_the_working_tree_runs_against_an_older_layout_from_a_temporary_worktree(tmp_path):
    repo = tmp_path / "repo"
    repo.mkdir()
    _git(repo, "init", "-q")
    _write_layout(repo, False, physics_text(omega_ns=20.0), app_text(fps=60.0))
    _git(repo, "add", ".")
    _git(repo, "-c", "user.name=t", "-c", "user.email=t@t", "commit", "-qm", "old layout")
    _write_layout(repo, True, physics_text(omega_ns=10.0), app_text(fps=30.0))
    _git(repo, "add", ".")
    _git(repo, "-c", "user.name=t", "-c", "user.email=t@t", "commit", "-qm", "poinsot.")
    # Uncommitted: the working tree, not HEAD, is what gets measured.
    (repo / "physics" / "canned.py").write_text(f"TEXT = {physics_text(omega_ns=5.0)!r}\n")
    options = compare.build_parser().parse_args(["--against", "HEAD~1", "--rounds", "2"])
    found, unpaired = compare.run_comparison(repo, "HEAD~1", ["physics", "app"], options)
    rows = {r.name: r for r in found}
    assert unpaired == []
    assert rows["physics generic (1,2,3) omega [ns/point]"].ratios == (0.25, 0.25)
    assert rows["app 10 client(s): frames per second per client"].verdict == "MISSED"
    assert rows["app 1 client(s): rebuild median [ms]"].ratios == (1.0, 1.0)
    assert _worktree_paths(repo) == {str(repo)}  # the temporary one is gone


@pytest.mark.server  # it starts a process of its own
def test_a_namespaced_tree_imports_its_own_folders_not_the_installed_package(tmp_path):
    _write_layout(tmp_path, True, "physics", "app")
    tree = compare.prepare(tmp_path, tmp_path / "scratch")
    assert tree.namespaced and tree.module("app") == "poinsot.app.benchmark"  # the older place
    (tmp_path / "app" / "devtools").mkdir()
    (tmp_path / "app" / "devtools" / "benchmark.py").write_text("")
    assert tree.module("app") == "poinsot.app.devtools.benchmark"  # today's, where it is
    done = subprocess.run(
        [compare.sys.executable, "-c", "import poinsot.physics.canned as c; print(c.__file__)"],
        cwd=tree.root,
        env=compare.environment(tree),
        check=True,
        capture_output=True,
        text=True,
    )
    assert done.stdout.strip() == str(tmp_path / "scratch" / "poinsot" / "physics" / "canned.py")


def test_options_a_revision_lacks_are_not_passed_to_it(tmp_path):
    _write_layout(tmp_path, False, "physics", "app")
    options = compare.build_parser().parse_args(["--against", "x", "-n", "100"])
    tree = compare.prepare(tmp_path, tmp_path / "scratch")
    assert tree.module("physics") == "physics.benchmark"
    command = compare.benchmark_command(tree, "physics", options)
    assert command[-4:] == ["-n", "100", "--repeat", "5"]
    (tmp_path / "physics" / "benchmark.py").write_text("# accepts --no-fit\n")
    assert compare.benchmark_command(tree, "physics", options)[-1] == "--no-fit"


def test_a_bad_revision_is_a_one_line_message(capsys):
    assert compare.main(["--against", "no-such-revision-anywhere", "--physics"]) == 2
    assert "cannot check out 'no-such-revision-anywhere'" in capsys.readouterr().err


@pytest.mark.slow
def test_the_real_physics_benchmark_of_head_against_head(capsys):
    """The real benchmark, tiny sizes, one round (20 to 40 s on a loaded 2-core machine)."""
    worktrees = _worktree_paths(REPO)  # other worktrees' commits may move meanwhile
    options = compare.build_parser().parse_args(
        ["--against", "HEAD", "--rounds", "1", "-n", "2000", "--repeat", "1"]
    )
    rows, unpaired = compare.run_comparison(REPO, "HEAD", ["physics"], options)
    assert len(rows) == 3 * 6 + 3 and unpaired == []
    missing = [r for r in rows if not (len(r.ratios) == 1 and r.median > 0)]
    assert missing == [], missing  # each figure's one ratio, and which one lacked it
    assert _worktree_paths(REPO) == worktrees


def test_each_side_runs_first_in_every_other_round(monkeypatch):
    """The first run of a pair is the slower one on this machine, the same tree on both sides:
    neither side may always be first."""
    order: list[str] = []
    monkeypatch.setattr(
        compare, "run_benchmark", lambda tree, benchmark, options: order.append(tree) or {}
    )
    options = compare.build_parser().parse_args(["--against", "HEAD"])
    assert options.rounds == 4
    compare.compare("new", "old", ["app"], options)  # type: ignore[arg-type]
    assert order == ["new", "old", "old", "new", "new", "old", "old", "new"]
