"""One session's playback: the simulation clock's speed (within the range of what is shown),
pause, step and the trail's length, and the panel's playback group that mirrors them.

The session posts these to its frame thread (:meth:`poinsot.app.live.session.session.Session.post`);
every method here runs there.
"""

from __future__ import annotations

from collections.abc import Callable

from poinsot.app.construction.construction import PoinsotScene
from poinsot.app.live.panel.clock import SimClock
from poinsot.app.model.parameters import SPEED_RANGE, TRAIL_RANGE, clamp

#: "Step" advances this many wall seconds' worth of simulation time.
STEP_SECONDS = 0.1


def clamp_trail(points: int) -> int:
    """A trail length within :data:`~poinsot.app.model.parameters.TRAIL_RANGE`."""
    return int(clamp(int(points), TRAIL_RANGE))


class Playback:
    """The clock's speed and pause and the trail's length, mirrored into the panel by
    ``show(speed, paused, trail)``. Frame thread only."""

    def __init__(
        self,
        clock: SimClock,
        scene: PoinsotScene,
        show: Callable[[float, bool, int], None],
        max_fps: float,
    ) -> None:
        self.clock, self.scene, self._show, self.max_fps = clock, scene, show, float(max_fps)
        #: The speeds the slider offers: a scene may narrow or widen them.
        self.speed_range = SPEED_RANGE

    @property
    def frame_time(self) -> float:
        """Simulation time one frame advances at full frame rate."""
        return self.clock.speed / self.max_fps

    def clamp_speed(self, speed: float) -> float:
        """(Any thread) a speed within the current range."""
        return clamp(float(speed), self.speed_range)

    def take(
        self, speed: float, trail: int, speed_range: tuple[float, float] = SPEED_RANGE
    ) -> None:
        """The playback a preset or a scene starts with."""
        self.speed_range = speed_range
        self.clock.speed = speed
        self.scene.trail_points = trail

    def set_speed(self, speed: float) -> None:
        self.clock.speed = speed
        self.scene.set_frame_time(self.frame_time)

    def set_trail(self, points: int) -> None:
        self.scene.trail_points = points

    def toggle_pause(self) -> None:
        self.clock.paused = not self.clock.paused
        self.show()

    def step(self) -> None:
        self.clock.paused = True
        self.clock.step(STEP_SECONDS * self.clock.speed)
        self.show()

    def show(self) -> None:
        """Mirror the speed, the pause and the trail into the panel."""
        self._show(self.clock.speed, self.clock.paused, self.scene.trail_points)
