"""The vocabulary of a scene: what a scene (:mod:`poinsot.app.lessons`) declares as data.

A scene is a lecture topic with its own body and motion, built from :mod:`poinsot.physics`
like the presets are, but with drawings, controls, readouts and plots of its own. Its
:class:`SceneSpec` says which body and motion it shows, which elements of Poinsot's
construction it reuses (:class:`~poinsot.app.model.elements.Element`, drawn by
:class:`~poinsot.app.construction.construction.PoinsotScene`), which drawings of its own it adds
(:class:`Part`: each names the scene nodes it creates), which controls it offers (:class:`Slider`,
:class:`Choice`, and the panel's shared groups such as speed and playback), which readouts it
fills (theory against the value measured from the motion) and which plots it draws
(:class:`PlotSpec`), with its sources (keys of docs/REFERENCES.md). The session, the screenshot
and the HTML export create exactly these and nothing else.

Per parameter change a scene's ``build(settings)`` asks physics for everything (a
:class:`Model`); its ``draw(canvas)`` makes the nodes once, ``fit`` sends the static shapes of a
model, and ``advance`` sends poses and trail increments only.
"""

from __future__ import annotations

import dataclasses
import html
import math
import re
from collections.abc import Callable, Mapping
from typing import Protocol

import numpy as np
import viser

from poinsot.app.construction.geometry import Geometry
from poinsot.app.construction.palette import Entry, Style
from poinsot.app.construction.sampled.batch import Frame
from poinsot.app.construction.view import DEFAULT_VIEW, View
from poinsot.app.model.elements import Control, Element, Solid
from poinsot.app.model.parameters import SPEED_RANGE
from poinsot.app.model.presets import Preset
from poinsot.physics import FreeRigidBody

RGB = tuple[int, int, int]
#: A control's value: a number (slider, numeric choice) or an option's label.
Value = float | str
Settings = Mapping[str, Value]

#: The setting of a start pointed at by hand, in a scene that takes one (its text is
#: :func:`start_setting`'s); any control moved drops it.
START_KEY = "start"


def start_setting(momentum: tuple[float, float, float], separatrix: bool) -> str:
    """The setting of a start pointed at: body-frame L (exact to the last bit) and whether it
    was snapped onto the separatrix."""
    return ",".join([*(format(float(v), ".17g") for v in momentum), "1" if separatrix else "0"])


def parse_start(text: str) -> tuple[np.ndarray, bool]:
    """The body-frame L and the separatrix flag of :func:`start_setting`'s text (ValueError
    if it is not one)."""
    parts = text.split(",")
    if len(parts) != 4 or parts[3] not in ("0", "1"):
        raise ValueError(f"a pointed start is three numbers and a flag, not {text!r}")
    momentum = np.array([float(v) for v in parts[:3]])
    if not np.all(np.isfinite(momentum)) or not np.any(momentum):
        raise ValueError(f"a pointed start needs a finite, nonzero L, not {text!r}")
    return momentum, parts[3] == "1"


#: The panel's groups a scene may share (the others edit a preset's parameters).
SHAREABLE: frozenset[Control] = frozenset(
    {Control.SPEED, Control.PLAYBACK, Control.TRAIL, Control.VISIBILITY}
)


@dataclasses.dataclass(frozen=True)
class Part:
    """A drawing of the scene's own, shown and hidden as a whole by its checkbox.

    ``nodes``: the scene node names it creates; ``trails``: those of its nodes that are trail
    groups (their chunks ``<group>/g<layer>/c<n>`` come and go); ``colors``: the colours of its
    lines, drawn unlit in exactly these colours (a picture of the scene shows them);
    ``surface``: its colour where it is a lit or translucent surface instead (shaded on screen),
    else None;
    ``legend``: its rows in the legend where it draws more than one thing (each colour it
    draws in one of them), else one row of its label is made (:meth:`rows`; ``translucent``:
    its surface is seen through).
    """

    key: str
    label: str
    nodes: tuple[str, ...]
    colors: tuple[RGB, ...] = ()
    trails: tuple[str, ...] = ()
    surface: RGB | None = None
    legend: tuple[Entry, ...] = ()
    translucent: bool = False

    def __post_init__(self) -> None:
        if not self.legend and len(self.colors) + (self.surface is not None) > 1:
            raise ValueError(f"part {self.key}: more than one colour needs its legend rows")

    def rows(self) -> tuple[Entry, ...]:
        """Its rows in the legend: its own, or its label with its one colour."""
        if self.legend:
            return self.legend
        if self.surface is not None:
            style: Style = "translucent" if self.translucent else "solid"
            return (Entry(self.label, (self.surface,), "patch", style),)
        return tuple(Entry(self.label, (color,), "line") for color in self.colors)


