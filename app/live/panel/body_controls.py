"""The body's controls in one session's panel: the principal moments (I₁, I₂, I₃), the energy
parameter D with its marks, the side of the separatrix and the pole, and |ω₀|.

Each control edits the session's desired :class:`~poinsot.app.model.parameters.Parameters` through
``edit`` (it only queues), and :meth:`BodyControls.show` mirrors a built body's parameters back
into the sliders (ranges, marks, values), but no value into a slider whose newer value from the
browser is still on its way to the parameters (:meth:`~.widgets.Sent.newer_than`). The panel
(:mod:`.panel`) declares which of these groups a preset shows.
"""

from __future__ import annotations

import asyncio
import math
from collections.abc import Callable, Iterable
from contextlib import AbstractContextManager
from typing import Any

import viser

from poinsot.app import viser_private as private
from poinsot.app.live.panel.widgets import (
    Pressed,
    Removable,
    Sent,
    Widgets,
    on_loop,
    set_marks,
    set_value,
)
from poinsot.app.model.elements import Control
from poinsot.app.model.parameters import INERTIA_RANGE, OMEGA_NORM_RANGE, Parameters

SIDE_OPTIONS = ("minor axis", "major axis")
POLE_OPTIONS = ("+ pole", "− pole")

#: Step of the D slider; a value within half a step of I₂ is I₂ exactly (the separatrix).
D_STEP = 0.001


def slider_range(default: tuple[float, float], values: Iterable[float]) -> tuple[float, float]:
    """A slider's range: ``default``, widened to hold ``values`` (a body of one's own can have
    a moment below the usual range, or spin faster), to round ends (hundredths below, tenths
    above)."""
    values = [float(v) for v in values]
    lo = min(default[0], *(math.floor(100.0 * v) / 100.0 if v >= 0.01 else v for v in values))
    return lo, max(default[1], *(math.ceil(10.0 * v) / 10.0 for v in values))


def energy_marks(params: Parameters) -> tuple[tuple[float, str], ...]:
    lo, hi = params.D_range
    mid = params.intermediate
    marks = [(lo, "min I"), (hi, "max I")]
    if lo < mid < hi:
        marks.insert(1, (mid, "I₂"))
    return tuple(marks)


