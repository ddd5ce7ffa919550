"""The control panel of one session: preset, sliders, playback, show/hide.

Only the controls the current preset declares are shown (:meth:`ControlPanel.declare` creates
whole groups, or shows them again; ``order`` keeps the layout stable whatever the creation
order). A group the preset does not declare is put away: the panel's own groups are hidden and
kept for when a preset declares them again (:class:`~poinsot.app.live.panel.widgets.Shelf`: no
widget of theirs is ever deleted, so no update can reach a deleted one), the groups other
modules add are retired (hidden at once, deleted later).
Callbacks never touch the scene or block: they hand a small action to the session's frame
thread via :class:`Actions`. Programmatic value changes (``event.client is None``) are
ignored, so the session can mirror its state into the widgets without feedback loops. The
time, readouts and the plot of ω are in the floating "Motion" window
(:mod:`poinsot.app.live.panel.motion_window`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Protocol, TypeVar

import viser

from poinsot.app.lessons import SCENES, scene_by_label
from poinsot.app.lessons.support.spec import SceneSpec
from poinsot.app.live.panel import readouts
from poinsot.app.live.panel.body_controls import D_STEP, BodyControls
from poinsot.app.live.panel.legend import caption
from poinsot.app.live.panel.motion_window import MotionWindow
from poinsot.app.live.panel.widgets import (
    Removable,
    Retirement,
    Sent,
    Shelf,
    Widgets,
    on_user,
    set_value,
    write_unless_newer,
)
from poinsot.app.model.docs_site import help_markdown
from poinsot.app.model.elements import Control, Element, Plot
from poinsot.app.model.parameters import (
    SPEED_RANGE,
    TRAIL_RANGE,
    Parameters,
)
from poinsot.app.model.presets import FITTED_TOSS, MENU, PRESETS, Preset
from poinsot.app.viser_private import gui_event_loop, set_dropdown_groups

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
__all__ = ["D_STEP", "ELEMENT_LABELS", "ControlPanel", "Widgets"]

Group = Control | Plot

# Layout: top-level order of the folders and the "Motion" window.
_ORDER: dict[str | Group, float] = {
    "scene": 0.0,
    Control.INERTIA: 10.0,
    "motion": 20.0,
    "playback": 30.0,
    Control.VISIBILITY: 40.0,
    "readouts": 50.0,
    Plot.OMEGA: 60.0,
}

#: The menu's groups, in order: (heading, the labels in it). The browser shows each label whole
#: under its heading (:func:`menu_groups`); a scene's label is shown without "Scene: ".
MENU_PRESETS = "Presets"
MENU_SCENES = "Textbook scenes"
MENU_OWN = "Your own body"
#: The menu's hint (a tooltip) and the line under it naming the choice whole.
MENU_HINT = (
    "Presets: classical cases. Textbook scenes: a lecture's pictures, theory against the "
    "motion. Your own body: a gyroscope recording, a mesh, or a body edited by hand."
)


#: The line that says the ellipsoid can be pointed at (``verb``: "Click" or "Tap").
POINTING_HINT = "_{verb} the ellipsoid to start ω there._"
#: The same line for a challenge's body, whose start is the question's.
FIXED_HINT = "_A challenge's body: its start is fixed._"


def menu_groups() -> list[tuple[str, list[str]]]:
    """The menu's labels under their headings: presets, textbook scenes, your own body."""
    own = MENU[MENU.index(FITTED_TOSS) :]
    return [
        (MENU_PRESETS, [p.label for p in PRESETS]),
        (MENU_SCENES, [s.label for s in SCENES]),
        (MENU_OWN, [p.label for p in own]),
    ]


def shown_label(label: str) -> str:
    """A menu label as the menu shows it under its heading."""
    return label.removeprefix("Scene: ")


#: A widget whose changes the panel listens to.
H = TypeVar(
    "H", bound=viser.GuiInputHandle[Any] | viser.GuiButtonHandle | viser.GuiButtonGroupHandle
)


class Actions(Protocol):
    """What the panel asks of its session (all non-blocking)."""

    def choose_preset(self, preset: Preset) -> None: ...
    def choose_scene(self, scene: SceneSpec) -> None: ...
    def edit(self, change: Callable[[Parameters], Parameters]) -> None: ...
    def set_speed(self, speed: float) -> None: ...
    def toggle_pause(self) -> None: ...
    def step(self) -> None: ...
    def reset(self) -> None: ...
    def set_trail(self, points: int) -> None: ...
    def set_visible(self, element: Element, visible: bool) -> None: ...
    def report(self, error: BaseException) -> None: ...


