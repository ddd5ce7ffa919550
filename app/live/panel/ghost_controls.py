"""The numerical ghost's controls in a session's panel: a checkbox, the method and its setting;
the ghost itself (:class:`poinsot.app.construction.ghost.ghost.Ghost`) exists only while the box is
ticked.

Lifecycle: the session mounts :class:`GhostControls` at start. Switching on creates the ghost,
whose readout and plot go below the controls (in the control panel, where the box was ticked:
a floating window would cover the panel or the "Motion" window on a 1280 x 720 projector);
switching off removes all of it.

Restarts (what a student expects): the ghost runs on the exact body's simulated time (speed,
pause and step act on both alike). It starts from the exact state at the current time when
switched on and whenever the method or its setting changes (a new race from here); Reset, or
any change of the body, restarts both together at t = 0.

Threads: GUI callbacks only record the wanted configuration (under a lock); the session's
frame thread applies it in :meth:`GhostControls.on_frame` and alone touches the ghost, its
nodes and its widgets. A failure there (a diverged solution, a midpoint rule that cannot
converge) switches the ghost off and says why in the panel.
"""

from __future__ import annotations

import dataclasses
import threading
from typing import Any

import viser

from poinsot.app.construction.construction import PoinsotScene
from poinsot.app.construction.ghost.ghost import Ghost
from poinsot.app.construction.ghost.setting import (
    DEFAULT_METHOD,
    DEFAULT_TOLERANCE,
    DIVISIONS,
    GAME_STEP_RATES,
    TOLERANCES,
    GhostConfig,
    division_label,
    game_step_label,
    tolerance_label,
)
from poinsot.app.construction.sampled.batch import Frame
from poinsot.app.live.panel.engine_upload import EngineLogUpload
from poinsot.app.live.panel.widgets import Retirement, Sent, on_user, set_value
from poinsot.physics.integrators import GAME_STEPS, INTEGRATORS

#: Order of the controls folder in the main panel (after "Show", before the lecture folder).
FOLDER_ORDER = 45.0

GAME_LABELS: dict[str, str] = {
    "no-gyro": "no gyroscopic term (Godot, brax)",
    "gyro-explicit": "explicit gyroscopic (Bullet)",
    "gyro-implicit": "implicit gyroscopic (Bullet)",
    "jolt": "Jolt (|L| kept)",
    "rk4": "RK4, fixed step",
}

METHOD_LABELS: dict[str, str] = {
    **{
        name: f"{name} ({'adaptive' if i.kind == 'adaptive' else 'fixed step'}, order {i.order})"
        for name, i in INTEGRATORS.items()
    },
    # The game engines' steps, by what they do and where they run (GAME_STEPS' titles).
    **{name: f"game: {GAME_LABELS[name]}" for name in GAME_STEPS},
}


