"""A scene on a viser server's shared scene, with no control panel and no session: what
``poinsot screenshot --scene`` photographs and ``poinsot export-html --scene`` records.

The same :class:`~poinsot.app.scenes.runtime.Showcase` a live session draws, driven by explicit
times (like :class:`poinsot.app.exports.stage.Stage` for the presets), so that a picture at time
T or a clip of S seconds is reproducible.
"""

from __future__ import annotations

import contextlib
import io
import math
import warnings

import numpy as np
import viser

from poinsot.app.exports.stage import SEEK_STEP, SEEK_WINDOW
from poinsot.app.scene.batch import Frame
from poinsot.app.scene.construction import PoinsotScene
from poinsot.app.scene.view import View, apply_lighting, configure_theme
from poinsot.app.scenes.runtime import Showcase
from poinsot.app.scenes.spec import SceneSpec, Settings


class SceneStage:
    """Create, :meth:`seek` or :meth:`advance`, then :meth:`stop` (or use ``with``)."""

    def __init__(
        self,
        spec: SceneSpec,
        settings: Settings | None = None,
        *,
        dark_mode: bool = True,
        host: str = "127.0.0.1",
        port: int = 0,
    ) -> None:
        """Raises ValueError (from physics or the scene) for settings that describe no body."""
        self.spec = spec
        self.dark_mode = dark_mode
        with contextlib.redirect_stdout(io.StringIO()):  # viser's banner: nobody browses this
            self.server = viser.ViserServer(host=host, port=port, verbose=False)
        try:
            warnings.filterwarnings("ignore", message=r"Queued a \w+ on a closed connection")
            configure_theme(self.server.gui, dark_mode=dark_mode)
            self.server.scene.world_axes.visible = False
            apply_lighting(self.server.scene)
            self.poinsot = PoinsotScene(
                self.server.scene, frozenset(), spec.trail_points, atomic=self.server.atomic
            )
            self.showcase = Showcase(spec, self.poinsot, atomic=self.server.atomic)
            self.frame: Frame = self.showcase.load(settings, t=0.0)
        except BaseException:
            self.stop()
            raise

    # -- context manager -----------------------------------------------------------------
    def __enter__(self) -> SceneStage:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def stop(self) -> None:
        with contextlib.redirect_stdout(io.StringIO()):
            self.server.stop()

    @property
    def url(self) -> str:
        return f"http://{self.server.get_host()}:{self.server.get_port()}"

    # -- time ----------------------------------------------------------------------------
    def advance(self, t: float) -> Frame:
        """Pose the scene at ``t`` and extend its traces (one animation frame)."""
        self.frame = self.showcase.advance(float(t))
        return self.frame

    def seek(self, t: float) -> Frame:
        """Show time ``t`` as a running app would: the traces drawn up to ``t``."""
        t = float(t)
        if not math.isfinite(t) or t < 0.0:
            raise ValueError(f"the time must be a finite number >= 0, got {t}")
        start = max(0.0, t - SEEK_WINDOW)
        if t < self.frame.t or start > self.frame.t:
            self.frame = self.showcase.load(t=start)
        steps = max(1, math.ceil((t - self.frame.t) / SEEK_STEP))
        for tt in np.linspace(self.frame.t, t, steps + 1)[1:]:
            self.advance(float(tt))
        return self.frame

    # -- camera --------------------------------------------------------------------------
    def set_initial_camera(self, view: View) -> None:
        """The camera every browser opening the stage (or a recording of it) starts with."""
        camera = self.server.initial_camera
        camera.up = view.up
        camera.position = view.position
        camera.look_at = view.look_at
        camera.fov = math.radians(view.fov_degrees)
