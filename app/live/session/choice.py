"""What one session shows: a preset (a named one, or "Custom" once a slider moved it away) or a
chosen scene, declared to the construction and the control panel.

Choosing a preset asks the session's :class:`~.rebuild.BodyBuild` for its body; choosing a scene
mounts its widgets and drawing (:class:`~.showcase.LiveShowcase`), which the next rebuild loads;
a hand edit asks for the edited body and may turn the preset into "Custom". Frame thread only.
"""

from __future__ import annotations

from collections.abc import Callable

import viser

from poinsot.app.construction.construction import PoinsotScene
from poinsot.app.construction.view import DEFAULT_VIEW
from poinsot.app.lessons.support.spec import SceneSpec, Value
from poinsot.app.live.panel.panel import ControlPanel
from poinsot.app.live.panel.playback import Playback
from poinsot.app.live.panel.showcase import LiveShowcase, ShowcaseActions
from poinsot.app.live.panel.widgets import Retirement
from poinsot.app.live.session.rebuild import BodyBuild
from poinsot.app.model.elements import ALL_ELEMENTS, Control, Element, Plot
from poinsot.app.model.parameters import SPEED_RANGE, Parameters
from poinsot.app.model.presets import CUSTOM, Preset


class Choice:
    """The preset or scene shown; ``resolve`` turns the menu's "Fitted toss" and "Body from a
    mesh" into the session's own, ``actions`` are what a scene's widgets ask of the session.
    ``menu_count``: the menu's ``count`` read when the change was asked for
    (:meth:`~.panel.ControlPanel.show_preset`)."""

    def __init__(
        self,
        preset: Preset,
        build: BodyBuild,
        *,
        client: viser.ClientHandle,
        scene: PoinsotScene,
        panel: ControlPanel,
        playback: Playback,
        retirement: Retirement,
        actions: ShowcaseActions,
        resolve: Callable[[Preset], Preset],
    ) -> None:
        self.build, self.client, self.scene, self.panel = build, client, scene, panel
        self.playback, self.retirement, self.actions = playback, retirement, actions
        self._resolve = resolve
        self.preset = preset
        #: The scene being shown, if one is chosen instead of a preset.
        self.showcase: LiveShowcase | None = None

    def apply_preset(self, preset: Preset, menu_count: int | None = None) -> None:
        """Show ``preset`` (Custom keeps the body asked for; a named one asks for its own)."""
        preset = self._resolve(preset)  # this session's own toss or mesh, if it has one
        self._leave_scene()
        self.preset = preset
        if preset is not CUSTOM:
            self.build.take(preset)
            self.playback.take(preset.speed, preset.trail_points)
        self.scene.declare(preset.elements)
        self._declare(preset.controls, preset.plots, preset.elements, self.build.desired)
        self.panel.show_preset(preset, menu_count)
        self.playback.show()

    def apply_scene(self, scene: SceneSpec, menu_count: int | None = None) -> None:
        """Show ``scene``: the construction's elements it declares, the panel's groups it shares
        (speed, playback, trail, show/hide), and its own controls, parts, readouts and plots."""
        self._leave_scene()
        self.preset = scene.identity()
        self.playback.take(scene.initial_speed(), scene.trail_points, scene.speed_range)
        self.showcase = LiveShowcase(
            scene, self.client, self.scene, self.panel.motion, self.actions, self.retirement
        )
        self._declare(scene.shared, frozenset(), scene.elements, self.build.desired)
        self.panel.show_preset(self.preset, menu_count)
        self.playback.show()
        scene.view.apply(self.client.camera)
        self.build.dirty = True

    def configure(self, key: str, value: Value) -> None:
        """A control of the current scene moved: rebuilt if the scene takes the value."""
        if self.showcase is not None and self.showcase.configure(key, value):
            self.build.dirty = True

    def set_part_visible(self, part: str, visible: bool) -> None:
        if self.showcase is not None:
            self.showcase.set_visible(part, visible)

    def edit(
        self, change: Callable[[Parameters], Parameters], menu_count: int | None = None
    ) -> None:
        """Ask for ``change`` of the parameters asked for; edited by hand, a preset becomes
        Custom."""
        new = change(self.build.desired)
        if not self.build.want(new):
            return
        if self.preset is not CUSTOM and not new.matches(self.preset):
            # Edited by hand: the scene becomes "Custom", which declares everything, and keeps
            # the controls the preset had (a toss's upload folder). Only additions happen here,
            # so the slider being dragged, or the ellipsoid clicked, stays in place.
            edited = self.preset
            self.preset = CUSTOM
            self.scene.declare(ALL_ELEMENTS)
            self._declare(CUSTOM.controls | edited.controls, CUSTOM.plots, CUSTOM.elements, new)
            self.panel.show_preset(CUSTOM, menu_count, edited)

    def _declare(
        self,
        controls: frozenset[Control],
        plots: frozenset[Plot],
        elements: frozenset[Element],
        params: Parameters,
    ) -> None:
        """Show exactly these groups in the panel, with the session's playback settings."""
        speed, trail = self.playback.clock.speed, self.scene.trail_points
        self.panel.declare(controls, plots, elements, params, speed, trail, self.scene.is_visible)

    def _leave_scene(self) -> None:
        """Remove the current scene (if any); the next preset rebuilds its body."""
        if self.showcase is not None:
            self.showcase.remove()
            self.showcase = None
            self.playback.speed_range = SPEED_RANGE
            self.build.unload()
            DEFAULT_VIEW.apply(self.client.camera)
