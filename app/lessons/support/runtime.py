"""One scene on one scene API: its model for the current settings, the elements of Poinsot's
construction it reuses, and its own drawing, driven by explicit times.

A live session (:mod:`poinsot.app.live.panel.showcase`), the screenshot and the HTML export
(:mod:`poinsot.app.stage.scene_stage`) all drive a scene through a :class:`Showcase`: :meth:`load`
per parameter change (physics once, then the static shapes), :meth:`advance` per frame (poses
and trail increments only). Not thread-safe: one thread drives a showcase.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from contextlib import AbstractContextManager

import numpy as np

from poinsot.app.construction.construction import PoinsotScene
from poinsot.app.construction.sampled.batch import Frame
from poinsot.app.construction.sampled.motion import Motion, MotionCache
from poinsot.app.lessons.support.spec import Canvas, Model, Readout, SceneSpec, Settings, Value
from poinsot.physics import FreeRigidBody


class Showcase:
    """Create on a :class:`PoinsotScene` (the scene's elements are declared on it), then
    :meth:`load` and :meth:`advance`; :meth:`remove` takes the scene's own nodes away."""

    def __init__(
        self,
        spec: SceneSpec,
        poinsot: PoinsotScene,
        atomic: Callable[[], AbstractContextManager[None]] = contextlib.nullcontext,
    ) -> None:
        self.spec = spec
        self.poinsot = poinsot
        self._atomic = atomic
        poinsot.declare(spec.elements)
        poinsot.trail_points = spec.trail_points
        self.drawing = spec.draw(Canvas(poinsot.api, poinsot.root, poinsot.body_frame))
        self.settings: dict[str, Value] = spec.defaults()
        self.model: Model | None = None
        self.frame: Frame | None = None

    @property
    def body(self) -> FreeRigidBody | None:
        """The exact torque-free motion on screen, if the scene shows one."""
        return None if self.model is None else self.model.body

    def load(
        self,
        settings: Settings | None = None,
        *,
        t: float = 0.0,
        frame_time: float = 1 / 60,
        shared: MotionCache | None = None,
    ) -> Frame:
        """Build the model for ``settings`` (default: the current ones) and show it at ``t``.
        ``shared``: the model and its motion come from there, built once for every showcase
        that asks for the same scene, settings and frame time (a lecturer's followers). Raises
        ValueError (from physics or the scene's checks) with the previous scene kept."""
        wanted = dict(self.settings if settings is None else settings)
        motion = None
        if shared is None:
            model = self.spec.build(wanted)
        else:
            key = (self.spec.name, tuple(sorted(wanted.items())))
            model = shared.get(key, lambda: self.spec.build(wanted))
            if model.body is not None:
                body, solid = model.body, model.solid
                motion = shared.get(
                    (key, frame_time), lambda: Motion.prepare(body, solid, frame_time)
                )
        previous = self.model
        with self._atomic():
            frame = self._show(model, t, frame_time, motion)
            try:
                self.drawing.fit(model, self.poinsot.geometry)
            except ValueError:
                if previous is not None:  # put the last valid scene back
                    self._show(previous, t, frame_time)
                raise
            self.model, self.settings = model, wanted
            self.frame = self.drawing.advance(t, frame)
        return self.frame

    def _show(
        self, model: Model, t: float, frame_time: float, motion: Motion | None = None
    ) -> Frame | None:
        """Load the construction with the model's body (or empty it): nothing is sent if this
        raises."""
        if model.body is not None:
            return self.poinsot.load(
                model.body, model.solid, t=t, frame_time=frame_time, motion=motion
            )
        self.poinsot.unload()
        return None

    def set_frame_time(self, frame_time: float) -> None:
        """The clock's speed changed (see :meth:`PoinsotScene.set_frame_time`)."""
        if self.body is not None:
            self.poinsot.set_frame_time(frame_time)

    def advance(self, t: float) -> Frame:
        """The frame at clock time ``t``: the construction's, then the scene's own parts."""
        if self.model is None:
            raise RuntimeError("load() the scene before advance()")
        with self._atomic():
            frame = self.poinsot.advance(t) if self.model.body is not None else None
            self.frame = self.drawing.advance(t, frame)
        return self.frame

    def set_visible(self, part: str, visible: bool) -> None:
        self.drawing.set_visible(part, visible)

    def is_visible(self, part: str) -> bool:
        return self.drawing.is_visible(part)

    def readouts(self, t: float) -> tuple[Readout, ...]:
        """The model's rows, exactly the ones the spec declares, in its order."""
        if self.model is None:
            return ()
        rows = self.model.readouts(t)
        names = tuple(r.quantity for r in rows)
        if names != self.spec.readouts:
            raise RuntimeError(f"scene {self.spec.name} filled {names}, not {self.spec.readouts}")
        return rows

    def plot(self, key: str, t: float) -> tuple[np.ndarray, ...] | None:
        """The data of plot ``key`` at ``t`` (None before a model is loaded)."""
        return None if self.model is None else self.model.plot(key, t)

    def remove(self) -> None:
        """Remove the scene's own nodes and forget its body (the construction's elements stay
        declared until the next scene or preset declares its own)."""
        self.drawing.remove()
        self.poinsot.unload()
        self.model = None