class GhostControls:
    """The ghost's controls in the session's panel, and the ghost itself while it is on."""

    def __init__(
        self,
        client: viser.ClientHandle,
        scene: PoinsotScene,
        retirement: Retirement,
        order: float = FOLDER_ORDER,
    ) -> None:
        """``scene``: the construction the ghost races (its body and geometry); ``retirement``:
        where a removed ghost's widgets go to be deleted a moment later."""
        self.client, self.scene, self.retirement = client, scene, retirement
        self._lock = threading.Lock()
        self._wanted = GhostConfig()
        self._applied = GhostConfig()
        self._callback_error = ""
        self.ghost: Ghost | None = None
        gui = self.client.gui
        self.folder = gui.add_folder("Numerical ghost", order=order, expand_by_default=False)
        with self.folder:
            self.enabled = gui.add_checkbox(
                "Show numerical ghost",
                False,
                order=0.0,
                hint="The same body advanced by a numerical integrator, drawn as a pale shell "
                "over the exact one. It starts from the exact state now; Reset or a new body "
                "restarts both at t = 0.",
            )
            self.method = gui.add_dropdown(
                "Method",
                tuple(METHOD_LABELS.values()),
                initial_value=METHOD_LABELS[DEFAULT_METHOD],
                order=1.0,
                hint="A numerical integrator (poinsot.physics.integrators), or a game "
                "engine's step at a game's frame step ('game: ...': no-gyro never flips); "
                "changing it restarts the ghost from the exact state.",
            )
            self.setting = gui.add_dropdown(
                "Tolerance",
                tuple(tolerance_label(t) for t in TOLERANCES),
                initial_value=tolerance_label(DEFAULT_TOLERANCE),
                order=2.0,
                hint="Relative tolerance (adaptive), step h = T/n (T the period of ω) or, "
                "for a game step, h = 1/60 s and the like.",
            )
            self.message = gui.add_markdown("", order=3.0)
            # A game engine's own log, judged against the exact motion (check-engine);
            # below the ghost's readout (10) and plot (11).
            self.engine_log = EngineLogUpload(self.client, order=20.0)
        # Browser changes only, each value checked against its widget first (:func:`on_user`).
        on_user(self.enabled, self._on_enabled, self._record_error)
        on_user(self.method, self._on_method, self._record_error)
        on_user(self.setting, self._on_setting, self._record_error)

    # -- callbacks (viser's threads): record the wish only -------------------------------
    def _record_error(self, exc: Exception) -> None:
        """Shown by the frame thread, never raised into viser."""
        with self._lock:
            self._callback_error = f"{type(exc).__name__}: {exc}"

    def _on_enabled(self, sent: Sent) -> None:
        self.configure(enabled=bool(sent.value))

    def _on_method(self, sent: Sent) -> None:
        for name, label in METHOD_LABELS.items():
            if label == sent.value:
                self.configure(method=name)

    def _on_setting(self, sent: Sent) -> None:
        value = str(sent.value)
        if value.startswith("T/"):
            self.configure(divisions=int(value[2:]))
        elif value.endswith(" s"):
            self.configure(game_rate=int(value[2:-2]))
        else:
            self.configure(tolerance=float(value))

    def configure(self, **changes: Any) -> None:
        """Ask for a configuration (any thread); the frame thread applies it."""
        with self._lock:
            self._wanted = dataclasses.replace(self._wanted, **changes)

    @property
    def wanted(self) -> GhostConfig:
        with self._lock:
            return self._wanted

    # -- frame thread --------------------------------------------------------------------
    def fit(self, exact_body: bool) -> None:
        """After a rebuild: the ghost races an exact torque-free body; without one (a scene that
        poses its own body) its controls are hidden and it is switched off."""
        if not exact_body:
            self.configure(enabled=False)
        self.folder.visible = exact_body

    def on_frame(self, frame: Frame | None) -> None:
        """Per frame, after the exact scene: apply the wanted configuration, advance the ghost.
        Never raises: a failure switches the ghost off and says why in the panel."""
        try:
            self.engine_log.on_frame()
            with self._lock:
                wanted, error = self._wanted, self._callback_error
                self._callback_error = ""
            if error:
                self._show(f"**⚠ {error}**")
            if wanted != self._applied:
                self._apply(wanted)
            if wanted.enabled and frame is not None:
                self._drive(wanted, frame)
        except Exception as exc:  # GhostDiverged, a midpoint that cannot converge, ...
            self._fail(exc)

    def _drive(self, wanted: GhostConfig, frame: Frame) -> None:
        """Create, restart or advance the ghost for this frame."""
        body, geometry = self.scene.body, self.scene.geometry
        if body is None or geometry is None:
            return
        ghost = self.ghost
        if ghost is None:
            with self.client.atomic():
                self.ghost = Ghost(
                    self.client.scene,
                    self.client.gui,
                    self.folder,
                    wanted,
                    body,
                    geometry,
                    frame,
                    self.client.atomic,
                )
            self._show("")
        elif ghost.config != wanted or ghost.body is not body:
            ghost.config = wanted
            ghost.restart(body, geometry, frame)
        elif ghost.state is not None and frame.t < ghost.state.t:
            ghost.restart(body, geometry, frame)  # the clock went back (Reset)
        else:
            with self.client.atomic():
                ghost.update(frame)

    def _apply(self, wanted: GhostConfig) -> None:
        """Mirror the configuration into the widgets (it may come from :meth:`configure`, not
        the browser); create nothing, remove the ghost if off."""
        if wanted.adaptive:
            options = tuple(tolerance_label(t) for t in TOLERANCES)
            label, value = "Tolerance", tolerance_label(wanted.tolerance)
        elif wanted.game:
            options = tuple(game_step_label(r) for r in GAME_STEP_RATES)
            label, value = "Game step", game_step_label(wanted.game_rate)
        else:
            options = tuple(division_label(n) for n in DIVISIONS)
            label, value = "Step h", division_label(wanted.divisions)
        if self.setting.options != options:
            self.setting.options = options
            self.setting.label = label
        set_value(self.enabled, wanted.enabled)
        set_value(self.method, METHOD_LABELS[wanted.method])
        set_value(self.setting, value)
        self._applied = wanted
        if not wanted.enabled and self.ghost is not None:
            self._remove()

    def _remove(self) -> None:
        ghost, self.ghost = self.ghost, None
        if ghost is not None:
            self.retirement.retire(ghost.remove())

    def _fail(self, exc: BaseException) -> None:
        try:
            self._remove()
        finally:
            self.configure(enabled=False)
            self._applied = dataclasses.replace(self._applied, enabled=False)
            set_value(self.enabled, False)
            self._show(f"**⚠ Ghost stopped: {type(exc).__name__}: {exc}**")

    def _show(self, text: str) -> None:
        if self.message.content != text:
            self.message.content = text


def add_ghost_controls(
    client: viser.ClientHandle, scene: PoinsotScene, retirement: Retirement, **kwargs: Any
) -> GhostControls:
    """Mount the ghost's folder on ``client``'s panel; call ``on_frame(frame)`` after each frame
    and :meth:`GhostControls.fit` after each rebuild (the ghost itself exists only while
    switched on)."""
    return GhostControls(client, scene, retirement, **kwargs)
