"""The phone's and tablet's page (app/live/lecture/layout.py): who gets it, and the camera that
frames the whole construction for the screen's shape (app/construction/cameras.framed)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import session_of, wait_until

from poinsot.app.construction.cameras import (
    body_and_traces,
    construction_points,
    framed,
    framed_above,
    sphere_points,
)
from poinsot.app.construction.view import DEFAULT_VIEW, View
from poinsot.app.lessons import scene_by_name
from poinsot.app.live.lecture.display import Style, column_widths, scene_look
from poinsot.app.live.lecture.layout import compact_aspect, header_text, touch_agent
from poinsot.app.model.presets import DEFAULT_PRESET


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


def test_a_phone_s_view_frames_the_body_and_its_traces_above_the_sheet() -> None:
    """390 x 844, a 56 px bar at the bottom: the body, the herpolhode's ring and L's tip fill
    the part above the bar (to its margin), and none of them is under it."""
    width, height, bar = 390.0, 844.0, 56.0
    points = body_and_traces(0.8, 1.2, 1.45)
    view = framed_above(DEFAULT_VIEW, width, height, bar, points)
    tx, ty = _projected(view, points)
    half = math.tan(math.radians(view.fov_degrees) / 2.0)
    # Screen pixels, y down, of every point.
    x = width / 2 + tx / half * height / 2
    y = height / 2 - ty / half * height / 2
    assert x.min() >= 0 and x.max() <= width
    assert y.min() >= 0 and y.max() <= height - bar
    # Filling it: across, the tightest edge at the margin (the body no longer 50 px wide).
    assert (x.max() - x.min()) >= 0.9 * width
    # Not the plane's whole disc: its rim is out of frame.
    rim = construction_points(0.8, 1.75, 1.45)
    rx, _ = _projected(view, rim)
    assert np.max(np.abs(rx)) > half * width / height


def test_large_text_widens_the_columns_and_the_labels_with_it() -> None:
    normal, large, projector = Style(), Style(large_text=True), Style(projector=True)
    assert column_widths(normal) == (300, 320)
    left, main = column_widths(large)
    assert left >= 1.3 * 300 and main >= 1.3 * 320
    assert scene_look(large).label_scale == pytest.approx(1.3 * scene_look(normal).label_scale)
    # The projector's left column: a compact legend, no wider than large text's.
    assert column_widths(projector)[0] <= 1.5 * 300


def test_the_sheet_s_header_gives_t_and_the_regime_when_shown() -> None:
    assert header_text(13.62, "polhode around the major axis") == (
        "t = 13.6 · polhode around the major axis"
    )
    assert header_text(0.0, "") == "t = 0.0"


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


def _shown_view(camera) -> View:
    return View(
        position=tuple(camera.position),
        look_at=tuple(camera.look_at),
        up=tuple(camera.up_direction),
        fov_degrees=math.degrees(camera.fov),
    )


def _direction(view: View) -> np.ndarray:
    d = np.subtract(view.look_at, view.position)
    return d / np.linalg.norm(d)


def _in_frame(view: View, points: np.ndarray, aspect: float) -> bool:
    tx, ty = _projected(view, points)
    half = math.tan(math.radians(view.fov_degrees) / 2.0)
    return bool(np.all(np.abs(ty) <= half + 1e-9) and np.all(np.abs(tx) <= half * aspect + 1e-9))


@pytest.mark.parametrize("name", ["polhode-family", "explorer-1"])
def test_a_phone_that_chooses_a_scene_sees_the_picture_drawn_beside_it(make_app, make_probe, name):
    """A phone held upright (390 x 844) that chooses a scene drawing a picture beside the
    construction (Landau's sphere, the momentum sphere) gets the camera framed anew, from the
    scene's own direction, with that picture in frame (the desktop's view left it off screen);
    back on a preset, the default direction, framed again."""
    spec = scene_by_name(name)
    assert spec.beside
    app = make_app()
    probe = make_probe(app, size=(390, 844))
    session = session_of(app)
    layout = session.layout
    assert layout is not None
    assert wait_until(lambda: layout.compact and layout.framings >= 1, 20)
    framings, aspect = layout.framings, 390 / 844
    desktop = [sphere_points(c, r) for c, r in spec.beside]
    assert not all(_in_frame(spec.view, p, aspect) for p in desktop)  # what it fixes
    # The session frames the camera on its thread; the panel may not have reached the probe.
    assert probe.wait_for(lambda p: p.has_widget("Preset"), 20)
    probe.set_value(probe.widget("Preset")[0], spec.identity().label)
    assert wait_until(lambda: session.showcase is not None and layout.framings > framings, 20)
    view = _shown_view(session.client.camera)
    assert np.allclose(_direction(view), _direction(spec.view), atol=1e-9)
    for points in desktop:
        assert _in_frame(view, points, aspect), spec.beside
    geometry = session.scene.geometry
    h = geometry.plane_height
    assert _in_frame(view, body_and_traces(h, geometry.herpolhode_radius, h + 0.65), aspect)
    framings = layout.framings
    probe.set_value(probe.widget("Preset")[0], DEFAULT_PRESET.label)
    assert wait_until(lambda: session.showcase is None and layout.framings > framings, 20)
    assert np.allclose(_direction(_shown_view(session.client.camera)), _direction(DEFAULT_VIEW))
