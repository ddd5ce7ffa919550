"""What a session sends after a frame besides the frame itself, each at its own rate: a sample
of the "Motion" window's plot, the plot's whole window, the time readout, and the widgets
retired from the panel (deleted a moment later).

The plot resends its whole window, at most every :data:`PLOT_MIN_FRAMES` frames and only on a
frame that carries neither traces nor a step of the label layout, so that no frame carries two
of them (12 Hz at 60 fps: a window that waits a frame still keeps up).
"""

from __future__ import annotations

from poinsot.app.construction.sampled.batch import Frame
from poinsot.app.live.panel.motion_window import MotionWindow
from poinsot.app.live.panel.widgets import Retirement

#: Plot and time-readout refresh rates [Hz].
PLOT_HZ = 10.0
TIME_HZ = 5.0
#: The plot's window is sent at most every PLOT_MIN_FRAMES frames.
PLOT_MIN_FRAMES = 5


class Refresh:
    """Call :meth:`after_frame` after each frame (frame thread only)."""

    def __init__(self, motion: MotionWindow, retirement: Retirement) -> None:
        self.motion, self.retirement = motion, retirement
        self._last_plot = self._last_time = 0.0  # monotonic times of the last refreshes
        self._frames_since_plot = PLOT_MIN_FRAMES  # frames drawn since the plot was last sent
        self._plot_unsent = False  # a sample was recorded since

    def after_frame(self, now: float, frame: Frame | None, paused: bool, busy: bool) -> None:
        """``busy``: this frame already carries traces or a step of the label layout."""
        motion = self.motion
        self._frames_since_plot += 1
        if now - self._last_plot >= 1.0 / PLOT_HZ and frame is not None:
            self._last_plot = now
            if paused and motion.fill_history(frame.t, frame.omega, 1.0 / PLOT_HZ):
                self._plot_unsent = True  # a paused link's plot: its history up to t
            motion.record_plot(frame.t, frame.omega, frame.wxyz)
            self._plot_unsent = True
        if self._plot_unsent and self._frames_since_plot >= PLOT_MIN_FRAMES and not busy:
            self._frames_since_plot, self._plot_unsent = 0, False
            motion.send_plot()
        if now - self._last_time >= 1.0 / TIME_HZ:
            self._last_time = now
            motion.show_time(frame.t if frame is not None else 0.0, paused)
            self.retirement.collect(now)
