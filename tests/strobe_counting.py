"""Counting the copies of a strobe picture (``poinsot screenshot --strobe``, the screenshot
button's strobe): each copy is a blob of the strobe's own colour."""

from __future__ import annotations

import numpy as np
from scipy import ndimage

#: A copy is a blob of at least this fraction of the largest one (all copies are the same mesh
#: at the same scale; what else takes the strobe's hue, where the green axis 2 shows through
#: the amber ellipsoid, is a few specks: measured 80 px against 665-1048 px per copy at
#: 960x540).
MIN_COPY_FRACTION = 0.25
#: ... and of at least this fraction of the picture (a copy at 960x540: 0.13 % or more; a
#: speck: 0.06 % or less, the longest where axis 2 crosses the ellipsoid), so that a picture
#: without copies counts none.
MIN_COPY_AREA = 8e-4


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
    smallest = max(MIN_COPY_AREA * strobe.size, MIN_COPY_FRACTION * sizes.max(initial=0.0))
    keep = index[sizes >= smallest]
    centres = ndimage.center_of_mass(strobe, blobs, keep)
    brightness = ndimage.mean(value, blobs, keep)
    return sorted((float(c[1]), float(v)) for c, v in zip(centres, brightness, strict=True))
