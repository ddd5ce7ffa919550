"""``poinsot report --quick``: the files it writes and what they must contain.

One quick run through the real command line (``quick_report`` in conftest.py, ~40 s on the
2-core CI machine), then checks on its outputs: the CSV columns exactly, every case x method
present, finite non-negative errors and positive timings, a verdict per case in report.md,
valid PNG images.
The study's building blocks are tested on their own below (cheap).
"""

from __future__ import annotations

import csv
import io
import math
import struct
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import STDERR_NAME
from PIL import Image
from rich.console import Console

from poinsot.app.report.measure.cases import CASES, StudyConfig
from poinsot.app.report.measure.progress import PLAIN_STEPS, Progress
from poinsot.app.report.measure.reference import TaylorReference
from poinsot.app.report.measure.runs import time_scale
from poinsot.app.report.tables import ERROR_VS_TIME_COLUMNS, EXACT, WORK_PRECISION_COLUMNS
from poinsot.physics import FreeRigidBody
from poinsot.physics.integrators import INTEGRATORS

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
QUICK_CASES = [c.name for c in StudyConfig.for_mode(quick=True).cases]


def read_rows(path: Path) -> tuple[list[str], list[dict[str, str]]]:
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        return list(reader.fieldnames or []), list(reader)


@pytest.mark.slow
def test_work_precision_csv_columns_and_coverage(quick_report):
    columns, rows = read_rows(quick_report / "work_precision.csv")
    assert tuple(columns) == WORK_PRECISION_COLUMNS
    assert tuple(columns) == (
        "case",
        "method",
        "setting",
        "seconds",
        "omega_error",
        "attitude_error",
        "energy_drift",
    )
    seen = {(r["case"], r["method"]) for r in rows}
    for case in QUICK_CASES:
        for method in [*INTEGRATORS, EXACT]:
            assert (case, method) in seen, (case, method)
    for r in rows:
        assert float(r["seconds"]) > 0.0, r
        for key in ("omega_error", "attitude_error", "energy_drift"):
            value = float(r[key])
            assert math.isfinite(value) and value >= 0.0, r


@pytest.mark.slow
def test_exact_rows_are_verified_and_far_more_accurate_than_coarse_runs(quick_report):
    _, rows = read_rows(quick_report / "work_precision.csv")
    for case in QUICK_CASES:
        exact = [r for r in rows if r["case"] == case and r["method"] == EXACT]
        assert len(exact) == 1
        # The closed form against the 32-digit reference, inside the horizon: near the
        # separatrix the phase is ill-conditioned, elsewhere it is a few ulps.
        assert float(exact[0]["omega_error"]) < 1e-9
        assert float(exact[0]["attitude_error"]) < 1e-9
        assert float(exact[0]["energy_drift"]) < 1e-14
        runs = [r for r in rows if r["case"] == case and r["method"] != EXACT]
        worst = max(float(r["omega_error"]) for r in runs)
        assert worst > 1e3 * float(exact[0]["omega_error"])


