"""``poinsot screenshot --strobe N`` in a real browser: the picture shows N copies of the body,
counted in the picture itself (each copy is a blob of the strobe's own colour), left to right
from the faintest, beside the construction with its traces."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import chromium_or_fail, run_command
from PIL import Image
from strobe_counting import copies_in, hue_saturation_value

from poinsot.app.construction import palette

pytestmark = [pytest.mark.browser, pytest.mark.slow]


def strobe_picture(tmp_path, capsys, *options: str) -> np.ndarray:
    chromium_or_fail()
    out = tmp_path / "s.png"
    # A process of its own, as a lecturer runs it (this one may already drive Chromium through
    # playwright's sync API, which allows one per thread).
    done = run_command(["screenshot", "--preset", "t_handle", *options, "--out", str(out)])
    assert done.returncode == 0, done.stderr
    return np.asarray(Image.open(out).convert("RGB"))


def test_a_strobe_of_8_shows_eight_copies_the_earliest_faintest(tmp_path, capsys):
    rgb = strobe_picture(tmp_path, capsys, "--strobe", "8", "--size", "960x540")
    copies = copies_in(rgb)
    assert len(copies) == 8, copies
    brightness = [v for _, v in copies]
    assert brightness[0] == min(brightness) and brightness[-1] > 1.5 * brightness[0], brightness
    # The traces are drawn too: the polhode's pink and the herpolhode's cyan (by hue: they lie
    # on the translucent ellipsoid and plane).
    hue, saturation, value = hue_saturation_value(rgb)
    for colour in (palette.POLHODE, palette.HERPOLHODE):
        want = hue_saturation_value(np.asarray([[colour]], dtype=np.uint8))[0][0, 0]
        near = (np.abs(hue - want) < 12) & (saturation > 0.25) & (value > 0.4)
        assert near.sum() > 200, (colour, near.sum())


def test_a_strobe_over_a_chosen_interval_counts_its_copies(tmp_path, capsys):
    rgb = strobe_picture(
        tmp_path, capsys, "--strobe", "3", "--from", "2", "--to", "6", "--size", "800x450"
    )
    assert len(copies_in(rgb)) == 3
