"""The video's pieces without a browser: the encoder (imageio-ffmpeg's bundled ffmpeg) writes
the frames it is given, H.264 yuv420p for MP4 and a looping GIF, read back by imageio and
Pillow; a render is laid on the theme's background, and renders reach the encoder in order on
its own thread (a failure there is raised); the clip's bounds (command line and
browser); a browser view's size brought within the browser's bound."""

from __future__ import annotations

import imageio.v2 as imageio
import numpy as np
import pytest
from PIL import Image

from poinsot.app.exports.video import Clip, check_clip, encoder, one_behind, rgb_on
from poinsot.app.live.lecture.video_export import fit_within


def frames(count: int, size: tuple[int, int]) -> list[np.ndarray]:
    """A bright square moving one step a frame on a dark ground."""
    width, height = size
    out = []
    for i in range(count):
        frame = np.full((height, width, 3), 20, np.uint8)
        frame[8:24, 4 + 2 * i : 20 + 2 * i] = (255, 179, 71)
        out.append(frame)
    return out


@pytest.mark.parametrize("suffix", [".mp4", ".gif"])
def test_the_encoder_writes_every_frame_it_is_given(tmp_path, suffix):
    path = tmp_path / f"clip{suffix}"
    given = frames(12, (64, 36))
    with encoder(path, (64, 36), 12.0) as sink:
        for frame in given:
            sink.send(frame)
    if suffix == ".mp4":
        reader = imageio.get_reader(path, format="FFMPEG")
        meta = reader.get_meta_data()
        read = np.stack([frame for frame in reader])
        reader.close()
        assert meta["codec"] == "h264" and meta["pix_fmt"].startswith("yuv420p"), meta
    else:
        with Image.open(path) as image:
            assert image.info.get("loop") == 0 and image.n_frames == 12
        read = np.asarray(imageio.mimread(path))[..., :3]
    assert read.shape == (12, 36, 64, 3)
    # The square is where it was put in each frame (lossy: compare its centre's colour).
    for i, frame in enumerate(read):
        assert np.abs(frame[16, 12 + 2 * i].astype(int) - (255, 179, 71)).max() < 40, i
        assert np.abs(frame[30, 60].astype(int) - 20).max() < 12


def test_a_render_is_laid_on_the_background():
    rgba = np.zeros((2, 2, 4), np.uint8)
    rgba[0, 0] = (200, 100, 50, 255)  # opaque
    rgba[0, 1] = (200, 100, 50, 0)  # nothing drawn
    rgba[1, 0] = (200, 100, 50, 128)  # half
    rgb = rgb_on(rgba, (20, 20, 20))
    assert rgb[0, 0].tolist() == [200, 100, 50] and rgb[0, 1].tolist() == [20, 20, 20]
    assert rgb[1, 0].tolist() == [110, 60, 35]


def test_renders_reach_each_encoder_in_order_laid_on_the_background():
    got: list[np.ndarray] = []
    also: list[np.ndarray] = []

    def sink(into: list[np.ndarray]):
        while True:
            into.append((yield))

    frames_in, more_in = sink(got), sink(also)
    frames_in.send(None)
    more_in.send(None)
    renders = [np.full((2, 3, 4), (10 * i, 0, 0, 255), np.uint8) for i in range(6)]
    renders[5][..., 3] = 0  # nothing drawn: the background
    with one_behind([frames_in, more_in], (20, 20, 20)) as put:
        for rgba in renders:
            put(rgba)
    assert [frame[0, 0].tolist() for frame in got] == [
        [0, 0, 0],
        [10, 0, 0],
        [20, 0, 0],
        [30, 0, 0],
        [40, 0, 0],
        [20, 20, 20],
    ]
    assert all(frame.shape == (2, 3, 3) for frame in got)
    assert [frame.tolist() for frame in also] == [frame.tolist() for frame in got]


def test_an_encoder_failure_is_raised_by_the_next_frame():
    def broken():
        yield
        raise OSError("the encoder is gone")

    frames_in = broken()
    frames_in.send(None)
    rgba = np.zeros((2, 2, 4), np.uint8)
    with pytest.raises(OSError, match="gone"), one_behind([frames_in], (0, 0, 0)) as put:
        put(rgba)
        put(rgba)


def test_the_clip_s_bounds():
    check_clip(Clip(4.0, 25.0, (640, 360)), ".mp4")
    check_clip(Clip(4.0, 25.0, (641, 361)), ".gif")  # a GIF may have odd sides
    check_clip(Clip(600.0, 60.0, (3840, 2160)), ".mp4")
    bad = [
        (Clip(4.0, 25.0, (641, 360)), ".mp4", False),
        (Clip(4.0, 25.0, (640, 360)), ".avi", False),
        (Clip(0.0, 25.0, (640, 360)), ".mp4", False),
        (Clip(4.0, 0.5, (640, 360)), ".mp4", False),
        (Clip(4.0, 25.0, (640, 360), t0=-1.0), ".mp4", False),
        (Clip(31.0, 25.0, (640, 360)), ".mp4", True),  # the browser: 30 s
        (Clip(4.0, 25.0, (2560, 1440)), ".mp4", True),  # the browser: 1920x1080
    ]
    for clip, suffix, browser in bad:
        with pytest.raises(ValueError):
            check_clip(clip, suffix, browser=browser)
    assert Clip(4.0, 25.0, (640, 360)).frames == 100
    assert Clip(2.0, 10.0, (64, 64), t0=3.0, speed=0.5).time(4) == pytest.approx(3.2)


def test_a_browser_view_is_brought_within_1920x1080_with_even_sides():
    assert fit_within((1281, 721), (1920, 1080), even=True) == (1280, 720)
    assert fit_within((1281, 721), (1920, 1080), even=False) == (1281, 721)
    assert fit_within((3840, 2000), (1920, 1080), even=True) == (1920, 1000)
    width, height = fit_within((2560, 1600), (1920, 1080), even=True)
    assert width <= 1920 and height <= 1080 and width % 2 == 0 and height % 2 == 0
    assert abs(width / height - 1.6) < 0.01


def test_the_browser_s_progress_shows_the_first_frame_then_every_twentieth():
    """A 30 s clip at 25 fps (750 frames): the bar and the message move after the first frame
    (software WebGL takes seconds per frame of a slide's size), then every 37 frames, and at
    the last; and a browser that has left cancels the clip."""
    import threading
    from types import SimpleNamespace

    from poinsot.app.live.lecture.video_export import VideoExport

    said: list[str] = []
    bars: list[float] = []
    session = SimpleNamespace(running=True)
    export = SimpleNamespace(
        lecture=SimpleNamespace(session=session),
        cancel=threading.Event(),
        _set_progress=bars.append,
    )
    progress = VideoExport._progress(export, said.append, 750)  # type: ignore[arg-type]
    for done in range(1, 751):
        progress(done, 750)
    shown = [int(text.split()[4]) for text in said]
    assert shown == [1, *range(37, 741, 37), 750]
    assert bars[0] == pytest.approx(100 / 750) and bars[-1] == 100.0
    assert not export.cancel.is_set()
    session.running = False  # the browser has left
    progress(2, 750)
    assert export.cancel.is_set()