#: The panel's own groups: put away on the :class:`Shelf` and shown again, never deleted.
_SHELVED: frozenset[Group] = frozenset(Control) | {Plot.OMEGA}


class ControlPanel:
    def __init__(
        self, gui: viser.GuiApi, actions: Actions, preset: Preset, retirement: Retirement
    ) -> None:
        self.gui = gui
        self.actions = actions
        self.retirement = retirement
        self.widgets = Widgets()
        self.shelf = Shelf()
        self._boxes: dict[Element, viser.GuiCheckboxHandle] = {}  # the show/hide checkboxes
        self._groups: dict[Group, list[Removable]] = {}
        self._folders: dict[str | Group, viser.GuiFolderHandle] = {}
        self._elements: frozenset[Element] = frozenset()
        #: Builders of groups that other modules add (uploads: the toss and mesh folders).
        self._extensions: dict[Group, Callable[[], list[Removable]]] = {}
        #: The menu's groups, and entries other modules add (:meth:`add_entry`).
        self._groups_shown = menu_groups()
        self._entries: dict[str, Callable[[], None]] = {}
        with gui.add_folder("Scene", order=_ORDER["scene"]) as folder:
            self._folders["scene"] = folder
            self.preset = gui.add_dropdown(
                "Preset",
                [label for _, labels in self._groups_shown for label in labels],
                initial_value=preset.label,
                hint=MENU_HINT,
            )
            self._send_groups()
            self.source = gui.add_markdown(self._source_text(preset))
            #: The guide's page for what is shown (served at /docs/: :mod:`...docs_site`).
            self.help = gui.add_markdown(help_markdown(preset.key))
            #: What a click (a tap) on the ellipsoid does, and what the last one did.
            self.pointing = gui.add_markdown("")
            self.status = gui.add_markdown("")
        #: "Click" or "Tap" (the pointer's, for a touch screen).
        self.pointing_verb = "Click"
        self.motion = MotionWindow(gui, order=_ORDER["readouts"])
        #: The body's groups (moments, D, side and pole, |ω₀|).
        self._loop = gui_event_loop(gui)  # viser's; runs the menu's and the sliders' writes
        self.body = BodyControls(
            gui, actions.edit, self.widgets, self._folder, self._on_user, self._loop
        )
        #: The browser's choices in the menu (a preset shown for an older one is not written
        #: over a newer one: :meth:`show_preset`).
        self.menu = Sent(preset.label)
        on_user(self.preset, self._choose_preset, self.actions.report, self.menu, inline=True)

    def _on_user(self, handle: H, callback: Callable[[Sent], None]) -> H:
        """Run ``callback(sent)`` for changes made in the browser only (:func:`on_user`), on
        viser's event loop: the panel's callbacks only post to the session's queue."""
        return on_user(handle, callback, self.actions.report, inline=True)

    def _send_groups(self) -> None:
        groups = [
            (name, [(label, shown_label(label)) for label in labels])
            for name, labels in self._groups_shown
        ]
        set_dropdown_groups(self.preset, groups)

    def add_entry(self, group: str, label: str, choose: Callable[[], None]) -> None:
        """A menu entry of another module's (the challenges'): ``choose()`` runs on viser's
        event loop when the browser picks it (it must only post)."""
        self._entries[label] = choose
        self._groups_shown.append((group, [label]))
        self.preset.options = [label for _, labels in self._groups_shown for label in labels]
        self._send_groups()

    def _choose_preset(self, handle: Sent) -> None:
        entry = self._entries.get(handle.value)
        if entry is not None:
            entry()
            return
        for p in MENU:
            if p.label == handle.value:
                self.actions.choose_preset(p)
        scene = scene_by_label(handle.value)
        if scene is not None:
            self.actions.choose_scene(scene)

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
        """Show exactly the declared groups (keeping existing ones, creating or taking back the
        missing ones), put the others away."""
        wanted: set[Group] = set(controls) | set(plots)
        self._elements = elements
        for key in list(self._groups):
            if key not in wanted:
                self._remove_group(key)
        builders: dict[Group, Callable[[], list[Removable]]] = {
            Control.INERTIA: lambda: self.body.build_inertia(params),
            Control.ENERGY: lambda: self.body.build_energy(params),
            Control.SIDE: self.body.build_side,
            Control.OMEGA_NORM: lambda: self.body.build_omega_norm(params),
            Control.SPEED: lambda: self._build_speed(speed),
            Control.PLAYBACK: self._build_playback,
            Control.TRAIL: lambda: self._build_trail(trail),
            Control.VISIBILITY: lambda: self._build_visibility(elements, visible),
            Plot.OMEGA: lambda: [self.motion.add_plot()],
            Plot.MEASURED: lambda: [self.motion.add_plot(measured=True)],
            **self._extensions,
        }
        taken = False
        for key in sorted(wanted, key=lambda k: _ORDER.get(k, 25.0)):
            if key not in self._groups:
                kept = self.shelf.take(key)
                self._groups[key] = builders[key]() if kept is None else self._restore(key, kept)
                taken = taken or kept is not None
        if Control.VISIBILITY in self._groups:
            self._show_boxes(elements, visible)
        self._prune_folders()
        self.motion.legend.show(elements)
        if taken:  # widgets taken back show the values of now
            self.show_parameters(params)
            if self.widgets.speed is not None:
                set_value(self.widgets.speed, float(speed))
            if self.widgets.trail is not None:
                set_value(self.widgets.trail, int(trail))

    def _restore(self, key: Group, handles: list[Removable]) -> list[Removable]:
        """A group taken back from the shelf: the panel and the Motion window hold it again."""
        self.widgets.remember(key, handles)
        plot = handles[0]
        if key is Plot.OMEGA and isinstance(plot, viser.GuiUplotHandle):
            self.motion.restore_plot(plot)
        return handles

    @property
    def groups(self) -> frozenset[Group]:
        return frozenset(self._groups)

    def extend(self, group: Group, build: Callable[[], list[Removable]]) -> None:
        """Let ``build`` create ``group`` (in folders of its own) when a preset declares it."""
        self._extensions[group] = build

    def _remove_group(self, key: Group) -> None:
        self.widgets.forget(key)
        if key in (Plot.OMEGA, Plot.MEASURED):
            self.motion.forget_plot()
        handles = self._groups.pop(key, [])
        if key in _SHELVED:
            self.shelf.stow(key, handles)
        else:
            self.retirement.retire(handles)

    def _folder(self, name: str | Group, label: str, expand: bool = True) -> viser.GuiFolderHandle:
        if name not in self._folders:
            self._folders[name] = self.gui.add_folder(
                label, order=_ORDER[name], expand_by_default=expand
            )
        folder = self._folders[name]
        if not folder.visible:
            folder.visible = True
        return folder

    def _prune_folders(self) -> None:
        used: set[str | Group] = {"scene"}
        if self._groups.keys() & {Control.ENERGY, Control.SIDE, Control.OMEGA_NORM}:
            used.add("motion")
        if self._groups.keys() & {Control.SPEED, Control.PLAYBACK, Control.TRAIL}:
            used.add("playback")
        for key in (Control.INERTIA, Control.VISIBILITY):
            if key in self._groups:
                used.add(key)
        for name, folder in self._folders.items():
            if folder.visible != (name in used):  # kept, like the groups inside
                folder.visible = name in used

    # -- groups --------------------------------------------------------------------------
    def _build_speed(self, speed: float) -> list[Removable]:
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
        self.widgets.speed = self._on_user(slider, lambda h: self.actions.set_speed(float(h.value)))
        return [slider]

    def _build_playback(self) -> list[Removable]:
        with self._folder("playback", "Playback"):
            pause = self.gui.add_button("Pause", icon=viser.Icon.PLAYER_PAUSE, order=1.0)
            step = self.gui.add_button("Step", icon=viser.Icon.PLAYER_TRACK_NEXT, order=2.0)
            reset = self.gui.add_button("Reset", icon=viser.Icon.REFRESH, order=3.0)
        self.widgets.pause = self._on_user(pause, lambda _: self.actions.toggle_pause())
        self._on_user(step, lambda _: self.actions.step())
        self._on_user(reset, lambda _: self.actions.reset())
        return [pause, step, reset]

    def _build_trail(self, trail: int) -> list[Removable]:
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
        self.widgets.trail = self._on_user(slider, lambda h: self.actions.set_trail(int(h.value)))
        return [slider]

    def _build_visibility(
        self, elements: frozenset[Element], visible: Callable[[Element], bool]
    ) -> list[Removable]:
        """A checkbox per element, made once (:meth:`_show_boxes` shows the declared ones)."""
        with self._folder(Control.VISIBILITY, "Show", expand=False):
            for n, element in enumerate(Element):
                if element in elements and element not in self._boxes:
                    box = self.gui.add_checkbox(
                        ELEMENT_LABELS[element], visible(element), order=float(n)
                    )
                    self._boxes[element] = self._on_user(box, self._visibility_callback(element))
        return list(self._boxes.values())

    def _show_boxes(self, elements: frozenset[Element], visible: Callable[[Element], bool]) -> None:
        """Show the checkboxes of ``elements`` (made if missing), ticked as the scene shows
        them; hide the others."""
        if not elements <= self._boxes.keys():
            self._groups[Control.VISIBILITY] = self._build_visibility(elements, visible)
        for element, box in self._boxes.items():
            if box.visible != (element in elements):
                box.visible = element in elements
            if element in elements:
                set_value(box, visible(element))

    def show_visibility(self, visible: Callable[[Element], bool]) -> None:
        """Tick the shown elements' boxes as ``visible`` says (the scene's, mirrored)."""
        for element, box in self._boxes.items():
            if box.visible:
                set_value(box, visible(element))

    def _visibility_callback(self, element: Element) -> Callable[[Sent], None]:
        return lambda handle: self.actions.set_visible(element, bool(handle.value))

    # -- mirroring the session's state ---------------------------------------------------
    def show_preset(
        self, preset: Preset, menu_count: int | None = None, edited: Preset | None = None
    ) -> None:
        """Show ``preset`` as the scene's source; in the menu too, unless the browser has chosen
        again since ``menu_count`` (``menu.count`` read when the change was asked for).
        ``edited``: the preset a hand edit started from, whose source stays (the Scene folder
        keeps its height: the sliders under it do not move)."""
        write_unless_newer(self.preset, preset.label, self.menu, menu_count, self._loop)
        self.source.content = self._source_text(preset, edited)
        self.help.content = help_markdown(preset.key)
        self.show_hint(preset)
        self.motion.legend.show_caption(caption(preset))

    @staticmethod
    def _source_text(preset: Preset, edited: Preset | None = None) -> str:
        """The choice's whole name (the menu's field may cut a long one), and its source (that
        of the preset ``edited`` from, if any)."""
        name = shown_label(preset.label)
        source = (edited or preset).source
        return f"**{name}**<br><small>_Source:_ {readouts.readable(source)}</small>"

    def show_hint(self, preset: Preset) -> None:
        """Say that the ellipsoid can be clicked, where a click starts the motion there (not on
        a scene of its own; a challenge's body says that its start is fixed)."""
        if preset.challenge:
            self.show_pointing(FIXED_HINT)
            return
        pointable = Element.ELLIPSOID in preset.elements and scene_by_label(preset.label) is None
        self.show_pointing(POINTING_HINT.format(verb=self.pointing_verb) if pointable else "")

    def show_pointing(self, text: str) -> None:
        """The line under the source saying what a click on the ellipsoid does (or did)."""
        text = f"<small>{text}</small>" if text else ""
        if self.pointing.content != text:
            self.pointing.content = text

    def show_status(self, message: str) -> None:
        text = f"**⚠ {message}**" if message else ""
        if self.status.content != text:
            self.status.content = text

    def show_parameters(self, params: Parameters) -> None:
        """Mirror parameters into the sliders (and the D slider's range and marks)."""
        self.body.show(params)

    def show_playback(self, speed: float, paused: bool, trail: int) -> None:
        w = self.widgets
        if w.speed is not None:
            set_value(w.speed, float(speed))
        if w.trail is not None:
            set_value(w.trail, int(trail))
        if w.pause is not None:
            w.pause.label = "Play" if paused else "Pause"
            w.pause.icon = viser.Icon.PLAYER_PLAY if paused else viser.Icon.PLAYER_PAUSE
