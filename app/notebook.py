"""The rolling ellipsoid inline in a Jupyter notebook: ``from poinsot.app.notebook import show``.

>>> show(preset="t_handle", seconds=20)                  # doctest: +SKIP
>>> show(scene="dzhanibekov", epsilon=1e-8)              # doctest: +SKIP
>>> show(body=FreeRigidBody((1, 2, 3), (0.1, 1, 0.2)))   # doctest: +SKIP

The clip is recorded as the standalone HTML page is (:func:`poinsot.app.exports.html.record`:
the app's own construction, frame by frame, through viser's public scene serializer) and shown
by the serializer's ``show()``: the viewer plays, loops and can be scrubbed, with no server.
The caption and the legend (what each colour is) are shown above it. Install with ``pip
install poinsot[notebook]`` (IPython's kernel).
"""

from __future__ import annotations

import dataclasses
import html
import math
from typing import Any

from viser.infra import StateSerializer

from poinsot.app.construction import palette
from poinsot.app.construction.cameras import RIDE_ALONG, canonical, space_view
from poinsot.app.exports.html import HTML_FPS, record
from poinsot.app.lessons import scene_by_name
from poinsot.app.lessons.support.spec import SceneSpec
from poinsot.app.live.panel.legend import caption, entries, legend_html
from poinsot.app.model.elements import ALL_ELEMENTS
from poinsot.app.model.parameters import Parameters, drawn_solid
from poinsot.app.model.presets import CUSTOM, DEFAULT_PRESET, PRESETS, Preset
from poinsot.app.stage.scene_stage import SceneStage
from poinsot.app.stage.served import Stage
from poinsot.physics import FreeRigidBody

#: Height of the inline viewer [CSS pixels].
HEIGHT = 560


def _preset(name: str) -> Preset:
    for preset in PRESETS:
        if preset.key == name:
            return preset
    raise ValueError(f"no preset named {name!r}; choose from {', '.join(p.key for p in PRESETS)}")


def _body_preset(body: FreeRigidBody) -> Preset:
    """A body of one's own as the app draws it: same moments and ω₀, L along +z."""
    if not isinstance(body, FreeRigidBody):
        raise ValueError(f"body must be a FreeRigidBody, not {type(body).__name__}")
    inertia = tuple(float(i) for i in body.inertia)
    omega0 = tuple(float(w) for w in body.omega0)
    params = Parameters(inertia, float(body.D), 1, math.hypot(*omega0), omega0)  # type: ignore[arg-type]
    solid = drawn_solid(params.inertia, CUSTOM, CUSTOM.inertia)
    return dataclasses.replace(
        CUSTOM,
        inertia=params.inertia,
        D=params.D,
        omega_norm=params.omega_norm,
        omega0=params.omega0,
        solid=solid,
    )


def _scene(name: str, settings: dict[str, Any]) -> tuple[SceneSpec, dict[str, Any]]:
    try:
        spec = scene_by_name(name)
    except KeyError as exc:
        raise ValueError(exc.args[0]) from None
    keys = {c.key for c in spec.controls}
    unknown = sorted(set(settings) - keys)
    if unknown:
        raise ValueError(
            f"the scene {spec.name} has no setting {', '.join(unknown)} "
            f"(its settings: {', '.join(sorted(keys)) or 'none'})"
        )
    return spec, {**spec.defaults(), **settings}


def clip(
    preset: str | None = None,
    *,
    scene: str | None = None,
    body: FreeRigidBody | None = None,
    seconds: float = 20.0,
    fps: float = HTML_FPS,
    view: str = "default",
    light: bool = False,
    **settings: Any,
) -> tuple[StateSerializer, str]:
    """The recording :func:`show` shows, and the HTML of its caption and legend. Raises
    ValueError for bad arguments."""
    if sum(x is not None for x in (preset, scene, body)) > 1:
        raise ValueError("give one of preset, scene or body")
    if settings and scene is None:
        raise ValueError(f"{', '.join(settings)}: settings belong to a scene (scene=...)")
    try:
        name = canonical(view)
    except ValueError as exc:
        raise ValueError(str(exc)) from None
    if name == RIDE_ALONG:
        raise ValueError("a clip starts from a fixed view, not ride-along")
    dark = not light
    look = palette.look(dark)
    if scene is not None:
        spec, chosen = _scene(scene, settings)
        with SceneStage(spec, chosen, dark_mode=dark) as stage:
            camera = spec.view if view == "default" else space_view(name)
            serializer = record(stage, seconds, fps, spec.initial_speed(), camera)
        legend = legend_html(entries(spec.elements, look))
        text = spec.label
    else:
        chosen_preset = _body_preset(body) if body is not None else _preset(preset or "")
        if preset is None and body is None:
            chosen_preset = DEFAULT_PRESET
        params = Parameters.from_preset(chosen_preset)
        with Stage(
            params,
            chosen_preset.solid,
            chosen_preset.elements,
            trail_points=chosen_preset.trail_points,
            dark_mode=dark,
        ) as pstage:
            serializer = record(pstage, seconds, fps, chosen_preset.speed, space_view(name))
        legend = legend_html(entries(chosen_preset.elements or ALL_ELEMENTS, look))
        text = caption(chosen_preset) if body is None else "A body of your own."
    return serializer, f"<p>{html.escape(text)}</p>{legend}"


def show(
    preset: str | None = None,
    *,
    scene: str | None = None,
    body: FreeRigidBody | None = None,
    seconds: float = 20.0,
    height: int = HEIGHT,
    light: bool = False,
    **options: Any,
) -> None:
    """Show ``seconds`` of a preset (by its key), a scene (by its name, with its settings as
    keywords: ``epsilon=1e-8``) or a body of one's own, playing inline under its legend;
    ``fps`` and ``view`` (default, along-L, side) as :func:`clip`. Raises ValueError for bad
    arguments."""
    if not (isinstance(height, int) and 100 <= height <= 4000):
        raise ValueError("height must be a whole number of pixels in [100, 4000]")
    from IPython.display import HTML, display
    from IPython.utils.capture import capture_output

    with capture_output():  # viser's server banners (rich) are not for the notebook
        serializer, legend = clip(
            preset, scene=scene, body=body, seconds=seconds, light=light, **options
        )

    display(HTML(legend))
    serializer.show(height=height, dark_mode=not light)
