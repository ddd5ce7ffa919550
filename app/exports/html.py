"""The animation as one standalone HTML page that plays from a file.

A :class:`~poinsot.app.stage.served.Stage` is recorded frame by frame with viser's scene
serializer (``insert_sleep`` between frames, ``as_html``): the viser client and the recording
in one file that plays from ``file://`` with no server.
"""

from __future__ import annotations

import math
import pathlib
import re
import time
from typing import Any

from viser.infra import StateSerializer

from poinsot.app.construction.cameras import space_view
from poinsot.app.construction.view import DEFAULT_VIEW, View
from poinsot.app.lessons.support.spec import SceneSpec
from poinsot.app.model.elements import Element, Solid
from poinsot.app.model.parameters import Parameters
from poinsot.app.model.presets import Preset
from poinsot.app.stage.scene_stage import SceneStage
from poinsot.app.stage.served import Stage

#: Frames per second of the recorded animation: smooth, and half the bytes of 60.
HTML_FPS = 30.0
#: Longest clip [s]. The page is viser's client (0.82 MB) plus the recording: a 20 s clip at
#: 30 fps adds ~0.12 MB (0.94 MB in all), about 6 kB per second.
HTML_MAX_SECONDS = 600.0


def animation_html(
    params: Parameters,
    solid: Solid | None,
    elements: frozenset[Element],
    *,
    seconds: float,
    speed: float = 1.0,
    fps: float = HTML_FPS,
    trail_points: int = 1200,
    view: View = DEFAULT_VIEW,
    dark_mode: bool = True,
    title: str = "Poinsot",
) -> str:
    """A standalone HTML page that plays ``seconds`` of the motion (``speed`` simulation time
    units per second), looping, in any browser, from a file."""
    _check_clip(seconds, fps)
    with Stage(params, solid, elements, trail_points=trail_points, dark_mode=dark_mode) as stage:
        return _record(stage, seconds, fps, speed, view, dark_mode, title)


def _check_clip(seconds: float, fps: float) -> None:
    if not (math.isfinite(seconds) and 0 < seconds <= HTML_MAX_SECONDS):
        raise ValueError(f"the clip length must be in (0, {HTML_MAX_SECONDS:g}] seconds")
    if not (math.isfinite(fps) and 1 <= fps <= 60):
        raise ValueError("the frame rate must be between 1 and 60 per second")


def _record(
    stage: Stage | SceneStage,
    seconds: float,
    fps: float,
    speed: float,
    view: View,
    dark_mode: bool,
    title: str,
) -> str:
    """Record ``seconds`` of a stage, frame by frame, as a page that plays from a file."""
    html = record(stage, seconds, fps, speed, view).as_html(dark_mode=dark_mode)
    safe_title = re.sub(r"[<>&\"]", "", title)
    return html.replace("<title>Viser</title>", f"<title>{safe_title}</title>", 1)


def record(
    stage: Stage | SceneStage, seconds: float, fps: float, speed: float, view: View
) -> StateSerializer:
    """``seconds`` of a stage recorded frame by frame (``speed`` simulation time units per
    second) by viser's scene serializer: its ``as_html()`` is a page, its ``show()`` the viewer
    inline in a notebook."""
    _check_clip(seconds, fps)
    stage.set_initial_camera(view)
    serializer = stage.server.get_scene_serializer()  # snapshot: the scene at t = 0
    frames = round(seconds * fps)
    for i in range(1, frames + 1):
        serializer.insert_sleep(1.0 / fps)
        stage.advance(i / fps * speed)
    return serializer


def scene_html(
    spec: SceneSpec,
    seconds: float,
    *,
    fps: float = HTML_FPS,
    view: View | None = None,
    dark_mode: bool = True,
) -> str:
    """:func:`animation_html` of a scene (:mod:`poinsot.app.lessons`) at its own settings,
    speed and camera (``view`` overrides the camera)."""
    _check_clip(seconds, fps)
    with SceneStage(spec, dark_mode=dark_mode) as stage:
        camera = spec.view if view is None else view
        title = f"Poinsot: {spec.label}"
        return _record(stage, seconds, fps, spec.initial_speed(), camera, dark_mode, title)


def preset_html(preset: Preset, seconds: float, **kwargs: Any) -> str:
    """:func:`animation_html` of a preset, at its speed and trail length."""
    kwargs.setdefault("speed", preset.speed)
    kwargs.setdefault("trail_points", preset.trail_points)
    kwargs.setdefault("title", f"Poinsot: {preset.label}")
    return animation_html(
        Parameters.from_preset(preset), preset.solid, preset.elements, seconds=seconds, **kwargs
    )


def export_html_command(
    out: pathlib.Path,
    preset: Preset | SceneSpec,
    *,
    seconds: float = 20.0,
    fps: float = HTML_FPS,
    view: str = "default",
    light: bool = False,
) -> int:
    """``poinsot export-html``: write the clip, print where and how big."""
    start = time.perf_counter()
    if isinstance(preset, SceneSpec):  # a scene frames itself unless another view is asked
        camera = None if view == "default" else space_view(view)
        html = scene_html(preset, seconds, fps=fps, view=camera, dark_mode=not light)
    else:
        html = preset_html(preset, seconds, fps=fps, view=space_view(view), dark_mode=not light)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(html, encoding="utf-8")
    size = out.stat().st_size
    print(
        f"wrote {out} ({size / 1e6:.2f} MB, {seconds:g} s at {fps:g} fps, "
        f"{'scene' if isinstance(preset, SceneSpec) else 'preset'} {preset.key}) in "
        f"{time.perf_counter() - start:.1f} s"
    )
    return 0
