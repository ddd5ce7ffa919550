"""``poinsot check-engine``: logs that the project makes from each game step and from the exact
solution, each given its verdict; broken files get one line and exit status 2."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from conftest import session_of, wait_until
from test_server import markdown_texts
from uploading import upload

from poinsot.app.cli.main import main
from poinsot.app.live.panel.engine_upload import BUTTON, MOMENTS
from poinsot.app.model.engine_logs import write_engine_log
from poinsot.physics import FreeRigidBody
from poinsot.physics.integrators import integrate

INERTIA = (1.0, 2.2782, 3.1839)
#: The T-handle flicked at 12 rad/s, 0.05 rad from its middle axis: 8 flips in 10 s.
FLICK = 12.0 * np.array([math.sin(0.05), math.cos(0.05), 0.0])
SECONDS = 10.0


def exact_log(path, attitude=True, step=1 / 60):
    t = np.arange(0.0, SECONDS + 1e-9, step)
    omega, rotation = FreeRigidBody(INERTIA, FLICK).state(t)
    write_engine_log(path, t, omega, INERTIA, rotation.as_quat() if attitude else None)
    return path


def game_log(path, method, step):
    t = np.arange(0.0, SECONDS + 1e-9, step)
    run = integrate(method, INERTIA, FLICK, None, t, step)
    write_engine_log(path, t, run.omega, INERTIA, run.attitude.as_quat())
    return path


@pytest.mark.parametrize(
    "method, step, status",
    [
        ("exact", 1 / 60, 0),
        ("rk4", 1 / 60, 0),  # energy drift 4e-5 per minute, the flips on time
        ("no-gyro", 1 / 60, 1),  # never flips; L turns in space
        ("gyro-explicit", 1 / 240, 1),  # gains energy (x5 per minute)
        ("gyro-implicit", 1 / 60, 1),  # loses it
        ("jolt", 1 / 60, 1),  # |L| kept, but 6 flips for 8, late
    ],
)
def test_each_log_gets_its_verdict_and_is_recognised(tmp_path, capsys, method, step, status):
    path = tmp_path / f"{method}.csv"
    if method == "exact":
        exact_log(path, step=step)
    else:
        game_log(path, method, step)
    out = tmp_path / "figures.json"
    assert main(["check-engine", str(path), "--json", str(out)]) == status
    text = capsys.readouterr().out
    figures = json.loads(out.read_text())
    assert figures["free_rigid_body"] is (status == 0)
    assert figures["looks_like"] == method
    assert f"Looks most like: {method}" in text
    assert ("moves as a free rigid body should" in text) is (status == 0)
    if method == "no-gyro":
        assert figures["measured_flips_s"] == [] and len(figures["predicted_flips_s"]) == 8
        assert figures["space_drift"] > 1e-2


def test_the_exact_log_without_attitude_and_with_the_moments_given(tmp_path, capsys):
    path = exact_log(tmp_path / "log.csv", attitude=False)
    text = path.read_text().split("\n", 1)[1]  # drop the '# inertia' comment
    path.write_text(
        text.replace("t,wx,wy,wz", "Time (s); wx (rad/s); wy (rad/s); wz (rad/s)").replace(",", ";")
    )
    assert main(["check-engine", str(path)]) == 2  # no moments
    assert "--inertia" in capsys.readouterr().err
    assert main(["check-engine", str(path), "--inertia", "1,2.2782,3.1839"]) == 0
    out = capsys.readouterr().out
    assert "L stays fixed" not in out and "Stays on one polhode" in out
    # Wrong moments: the log no longer flips when the exact motion would.
    assert main(["check-engine", str(path), "--inertia", "1,2,3.1839"]) == 1


@pytest.mark.parametrize(
    "content, message",
    [
        (b"", "no header"),
        (b"\xff\xfe\x00binary", "not a text file"),
        (b"t,wx,wy\n0,1,2\n", "no column wz"),
        (b"t,wx,wy,wz,qw\n0,1,2,3,1\n", "qw, qx, qy, qz"),
        (b"t,wx,wy,wz\n0,1,2,3\n1,1,2,x\n2,1,1,1\n", "row 3"),
        (b"t,wx,wy,wz\n0,1,2,3\n", "at least 3"),
        (b"t,wx,wy,wz\n0,1,2,3\n0,1,2,3\n1,1,2,3\n", "increase"),
        (b"t,wx,wy,wz\n0,1,nan,3\n1,1,2,3\n2,1,2,3\n", "not finite"),
        (b"# inertia: 1, 0, 2\nt,wx,wy,wz\n0,1,2,3\n1,1,2,3\n2,1,2,3\n", "positive moments"),
    ],
)
def test_a_broken_log_is_one_line_and_exit_2(tmp_path, capsys, content, message):
    path = tmp_path / "broken.csv"
    path.write_bytes(content)
    assert (
        main(
            ["check-engine", str(path), "--inertia", "1,2,3"]
            if b"inertia" not in content
            else ["check-engine", str(path)]
        )
        == 2
    )
    err = capsys.readouterr().err
    assert message in err
    assert err.count("\n") == 1 and "Traceback" not in err


def test_bad_inertia_option_is_exit_2(tmp_path, capsys):
    path = exact_log(tmp_path / "log.csv")
    assert main(["check-engine", str(path), "--inertia", "1,2"]) == 2
    assert "three positive moments" in capsys.readouterr().err
    # Moments 1e20 apart: no body the physics can build, still one line and exit 2.
    assert main(["check-engine", str(path), "--inertia", "1e-200,1,1e200"]) == 2
    err = capsys.readouterr().err
    assert "no free body" in err and err.count("\n") == 1


# -- the same check in the browser: an upload in the ghost's folder --------------------------
def test_an_uploaded_log_gets_its_verdict_in_the_panel(tmp_path, poinsot_app, probe):
    session = session_of(poinsot_app)
    checker = session.ghost.engine_log
    assert probe.wait_for(lambda p: p.has_widget(BUTTON) and p.has_widget(MOMENTS), 10)

    def answer_with(text: str) -> str:
        assert probe.wait_for(lambda p: any(text in m for m in markdown_texts(p)), 20), text
        return next(m for m in markdown_texts(probe) if text in m)

    upload(probe, BUTTON, "exact.csv", exact_log(tmp_path / "exact.csv").read_bytes())
    assert wait_until(lambda: checker.finished >= 1, 30)
    shown = answer_with("exact.csv: moves as a free rigid body should")
    assert "Looks most like: exact" in shown and "Flips when the exact motion does" in shown

    nogyro = game_log(tmp_path / "nogyro.csv", "no-gyro", 1 / 60).read_bytes()
    upload(probe, BUTTON, "nogyro.csv", nogyro)
    assert wait_until(lambda: checker.finished >= 2, 30)
    shown = answer_with("nogyro.csv: does NOT move as a free rigid body should")
    assert "Looks most like: no-gyro" in shown and "measured 0" in shown

    upload(probe, BUTTON, "broken.csv", b"t,wx,wy\n0,1,2\n")
    assert wait_until(lambda: checker.finished >= 3, 30)
    assert "no column wz" in answer_with("⚠ broken.csv")
    assert session.stats.errors == 0, session.stats.last_error
