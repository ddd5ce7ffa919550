"""Links to the exact state: a page's query names what a browser opens, and "Copy link" writes
the query of what is on screen.

- ``?preset=t_handle&t=12&view=side``: a preset, at simulation time ``t``, seen from a view;
- ``?scene=dzhanibekov&epsilon=1e-8``: a scene, and any of its controls by its key (a slider's
  number, a choice's option or its number);
- ``?I=1,2,2.6&D=2.1&side=major&pole=plus&w=1.2``: a body of one's own (the moments, D, the
  side of the separatrix, the pole, |ω₀|), on top of ``preset`` if one is named;
- with any of them ``speed=0.5`` and ``paused=1``;
- ``?follow=1``: follow the lecturer (:mod:`.lead`), alone or after any of these (a lecturer
  who leads soon after replaces them).

A link with a parameter that is unknown, repeated or out of range opens the server's default
scene with a message naming it (:func:`opening` never raises). viser's own page parameters
(``websocket``, ``darkMode``, ``initialCamera…``, ``fixedDpr``...: :data:`VISER_OWN`) are left
to viser.

How a session learns its page's address: :func:`poinsot.app.viser_private.page_address`.
"""

from __future__ import annotations

import dataclasses
import math
import urllib.parse
from collections.abc import Mapping
from typing import Any, Protocol

from poinsot.app.construction.cameras import CAMERA_NAMES, canonical
from poinsot.app.lessons import scene_by_name, scene_names
from poinsot.app.lessons.support.spec import Choice, SceneControl, SceneSpec, Slider, Value
from poinsot.app.model.parameters import SPEED_RANGE, Parameters
from poinsot.app.model.presets import CUSTOM, DEFAULT_PRESET, PRESETS, Preset

#: Parameters of every link; a scene's control keys come on top.
GENERAL = ("preset", "scene", "t", "view", "speed", "paused", "follow")
#: A body of one's own.
BODY = ("I", "D", "side", "pole", "w")
#: The page parameters viser's client reads itself (prefixes): the server's address, the theme
#: and the first camera, and its display settings (a fixed pixel ratio, the frame-rate
#: panel, the camera's log, the logo, the orbit-origin tool).
VISER_OWN = (
    "websocket",
    "darkMode",
    "initialCamera",
    "fixedDpr",
    "showStats",
    "logCamera",
    "hideViserLogo",
    "forceOrbitOriginTool",
)
#: Latest simulation time a link may ask for [time units].
MAX_TIME = 1e6
_TRUE, _FALSE = ("1", "true", "yes", "on"), ("0", "false", "no", "off", "")


class LinkError(ValueError):
    """A link's parameter that cannot be opened; ``str()`` names it."""


@dataclasses.dataclass(frozen=True)
class Opening:
    """What a new session opens: a preset (or a body of one's own as a preset), or a scene
    whose controls start at the link's values; then the clock, the view and a message."""

    preset: Preset
    scene: SceneSpec | None = None
    t: float | None = None
    view: str | None = None
    speed: float | None = None
    paused: bool = False
    follow: bool = False
    problem: str = ""
    page: str = ""  # the page's address without its query


def _pairs(query: str) -> dict[str, str]:
    pairs: dict[str, str] = {}
    for key, value in urllib.parse.parse_qsl(query.lstrip("?"), keep_blank_values=True):
        if key.startswith(VISER_OWN):
            continue
        if key in pairs:
            raise LinkError(f"{key!r} is given twice")
        pairs[key] = value.strip()
    return pairs


def _number(key: str, text: str, lo: float = -math.inf, hi: float = math.inf) -> float:
    try:
        value = float(text)
    except ValueError:
        raise LinkError(f"{key}={text!r} is not a number") from None
    if not (math.isfinite(value) and lo <= value <= hi):
        raise LinkError(f"{key}={text} is outside [{lo:g}, {hi:g}]")
    return value


def _choice_option(control: Choice, text: str) -> str:
    if text in control.options:
        return text
    if control.values:
        try:
            number = float(text)
        except ValueError:
            number = math.nan
        for option, value in zip(control.options, control.values, strict=True):
            if math.isclose(number, value, rel_tol=1e-9):
                return option
    raise LinkError(f"{control.key}={text!r} is not one of {', '.join(control.options)}")


def _scene(spec: SceneSpec, pairs: Mapping[str, str]) -> SceneSpec:
    """``spec`` with its controls starting at the link's values."""
    by_key = {c.key: c for c in spec.controls}
    unknown = sorted(set(pairs) - set(by_key))
    if unknown:
        names = ", ".join(by_key) or "none"
        raise LinkError(
            f"{', '.join(repr(k) for k in unknown)} is not a parameter of the scene "
            f"{spec.name} (its controls: {names})"
        )
    controls: list[SceneControl] = []
    for control in spec.controls:
        text = pairs.get(control.key)
        if text is None:
            controls.append(control)
        elif isinstance(control, Slider):
            initial = _number(control.key, text, control.lo, control.hi)
            controls.append(dataclasses.replace(control, initial=initial))
        else:
            controls.append(dataclasses.replace(control, initial=_choice_option(control, text)))
    return dataclasses.replace(spec, controls=tuple(controls))