@pytest.mark.slow
def test_error_vs_time_csv(quick_report):
    columns, rows = read_rows(quick_report / "error_vs_time.csv")
    assert tuple(columns) == ERROR_VS_TIME_COLUMNS
    seen = {(r["case"], r["method"]) for r in rows}
    for case in QUICK_CASES:
        for method in [*INTEGRATORS, EXACT]:
            assert (case, method) in seen, (case, method)
    for r in rows:
        assert float(r["t"]) >= 0.0
        assert float(r["omega_error"]) >= 0.0 and float(r["attitude_error"]) >= 0.0
    # Over the generic case's ten periods the geometric methods' error is a phase error that
    # grows linearly (x10 from 1 to 10 periods, measured 9.4-10.0); the Runge-Kutta pairs' error
    # grows too (faster than linearly at tight tolerances: ~t^2).
    for method in INTEGRATORS:
        runs = [r for r in rows if r["case"] == "generic" and r["method"] == method]
        final = {r["setting"]: float(r["omega_error"]) for r in runs}  # last row per setting
        finest = min(final, key=final.__getitem__)
        errs = [float(r["omega_error"]) for r in runs if r["setting"] == finest]
        ratio = errs[-1] / errs[len(errs) // 10]
        if INTEGRATORS[method].conserves_norm:
            assert 8.0 < ratio < 12.5, (method, finest, ratio)
        else:
            assert ratio > 2.0, (method, finest, ratio)


@pytest.mark.slow
def test_report_markdown_has_verdicts_and_findings(quick_report):
    text = (quick_report / "report.md").read_text()
    assert "## Verdicts" in text
    verdicts = text.split("## Verdicts", 1)[1].split("##", 1)[0]
    for case in QUICK_CASES:
        assert f"**{case}**:" in verdicts
    assert "## Stability of the exact solution" in text
    assert "## Speed-up of the exact solution over DOP853 at t = 1e4" in text
    assert "**Speed-up:" in text
    assert "mpmath" in text
    games = text.split("## Game-engine steps: does the body flip?", 1)[1].split("\n## ", 1)[0]
    assert "| T-handle preset, 2 rad/s | no-gyro | 1/60 s | never |" in games
    assert (quick_report / "game_steps.csv").read_text().count("\n") == 1 + 22
    for name in ("work_precision.png", "work_precision_attitude.png", "error_vs_time.png"):
        assert f"]({name})" in text


@pytest.mark.slow
@pytest.mark.parametrize(
    "name", ["work_precision.png", "work_precision_attitude.png", "error_vs_time.png"]
)
def test_figures_are_valid_png_images(quick_report, name):
    data = (quick_report / name).read_bytes()
    assert data[:8] == PNG_SIGNATURE
    width, height = struct.unpack(">II", data[16:24])
    assert width > 400 and height > 300
    with Image.open(quick_report / name) as image:
        image.verify()
    with Image.open(quick_report / name) as image:
        pixels = np.asarray(image.convert("L"))
    assert pixels.std() > 10  # not a blank canvas


# --------------------------------------------------------------------------------------------
# Building blocks


def test_cases_are_data_with_sources_and_horizons():
    names = [c.name for c in CASES]
    assert len(names) == len(set(names))
    for case in CASES:
        assert case.source
        assert (case.periods is None) != (case.horizon is None)
        body = FreeRigidBody(case.inertia, case.omega0)
        if case.periods is not None:
            assert math.isfinite(body.period)
    by_name = {c.name: c for c in CASES}
    # The exact separatrix: G^2 - 2T I2 == 0 in floating point.
    sep = by_name["separatrix"]
    i, w = np.array(sep.inertia), np.array(sep.omega0)
    assert np.sum((i * w) ** 2) - np.sum(i * w * w) * i[1] == 0.0
    # The near-separatrix ladder reaches 1 - m = 1e-14 (to the rounding of the float omega0).
    mcs = sorted(
        FreeRigidBody(c.inertia, c.omega0).complementary_parameter
        for c in CASES
        if c.name.startswith("near-separatrix")
    )
    assert mcs[0] == pytest.approx(1e-14, rel=0.05) and mcs[-1] == pytest.approx(1e-6, rel=1e-6)
    assert by_name["flat plate"].inertia[2] == sum(by_name["flat plate"].inertia[:2])
    assert by_name["long horizon"].periods == 1e4
    toutatis = FreeRigidBody(by_name["Toutatis"].inertia, by_name["Toutatis"].omega0)
    assert toutatis.period == pytest.approx(5.41, rel=1e-4)
    assert toutatis.second_period == pytest.approx(7.35, rel=1e-4)


def test_time_scale_follows_the_fastest_rate():
    assert time_scale((1.0, 1.0, 1.0), (0.0, 0.0, 2.0)) == pytest.approx(math.pi)
    # Euler's rate |I2 - I3| / I1 |omega| = 990 |omega| dominates on (1, 10, 1000).
    assert time_scale((1.0, 10.0, 1000.0), (1.0, 0.0, 0.0)) == pytest.approx(2 * math.pi / 990)


def test_taylor_reference_is_self_consistent_at_30_digits():
    inertia, omega0 = (13.0, 10.0, 5.0), (0.3, 0.6, 0.9)
    body = FreeRigidBody(inertia, omega0)
    ref = TaylorReference(inertia, omega0, digits=32)
    assert ref.find_period(body.period)
    finer = TaylorReference(inertia, omega0, digits=40)
    assert finer.find_period(body.period)
    ctx = finer.ctx
    assert abs(ref.period - finer.period) < ctx.mpf(10) ** -30 * finer.period
    for t in (3.7, 0.5 * float(finer.period), 250.0):
        (w_a, q_a), (w_b, q_b) = ref.state(t), finer.state(t)
        assert max(abs(a - b) for a, b in zip(w_a + q_a, w_b + q_b, strict=True)) < 1e-29
    # Invariants of the motion, at 40 digits, across a folded time (t > period).
    two_t0, g0, l0 = finer.invariants(0.0)
    two_t, g, lvec = finer.invariants(250.0)
    assert abs(two_t / two_t0 - 1) < 1e-35 and abs(g / g0 - 1) < 1e-35
    assert max(abs(a - b) for a, b in zip(lvec, l0, strict=True)) < 1e-35 * ctx.sqrt(g0)


@pytest.mark.parametrize(
    "inertia, omega0, t",
    [
        ((2.0, 3.0, 6.0), (3.0, 0.25, 1.0), 20.0),  # on the separatrix: integrated directly
        ((1e-4, 1.0, 1.0), (50.0, 1.0, 0.5), 3.0),  # a needle: omega components of 50 and 1
        ((1.0, 10.0, 1000.0), (1.0, 1.0, 1.0), 0.3),  # stiff, non-physical
    ],
)
def test_taylor_reference_keeps_the_invariants_to_32_digits(inertia, omega0, t):
    ref = TaylorReference(inertia, omega0)
    two_t0, g0, l0 = ref.invariants(0.0)
    two_t, g, lvec = ref.invariants(t)
    assert abs(two_t / two_t0 - 1) < 1e-31 and abs(g / g0 - 1) < 1e-31
    assert max(abs(a - b) for a, b in zip(lvec, l0, strict=True)) < 1e-31 * ref.ctx.sqrt(g0)


def test_taylor_reference_rejects_a_wrong_period():
    inertia, omega0 = (13.0, 10.0, 5.0), (0.3, 0.6, 0.9)
    body = FreeRigidBody(inertia, omega0)
    ref = TaylorReference(inertia, omega0)
    assert not ref.find_period(0.5 * body.period)  # a crossing of one component, not a period
    assert not ref.find_period(body.period * (1 + 1e-6))  # converges, but not to the guess
    assert ref.period is None
    assert ref.find_period(body.period * (1 + 1e-12))


def test_taylor_reference_agrees_with_the_exact_solution():
    inertia, omega0 = (1.0, 3.0836, 3.235), (1.714199, 0.0, 0.644256)
    body = FreeRigidBody(inertia, omega0)
    ref = TaylorReference(inertia, omega0)
    assert ref.find_period(body.period)
    for t in (1.0, 20.0, 1e3):
        c = ref.compare(t, body.omega(t), body.attitude(t).as_quat())
        assert c.omega_error < 1e-12 and c.attitude_error < 1e-11


@pytest.fixture
def plain_env(monkeypatch) -> None:
    """No variable that would make rich take a file for a terminal."""
    for name in ("FORCE_COLOR", "TTY_COMPATIBLE", "TTY_INTERACTIVE"):
        monkeypatch.delenv(name, raising=False)


def test_progress_in_a_file_is_a_few_plain_lines(capsys, plain_env):
    bar = Progress(1000)
    for k in range(1000):
        bar.advance(f"step {k}")
    bar.close()
    err = capsys.readouterr().err
    lines = err.splitlines()
    assert "\r" not in err and "\x1b" not in err
    assert len(lines) == PLAIN_STEPS, lines  # one per tenth, the last one says 100 %
    assert lines[0].startswith("report:  10%") and lines[-1].startswith("report: 100%")
    assert err.endswith("\n")


def test_progress_closed_early_still_says_done(capsys, plain_env):
    bar = Progress(4)
    bar.advance("a")
    bar.close()
    assert capsys.readouterr().err.splitlines() == ["report:  25%  a", "report: 100%  done"]


def test_progress_on_a_terminal_is_a_rich_bar():
    out = io.StringIO()
    console = Console(file=out, force_terminal=True, force_interactive=True, width=100)
    bar = Progress(4, console=console)
    bar.advance("a")
    bar.advance("b", 2)
    bar.close()
    text = out.getvalue()
    assert "━" in text and "100%" in text and "done" in text  # rich's bar, filled
    assert "report:" not in text  # not the plain lines


def test_progress_disabled_writes_nothing(capsys):
    bar = Progress(4, enabled=False)
    bar.advance("a")
    bar.close()
    assert capsys.readouterr().err == ""


@pytest.mark.slow
def test_report_quick_into_a_file_writes_a_few_lines_of_progress(quick_report):
    """``poinsot report --quick 2> file``: stderr as a file holds a few plain lines, not
    hundreds of carriage-return frames of a bar."""
    err = (quick_report / STDERR_NAME).read_text()
    assert "\r" not in err and "\x1b" not in err
    progress = [line for line in err.splitlines() if line.startswith("report:")]
    assert 1 <= len(progress) <= PLAIN_STEPS, err
    assert progress[-1].startswith("report: 100%")


@pytest.mark.server  # it starts a process of its own
def test_python_dash_m_runs_the_report_command():
    done = subprocess.run(
        [sys.executable, "-m", "poinsot.app.report", "--help"],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert "--quick" in done.stdout and "--out" in done.stdout