class BodyControls:
    """Builds the body's groups into the panel's folders and mirrors parameters into them."""

    def __init__(
        self,
        gui: viser.GuiApi,
        edit: Callable[[Callable[[Parameters], Parameters]], None],
        widgets: Widgets,
        folder: Callable[[str | Control, str], AbstractContextManager[Any]],
        on_user: Callable[[Any, Callable[[Sent], None]], Any],
        loop: asyncio.AbstractEventLoop,
    ) -> None:
        """``folder(name, label)``: the panel's folder to build in; ``on_user(handle,
        callback)``: listen to the browser's changes only (:func:`~.widgets.on_user`);
        ``loop``: viser's event loop, where the sliders' values are written (:meth:`_mirror`)."""
        self.gui, self.edit, self.widgets = gui, edit, widgets
        self.folder, self.on_user, self._loop = folder, on_user, loop
        #: Per slider: the browser's values (their count as they arrived), and the count of
        #: the last one applied to the parameters asked for (:meth:`_edit`, :meth:`_mirror`).
        self._sent: dict[str, Sent] = {}
        self._applied: dict[str, tuple[Sent, int]] = {}
        #: The pole's group (built with the side's), and the options shown pressed in both.
        self._pole: viser.GuiButtonGroupHandle | None = None
        self._pressed = Pressed()

    def build_inertia(self, params: Parameters) -> list[Removable]:
        sliders = []
        lo, hi = slider_range(INERTIA_RANGE, params.inertia)
        with self.folder(Control.INERTIA, "Body: principal moments"):
            for i in range(3):
                slider = self.gui.add_slider(
                    f"I{'₁₂₃'[i]}",
                    lo,
                    hi,
                    0.01,
                    float(params.inertia[i]),
                    order=float(i),
                    hint="A principal moment of inertia (mass × length²).",
                )
                sliders.append(self.on_user(slider, self._inertia_callback(i)))
        self.widgets.inertia = tuple(sliders)
        return list(sliders)

    def _inertia_callback(self, index: int) -> Callable[[Sent], None]:
        def callback(handle: Sent) -> None:
            value = float(handle.value)
            self._edit(f"I{index}", handle, lambda p: p.with_inertia(index, value))

        return callback

    def build_energy(self, params: Parameters) -> list[Removable]:
        lo, hi = params.D_range
        with self.folder("motion", "Motion"):
            slider = self.gui.add_slider(
                "D = |L|²/2T",
                lo,
                hi,
                D_STEP,
                float(params.D),
                order=0.0,
                marks=energy_marks(params),
                hint="Energy parameter in [I_min, I_max]; D = I₂ (its mark) is the separatrix.",
            )

        def move(handle: Sent) -> None:
            value = float(handle.value)
            self._edit("D", handle, lambda p: p.with_D(value, snap=D_STEP / 2))

        self.widgets.energy = self.on_user(slider, move)
        return [slider]

    def build_side(self) -> list[Removable]:
        with self.folder("motion", "Motion"):
            side = self.gui.add_button_group("Side of separatrix", SIDE_OPTIONS, order=1.0)
            pole = self.gui.add_button_group("Polhode", POLE_OPTIONS, order=2.0)

        def choose_side(handle: Sent) -> None:
            choice = "major" if handle.value == SIDE_OPTIONS[1] else "minor"
            self.edit(lambda p: p.mirrored(choice))

        def choose_pole(handle: Sent) -> None:
            sign = 1 if handle.value == POLE_OPTIONS[0] else -1
            self.edit(lambda p: p.with_pole(sign))

        self.widgets.side, self._pole = side, pole
        return [self.on_user(side, choose_side), self.on_user(pole, choose_pole)]

    def build_omega_norm(self, params: Parameters) -> list[Removable]:
        with self.folder("motion", "Motion"):
            slider = self.gui.add_slider(
                "|ω₀|",
                *slider_range(OMEGA_NORM_RANGE, (params.omega_norm,)),
                0.05,
                float(params.omega_norm),
                order=3.0,
                hint="Initial angular speed (rad per time unit).",
            )

        def move(handle: Sent) -> None:
            value = float(handle.value)
            self._edit("omega", handle, lambda p: p.with_omega_norm(value))

        self.widgets.omega_norm = self.on_user(slider, move)
        return [slider]

    def show(self, params: Parameters) -> None:
        """Mirror parameters into the sliders (and the D slider's range and marks). The
        sliders' values are written on viser's event loop in one call (:meth:`_mirror`): one
        wake-up of the loop for the whole body, not one a slider (a class of followers mirrors
        every move of the lecturer's)."""
        w = self.widgets
        writes: list[Callable[[], None]] = []
        lo, hi = slider_range(INERTIA_RANGE, params.inertia)
        for i, (slider, moment) in enumerate(zip(w.inertia, params.inertia, strict=False)):
            if (slider.min, slider.max) != (lo, hi):
                slider.min, slider.max = lo, hi
            writes.append(self._mirror(f"I{i}", slider, float(moment)))
        if w.energy is not None:
            w.energy.min, w.energy.max = params.D_range
            set_marks(w.energy, energy_marks(params))
            writes.append(self._mirror("D", w.energy, float(params.D)))
        if w.side is not None and w.side.visible != params.has_separatrix:
            w.side.visible = params.has_separatrix  # a symmetric body has no separatrix
        if w.side is not None and self._pole is not None:
            self._pressed.show(w.side, SIDE_OPTIONS[params.side() == "major"])
            self._pressed.show(self._pole, POLE_OPTIONS[params.pole_sign < 0])
        if w.omega_norm is not None:
            lo, hi = slider_range(OMEGA_NORM_RANGE, (params.omega_norm,))
            if (w.omega_norm.min, w.omega_norm.max) != (lo, hi):
                w.omega_norm.min, w.omega_norm.max = lo, hi
            writes.append(self._mirror("omega", w.omega_norm, float(params.omega_norm)))
        if writes:
            on_loop(self._loop, run_writes, writes, self.gui)

    # -- a slider moved in the browser, and the body shown ----------------------------------
    def _edit(self, key: str, sent: Sent, change: Callable[[Parameters], Parameters]) -> None:
        """Queue ``change``, the browser's value of slider ``key`` as it arrived (viser's event
        loop: ``sent.count`` counts it); applied, it is the last of that slider's values the
        parameters hold."""
        count = sent.count
        self._sent[key] = sent

        def apply(params: Parameters) -> Parameters:
            new = change(params)
            self._applied[key] = (sent, count)
            return new

        self.edit(apply)

    def _mirror(self, key: str, slider: Any, value: float) -> Callable[[], None]:
        """The write that shows ``value`` in slider ``key``, unless the browser has sent it a
        newer value than the parameters shown hold: a body built for an older value (keys
        pressed faster than the body is rebuilt) would put the thumb back under the user's
        hand, and the next key would step from there. The newer value is shown once applied
        (snapped if need be).

        The check and the write run on viser's event loop (made on the frame thread, run there
        by :meth:`show`). viser stores a browser's value in the handle there, then runs the
        callbacks that count it (:func:`~.widgets.on_user`); a write from the frame thread
        landing between the two would replace the user's value before it is counted, and the
        edit would ask for the mirrored one. The count the shown parameters hold is read here,
        when they are shown: by the time the loop writes, the frame thread may have applied a
        newer value."""
        sent = self._sent.get(key)
        applied = 0
        if sent is not None:
            applied_sent, count = self._applied.get(key, (sent, 0))
            applied = count if applied_sent is sent else 0

        def write() -> None:
            now = self._sent.get(key)
            if now is not None and (now is not sent or now.newer_than(applied)):
                return  # the browser's newer value is on its way to the parameters
            set_value(slider, value)

        return write


def run_writes(writes: list[Callable[[], None]], gui: viser.GuiApi) -> None:
    """On viser's event loop: the sliders' writes of one :meth:`BodyControls.show`, in order
    (to nobody, silently, if ``gui``'s browser left since they were handed over)."""
    with private.gui_quiet_if_closed(gui):
        for write in writes:
            write()