def _body(base: Preset, pairs: Mapping[str, str]) -> Preset:
    """A body of one's own from ``base``'s values and the link's (shown as "Custom")."""
    p = Parameters.from_preset(base)
    if "I" in pairs:
        moments = pairs["I"].split(",")
        if len(moments) != 3:
            raise LinkError(f"I={pairs['I']!r} needs three moments, as I=1,2,2.6")
        for i, text in enumerate(moments):
            p = p.with_inertia(i, _number("I", text, 0.0, math.inf))
    if "D" in pairs:
        lo, hi = p.D_range
        p = p.with_D(_number("D", pairs["D"], lo, hi))
    if "side" in pairs:
        if pairs["side"] not in ("minor", "major"):
            raise LinkError(f"side={pairs['side']!r} is not minor or major")
        p = p.mirrored(pairs["side"])
    if "pole" in pairs:
        signs = {"plus": 1, "+1": 1, "1": 1, "minus": -1, "-1": -1}
        if pairs["pole"] not in signs:
            raise LinkError(f"pole={pairs['pole']!r} is not plus or minus")
        p = p.with_pole(signs[pairs["pole"]])
    if "w" in pairs:
        p = p.with_omega_norm(_number("w", pairs["w"], 1e-300))
    try:
        p.build()
    except ValueError as exc:
        raise LinkError(
            f"no body has {', '.join(k for k in BODY if k in pairs)} so: {exc}"
        ) from None
    same_body = p.inertia == Parameters.from_preset(base).inertia
    return dataclasses.replace(
        CUSTOM,
        inertia=p.inertia,
        D=p.D,
        pole_sign=p.pole_sign,
        omega_norm=p.omega_norm,
        omega0=p.omega0,
        speed=base.speed,
        trail_points=base.trail_points,
        solid=base.solid if same_body else None,
    )


def parse(
    query: str, preset: Preset = DEFAULT_PRESET, scene: SceneSpec | None = None, page: str = ""
) -> Opening:
    """The opening a link's ``query`` asks for; :class:`LinkError` names a bad parameter. A
    link that names no preset, scene or body opens ``preset`` or ``scene`` (the server's)."""
    pairs = _pairs(query)
    if "preset" in pairs and "scene" in pairs:
        raise LinkError("a link opens a preset or a scene, not both")
    rest = {k: v for k, v in pairs.items() if k not in GENERAL}
    if "scene" in pairs:
        try:
            scene = scene_by_name(pairs["scene"])
        except KeyError:
            raise LinkError(
                f"scene={pairs['scene']!r} is not a scene ({', '.join(scene_names())})"
            ) from None
        own = {control.key for control in scene.controls}  # the polhode family's D is its own
        if any(k in rest and k not in own for k in BODY):
            raise LinkError(f"the scene {scene.name} brings its own body: no I, D, side, pole or w")
        scene = _scene(scene, rest)
    elif "preset" in pairs or rest:
        scene = None
        if "preset" in pairs:
            keys = [p.key for p in PRESETS]
            if pairs["preset"] not in keys:
                raise LinkError(f"preset={pairs['preset']!r} is not a preset ({', '.join(keys)})")
            preset = next(p for p in PRESETS if p.key == pairs["preset"])
        unknown = sorted(set(rest) - set(BODY))
        if unknown:
            raise LinkError(f"unknown parameter {', '.join(repr(k) for k in unknown)}")
        if rest:
            preset = _body(preset, rest)
    return _general(pairs, preset, scene, page)


def _general(
    pairs: Mapping[str, str], preset: Preset, scene: SceneSpec | None, page: str
) -> Opening:
    t = view = speed = None
    if "t" in pairs:
        t = _number("t", pairs["t"], 0.0, MAX_TIME)
    if "view" in pairs:
        try:
            view = canonical(pairs["view"])
        except ValueError:
            raise LinkError(f"view={pairs['view']!r} is not {', '.join(CAMERA_NAMES)}") from None
    if "speed" in pairs:
        lo, hi = SPEED_RANGE if scene is None else scene.speed_range
        speed = _number("speed", pairs["speed"], lo, hi)
    paused, follow = (_flag(pairs, key) for key in ("paused", "follow"))
    return Opening(preset, scene, t, view, speed, paused, follow, page=page)


def _flag(pairs: Mapping[str, str], key: str) -> bool:
    flag = pairs.get(key, "0").lower()
    if flag not in _TRUE + _FALSE:
        raise LinkError(f"{key}={pairs[key]!r} is not 0 or 1")
    return flag in _TRUE


