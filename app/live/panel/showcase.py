"""A scene (:mod:`poinsot.app.lessons`) in a live session: its controls, the show/hide of its
parts, its readouts and plots, around the :class:`~poinsot.app.lessons.support.runtime.Showcase`
that draws it.

The session owns one :class:`LiveShowcase` while a scene is chosen and hands it its frame
thread's work (:meth:`load`, :meth:`advance`, :meth:`refresh`); the widgets' callbacks only
post actions to the session (:class:`ShowcaseActions`), like the control panel's. Exactly the
spec's controls, part checkboxes and plots are created, in a folder of their own and in the
"Motion" window, and all of them are retired when the scene goes.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, Protocol

import numpy as np
import viser
import viser.uplot

from poinsot.app.construction import palette
from poinsot.app.construction.construction import PoinsotScene
from poinsot.app.construction.sampled.batch import Frame
from poinsot.app.construction.sampled.motion import MotionCache
from poinsot.app.lessons.support import colors
from poinsot.app.lessons.support.runtime import Showcase
from poinsot.app.lessons.support.spec import (
    START_KEY,
    Choice,
    PlotSpec,
    SceneControl,
    SceneSpec,
    Slider,
    Value,
    screen_table,
)
from poinsot.app.live.panel.motion_window import MotionWindow
from poinsot.app.live.panel.widgets import (
    Pressed,
    Removable,
    Retirement,
    Sent,
    on_user,
    set_value,
)
from poinsot.physics import FreeRigidBody

#: Order of the scene's folder in the panel (after "Scene", before "Playback").
FOLDER_ORDER = 15.0
#: Refresh rates of the readouts and the plots [Hz] (the readouts may change with time).
READOUT_HZ = 5.0
PLOT_HZ = 10.0


class ShowcaseActions(Protocol):
    """What the scene's widgets ask of the session (all non-blocking)."""

    def configure_scene(self, key: str, value: Value) -> None: ...
    def set_part_visible(self, part: str, visible: bool) -> None: ...
    def set_speed(self, speed: float) -> None: ...
    def report(self, error: BaseException) -> None: ...


