"""Where a session's motion comes from: its own, or the lecturer's while it follows.

The one place that tells the two apart. The frame loop asks it the frame's simulation time
(:meth:`MotionSource.now`), the rebuild whether it holds the other sessions' frames
(:attr:`MotionSource.holds_others`) and which of the process's caches it builds a body or a
scene from (:attr:`MotionSource.motions`, :attr:`MotionSource.scenes`):

- its own: the session's clock, its own bodies and scenes, and a rebuild that runs alone (the
  student who moved a slider sees the new body at once: :class:`~..hardening.budget.RebuildGate`);
- following (:mod:`..classroom.lead`): the lead's time, one clock for every follower of the
  process (:meth:`~..classroom.follow.FollowHub.now`; the session's own before the lead's
  first state), the process's one motion of a body and one model and motion of a scene, and a
  rebuild that holds nobody (it mirrors the lead's move, whose rebuild took precedence where
  the lead is; a class of followers rebuilding one after the other would hold each other's
  frames for the whole round).
"""

from __future__ import annotations

from typing import Protocol

from poinsot.app.construction.sampled.motion import MotionCache
from poinsot.app.live.classroom.follow import FollowHub
from poinsot.app.live.panel.clock import SimClock


class Following(Protocol):
    """What the source reads of the session's "Class" folder: whether it follows, and the
    process's hub."""

    mode: str
    hub: FollowHub


class MotionSource:
    """A session's motion source (see the module's docstring). Frame thread."""

    def __init__(self, clock: SimClock, following: Following) -> None:
        self._clock, self._following = clock, following

    @property
    def follows(self) -> bool:
        """The lead's motion, not the session's own."""
        return self._following.mode == "follow"

    @property
    def lead_known(self) -> bool:
        """Following, and the lead's state received (its time is the hub's)."""
        return self.follows and self._following.hub.state is not None

    def now(self) -> float:
        """The frame's simulation time."""
        if self.follows:
            t = self._following.hub.now()
            if t is not None:
                return t
        return float(self._clock.now())

    @property
    def holds_others(self) -> bool:
        """A rebuild holds the other sessions' frames (its own, not a follower's)."""
        return not self.follows

    @property
    def motions(self) -> MotionCache | None:
        """The process's bodies' motions while following; None: the session builds its own."""
        return self._following.hub.motions if self.follows else None

    @property
    def scenes(self) -> MotionCache | None:
        """The process's scenes' models and motions while following; None: its own."""
        return self._following.hub.scenes if self.follows else None