def opening(
    address: str | None,
    preset: Preset,
    scene: SceneSpec | None,
    landing: tuple[int, int] = (0, 0),
) -> Opening:
    """What the page at ``address`` opens: its link's state, or (no query, no address) the
    server's ``preset`` or ``scene``; a bad link opens those too, with a message naming its
    parameter. ``landing``: (this server's port, its landing's): a page served straight from
    here copies links that name the landing, which spreads the browsers that open them."""
    page, _, query = (address or "").partition("?")
    query = query.partition("#")[0]
    parts = urllib.parse.urlsplit(page)
    if all(landing) and parts.port == landing[0] and parts.hostname:
        host = f"[{parts.hostname}]" if ":" in parts.hostname else parts.hostname
        page = parts._replace(netloc=f"{host}:{landing[1]}").geturl()
    default = Opening(preset, scene, page=page)
    if not _pairs_or_empty(query):
        return default
    try:
        return parse(query, preset, scene, page)
    except LinkError as exc:
        problem = f"This link could not be opened ({exc}); showing the default scene instead."
        return dataclasses.replace(default, problem=problem)


def _pairs_or_empty(query: str) -> bool:
    """Does the query hold anything for us (a bad one counts)?"""
    try:
        return bool(_pairs(query))
    except LinkError:
        return True


class LinkState(Protocol):
    """What a link reads of a session (its front): what it shows and the view chosen."""

    @property
    def showcase(self) -> Any: ...
    @property
    def preset(self) -> Preset: ...
    @property
    def params(self) -> Parameters: ...
    @property
    def frame(self) -> Any: ...
    @property
    def clock(self) -> Any: ...
    @property
    def camera(self) -> str: ...


class Opened(Protocol):
    """What a link opens in a new session: its lecture tools (the page, the view), panel,
    clock, construction and "Class" folder, and its queue."""

    clock: Any
    lecture: Any
    panel: Any
    scene: Any
    follow: Any

    def set_speed(self, speed: float) -> None: ...
    def post(self, action: Any, key: object = None) -> None: ...


def apply(session: Opened, link: Opening) -> None:
    """The clock, view and message of ``link`` in a new session (before its thread starts:
    the session was built with ``link.preset`` or ``link.scene``)."""
    session.lecture.page = link.page
    if link.speed is not None:
        session.set_speed(link.speed)
    if link.view is not None:
        session.lecture.set_camera(link.view)

    def action() -> None:
        clock = session.clock
        if link.paused:
            clock.paused = True
        if link.t is not None or link.paused:  # paused at once: at the link's time, or 0
            clock.reset(link.t or 0.0)
            session.panel.motion.clear_plot()  # its first sample is t = 0's
        session.panel.show_playback(clock.speed, clock.paused, session.scene.trail_points)
        if link.problem:
            session.panel.show_status(link.problem)

    session.post(action)
    if link.follow:
        session.follow.start_following()


def _text(value: float) -> str:
    return format(value, ".10g")


def query_of(session: LinkState) -> str:
    """The query of what ``session`` shows (its frame thread: it reads the session's state)."""
    pairs: list[tuple[str, str]] = []
    showcase = session.showcase
    if showcase is not None:
        spec = scene_by_name(showcase.spec.name)  # the catalogue's, with its own defaults
        pairs.append(("scene", spec.name))
        pairs += _settings(spec, showcase.desired)
        speed = spec.initial_speed()
    elif session.preset in PRESETS:
        pairs.append(("preset", session.preset.key))
        speed = session.preset.speed
    else:
        p = session.params
        pairs.append(("I", ",".join(_text(m) for m in p.inertia)))
        pairs += [("D", _text(p.D)), ("pole", "plus" if p.pole_sign > 0 else "minus")]
        pairs.append(("w", _text(p.omega_norm)))
        speed = DEFAULT_PRESET.speed
    clock = session.clock
    t = session.frame.t if session.frame is not None else clock.now()
    pairs.append(("t", format(max(t, 0.0), ".6g")))
    if session.camera != "default":
        pairs.append(("view", session.camera))
    if not math.isclose(clock.speed, speed, rel_tol=1e-9):
        pairs.append(("speed", _text(clock.speed)))
    if clock.paused:
        pairs.append(("paused", "1"))
    return urllib.parse.urlencode(pairs, safe=",")


def _settings(spec: SceneSpec, desired: Mapping[str, Value]) -> list[tuple[str, str]]:
    """The scene's controls whose values are not their initial ones."""
    out: list[tuple[str, str]] = []
    for control in spec.controls:
        value = desired.get(control.key)
        if value is None or (isinstance(control, Choice) and control.speed):
            continue
        if isinstance(control, Slider):
            if not math.isclose(float(value), control.initial, rel_tol=1e-12):
                out.append((control.key, _text(float(value))))
            continue
        option = next((o for o in control.options if control.value(o) == value), control.initial)
        if option != control.initial:
            out.append((control.key, option))
    return out


def link_of(session: LinkState, page: str) -> str:
    """The link of what ``session`` shows on ``page`` (its page's address as the browser sees
    it: through a landing or a proxy, :attr:`Opening.page`) and the query; the query alone if
    the page's address is unknown."""
    return f"{page}?{query_of(session)}"
