"""One session's frame thread: it wakes at its client's frame time (or when an action is posted),
runs the session's queued work, and draws a frame if the browser has taken the one before
(:class:`~..hardening.pacing.Pacer`). Frames are due on a cadence
(:func:`~..hardening.pacing.next_due`): a frame drawn late shortens the wait for the next, so
that the rate is the pacer's, not the pacer's less the frames' own delays.

While another session rebuilds, a due frame waits for that rebuild to end
(:meth:`~..hardening.budget.RebuildGate.hold` wakes it) for at most
:data:`~..hardening.budget.HOLD_SECONDS`, so that a
slider move elsewhere runs alone and many students dragging sliders never freeze the others.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

from poinsot.app.live.hardening.budget import HOLD_SECONDS, RebuildGate
from poinsot.app.live.hardening.pacing import Pacer, SessionStats, next_due


class FrameLoop:
    """:meth:`start` the thread, :meth:`wake` it from any thread, :meth:`close` it once."""

    def __init__(
        self,
        name: str,
        *,
        pacer: Pacer,
        budget: RebuildGate,
        stats: SessionStats,
        max_fps: float,
        work: Callable[[], None],
        draw: Callable[[float], bool],
        report: Callable[[BaseException], None],
    ) -> None:
        """``work()``: the queued actions and a rebuild, before each frame; ``draw(now)``: a
        frame, True if it was drawn (False: the browser has not taken the one before);
        ``report(error)``: anything either raised (the loop survives it)."""
        self.name = name
        self.pacer, self.budget, self.stats = pacer, budget, stats
        self.max_fps = float(max_fps)
        self._work, self._draw, self._report = work, draw, report
        self._wake, self._stop = threading.Event(), threading.Event()
        self._due_now = False
        self.thread: threading.Thread | None = None

    def start(self) -> None:
        thread = threading.Thread(target=self._run, name=self.name, daemon=True)
        thread.start()
        self.thread = thread  # only a started thread is ever joined by close()

    def wake(self) -> None:
        """Run the work now rather than at the next frame time (any thread; never blocks)."""
        self._wake.set()

    def draw_now(self) -> None:
        """From the work (frame thread): the next frame is due at once, not at the rate's next
        time (a follower whose frames the process's cast sent, drawing its own again)."""
        self._due_now = True

    def close(self, timeout: float | None = None) -> None:
        """Stop the thread (never called from it). Safe to call twice."""
        self._stop.set()
        self._wake.set()
        if timeout is not None and self.thread is not None:
            if self.thread is not threading.current_thread():
                self.thread.join(timeout)

    @property
    def running(self) -> bool:
        return self.thread is not None and self.thread.is_alive()

    def _run(self) -> None:
        next_frame = due = time.monotonic()
        held = False  # a due frame waits for another session's rebuild (RebuildGate.hold)
        while not self._stop.is_set():
            delay = next_frame - time.monotonic()
            if delay > 0 and not (held and not self.budget.rebuilding):
                self._wake.wait(delay)  # set by an action, or by the rebuild's end if held
                self._wake.clear()
            if self._stop.is_set():
                break
            cpu0 = time.thread_time()
            drawn = False
            try:
                self._work()
                now = time.monotonic()
                if self._due_now:  # the work asked for a frame now (:meth:`draw_now`)
                    self._due_now, next_frame = False, min(next_frame, now)
                if held and not self.budget.rebuilding:
                    next_frame = now  # the rebuild that held this frame is over
                if now >= next_frame and now - due < HOLD_SECONDS and self.budget.hold(self._wake):
                    held, next_frame = True, due + HOLD_SECONDS  # a slider move elsewhere first
                elif now >= next_frame:
                    held = False
                    drawn = self._draw(now)
                    step = self.pacer.interval
                    if drawn:
                        next_frame = due = next_due(due, now, step)
                    else:  # not taken yet: polled again at the pacer's lowered rate
                        next_frame = now + step
            except Exception as exc:  # the loop must survive anything; the user sees it
                self._report(exc)
                next_frame = time.monotonic() + 1.0 / self.max_fps
            if drawn:
                self.stats.frame_cpu_seconds.append(time.thread_time() - cpu0)
