"""``poinsot screenshot --strobe N`` in a real browser: the picture shows N copies of the body,
counted in the picture itself (each copy is a blob of the strobe's own colour), left to right
from the faintest, beside the construction with its traces."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import chromium_or_fail
from PIL import Image
from scipy import ndimage

from poinsot.app import cli
from poinsot.app.scene import palette

pytestmark = [pytest.mark.browser, pytest.mark.slow]

#: A copy is a blob of at least this fraction of the largest one (all copies are the same mesh
#: at the same scale; what else takes the strobe's hue, where the green axis 2 shows through
#: the amber ellipsoid, is a few specks: measured 80 px against 665-1048 px per copy at
#: 960x540).
MIN_COPY_FRACTION = 0.25


def hue_saturation_value(rgb: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    px = rgb.astype(np.float64) / 255.0
    hi, lo = px.max(axis=2), px.min(axis=2)
    chroma = hi - lo
    r, g, b = px[..., 0], px[..., 1], px[..., 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        hue = 60.0 * np.where(
            hi == r,
            ((g - b) / chroma) % 6,
            np.where(hi == g, (b - r) / chroma + 2, (r - g) / chroma + 4),
        )
        saturation = np.where(hi > 0, chroma / hi, 0.0)
    return np.where(chroma > 0, hue, -1.0), saturation, hi


def copies_in(rgb: np.ndarray) -> list[tuple[float, float]]:
    """The copies in a strobe picture: (x of the centre, mean brightness), left to right."""
    hue, saturation, value = hue_saturation_value(rgb)
    strobe = (hue > 70) & (hue < 95) & (saturation > 0.3) & (value > 0.15)
    blobs, count = ndimage.label(ndimage.binary_closing(strobe, iterations=3))
    index = np.arange(1, count + 1)
    sizes = ndimage.sum(strobe, blobs, index)
    keep = index[sizes >= MIN_COPY_FRACTION * sizes.max()] if count else index
    centres = ndimage.center_of_mass(strobe, blobs, keep)
    brightness = ndimage.mean(value, blobs, keep)
    return sorted((float(c[1]), float(v)) for c, v in zip(centres, brightness, strict=True))


def strobe_picture(tmp_path, capsys, *options: str) -> np.ndarray:
    chromium_or_fail()
    out = tmp_path / "s.png"
    code = cli.main(["screenshot", "--preset", "t_handle", *options, "--out", str(out)])
    captured = capsys.readouterr()
    assert code == 0, captured.err
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
