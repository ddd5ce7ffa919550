"""What a session's frame thread does (:class:`~.frame_loop.FrameLoop` calls it): before each
frame the queued actions and, if they asked for one, a rebuild; a frame, if the browser has
taken the one before; after it the refreshes at their rates.

The frame's time is the motion source's (:mod:`.source`: the session's own, or the lead's
while following); each frame goes out in one atomic window, flushed at once. A follower whose
frame is the lead's has its poses sent by the process's cast (:mod:`..classroom.cast`) and
draws the rest of its frames (traces, labels, plot) at a low rate.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Protocol

import viser

from poinsot.app.construction.construction import PoinsotScene
from poinsot.app.construction.sampled.batch import Frame
from poinsot.app.live.classroom.cast import Source
from poinsot.app.live.classroom.shared_frames import SharedFrames
from poinsot.app.live.hardening.pacing import Pacer, SessionStats
from poinsot.app.live.panel.clock import SimClock
from poinsot.app.live.session.actions import ActionQueue
from poinsot.app.live.session.choice import Choice
from poinsot.app.live.session.front import Status
from poinsot.app.live.session.refresh import Refresh
from poinsot.app.live.session.source import MotionSource


class OnFrame(Protocol):
    """A tool that follows the frames drawn (the lecture tools' camera and display, the
    ghost)."""

    def on_frame(self, frame: Frame) -> None: ...


class AfterFrame(Protocol):
    """A tool told after each frame (the "Class" folder: a lead publishes its state)."""

    def on_frame(self, now: float) -> None: ...


class FrameWork:
    """The session's frame-thread work (see the module's docstring). ``tools``: told of each
    frame drawn, in order; ``laid_out``: whether this frame carries a step of the labels'
    layout (the plot then waits); ``header(now, t)``: the page's header after a frame."""

    def __init__(
        self,
        client: viser.ClientHandle,
        *,
        pacer: Pacer,
        queue: ActionQueue,
        status: Status,
        choice: Choice,
        source: MotionSource,
        clock: SimClock,
        refresh: Refresh,
        tools: tuple[OnFrame, ...],
        publish: AfterFrame,
        laid_out: Callable[[], bool],
        header: Callable[[float, float], None],
        shared: SharedFrames,
        own_view: Callable[[], bool],
    ) -> None:
        self.client, self.pacer, self.queue, self.status = client, pacer, queue, status
        self.choice, self.build, self.source, self.clock = choice, choice.build, source, clock
        self.scene: PoinsotScene = choice.build.scene
        self.stats: SessionStats = choice.build.stats
        self.refresh, self.tools, self.publish = refresh, tools, publish
        self._laid_out = laid_out
        self._header = header  # (now, t): the page's header (a phone's sheet: t, the regime)
        #: A follower's poses sent by the process's cast while its frame is the lead's;
        #: ``own_view()``: the follower's view is its own (its ghost, a ride-along camera).
        self.shared, self._own_view = shared, own_view

    def work(self) -> None:
        """Before each frame: the queued actions, then a rebuild if they asked for one (none
        once the client has left: what they would send goes to nobody)."""
        outbox = self.pacer.outbox
        try:
            if outbox.closed():
                return
            with outbox.quiet_if_left():
                self._drain()
                if self.build.dirty:
                    self._rebuild()
        finally:
            self.shared.worked()  # a follower that made the lead's new body: the others go on
        self.shared.update(self._shared_source())

    def _rebuild(self) -> None:
        """Rebuild; a lead's new body or scene then goes to its followers at once, not after
        its next frame (up to a frame interval later, every follower's rebuild waiting). A
        follower in the cast rebuilds through the gate its own frames pass, one at a time in
        the process (:meth:`.classroom.shared_frames.SharedFrames.drawing`): a hall's rebuilds
        after the lead's move would otherwise all want the interpreter at once."""
        with self.shared.drawing():
            self.build.rebuild(self.choice.showcase)
        self.publish.on_frame(time.monotonic())

    def _shared_source(self) -> Source | None:
        """What the cast poses this follower from, if its frame is the lead's (a body, not a
        lecture scene; the lead's state received; no rebuild pending; its view not its own);
        None: its own frames."""
        if not self.source.lead_known or self.choice.showcase is not None:
            return None
        if self.build.dirty or self._own_view():
            return None
        return Source.of(self.scene)

    def draw(self, now: float) -> bool:
        """Draw a frame, unless the browser has not yet taken the one before (:class:`Pacer`:
        skipped, the rate lowered). A frame's messages go out at once, in one atomic window."""
        if not self.pacer.may_draw():
            return False
        with self.shared.drawing(), self.pacer.outbox.quiet_if_left(), self.client.atomic():
            self._advance()
            self._after(now)
        self.client.flush()  # out now, not at viser's next 1/60 s window
        self.pacer.sent()
        return True

    def _after(self, now: float) -> None:
        """After a frame: the plot, the time readout and retired widgets at their rates
        (:class:`~.refresh.Refresh`), and the scene's own readouts and plots."""
        self.publish.on_frame(now)  # a lead publishes its state
        busy = self.scene.sent_traces or self._laid_out()  # a layout step
        frame, showcase = self.build.frame, self.choice.showcase
        self.refresh.after_frame(now, frame, self.clock.paused, busy)
        if frame is not None:  # a phone's sheet: t and the regime in its header
            self._header(now, frame.t)
        if showcase is not None and frame is not None:
            showcase.refresh(now, frame.t)  # its readouts and plots, at their rates

    def _drain(self) -> None:
        refused = self.queue.run(self.status.report)
        if refused:  # said after the rebuild they ask for (which clears the status line)
            if self.build.dirty:
                self._rebuild()
            self.status.say(f"Too many changes at once: {refused} were ignored; please redo them.")

    def _advance(self) -> None:
        showcase = self.choice.showcase
        if (self.build.body is None) if showcase is None else not showcase.loaded:
            return
        start = time.perf_counter()
        t = self.source.now()  # the session's own time, or the lead's while following
        frame = self.scene.advance(t) if showcase is None else showcase.advance(t)
        self.build.frame = frame
        for tool in self.tools:
            tool.on_frame(frame)
        self.stats.frame_seconds.append(time.perf_counter() - start)
        self.stats.frames += 1
