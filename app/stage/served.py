"""A stage: one body drawn by the app's own construction on a viser server's *shared* scene,
with no control panel and no session.

What the standalone HTML export records and what ``poinsot screenshot`` photographs: the same
:class:`~poinsot.app.construction.construction.PoinsotScene` the live app draws for each browser,
driven here by explicit times instead of a clock, so that a picture at time T or a clip of S seconds
is reproducible.
"""

from __future__ import annotations

import contextlib
import io
import math
import warnings
from collections.abc import Callable
from contextlib import AbstractContextManager
from typing import Self

import numpy as np
import viser

from poinsot.app.construction import palette
from poinsot.app.construction.construction import PoinsotScene
from poinsot.app.construction.labels.layout import Camera
from poinsot.app.construction.sampled.batch import Frame
from poinsot.app.construction.view import View, apply_lighting, configure_theme
from poinsot.app.model.elements import Element, Solid
from poinsot.app.model.parameters import Parameters
from poinsot.app.model.presets import Preset

#: Largest step of simulation time between two trail updates while seeking [time units]. The
#: scene resamples every step by chord length (at most 48 points a step), so this only bounds
#: how much motion one step may cover.
SEEK_STEP = 0.05
#: Seeking to time T replays at most this much simulation time before T: enough to fill any
#: trail the presets declare (up to 6000 points at chord 0.02 display units).
SEEK_WINDOW = 250.0


def open_server(host: str, port: int, dark_mode: bool) -> viser.ViserServer:
    """A viser server lit and themed as each browser of the app is, without world axes."""
    # viser prints a "listening" banner (and "Server stopped"): noise from a stage, which
    # nobody browses by hand, so it is swallowed.
    with contextlib.redirect_stdout(io.StringIO()):
        server = viser.ViserServer(host=host, port=port, verbose=False)
    try:
        warnings.filterwarnings("ignore", message=r"Queued a \w+ on a closed connection")
        configure_theme(server.gui, dark_mode=dark_mode)
        server.scene.world_axes.visible = False
        apply_lighting(server.scene)
    except BaseException:
        stop_server(server)
        raise
    return server


#: Where a stage draws: None for the server's shared scene (every browser sees it), or a
#: function that opens one browser on the (still empty) server and returns its client, whose
#: own scene is then drawn on. A video draws on its one browser's scene, so that each frame's
#: updates and the render request that follows them ride one queue, in order.
ClientOf = Callable[[viser.ViserServer], viser.ClientHandle]


def scene_target(
    server: viser.ViserServer, client_of: ClientOf | None
) -> tuple[viser.SceneApi, Callable[[], AbstractContextManager[None]], viser.ClientHandle | None]:
    """The scene API a stage draws on, its ``atomic``, and the client if it is one browser's."""
    if client_of is None:
        return server.scene, server.atomic, None
    client = client_of(server)
    return client.scene, client.atomic, client


def themed_construction(
    api: viser.SceneApi,
    atomic: Callable[[], AbstractContextManager[None]],
    elements: frozenset[Element],
    trail_points: int,
    dark_mode: bool,
) -> PoinsotScene:
    """The app's construction on a scene API, in the theme's colours (the look a browser of
    the app gets on that theme): what every stage draws on."""
    scene = PoinsotScene(api, elements, trail_points, atomic=atomic)
    scene.restyle(palette.look(dark_mode))
    return scene


def stop_server(server: viser.ViserServer) -> None:
    with contextlib.redirect_stdout(io.StringIO()):
        server.stop()


class ServedStage:
    """What every stage does with its server and its time: ``with``, :meth:`stop`, the
    :attr:`url`, the initial camera, and :meth:`seek` (by :meth:`advance` from a
    :meth:`restart`, which a stage defines)."""

    server: viser.ViserServer
    frame: Frame
    #: The browser whose own scene the stage draws on (None: the shared scene).
    client: viser.ClientHandle | None = None
    atomic: Callable[[], AbstractContextManager[None]]

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def stop(self) -> None:
        stop_server(self.server)

    @property
    def url(self) -> str:
        return f"http://{self.server.get_host()}:{self.server.get_port()}"

    def advance(self, t: float) -> Frame:
        """Pose the stage at ``t`` and extend its traces (one animation frame)."""
        raise NotImplementedError

    def restart(self, t: float) -> Frame:
        """Show time ``t`` with the traces started afresh there."""
        raise NotImplementedError

    def seek(self, t: float) -> Frame:
        """Show time ``t`` as a running app would: the traces drawn up to ``t``."""
        t = float(t)
        if not math.isfinite(t) or t < 0.0:
            raise ValueError(f"the time must be a finite number >= 0, got {t}")
        start = max(0.0, t - SEEK_WINDOW)
        if t < self.frame.t or start > self.frame.t:
            # Restart the traces at ``start`` instead of drawing one long chord to it.
            self.frame = self.restart(start)
        steps = max(1, math.ceil((t - self.frame.t) / SEEK_STEP))
        for tt in np.linspace(self.frame.t, t, steps + 1)[1:]:
            self.advance(float(tt))
        return self.frame

    def set_initial_camera(self, view: View) -> None:
        """The camera every browser opening the stage (or a recording of it) starts with."""
        camera = self.server.initial_camera
        camera.up = view.up
        camera.position = view.position
        camera.look_at = view.look_at
        camera.fov = math.radians(view.fov_degrees)


class Stage(ServedStage):
    """Create, :meth:`seek` or :meth:`advance`, then :meth:`stop` (or use ``with``)."""

    def __init__(
        self,
        params: Parameters,
        solid: Solid | None,
        elements: frozenset[Element],
        *,
        trail_points: int = 1200,
        dark_mode: bool = True,
        host: str = "127.0.0.1",
        port: int = 0,
        client_of: ClientOf | None = None,
    ) -> None:
        """Raises ValueError (from physics or the scene) for parameters that describe no body.
        ``client_of``: draw on one browser's own scene (:data:`ClientOf`)."""
        body = params.build()
        self.params = params
        self.dark_mode = dark_mode
        self.server = open_server(host, port, dark_mode)
        try:
            api, self.atomic, self.client = scene_target(self.server, client_of)
            self.scene = themed_construction(api, self.atomic, elements, trail_points, dark_mode)
            self.frame: Frame = self.scene.load(body, solid, t=0.0)
        except BaseException:
            self.stop()
            raise
        self.body = body
        self.solid = solid

    @classmethod
    def from_preset(cls, preset: Preset, **kwargs) -> Stage:
        kwargs.setdefault("trail_points", preset.trail_points)
        return cls(Parameters.from_preset(preset), preset.solid, preset.elements, **kwargs)

    # -- time ----------------------------------------------------------------------------
    @property
    def t(self) -> float:
        return self.frame.t

    def advance(self, t: float) -> Frame:
        """Pose the body at ``t`` and extend the traces (one animation frame)."""
        self.frame = self.scene.advance(float(t))
        return self.frame

    def restart(self, t: float) -> Frame:
        return self.scene.load(self.body, self.solid, t=t)

    # -- camera --------------------------------------------------------------------------
    def lay_out_labels(self, view: View, size: tuple[int, int]) -> None:
        """Place the labels for a picture of ``size`` (width, height) from ``view``."""
        width, height = size
        camera = Camera(
            np.asarray(view.position, float),
            np.asarray(view.look_at, float),
            np.asarray(view.up, float),
            math.radians(view.fov_degrees),
            float(width),
            float(height),
        )
        with self.atomic():
            self.scene.lay_out_labels(camera)
