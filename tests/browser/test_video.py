"""``poinsot video`` in a real browser (Debian's Chromium, software WebGL): the MP4 and the GIF
of one run (``--out clip.mp4 clip.gif``: the frames rendered once, encoded into each) decode
(imageio, through the ffmpeg of imageio-ffmpeg) to the frames asked for, of the size
asked for, each different from the one before (every frame shows its own time); the MP4 is
H.264 in yuv420p, the GIF loops."""

from __future__ import annotations

from pathlib import Path

import imageio.v2 as imageio
import imageio.v3 as iio
import numpy as np
import pytest
from conftest import chromium_or_fail, run_command
from PIL import Image

from poinsot.app.exports.screenshot import THEME_BACKGROUND

pytestmark = [pytest.mark.browser, pytest.mark.slow]

#: Mean absolute change between two successive frames [0-255] above which they count as
#: different: the rolling body moves every frame (measured 1.0-3.3 at 640x360, 25 fps), while
#: a frame rendered again unchanged differs by the encoder's noise only.
MIN_CHANGE = 0.3


@pytest.fixture(scope="module")
def filmed(tmp_path_factory) -> dict[str, Path]:
    """ONE ``poinsot video`` run that writes both files: the frames are rendered once and
    encoded into each (by suffix: the MP4 and the GIF)."""
    chromium_or_fail()
    folder = tmp_path_factory.mktemp("video")
    outs = {suffix: folder / f"v{suffix}" for suffix in (".mp4", ".gif")}
    argv = ["video", "--preset", "t_handle", "--seconds", "2", "--fps", "25"]
    # A process of its own, as a lecturer runs it (this one may already drive Chromium through
    # playwright's sync API, which allows one per thread).
    done = run_command([*argv, "--size", "640x360", "--out", *map(str, outs.values())])
    assert done.returncode == 0, done.stderr
    for out in outs.values():
        assert f"wrote {out} (640x360, 50 frames at 25 fps" in done.stdout, done.stdout
    assert "50/50 frames" in done.stderr  # the progress (plain lines: not a terminal)
    return outs


def assert_a_moving_scene(frames: np.ndarray) -> None:
    assert frames.shape[:3] == (50, 360, 640), frames.shape
    rgb = frames[..., :3]
    changes = np.array(
        [np.abs(b.astype(np.int16) - a).mean() for a, b in zip(rgb[:-1], rgb[1:], strict=True)]
    )
    assert changes.min() > MIN_CHANGE, np.flatnonzero(changes <= MIN_CHANGE)
    # Opaque on the dark theme, something drawn in the middle.
    corner = rgb[:, :4, :4].reshape(-1, 3).astype(np.int16)
    assert np.abs(corner - THEME_BACKGROUND[True]).max() <= 6
    drawn = np.abs(rgb[0].astype(np.int16) - THEME_BACKGROUND[True]).max(axis=2) > 24
    assert 0.1 < drawn.mean() < 0.9, drawn.mean()


def test_the_mp4_decodes_to_50_frames_of_640x360_that_change(filmed):
    out = filmed[".mp4"]
    reader = imageio.get_reader(out, format="FFMPEG")
    meta = reader.get_meta_data()
    # (not list(reader): its length is "inf" until read, and list() would preallocate it)
    frames = np.stack([frame for frame in reader])
    reader.close()
    assert meta["codec"] == "h264" and meta["pix_fmt"].startswith("yuv420p"), meta
    assert meta["fps"] == 25.0
    assert_a_moving_scene(frames)


def test_the_gif_decodes_to_50_frames_of_640x360_that_change_and_loops(filmed):
    out = filmed[".gif"]
    with Image.open(out) as image:
        assert image.info.get("loop") == 0  # forever
        assert image.info.get("duration") == 40  # 25 frames per second
    frames = iio.imread(out, index=None)
    assert_a_moving_scene(frames)