class LiveShowcase:
    """The scene's widgets and drawing in one session. Frame thread only, except the callbacks."""

    def __init__(
        self,
        spec: SceneSpec,
        client: viser.ClientHandle,
        poinsot: PoinsotScene,
        motion: MotionWindow,
        actions: ShowcaseActions,
        retirement: Retirement,
    ) -> None:
        self.spec = spec
        self.gui = client.gui
        self.motion = motion
        self.actions = actions
        self.retirement = retirement
        self.showcase = Showcase(spec, poinsot, atomic=client.atomic)
        self.desired: dict[str, Value] = spec.defaults()
        self.widgets: list[Removable] = []
        self.plots: dict[str, viser.GuiUplotHandle] = {}
        self.sliders: dict[str, viser.GuiSliderHandle[float]] = {}
        self.part_boxes: dict[str, viser.GuiCheckboxHandle] = {}
        #: The choices shown as buttons, and the option shown pressed in each.
        self.groups: dict[str, tuple[Choice, viser.GuiButtonGroupHandle]] = {}
        self._pressed = Pressed()
        self._shown: dict[str, int] = {}  # plot key -> samples last sent
        self._last_readout = self._last_plot = -1e9
        self._readout_text = ""
        self.folder = self.gui.add_folder(spec.label.removeprefix("Scene: "), order=FOLDER_ORDER)
        with self.folder:
            for n, control in enumerate(spec.controls):
                self.widgets.append(self._add_control(control, float(n)))
            for n, part in enumerate(spec.parts):
                box = self.gui.add_checkbox(part.label, True, order=100.0 + n)
                self.part_boxes[part.key] = box
                self.widgets.append(self._on_user(box, self._part_callback(part.key)))
        self.widgets.append(self.folder)
        with motion.tab:
            for n, plot in enumerate(spec.plots):
                self.plots[plot.key] = _add_plot(self.gui, plot, order=10.0 + n)
        self.widgets.extend(self.plots.values())
        motion.legend.show_rows("scene", [row for part in spec.parts for row in part.rows()])

    # -- widgets (callbacks run on viser's threads) --------------------------------------
    def _on_user(self, handle: Any, callback: Callable[[Sent], None]) -> Any:
        """Run ``callback(sent)`` for changes made in the browser only (:func:`on_user`)."""
        return on_user(handle, callback, self.actions.report)

    def _add_control(self, control: SceneControl, order: float) -> Removable:
        gui = self.gui
        if isinstance(control, Slider):
            slider = gui.add_slider(
                control.label,
                control.lo,
                control.hi,
                control.step,
                control.initial,
                marks=control.marks or None,
                hint=control.hint or None,
                order=order,
            )
            self.sliders[control.key] = slider
            return self._on_user(slider, self._slider_callback(control))
        if control.buttons:
            group = gui.add_button_group(control.label, control.options, order=order)
            self.groups[control.key] = (control, group)
            return self._on_user(group, self._choice_callback(control))
        dropdown = gui.add_dropdown(
            control.label,
            control.options,
            initial_value=control.initial,
            hint=control.hint or None,
            order=order,
        )
        return self._on_user(dropdown, self._choice_callback(control))

    def _slider_callback(self, control: Slider) -> Callable[[Any], None]:
        def callback(handle: Sent) -> None:
            self.actions.configure_scene(control.key, float(handle.value))

        return callback

    def _choice_callback(self, control: Choice) -> Callable[[Any], None]:
        def callback(handle: Any) -> None:
            value = control.value(str(handle.value))
            if control.speed:
                self.actions.set_speed(float(value))
            else:
                self.actions.configure_scene(control.key, value)

        return callback

    def _part_callback(self, part: str) -> Callable[[Sent], None]:
        return lambda handle: self.actions.set_part_visible(part, bool(handle.value))

    # -- frame thread --------------------------------------------------------------------
    @property
    def body(self) -> FreeRigidBody | None:
        return self.showcase.body

    @property
    def loaded(self) -> bool:
        return self.showcase.model is not None

    def configure(self, key: str, value: Value) -> bool:
        """Ask for a new setting; True if the scene must be rebuilt. A control moved drops a
        start pointed at (the control chooses the motion again)."""
        if self.desired.get(key) == value:
            return False
        if key != START_KEY:
            self.desired.pop(START_KEY, None)
        self.desired[key] = value
        return True

    def load(self, frame_time: float, shared: MotionCache | None = None) -> Frame:
        """Build and show the desired settings at t = 0 (ValueError: the last scene is kept);
        ``shared``: a follower's, the model and motion of the process (:class:`Showcase`)."""
        frame = self.showcase.load(self.desired, t=0.0, frame_time=frame_time, shared=shared)
        if START_KEY in self.desired:
            self._show_model_values()
        self._shown.clear()
        self._last_readout = self._last_plot = -1e9
        self._show_pressed()
        self.refresh(0.0, frame.t)
        return frame

    def _show_pressed(self) -> None:
        """Each choice shown as buttons shows the option of the settings just loaded."""
        for key, (control, group) in self.groups.items():
            on = [o for o in control.options if control.value(o) == self.desired.get(key)]
            if on:
                self._pressed.show(group, on[0])

    def _show_model_values(self) -> None:
        """After a start pointed at, a slider whose key the model has (the D the point gave)
        shows the model's value (a server-set value calls no scene callback)."""
        model = self.showcase.model
        for key, handle in self.sliders.items():
            value = getattr(model, key, None)
            if isinstance(value, float) and math.isfinite(value):
                value = min(max(value, handle.min), handle.max)
                self.desired[key] = value
                set_value(handle, value)

    def advance(self, t: float) -> Frame:
        return self.showcase.advance(t)

    def refresh(self, now: float, t: float) -> None:
        """The readouts (at READOUT_HZ, sent when their text changes) and the plots (at
        PLOT_HZ, sent when they show more samples)."""
        if now - self._last_readout >= 1.0 / READOUT_HZ:
            self._last_readout = now
            text = screen_table(self.showcase.readouts(t))
            if text != self._readout_text:
                self._readout_text = text
                self.motion.show_readouts(text)
        if now - self._last_plot >= 1.0 / PLOT_HZ:
            self._last_plot = now
            for key, handle in self.plots.items():
                data = self.showcase.plot(key, t)
                if data is not None and len(data[0]) >= 2 and len(data[0]) != self._shown.get(key):
                    if all(np.all(np.isfinite(a)) for a in data):
                        handle.data = data
                        self._shown[key] = len(data[0])

    def set_visible(self, part: str, visible: bool) -> None:
        self.showcase.set_visible(part, visible)

    def hidden_parts(self) -> tuple[str, ...]:
        """The keys of the scene's parts that are hidden, in the spec's order."""
        return tuple(p.key for p in self.spec.parts if not self.showcase.is_visible(p.key))

    def show_parts(self, hidden: tuple[str, ...]) -> None:
        """Hide exactly the parts ``hidden`` names (a lead's, on a follower), checkboxes too."""
        for part in self.spec.parts:
            visible = part.key not in hidden
            if self.showcase.is_visible(part.key) != visible:
                self.showcase.set_visible(part.key, visible)
                set_value(self.part_boxes[part.key], visible)

    def remove(self) -> None:
        """Take the scene's nodes away and retire its widgets."""
        self.showcase.remove()
        self.retirement.retire(self.widgets)
        self.widgets, self.plots = [], {}
        self.motion.show_readouts("")
        self.motion.legend.show_rows("scene", ())


def _add_plot(gui: viser.GuiApi, plot: PlotSpec, order: float) -> viser.GuiUplotHandle:
    """A plot with labelled axes, created with two samples (an empty first data set leaves
    uPlot's x range NaN, see :class:`~poinsot.app.live.panel.motion_window.MotionWindow`)."""
    series = [viser.uplot.Series(label=plot.x_label)]
    for label, stroke in plot.series:
        # A theory's curve is dashed: told from the motion's without its colour.
        line = viser.uplot.Series(label=label, stroke=stroke, width=2)
        if stroke == colors.PLOT_THEORY:
            line["dash"] = colors.THEORY_DASH
        series.append(line)
    x_axis, y_axis = palette.plot_axes()
    axes = (
        viser.uplot.Axis(**{**x_axis, "label": plot.x_label}),
        viser.uplot.Axis(**{**y_axis, "label": plot.y_label}),
    )
    zeros = np.zeros(2)
    return gui.add_uplot(
        data=(np.array([0.0, 1.0]), *(zeros for _ in plot.series)),
        series=tuple(series),
        title=plot.title,
        scales=palette.plot_scales(),
        axes=axes,
        aspect=1.6,
        order=order,
    )
