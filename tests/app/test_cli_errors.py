"""Every bad command line is one line on stderr: exit status 2 for a bad argument, 1 for a failure
after the arguments were accepted; a traceback only with ``--debug``."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from poinsot.app.cli import main as cli
from poinsot.app.devtools.load import cli as load_cli


def _run_main(main, argv: list[str], capsys) -> tuple[int, str]:
    try:
        code = main(argv)
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else 1
    return int(code), capsys.readouterr().err


def _assert_one_line(code: int, err: str, expected: int, prog: str) -> None:
    assert "Traceback" not in err, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith(f"{prog}: error: "), lines[0]
    assert code == expected, err


@pytest.fixture
def recording(tmp_path):
    path = tmp_path / "toss.csv"
    path.write_text("t,wx,wy,wz\n0,1,2,3\n")
    return str(path)


OUT_PNG, OUT_HTML, OUT_MP4 = "{tmp}/x.png", "{tmp}/x.html", "{tmp}/x.mp4"

#: (argv, which command the one line names); every argument of every command, each broken.
BAD = [
    # serve (the top level serves): only what argparse already checks
    (["--port", "eighty"], "poinsot"),
    (["--preset", "nope"], "poinsot"),
    (["serve", "--scene", "nope"], "poinsot serve"),
    (["serve", "--bogus"], "poinsot"),  # argparse reports extras at the top
    (["nonsense-command"], "poinsot"),
    # report
    (["report", "--out", "/proc/x"], "poinsot report"),
    (["report", "--out", "/etc/hostname/sub"], "poinsot report"),
    (["report", "--quick=yes"], "poinsot report"),
    # screenshot
    (["screenshot"], "poinsot screenshot"),  # --out is required
    (["screenshot", "--out", "/proc/x.png"], "poinsot screenshot"),
    (["screenshot", "--out", "{tmp}"], "poinsot screenshot"),
    (["screenshot", "--out", OUT_PNG, "--time", "nan"], "poinsot screenshot"),
    (["screenshot", "--out", OUT_PNG, "--time", "-1"], "poinsot screenshot"),
    (["screenshot", "--out", OUT_PNG, "--size", "0x5"], "poinsot screenshot"),
    (["screenshot", "--out", OUT_PNG, "--size", "big"], "poinsot screenshot"),
    (["screenshot", "--out", OUT_PNG, "--view", "under"], "poinsot screenshot"),
    (["screenshot", "--out", OUT_PNG, "--preset", "nope"], "poinsot screenshot"),
    (["screenshot", "--out", OUT_PNG, "--scene", "nope"], "poinsot screenshot"),
    (["screenshot", "--out", OUT_PNG, "--background", "plaid"], "poinsot screenshot"),
    (["screenshot", "--out", OUT_PNG, "--strobe", "1"], "poinsot screenshot"),
    (["screenshot", "--out", OUT_PNG, "--strobe", "99"], "poinsot screenshot"),
    (["screenshot", "--out", OUT_PNG, "--strobe", "two"], "poinsot screenshot"),
    (
        ["screenshot", "--out", OUT_PNG, "--strobe", "4", "--from", "5", "--to", "2"],
        "poinsot screenshot",
    ),
    (["screenshot", "--out", OUT_PNG, "--strobe", "4", "--to", "nan"], "poinsot screenshot"),
    (["screenshot", "--out", OUT_PNG, "--from", "2"], "poinsot screenshot"),  # no --strobe
    (["screenshot", "--out", OUT_PNG, "--strobe", "4", "--time", "3"], "poinsot screenshot"),
    (
        ["screenshot", "--out", OUT_PNG, "--strobe", "4", "--view", "ride-along"],
        "poinsot screenshot",
    ),
    # export-html
    (["export-html", "--out", OUT_HTML, "--seconds", "-5"], "poinsot export-html"),
    (["export-html", "--out", OUT_HTML, "--seconds", "inf"], "poinsot export-html"),
    (["export-html", "--out", OUT_HTML, "--seconds", "1e9"], "poinsot export-html"),
    (["export-html", "--out", OUT_HTML, "--fps", "0"], "poinsot export-html"),
    (["export-html", "--out", OUT_HTML, "--fps", "nan"], "poinsot export-html"),
    (["export-html", "--out", OUT_HTML, "--view", "ride-along"], "poinsot export-html"),
    (["export-html", "--out", "/proc/x.html"], "poinsot export-html"),
    (["export-html", "--out", "{tmp}"], "poinsot export-html"),
    # video
    (["video"], "poinsot video"),  # --out is required
    (["video", "--out", "{tmp}/x.avi"], "poinsot video"),
    (["video", "--out", "/proc/x.mp4"], "poinsot video"),
    (["video", "--out", OUT_MP4, "--size", "641x360"], "poinsot video"),  # yuv420p: even
    (["video", "--out", OUT_MP4, "--size", "4000x2000"], "poinsot video"),
    (["video", "--out", OUT_MP4, "--seconds", "0"], "poinsot video"),
    (["video", "--out", OUT_MP4, "--seconds", "nan"], "poinsot video"),
    (["video", "--out", OUT_MP4, "--fps", "0"], "poinsot video"),
    (["video", "--out", OUT_MP4, "--fps", "120"], "poinsot video"),
    (["video", "--out", OUT_MP4, "--from", "-1"], "poinsot video"),
    (["video", "--out", OUT_MP4, "--view", "under"], "poinsot video"),
    (["video", "--out", OUT_MP4, "--preset", "nope"], "poinsot video"),
    (["video", "--out", OUT_MP4, "--scene", "nope"], "poinsot video"),
    # benchmark
    (["benchmark", "--clients", "0"], "poinsot benchmark"),
    (["benchmark", "--clients", "-3"], "poinsot benchmark"),
    (["benchmark", "--clients", "two"], "poinsot benchmark"),
    (["benchmark", "--seconds", "0"], "poinsot benchmark"),
    (["benchmark", "--seconds", "nan"], "poinsot benchmark"),
    (["benchmark", "--redraws", "0"], "poinsot benchmark"),
    # fit
    (["fit"], "poinsot fit"),
    (["fit", "/nonexistent/toss.zip"], "poinsot fit"),
    (["fit", "{rec}", "--start", "soon"], "poinsot fit"),
    (["fit", "{rec}", "--end", "inf"], "poinsot fit"),
    (["fit", "{rec}", "--start", "3", "--end", "2"], "poinsot fit"),
    (["fit", "{rec}", "--json", "/proc/fits.json"], "poinsot fit"),
    (["fit", "{rec}", "--plot", "{tmp}"], "poinsot fit"),
]


def _fill(argv: list[str], tmp_path, recording: str) -> list[str]:
    return [a.format(tmp=tmp_path, rec=recording) for a in argv]


@pytest.mark.parametrize(("argv", "prog"), BAD, ids=[" ".join(a) for a, _ in BAD])
def test_a_bad_argument_is_one_line_and_status_2(argv, prog, tmp_path, recording, capsys):
    code, err = _run_main(cli.main, _fill(argv, tmp_path, recording), capsys)
    _assert_one_line(code, err, 2, prog)
    assert not list(tmp_path.glob("x.*")), "nothing is written for a refused command"


LOAD = "python -m poinsot.app.devtools.load"
BAD_LOAD = [
    ["--clients", "0"],
    ["--clients", "many"],
    ["--seconds", "-1"],
    ["--seconds", "nan"],
    ["--slider-period", "0"],
    ["--storm", "0"],
    ["--storm-workers", "0"],
    ["--storm-steady", "-1"],
    ["--settle-seconds", "0"],
    ["--stall-seconds", "inf"],
    ["--flood-seconds", "0"],
    ["--flood-rate", "-10"],
    ["--phase", "nap"],
    ["--phase", "flood", "--clients", "1"],
    ["--min-fps", "-1"],
    ["--max-redraw-ms", "0"],
    ["--max-rss-growth", "nan"],
    ["--storm-tolerance", "-0.1"],
    ["--min-keep", "1.5"],
    ["--max-errors", "-1"],
]


@pytest.mark.parametrize("argv", BAD_LOAD, ids=[" ".join(a) for a in BAD_LOAD])
def test_a_bad_load_argument_is_one_line_and_status_2(argv, capsys):
    code, err = _run_main(load_cli.main, argv, capsys)
    _assert_one_line(code, err, 2, LOAD)


def _broken(**_: object) -> int:
    raise RuntimeError("the disk caught fire\nsecond line")


def test_a_failure_after_the_arguments_is_one_line_and_status_1(tmp_path, monkeypatch, capsys):
    import poinsot.app.exports.html as html

    monkeypatch.setattr(html, "export_html_command", lambda *a, **k: _broken())
    argv = ["export-html", "--out", str(tmp_path / "x.html")]
    code, err = _run_main(cli.main, argv, capsys)
    _assert_one_line(code, err, 1, "poinsot export-html")
    assert "RuntimeError: the disk caught fire second line" in err and "--debug" in err
    # --debug, before or after the command, shows where it failed
    for debug in (["--debug", *argv], [*argv, "--debug"]):
        code, err = _run_main(cli.main, debug, capsys)
        assert code == 1 and "Traceback" in err and "_broken" in err
        assert err.strip().splitlines()[-1].startswith("poinsot export-html: error: RuntimeError")


def test_the_load_tool_reports_a_failure_in_one_line(monkeypatch, capsys):
    def explode(phases, cfg):
        raise OSError("no more processes")

    monkeypatch.setattr(load_cli, "run", explode)
    code, err = _run_main(load_cli.main, ["--phase", "soak"], capsys)
    _assert_one_line(code, err, 1, LOAD)


@pytest.mark.slow
@pytest.mark.parametrize(
    "argv",
    [
        ["report", "--out", "/proc/x"],
        ["export-html", "--seconds", "-5", "--out", "x.html"],
        ["export-html", "--fps", "0", "--out", "x.html"],
    ],
)
def test_the_installed_command_answers_in_one_line(argv, tmp_path):
    """The console script as a user runs it (a fresh interpreter, the real stderr)."""
    done = subprocess.run(
        [sys.executable, "-m", "poinsot.app", *argv],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=tmp_path,
        env={**os.environ, "PYTHONWARNINGS": "ignore"},
    )
    _assert_one_line(done.returncode, done.stderr, 2, f"poinsot {argv[0]}")
    assert not list(tmp_path.iterdir())
