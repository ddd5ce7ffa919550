"""A scene on a viser server's shared scene, with no control panel and no session: what
``poinsot screenshot --scene`` photographs and ``poinsot export-html --scene`` records.

The same :class:`~poinsot.app.lessons.support.runtime.Showcase` a live session draws, driven by
explicit times (like :class:`poinsot.app.stage.served.Stage` for the presets), so that a picture at
time T or a clip of S seconds is reproducible.
"""

from __future__ import annotations

from poinsot.app.construction.sampled.batch import Frame
from poinsot.app.lessons.support.runtime import Showcase
from poinsot.app.lessons.support.spec import SceneSpec, Settings
from poinsot.app.stage.served import (
    ClientOf,
    ServedStage,
    open_server,
    scene_target,
    themed_construction,
)


class SceneStage(ServedStage):
    """Create, :meth:`seek` or :meth:`advance`, then :meth:`stop` (or use ``with``)."""

    def __init__(
        self,
        spec: SceneSpec,
        settings: Settings | None = None,
        *,
        dark_mode: bool = True,
        host: str = "127.0.0.1",
        port: int = 0,
        client_of: ClientOf | None = None,
    ) -> None:
        """Raises ValueError (from physics or the scene) for settings that describe no body.
        ``client_of``: draw on one browser's own scene (:data:`ClientOf`)."""
        self.spec = spec
        self.dark_mode = dark_mode
        self.server = open_server(host, port, dark_mode)
        try:
            api, self.atomic, self.client = scene_target(self.server, client_of)
            self.poinsot = themed_construction(
                api, self.atomic, frozenset(), spec.trail_points, dark_mode
            )
            self.showcase = Showcase(spec, self.poinsot, atomic=self.atomic)
            self.frame = self.showcase.load(settings, t=0.0)
        except BaseException:
            self.stop()
            raise

    def advance(self, t: float) -> Frame:
        """Pose the scene at ``t`` and extend its traces (one animation frame)."""
        self.frame = self.showcase.advance(float(t))
        return self.frame

    def restart(self, t: float) -> Frame:
        return self.showcase.load(t=t)