@dataclasses.dataclass(frozen=True)
class Slider:
    """A slider; its value (a float) goes into the settings under ``key``."""

    key: str
    label: str
    lo: float
    hi: float
    step: float
    initial: float
    hint: str = ""
    marks: tuple[tuple[float, str], ...] = ()


@dataclasses.dataclass(frozen=True)
class Choice:
    """A dropdown (or a row of buttons if ``buttons``). The settings get the chosen option's
    label, or its number from ``values`` when given. A choice with ``speed`` sets the clock's
    speed (simulation time per second) instead of a setting of the model."""

    key: str
    label: str
    options: tuple[str, ...]
    initial: str
    hint: str = ""
    values: tuple[float, ...] = ()
    buttons: bool = False
    speed: bool = False

    def __post_init__(self) -> None:
        if self.initial not in self.options:
            raise ValueError(f"choice {self.key}: {self.initial!r} is not an option")
        if self.values and len(self.values) != len(self.options):
            raise ValueError(f"choice {self.key}: one value per option")

    def value(self, option: str) -> Value:
        """The setting for ``option``."""
        index = self.options.index(option)
        return float(self.values[index]) if self.values else option


SceneControl = Slider | Choice


@dataclasses.dataclass(frozen=True)
class PlotSpec:
    """A uPlot in the "Motion" window: x and the named series (label, "#rrggbb")."""

    key: str
    title: str
    x_label: str
    y_label: str
    series: tuple[tuple[str, str], ...]


@dataclasses.dataclass(frozen=True)
class Readout:
    """One row of the readout table: the theory's value and the value measured from the motion
    the scene shows (either may be "—" with the reason in ``note``).

    A row that compares two numbers (:meth:`compare`) also carries their gap: ``gap`` is
    measured/theory − 1 (the relative difference the measured cell shows), or the difference
    in units of a scale the row names where the theory is 0 or a fraction, or the deviation
    itself where the theory is "0"; ``tolerance`` is the largest ``|gap|`` the scene states for
    the row. Both are None where the row compares nothing.
    """

    quantity: str
    theory: str
    measured: str
    note: str = ""
    gap: float | None = None
    tolerance: float | None = None
    #: False where the theory does not hold for this motion (its note says why): the screen
    #: says so instead of showing a gap.
    applies: bool = True

    @classmethod
    def compare(
        cls,
        quantity: str,
        theory: float,
        measured: float,
        tolerance: float,
        note: str = "",
        *,
        digits: int = 6,
        scale: float | None = None,
        text: tuple[str, str] | None = None,
    ) -> Readout:
        """A row of ``theory`` against ``measured``, shown with ``digits`` significant digits and
        the relative gap (or as ``text``, the two cells, where the row has its own format);
        ``scale`` replaces the theory as the unit of the gap."""
        unit = theory if scale is None else scale
        gap = (measured - theory) / unit if unit != 0.0 else math.nan
        theory_text, measured_text = (
            (number(theory, digits), relative(measured, theory, digits)) if text is None else text
        )
        return cls(quantity, theory_text, measured_text, note, gap, tolerance)

    @property
    def within(self) -> bool | None:
        """Whether the gap is within the tolerance (None: the row compares nothing)."""
        if self.gap is None or self.tolerance is None:
            return None
        return bool(abs(self.gap) <= self.tolerance)


class Model(Protocol):
    """What a scene's ``build(settings)`` returns: the physics for one set of settings.

    ``body``: the exact motion the Poinsot construction draws (None for a scene that draws and
    poses its own body); ``solid``: the construction's solid (None: the scene draws its own).
    """

    @property
    def body(self) -> FreeRigidBody | None: ...

    @property
    def solid(self) -> Solid | None: ...

    def readouts(self, t: float) -> tuple[Readout, ...]:
        """The rows at simulation time ``t`` (most are constant per model)."""
        ...

    def plot(self, key: str, t: float) -> tuple[np.ndarray, ...]:
        """The data of plot ``key`` shown at time ``t``: (x, series...), finite."""
        ...


