"""The control panel of one session: preset, sliders, playback, show/hide, readouts, plot.

Only the controls the current preset declares exist (:meth:`ControlPanel.declare` creates and
removes whole groups; ``order`` keeps the layout stable whatever the creation order). A removed
group is hidden at once and deleted RETIRE_SECONDS later (:meth:`ControlPanel.collect`): the
browser applies the GUI updates of one rendered frame after that frame's removals, so an
update sent just before a removal would otherwise reach an element that no longer exists and
log a console error. Callbacks
never touch the scene or block: they hand a small action to the session's frame thread via
``Actions``. Programmatic value changes (``event.client is None``) are ignored, so the
session can mirror its state into the widgets without feedback loops.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import Any, Protocol

import numpy as np
import viser
import viser.uplot
from poinsot.app.live import readouts
from poinsot.app.parameters import (
    INERTIA_RANGE,
    OMEGA_NORM_RANGE,
    SPEED_RANGE,
    TRAIL_RANGE,
    Parameters,
)
from poinsot.app.presets import CUSTOM, PRESETS, Control, Element, Plot, Preset
from poinsot.app.scene import palette

ELEMENT_LABELS: dict[Element, str] = {
    Element.ELLIPSOID: "energy ellipsoid",
    Element.AXES: "principal axes",
    Element.PLANE: "invariable plane",
    Element.CONTACT: "contact point",
    Element.OMEGA: "ω (instantaneous axis)",
    Element.L: "L (angular momentum)",
    Element.POLHODE: "polhode (live)",
    Element.POLHODE_FULL: "polhode (whole curve)",
    Element.HERPOLHODE: "herpolhode (live)",
    Element.SOLID: "solid body",
}

SIDE_OPTIONS = ("minor axis", "major axis")
POLE_OPTIONS = ("+ pole", "− pole")

#: Number of plot samples kept (one per plot refresh, 10 per second: the last 30 s).
PLOT_SAMPLES = 300
#: Delay between hiding a removed widget and deleting it [s].
RETIRE_SECONDS = 1.5
#: Width of the floating readout window [CSS px].
DATA_WINDOW_WIDTH = 360

# Layout: top-level order of the folders and the plot.
_ORDER = {
    "scene": 0.0,
    Control.INERTIA: 10.0,
    "motion": 20.0,
    "playback": 30.0,
    Control.VISIBILITY: 40.0,
    "readouts": 50.0,
    Plot.OMEGA: 60.0,
}


class Actions(Protocol):
    """What the panel asks of its session (all non-blocking)."""

    def choose_preset(self, preset: Preset) -> None: ...
    def edit(self, change: Callable[[Parameters], Parameters]) -> None: ...
    def set_speed(self, speed: float) -> None: ...
    def toggle_pause(self) -> None: ...
    def step(self) -> None: ...
    def reset(self) -> None: ...
    def set_trail(self, points: int) -> None: ...
    def set_visible(self, element: Element, visible: bool) -> None: ...
    def report(self, error: BaseException) -> None: ...


class ControlPanel:
    def _user_only(self, callback: Callable[[Any], None]) -> Callable[[viser.GuiEvent], None]:
        """Run ``callback(handle)`` for changes made in the browser only (a value set by the
        server fires the same callbacks, with no client); never let it raise into viser."""

        def wrapped(event: viser.GuiEvent) -> None:
            if event.client is None:
                return
            try:
                callback(event.target)
            except Exception as exc:
                self.actions.report(exc)

        return wrapped

    def __init__(self, gui: viser.GuiApi, actions: Actions, preset: Preset) -> None:
        self.gui = gui
        self.actions = actions
        self._groups: dict[Any, list[Any]] = {}
        self._group_names: dict[Any, list[str]] = {}
        self._folders: dict[str, viser.GuiFolderHandle] = {}
        self.handles: dict[str, Any] = {}
        self._elements: frozenset[Element] = frozenset()
        self._plot_t: list[float] = []
        self._plot_w: list[np.ndarray] = []
        self._retired: list[tuple[float, Any]] = []
        self._data_window: Any = None
        self._data_tab: Any = None

        with gui.add_folder("Scene", order=_ORDER["scene"]) as folder:
            self._folders["scene"] = folder
            labels = [p.label for p in PRESETS] + [CUSTOM.label]
            self.handles["preset"] = preset_dd = gui.add_dropdown(
                "Preset",
                labels,
                initial_value=preset.label,
                hint="Start from a classical case; editing a slider turns it into 'Custom'.",
            )
            self.handles["source"] = gui.add_markdown(self._source_text(preset))
            self.handles["status"] = gui.add_markdown("")

        @preset_dd.on_update
        @self._user_only
        def _(handle) -> None:
            for p in (*PRESETS, CUSTOM):
                if p.label == handle.value:
                    actions.choose_preset(p)

    # -- declaration ---------------------------------------------------------------------
    def declare(
        self,
        controls: frozenset[Control],
        plots: frozenset[Plot],
        elements: frozenset[Element],
        params: Parameters,
        speed: float,
        trail: int,
        visible: Callable[[Element], bool],
    ) -> None:
        """Create exactly the declared groups (keeping existing ones), remove the others."""
        wanted: set[Any] = set(controls) | set(plots)
        if Control.VISIBILITY in controls and elements != self._elements:
            self._remove_group(Control.VISIBILITY)  # rebuilt below for the new elements
        self._elements = elements
        for key in list(self._groups):
            if key not in wanted:
                self._remove_group(key)
        builders: dict[Any, Callable[[], list[Any]]] = {
            Control.INERTIA: lambda: self._build_inertia(params),
            Control.ENERGY: lambda: self._build_energy(params),
            Control.SIDE: lambda: self._build_side(params),
            Control.OMEGA_NORM: lambda: self._build_omega_norm(params),
            Control.SPEED: lambda: self._build_speed(speed),
            Control.PLAYBACK: self._build_playback,
            Control.TRAIL: lambda: self._build_trail(trail),
            Control.VISIBILITY: lambda: self._build_visibility(elements, visible),
            Plot.OMEGA: self._build_plot,
        }
        if self._data_tab is None:
            self._build_data_window()
        for key in sorted(wanted, key=lambda k: _ORDER.get(k, 25.0)):
            if key not in self._groups:
                self._groups[key] = builders[key]()
        self._prune_folders()

    def _build_data_window(self) -> None:
        """Readouts and the plot float at the bottom left of the 3D view, so that a lecture
        sees them beside the scene without scrolling the control panel."""
        window = self.gui.add_panel(order=_ORDER["readouts"])
        self._data_window = window
        self._data_tab = window.add_tab("Motion", viser.Icon.CHART_LINE)
        with self._data_tab:
            self.handles["time"] = self.gui.add_markdown(
                readouts.time_markdown(0.0, False), order=0.0
            )
            self.handles["readouts"] = self.gui.add_markdown("", order=1.0)
        window.float(x=16, y=-16, width=DATA_WINDOW_WIDTH)

    @property
    def groups(self) -> frozenset[Any]:
        return frozenset(self._groups)

    def _remove_group(self, key: Any) -> None:
        for name in self._group_names.pop(key, []):
            self.handles.pop(name, None)
        self._retire(self._groups.pop(key, []))

    def _retire(self, handles: list[Any]) -> None:
        """Hide now, delete after RETIRE_SECONDS (see the module docstring)."""
        due = time.monotonic() + RETIRE_SECONDS
        for handle in handles:
            handle.visible = False
            self._retired.append((due, handle))

    def collect(self, now: float | None = None) -> int:
        """Delete the retired widgets that are due; returns how many are still waiting."""
        now = time.monotonic() if now is None else now
        keep = []
        for due, handle in self._retired:
            if due <= now:
                handle.remove()
            else:
                keep.append((due, handle))
        self._retired = keep
        return len(keep)

    def _folder(self, name: str, label: str, expand: bool = True) -> viser.GuiFolderHandle:
        if name not in self._folders:
            self._folders[name] = self.gui.add_folder(
                label, order=_ORDER[name], expand_by_default=expand
            )
        return self._folders[name]

    def _prune_folders(self) -> None:
        used = {"scene"}
        if self._groups.keys() & {Control.ENERGY, Control.SIDE, Control.OMEGA_NORM}:
            used.add("motion")
        if self._groups.keys() & {Control.SPEED, Control.PLAYBACK, Control.TRAIL}:
            used.add("playback")
        for key in (Control.INERTIA, Control.VISIBILITY):
            if key in self._groups:
                used.add(key)
        for name in [n for n in self._folders if n not in used]:
            self._retire([self._folders.pop(name)])

    def _tag(self, key: Any, **handles: Any) -> list[Any]:
        self._group_names[key] = list(handles)
        self.handles.update(handles)
        return list(handles.values())

    # -- groups --------------------------------------------------------------------------
    def _build_inertia(self, params: Parameters) -> list[Any]:
        folder = self._folder(Control.INERTIA, "Body: principal moments")
        sliders = {}
        with folder:
            for i in range(3):
                slider = self.gui.add_slider(
                    f"I{'₁₂₃'[i]}",
                    INERTIA_RANGE[0],
                    INERTIA_RANGE[1],
                    0.01,
                    float(params.inertia[i]),
                    order=float(i),
                    hint="A principal moment of inertia (mass × length²).",
                )
                slider.on_update(self._user_only(self._inertia_cb(i)))
                sliders[f"I{i + 1}"] = slider
        return self._tag(Control.INERTIA, **sliders)

    def _inertia_cb(self, index: int) -> Callable[[Any], None]:
        def cb(handle) -> None:
            value = float(handle.value)
            self.actions.edit(lambda p: p.with_inertia(index, value))

        return cb

    def _build_energy(self, params: Parameters) -> list[Any]:
        lo, hi = params.D_range
        with self._folder("motion", "Motion"):
            slider = self.gui.add_slider(
                "D = |L|²/2T",
                lo,
                hi,
                0.001,
                float(params.D),
                order=0.0,
                marks=self._energy_marks(params),
                hint="Energy parameter in [I_min, I_max]; D = I₂ is the separatrix.",
            )

        @slider.on_update
        @self._user_only
        def _(handle) -> None:
            value = float(handle.value)
            self.actions.edit(lambda p: _with_D(p, value))

        return self._tag(Control.ENERGY, energy=slider)

    @staticmethod
    def _energy_marks(params: Parameters) -> tuple[tuple[float, str], ...]:
        lo, hi = params.D_range
        mid = params.intermediate
        marks = [(lo, "min I"), (hi, "max I")]
        if lo < mid < hi:
            marks.insert(1, (mid, "I₂"))
        return tuple(marks)

    def _build_side(self, params: Parameters) -> list[Any]:
        with self._folder("motion", "Motion"):
            side = self.gui.add_button_group("Side of separatrix", SIDE_OPTIONS, order=1.0)
            pole = self.gui.add_button_group("Polhode", POLE_OPTIONS, order=2.0)

        def choose_side(handle) -> None:
            choice = "major" if handle.value == SIDE_OPTIONS[1] else "minor"
            self.actions.edit(lambda p: p.mirrored(choice))

        def choose_pole(handle) -> None:
            sign = 1 if handle.value == POLE_OPTIONS[0] else -1
            self.actions.edit(lambda p: _with_pole(p, sign))

        side.on_click(self._user_only(choose_side))
        pole.on_click(self._user_only(choose_pole))

        return self._tag(Control.SIDE, side=side, pole=pole)

    def _build_omega_norm(self, params: Parameters) -> list[Any]:
        with self._folder("motion", "Motion"):
            slider = self.gui.add_slider(
                "|ω₀|",
                OMEGA_NORM_RANGE[0],
                OMEGA_NORM_RANGE[1],
                0.05,
                float(params.omega_norm),
                order=3.0,
                hint="Initial angular speed (rad per time unit).",
            )

        @slider.on_update
        @self._user_only
        def _(handle) -> None:
            value = float(handle.value)
            self.actions.edit(lambda p: _with_omega_norm(p, value))

        return self._tag(Control.OMEGA_NORM, omega_norm=slider)

    def _build_speed(self, speed: float) -> list[Any]:
        with self._folder("playback", "Playback"):
            slider = self.gui.add_slider(
                "Speed",
                SPEED_RANGE[0],
                SPEED_RANGE[1],
                0.05,
                float(speed),
                order=0.0,
                hint="Simulation time units per second.",
            )
        slider.on_update(self._user_only(lambda h: self.actions.set_speed(float(h.value))))
        return self._tag(Control.SPEED, speed=slider)

    def _build_playback(self) -> list[Any]:
        with self._folder("playback", "Playback"):
            pause = self.gui.add_button("Pause", icon=viser.Icon.PLAYER_PAUSE, order=1.0)
            step = self.gui.add_button("Step", icon=viser.Icon.PLAYER_TRACK_NEXT, order=2.0)
            reset = self.gui.add_button("Reset", icon=viser.Icon.REFRESH, order=3.0)
        pause.on_click(self._user_only(lambda _: self.actions.toggle_pause()))
        step.on_click(self._user_only(lambda _: self.actions.step()))
        reset.on_click(self._user_only(lambda _: self.actions.reset()))
        return self._tag(Control.PLAYBACK, pause=pause, step=step, reset=reset)

    def _build_trail(self, trail: int) -> list[Any]:
        with self._folder("playback", "Playback"):
            slider = self.gui.add_slider(
                "Trail length",
                TRAIL_RANGE[0],
                TRAIL_RANGE[1],
                100,
                int(trail),
                order=4.0,
                hint="Points kept in the polhode and herpolhode traces.",
            )
        slider.on_update(self._user_only(lambda h: self.actions.set_trail(int(h.value))))
        return self._tag(Control.TRAIL, trail=slider)

    def _build_visibility(
        self, elements: frozenset[Element], visible: Callable[[Element], bool]
    ) -> list[Any]:
        boxes = {}
        with self._folder(Control.VISIBILITY, "Show", expand=False):
            for n, element in enumerate(e for e in Element if e in elements):
                box = self.gui.add_checkbox(
                    ELEMENT_LABELS[element], visible(element), order=float(n)
                )
                box.on_update(self._user_only(self._visible_cb(element)))
                boxes[f"show_{element.value}"] = box
        return self._tag(Control.VISIBILITY, **boxes)

    def _visible_cb(self, element: Element) -> Callable[[Any], None]:
        return lambda handle: self.actions.set_visible(element, bool(handle.value))

    def _build_plot(self) -> list[Any]:
        series = [viser.uplot.Series(label="t")]
        for i, color in enumerate(palette.PLOT_SERIES):
            series.append(viser.uplot.Series(label=f"ω{'₁₂₃'[i]}", stroke=color, width=2))
        axis = {
            "stroke": "#c8d0da",
            "grid": {"stroke": "#3a4048", "width": 1},
            "ticks": {"stroke": "#3a4048"},
        }
        # Created with two samples, not empty: viser's uPlot keeps the x range relative to the
        # data's extent, and an empty first data set (extent -inf..inf) leaves it NaN forever.
        with self._data_tab:
            plot = self._add_plot(series, axis)
        self._plot_t, self._plot_w = [], []
        return self._tag(Plot.OMEGA, plot=plot)

    def _add_plot(self, series, axis):
        zeros = np.zeros(2)
        return self.gui.add_uplot(
            data=(np.array([0.0, 1.0]), zeros, zeros, zeros),
            series=tuple(series),
            title="ω in the body frame",
            scales={"x": {"time": False, "auto": True}, "y": {"auto": True}},
            axes=(axis, axis),  # type: ignore[arg-type]
            aspect=1.7,
            order=2.0,
        )

    # -- mirroring the session's state ---------------------------------------------------
    def show_preset(self, preset: Preset) -> None:
        self.handles["preset"].value = preset.label
        self.handles["source"].content = self._source_text(preset)

    @staticmethod
    def _source_text(preset: Preset) -> str:
        return f"<small>_Source:_ {preset.source}</small>"

    def show_status(self, message: str) -> None:
        handle = self.handles["status"]
        text = f"**⚠ {message}**" if message else ""
        if handle.content != text:
            handle.content = text

    def show_parameters(self, params: Parameters) -> None:
        """Mirror parameters into the sliders (and the D slider's range and marks)."""
        for i in range(3):
            slider = self.handles.get(f"I{i + 1}")
            if slider is not None:
                slider.value = float(params.inertia[i])
        energy = self.handles.get("energy")
        if energy is not None:
            lo, hi = params.D_range
            energy.min, energy.max = lo, hi
            energy.marks = self._energy_marks(params)
            energy.value = float(params.D)
        if "omega_norm" in self.handles:
            self.handles["omega_norm"].value = float(params.omega_norm)

    def show_playback(self, speed: float, paused: bool, trail: int) -> None:
        if "speed" in self.handles:
            self.handles["speed"].value = float(speed)
        if "trail" in self.handles:
            self.handles["trail"].value = int(trail)
        if "pause" in self.handles:
            pause = self.handles["pause"]
            pause.label = "Play" if paused else "Pause"
            pause.icon = viser.Icon.PLAYER_PLAY if paused else viser.Icon.PLAYER_PAUSE

    def show_readouts(self, text: str) -> None:
        self.handles["readouts"].content = text

    def show_time(self, t: float, paused: bool) -> None:
        text = readouts.time_markdown(t, paused)
        if self.handles["time"].content != text:
            self.handles["time"].content = text

    def clear_plot(self) -> None:
        self._plot_t, self._plot_w = [], []

    def record_plot(self, t: float, omega: np.ndarray) -> None:
        """Add a sample (the session does, at the plot's refresh rate, then sends)."""
        if "plot" not in self.handles:
            return
        if self._plot_t and t < self._plot_t[-1]:
            self.clear_plot()
        if self._plot_t and t == self._plot_t[-1]:
            return
        self._plot_t.append(float(t))
        self._plot_w.append(np.array(omega, dtype=np.float64))  # a copy: not a batch's view
        if len(self._plot_t) > PLOT_SAMPLES:
            del self._plot_t[0], self._plot_w[0]

    def send_plot(self) -> bool:
        plot = self.handles.get("plot")
        if plot is None or len(self._plot_t) < 2:
            return False
        w = np.asarray(self._plot_w)
        data = (np.asarray(self._plot_t), w[:, 0].copy(), w[:, 1].copy(), w[:, 2].copy())
        if all(np.all(np.isfinite(a)) for a in data):
            plot.data = data
            return True
        return False


def _with_D(p: Parameters, D: float) -> Parameters:
    lo, hi = p.D_range
    return Parameters(p.inertia, min(max(D, lo), hi), p.pole_sign, p.omega_norm)


def _with_pole(p: Parameters, sign: int) -> Parameters:
    return Parameters(p.inertia, p.D, sign, p.omega_norm)


def _with_omega_norm(p: Parameters, value: float) -> Parameters:
    if not math.isfinite(value) or value <= 0:
        return p
    return Parameters(p.inertia, p.D, p.pole_sign, value)
