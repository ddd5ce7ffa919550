"""The lecture folder's "Video" button in a real browser: it hands down an MP4 of the current
scene from the current time, at the 3D view's size (even sides), that decodes to the frames
asked for, each different from the one before; while a clip is filmed the session keeps drawing
frames (the clip has a thread of its own), the progress shows in the panel, and "Cancel video"
stops it with no file handed down and the next clip free to start. The "Strobe: 8 copies" toggle
makes the screenshot button's picture a strobe: eight copies, counted in the picture."""

from __future__ import annotations

import re

import imageio.v2 as imageio
import numpy as np
import pytest
from conftest import chromium_or_fail, lecture_of, session_of, wait_until
from PIL import Image
from strobe_counting import copies_in

from poinsot.app.exports.video import BROWSER_MAX_SIZE, DEFAULT_FPS
from poinsot.app.live.lecture.video_export import fit_within
from poinsot.app.model.presets import preset_by_key

pytestmark = [pytest.mark.browser, pytest.mark.slow]


def started(app):
    session = session_of(app)
    assert wait_until(lambda: session.stats.frames >= 10, 20), "the scene is not animating"
    return session


def test_the_video_button_downloads_an_mp4_of_the_current_view(poinsot_app, open_page, tmp_path):
    chromium_or_fail()
    page = open_page(poinsot_app.url, width=960, height=540, live_view=False)
    session = started(poinsot_app)
    lecture = lecture_of(session)
    page.press_slider("Video length [s]", "Home")  # 1 s
    assert wait_until(lambda: lecture.video.seconds.value == 1, 30)
    page.choose("Picture size", "current view")  # the slide's 1920x1080 unless chosen
    assert wait_until(lambda: lecture.size.value == "current view", 10)
    t_before = session.clock.now()
    with page.page.expect_download(timeout=300_000) as info:
        page.click_button("Video")
        # The clip has its own thread: the session keeps drawing while it is filmed.
        frames = session.stats.frames
        assert wait_until(lambda: session.stats.frames > frames + 10, 30)
    download = info.value
    name = download.suggested_filename
    assert re.fullmatch(r"poinsot_major_t\d+\.\d\d\.mp4", name), name
    assert float(name[len("poinsot_major_t") : -4]) >= round(t_before, 2) - 0.01
    path = tmp_path / name
    download.save_as(path)
    reader = imageio.get_reader(path, format="FFMPEG")
    meta = reader.get_meta_data()
    frames_read = np.stack([frame for frame in reader])
    reader.close()
    camera = session.client.camera
    width, height = fit_within((camera.image_width, camera.image_height), BROWSER_MAX_SIZE, True)
    assert meta["codec"] == "h264" and meta["pix_fmt"].startswith("yuv420p"), meta
    assert frames_read.shape == (round(DEFAULT_FPS), height, width, 3), frames_read.shape
    changes = [
        np.abs(b.astype(np.int16) - a).mean()
        for a, b in zip(frames_read[:-1], frames_read[1:], strict=True)
    ]
    assert min(changes) > 0.1, changes
    assert wait_until(lambda: name in lecture.message.content, 10), lecture.message.content
    assert lecture.video.last_file == name and page.errors == []


def test_a_video_can_be_cancelled_and_the_next_one_starts(poinsot_app, open_page):
    chromium_or_fail()
    page = open_page(poinsot_app.url, width=960, height=540, live_view=False)
    session = started(poinsot_app)
    lecture = lecture_of(session)
    video = lecture.video
    downloads: list[object] = []
    page.page.on("download", lambda download: downloads.append(download))
    page.press_slider("Video length [s]", "End")  # 30 s: it will not end by itself soon
    assert wait_until(lambda: video.seconds.value == 30, 30)
    # The 3D view's size, not a slide's: software WebGL draws its frames several times faster.
    page.choose("Picture size", "current view")
    assert wait_until(lambda: lecture.size.value == "current view", 30)
    page.click_button("Video")
    assert wait_until(lambda: video.progress.visible and video.progress.value > 0, 240), (
        lecture.message.content
    )
    # The progress bar moves just before the message names the frame: wait for it.
    assert wait_until(lambda: "frame" in lecture.message.content, 30), lecture.message.content
    page.click_button("Cancel video")
    assert wait_until(lambda: video.thread is not None and not video.thread.is_alive(), 60)
    assert lecture.message.content == "Video cancelled."
    assert not video.progress.visible and not video.button.disabled
    assert downloads == []
    # The next clip is free to start (the one-at-a-time slot was released).
    assert video.start()
    video.cancel.set()
    assert wait_until(lambda: not video.thread.is_alive(), 120)
    assert page.errors == []


def test_the_strobe_toggle_adds_eight_copies_to_the_screenshot(make_app, open_page):
    chromium_or_fail()
    app = make_app(preset_by_key("t_handle"))
    page = open_page(app.url, width=960, height=540, live_view=False)
    session = started(app)
    lecture = lecture_of(session)
    assert wait_until(lambda: session.clock.now() > 2.0, 60)
    page.choose("Picture size", "1920×1080")  # the 3D view here is narrow: copies of 40 px
    page.set_checkbox("Strobe: 8 copies", True)
    assert wait_until(lambda: lecture.strobe.value and lecture.size.value == "1920×1080", 30)
    copies = copies_in(screenshot_rgb(page))
    assert len(copies) == 8, copies
    brightness = [v for _, v in copies]
    assert brightness[0] == min(brightness), brightness
    # The copies were there for that picture only: without the toggle, none.
    page.set_checkbox("Strobe: 8 copies", False)
    assert wait_until(lambda: not lecture.strobe.value, 30)
    assert copies_in(screenshot_rgb(page)) == []
    assert page.errors == []


def screenshot_rgb(page) -> np.ndarray:
    with page.page.expect_download(timeout=120_000) as info:
        page.click_button("Screenshot (PNG)")
    return np.asarray(Image.open(info.value.path()).convert("RGB"))
