"""The export commands in a real browser (Debian's Chromium, started by the command itself in
a process of its own): ``poinsot screenshot`` writes a PNG of the requested size with the scene
on it, and leaves no process behind, neither when it finishes nor when it is killed;
``poinsot video`` killed while it films leaves neither a process (Chromium, ffmpeg) nor a
half-written file."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import threading
import time
import uuid
from collections.abc import Callable

import numpy as np
import pytest
from conftest import chromium_or_fail, wait_until
from PIL import Image
from test_exports_page import MIN_AMBER, amber_fraction

from poinsot.app.exports.screenshot import THEME_BACKGROUND

pytestmark = pytest.mark.browser

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


# -- the CLI -----------------------------------------------------------------------------------
def processes_with(token: str) -> dict[int, str]:
    """pid -> command of every live process whose environment carries ``token``."""
    found = {}
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            with open(f"/proc/{pid}/environ", "rb") as f:
                if token.encode() not in f.read():
                    continue
            with open(f"/proc/{pid}/cmdline", "rb") as f:
                found[int(pid)] = f.read().replace(b"\0", b" ").decode(errors="replace")[:120]
        except (FileNotFoundError, ProcessLookupError, PermissionError):
            continue
    return found


class Watch:
    """Polls, while a command runs, for the processes it started (found by an environment
    token every child inherits): proof that a browser really ran."""

    def __init__(self, token: str) -> None:
        self.token = token
        self.seen: dict[int, str] = {}
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.is_set():
            self.seen.update(processes_with(self.token))
            self._stop.wait(0.2)

    def chromium_seen(self) -> bool:
        return any("chromium" in cmd or "chrome" in cmd for cmd in self.seen.values())

    def stop(self) -> None:
        self._stop.set()
        self._thread.join()


def cli(*args: str, token: str) -> subprocess.Popen:
    env = {**os.environ, "POINSOT_TEST_TOKEN": token}
    return subprocess.Popen(
        [sys.executable, "-m", "poinsot.app", *args],
        cwd=ROOT,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def killed_midway(
    proc: subprocess.Popen, token: str, begun: Callable[[], bool] = lambda: True
) -> None:
    """SIGTERM to a command once its Chromium runs and ``begun()`` holds: it exits with an
    error, and no process it started is left."""
    try:
        started = wait_until(
            lambda: any("chrom" in c for c in processes_with(token).values()), 60, poll=0.1
        )
        assert started, "chromium never started"
        assert wait_until(begun, 120, poll=0.1), "the command never began its work"
        proc.send_signal(signal.SIGTERM)
        proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode != 0
    assert wait_until(lambda: not processes_with(token), 15), processes_with(token)


def test_cli_screenshot_writes_the_png_and_leaves_no_process(tmp_path):
    chromium_or_fail()
    out = tmp_path / "shot.png"
    token = f"poinsot-{uuid.uuid4()}"
    watch = Watch(token)
    start = time.monotonic()
    proc = cli(
        "screenshot",
        "--preset",
        "t_handle",
        "--time",
        "6",
        "--size",
        "800x450",
        "--out",
        str(out),
        token=token,
    )
    try:
        stdout, stderr = proc.communicate(timeout=240)
    finally:
        if proc.poll() is None:
            proc.kill()
    elapsed = time.monotonic() - start
    watch.stop()
    assert proc.returncode == 0, stderr
    assert re.search(r"wrote .*shot\.png \(800x450, scene t_handle, t = 6", stdout), stdout
    assert watch.chromium_seen(), watch.seen
    assert wait_until(lambda: not processes_with(token), 10), processes_with(token)
    image = Image.open(out)
    assert image.format == "PNG" and image.size == (800, 450) and image.mode == "RGB"
    rgb = np.asarray(image)
    # Opaque on the dark theme's background, the construction in the middle.
    for corner in (rgb[0, 0], rgb[0, -1], rgb[-1, 0], rgb[-1, -1]):
        assert tuple(corner) == THEME_BACKGROUND[True]
    assert amber_fraction(rgb) > MIN_AMBER
    drawn = np.any(rgb != THEME_BACKGROUND[True], axis=2)
    assert 0.15 < drawn.mean() < 0.9, drawn.mean()  # framed: fills the picture, not the edges
    print(f"CLI screenshot 800x450 in {elapsed:.1f} s")


def test_cli_screenshot_killed_midway_leaves_no_process(tmp_path):
    chromium_or_fail()
    token = f"poinsot-{uuid.uuid4()}"
    proc = cli(
        "screenshot",
        "--preset",
        "major",
        "--size",
        "640x360",
        "--out",
        str(tmp_path / "never.png"),
        token=token,
    )
    killed_midway(proc, token)
    assert not (tmp_path / "never.png").exists()


def test_cli_video_killed_midway_leaves_no_process_and_no_file(tmp_path):
    chromium_or_fail()
    token = f"poinsot-{uuid.uuid4()}"
    out = tmp_path / "never.mp4"
    proc = cli(
        "video",
        "--preset",
        "major",
        "--seconds",
        "30",
        "--size",
        "320x180",
        "--out",
        str(out),
        token=token,
    )
    # Killed while it films: ffmpeg has begun the file.
    killed_midway(proc, token, lambda: out.exists())
    assert not out.exists()  # no half-written video left behind
