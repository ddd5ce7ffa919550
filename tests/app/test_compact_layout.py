"""The phone's and tablet's page (app/live/ui/layout.py): who gets it, and the camera that frames
the whole construction for the screen's shape (app/scene/cameras.framed)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from poinsot.app.live.ui.layout import compact_aspect, touch_agent
from poinsot.app.scene.cameras import construction_points, framed
from poinsot.app.scene.view import DEFAULT_VIEW


def _projected(view, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each point's horizontal and vertical angle off the view's axis, as tangents."""
    forward = np.subtract(view.look_at, view.position)
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, view.up)
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    q = points - np.asarray(view.position)
    depth = q @ forward
    return (q @ right) / depth, (q @ up) / depth


@pytest.mark.parametrize("aspect", [390 / 844, 844 / 390, 820 / 1180, 1.6, 3.0])
def test_the_framed_view_holds_the_whole_construction_and_no_more(aspect: float) -> None:
    points = construction_points(0.8, 1.75, 1.45)
    view = framed(DEFAULT_VIEW, aspect, points, margin=0.05)
    tx, ty = _projected(view, points)
    half = math.tan(math.radians(view.fov_degrees) / 2.0)
    assert np.all(np.abs(ty) <= half * 0.95 + 1e-9)
    assert np.all(np.abs(tx) <= half * aspect * 0.95 + 1e-9)
    # Tight: some point touches the margin across or up and down.
    tightest = max(np.max(np.abs(tx)) / (half * aspect), np.max(np.abs(ty)) / half)
    assert tightest == pytest.approx(0.95, abs=1e-6)
    # The same direction as the default view.
    d0 = np.subtract(DEFAULT_VIEW.look_at, DEFAULT_VIEW.position)
    d1 = np.subtract(view.look_at, view.position)
    assert np.allclose(d0 / np.linalg.norm(d0), d1 / np.linalg.norm(d1))


def test_phones_and_tablets_and_odd_shapes_are_compact_desktops_are_not() -> None:
    assert touch_agent("Mozilla/5.0 (iPhone; CPU iPhone OS 17_0 like Mac OS X) Mobile/15E148")
    assert touch_agent("Mozilla/5.0 (Linux; Android 13; SM-X700) AppleWebKit/537.36")
    assert not touch_agent("Mozilla/5.0 (X11; Linux x86_64) HeadlessChrome/120.0 Safari/537.36")
    assert not touch_agent("")
    # The canvas between a desktop's two docked columns: 1280x800, 960x540, 1920x1080.
    for width, height in ((652, 800), (332, 540), (1292, 1080), (1280, 800)):
        assert not compact_aspect(width, height)
    assert compact_aspect(390, 844) and compact_aspect(844, 390)
    assert not compact_aspect(0, 800)