@dataclasses.dataclass(frozen=True)
class Canvas:
    """Where a scene draws: the scene API, the root of the construction, and its body frame
    (whose orientation is the attitude)."""

    api: viser.SceneApi
    root: str
    body: viser.FrameHandle


class Drawing(Protocol):
    """A scene's own nodes (its :class:`Part` s)."""

    def fit(self, model: Model, geometry: Geometry | None) -> None:
        """Send the static shapes of ``model`` (once per parameter change)."""

    def advance(self, t: float, frame: Frame | None) -> Frame:
        """Per frame: poses and trail increments at time ``t``; ``frame`` is what the Poinsot
        construction drew (None when the scene poses the body itself)."""
        ...

    def set_visible(self, part: str, visible: bool) -> None: ...

    def is_visible(self, part: str) -> bool: ...

    def remove(self) -> None: ...


@dataclasses.dataclass(frozen=True)
class SceneSpec:
    """A scene, declared as data (see the module docstring).

    ``body`` and ``motion`` say in words which body and which :mod:`poinsot.physics` model it
    shows; ``build`` and ``draw`` are the scene module's model and drawing.
    """

    name: str
    label: str
    source: str
    body: str
    motion: str
    elements: frozenset[Element]
    parts: tuple[Part, ...]
    controls: tuple[SceneControl, ...]
    shared: frozenset[Control]
    readouts: tuple[str, ...]
    plots: tuple[PlotSpec, ...]
    build: Callable[[Settings], Model]
    draw: Callable[[Canvas], Drawing]
    view: View = DEFAULT_VIEW
    #: Pictures drawn beside the construction, each as a sphere that holds it (centre, radius;
    #: display units): a view framed for a phone's or a tablet's aspect keeps them in frame
    #: with the construction (:mod:`poinsot.app.live.lecture.layout`).
    beside: tuple[tuple[tuple[float, float, float], float], ...] = ()
    speed: float = 1.0
    speed_range: tuple[float, float] = SPEED_RANGE
    trail_points: int = 1200
    #: Simulation time of ``poinsot screenshot --scene`` (what the picture shows best).
    picture_time: float = 10.0
    #: The settings (over the defaults) the readout table of the scenes shows, at
    #: ``picture_time`` (``python -m poinsot.app.lessons.readouts``).
    table_settings: tuple[Mapping[str, Value], ...] = ({},)

    def __post_init__(self) -> None:
        if not self.shared <= SHAREABLE:
            raise ValueError(f"scene {self.name}: shares {set(self.shared - SHAREABLE)}")
        keys = [c.key for c in self.controls] + [p.key for p in self.parts]
        if len(set(keys)) != len(keys):
            raise ValueError(f"scene {self.name}: control and part keys must be distinct")
        if not (math.isfinite(self.picture_time) and self.picture_time >= 0.0):
            raise ValueError(f"scene {self.name}: picture_time must be a time >= 0")

    @property
    def key(self) -> str:
        return self.name

    def defaults(self) -> dict[str, Value]:
        """The settings of the controls' initial values (speed choices excluded)."""
        out: dict[str, Value] = {}
        for control in self.controls:
            if isinstance(control, Slider):
                out[control.key] = float(control.initial)
            elif not control.speed:
                out[control.key] = control.value(control.initial)
        return out

    def initial_speed(self) -> float:
        """The clock's speed at start: a speed choice's initial value, else ``speed``."""
        for control in self.controls:
            if isinstance(control, Choice) and control.speed:
                return float(control.value(control.initial))
        return self.speed

    def identity(self) -> Preset:
        """What the rest of a session reads of its current preset while this scene is shown:
        the key (file names of exports), the label (the dropdown) and the source. The moments
        and motion are the scene's own (its model's), not these placeholders."""
        return Preset(
            key=self.name,
            label=self.label,
            source=self.source,
            inertia=(1.0, 1.0, 1.0),
            D=1.0,
            speed=self.speed,
            trail_points=self.trail_points,
            elements=self.elements,
            controls=self.shared,
            plots=frozenset(),
        )

    def node_names(self) -> frozenset[str]:
        """Every node its parts create (trail chunks excluded)."""
        return frozenset(n for part in self.parts for n in part.nodes)

    def control_labels(self) -> frozenset[str]:
        """The labels of its own widgets: controls and the parts' checkboxes."""
        return frozenset([c.label for c in self.controls] + [p.label for p in self.parts])


