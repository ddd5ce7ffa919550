"""``poinsot fit`` as a student runs it: on a recording written to disk. The table and a missing
file run in a real process (no traceback there either); the other cases call the command line's
``main`` in this process, with the same arguments, and read what it printed."""

from __future__ import annotations

import json
import subprocess
import sys
import zipfile

import numpy as np
import pytest
from uploading import TOSS_INERTIA, expected_moments, toss_recording

from poinsot.app.cli import main as cli
from poinsot.physics.fit import synthetic_toss


def poinsot(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "poinsot.app.cli", "fit", *args],
        capture_output=True,
        text=True,
        timeout=120,
    )


@pytest.fixture
def in_process(capsys):
    """``poinsot fit ARGS`` through :func:`poinsot.app.cli.main.main` in this process, as a
    finished process: its exit status (argparse's too) and what it printed."""

    def run(*args: str) -> subprocess.CompletedProcess[str]:
        try:
            status = cli.main(["fit", *args])
        except SystemExit as exc:
            status = exc.code if isinstance(exc.code, int) else 1
        out, err = capsys.readouterr()
        return subprocess.CompletedProcess(["poinsot", "fit", *args], status, out, err)

    return run


def one_line_error(done: subprocess.CompletedProcess[str]) -> str:
    assert done.returncode != 0
    assert "Traceback" not in done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    return lines[0]


@pytest.fixture
def recording(tmp_path):
    path = tmp_path / "toss.csv"
    path.write_bytes(toss_recording())
    return path


@pytest.mark.server  # it starts a process of its own
def test_the_table_and_the_json(recording, tmp_path):
    out = tmp_path / "fits.json"
    done = poinsot(str(recording), "--json", str(out))
    assert done.returncode == 0, done.stderr
    assert "1 toss" in done.stdout and "Ix" in done.stdout and "flip (fit)" in done.stdout
    data = json.loads(out.read_text())
    (segment,) = data["segments"]
    for key in ("start", "end", "inertia", "omega0", "rms", "period", "flip_period", "message"):
        assert key in segment, key
    np.testing.assert_allclose(segment["inertia"], expected_moments(), atol=5e-3)
    assert segment["start"] < segment["end"] and segment["rms"] < 0.05
    assert segment["explained"] is True


def test_a_chosen_stretch_of_a_phyphox_zip_in_degrees(tmp_path, in_process):
    t, w = synthetic_toss(TOSS_INERTIA, (0.3, 10.0, 0.3), duration=2.0, seed=3)
    table = np.column_stack([t, np.degrees(w)])
    text = "t,wx,wy,wz\n" + "\n".join(",".join(f"{v:.12g}" for v in row) for row in table)
    archive = tmp_path / "export.zip"
    with zipfile.ZipFile(archive, "w") as z:
        z.writestr("Raw Data.csv", text + "\n")
    out = tmp_path / "fits.json"
    done = in_process(str(archive), "--start", "0.5", "--end", "1.5", "--deg", "--json", str(out))
    assert done.returncode == 0, done.stderr
    (segment,) = json.loads(out.read_text())["segments"]
    assert 0.5 <= segment["start"] < segment["end"] <= 1.5
    np.testing.assert_allclose(segment["inertia"], expected_moments(), atol=2e-2)


def test_rotation_and_bias_are_fitted_on_request(recording, tmp_path, in_process):
    out = tmp_path / "fits.json"
    done = in_process(str(recording), "--rotation", "--bias", "--json", str(out))
    assert done.returncode == 0, done.stderr
    (segment,) = json.loads(out.read_text())["segments"]
    assert len(segment["rotation"]) == 3 and len(segment["bias"]) == 3


@pytest.mark.server  # it starts a process of its own
def test_a_missing_file_is_one_line(tmp_path):
    line = one_line_error(poinsot(str(tmp_path / "nowhere.csv")))
    assert line.startswith("poinsot fit:") and "no such file" in line


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        (["--start", "3", "--end", "2"], "must come before the end"),
        (["--start", "soon"], "'soon' is not a time in seconds"),
        (["--end", "nan"], "'nan' is not a time in seconds"),
    ],
)
def test_bad_values_are_one_line(recording, args, expected, in_process):
    line = one_line_error(in_process(str(recording), *args))
    assert expected in line


def test_a_file_that_is_no_recording_is_one_line(tmp_path, in_process):
    path = tmp_path / "photo.csv"
    path.write_bytes(b"\x89PNG\r\n\x1a\n\x00\x00")
    line = one_line_error(in_process(str(path)))
    assert "is not a text (CSV) file" in line