def table(rows: tuple[Readout, ...]) -> str:
    """Readout rows as a markdown table (quantity, theory, measured); notes below it."""
    escape = lambda text: text.replace("|", "\\|")  # noqa: E731
    lines = ["| quantity | theory | measured |", "|:--|--:|--:|"]
    lines += [f"| {escape(r.quantity)} | {escape(r.theory)} | {escape(r.measured)} |" for r in rows]
    notes = [f"<small>{r.quantity}: {r.note}</small>" for r in rows if r.note]
    return "\n".join(lines + ([""] + notes if notes else []))


#: Significant figures of a number on screen (the readout table and the CSV keep them all).
SCREEN_DIGITS = 4
_NUMBER = re.compile(r"(?<![\w.^₀-₉])[-+−]?\d+\.\d+(?:e[-+]?\d+)?(?![\w.])")


def on_screen(text: str) -> str:
    """``text`` with each decimal number cut to SCREEN_DIGITS significant figures."""

    def cut(match: re.Match[str]) -> str:
        text = match.group(0)
        value = float(text.replace("−", "-"))
        cut = number(float(f"{value:.{SCREEN_DIGITS}g}"), SCREEN_DIGITS)
        return cut.replace("-", "−", 1) if text.startswith("−") else cut

    return _NUMBER.sub(cut, text)


def screen_cells(row: Readout) -> tuple[str, str]:
    """A row's theory and measured cells as the screen shows them: SCREEN_DIGITS figures, the
    gap in words (a percentage, or "agrees" within a millionth), and "not valid here" where
    the theory does not hold."""
    theory = on_screen(row.theory)
    measured = on_screen(row.measured.split(" (")[0]) if row.gap is not None else row.measured
    if row.gap is not None and math.isfinite(row.gap) and row.measured.endswith(")"):
        size = abs(row.gap)
        said = "agrees" if size < 1e-6 else f"{100.0 * row.gap:+.2g} %"
        measured = f"{measured} ({said})"
    elif row.gap is None:
        measured = on_screen(row.measured)
    if not row.applies:
        theory = f"{theory} (not valid here)"
    return theory, measured


def _full(shown: str, full: str) -> str:
    """A cell showing ``shown``, with every digit of ``full`` on hover where they differ."""
    if shown == full:
        return shown
    return f'<span title="{html.escape(full)}">{html.escape(shown, quote=False)}</span>'


def screen_table(rows: tuple[Readout, ...]) -> str:
    """Readout rows as the screen shows them (:func:`screen_cells`; every digit on hover),
    notes below."""
    escape = lambda text: text.replace("|", "\\|")  # noqa: E731
    lines = ["| quantity | theory | measured |", "|:--|--:|--:|"]
    for r in rows:
        theory, measured = screen_cells(r)
        cells = (r.quantity, _full(theory, r.theory), _full(measured, r.measured))
        lines.append("| " + " | ".join(escape(c) for c in cells) + " |")
    notes = [f"<small>{r.quantity}: {on_screen(r.note)}</small>" for r in rows if r.note]
    return "\n".join(lines + ([""] + notes if notes else []))


def number(x: float, digits: int = 6) -> str:
    """A readout number: ``digits`` significant digits, ∞ and — for inf and NaN."""
    if math.isinf(x):
        return "∞"
    if math.isnan(x):
        return "—"
    return f"{x + 0.0:.{digits}g}"  # + 0.0: no "-0"


def relative(measured: float, theory: float, digits: int = 6) -> str:
    """``measured`` with its relative difference from ``theory``."""
    if not (math.isfinite(measured) and math.isfinite(theory)) or theory == 0.0:
        return number(measured, digits)
    gap = measured / theory - 1.0
    return f"{number(measured, digits)} ({gap:+.1e})"
