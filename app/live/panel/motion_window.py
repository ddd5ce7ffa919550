"""The left column of a session ("What you see"): the caption and the legend
(:mod:`poinsot.app.live.panel.legend`), the time, the readouts of the motion's constants, and the
live plot of ω in the body frame.

It is docked on the left edge and the control panel on the right one, so that neither covers
the 3D view (which takes the width between them, its picture centred there) and a lecture sees
the names, colours and numbers beside the scene without scrolling the control panel. The plot
exists only while the preset declares it (:class:`~poinsot.app.model.elements.Plot`); the session
records a sample and sends the window of the last PLOT_SAMPLES at the plot's refresh rate. For
an uploaded toss the plot also shows the measured ω (:mod:`poinsot.app.live.panel.overlay`).
"""

from __future__ import annotations

import numpy as np
import viser
import viser.uplot

from poinsot.app.construction import palette
from poinsot.app.construction.sampled.frames import wxyz
from poinsot.app.live.panel import plots, readouts
from poinsot.app.live.panel.legend import Legend
from poinsot.app.live.panel.overlay import LEGEND, Measured, measured_series, merge
from poinsot.physics import FreeRigidBody

#: Number of plot samples kept (one per plot refresh, 10 per second: the last 30 s).
PLOT_SAMPLES = 300
#: Width of the left column [CSS px]: the 3D view keeps about half of a 1280 px screen.
WINDOW_WIDTH = 300


class MotionWindow:
    """Time, readouts and (when declared) the plot of ω. Driven by the session's frame thread."""

    def __init__(self, gui: viser.GuiApi, order: float) -> None:
        self.gui = gui
        self.window = window = gui.add_panel(order=order)
        self.tab = window.add_tab("What you see", viser.Icon.EYE)
        with self.tab:
            self.legend = Legend(gui, order=-2.0)
            self.time = gui.add_markdown(readouts.time_markdown(0.0, False), order=0.0)
            self.readouts = gui.add_markdown("", order=1.0)
            #: What the ω plot draws: ω, the angles of L to the axes, the Euler angles.
            self.choice = plots.PlotChoice(gui, order=1.9)
            #: The text size's style element (:mod:`poinsot.app.live.lecture.display`; the control
            #: panel has one too: a folded column's content, and its style, is not on the page).
            self.style = gui.add_html("", order=100.0)
        gui.main_panel.dock_right()
        window.dock_left()
        window.set_width(WINDOW_WIDTH)
        self.plot: viser.GuiUplotHandle | None = None
        self._t: list[float] = []
        self._omega: list[np.ndarray] = []
        self._wxyz: list[np.ndarray] = []
        #: The motion the readouts describe (the plot's angles are read off its moments and L).
        self.body: FreeRigidBody | None = None
        #: An uploaded toss's samples, drawn when the plot was added with ``measured=True``.
        self.measured = Measured(np.zeros(0), np.zeros((0, 3)), np.zeros((0, 3)))
        self._with_measured = False

    # -- the plot's lifecycle (the panel declares and retires it) ---------------------------
    def add_plot(self, measured: bool = False) -> viser.GuiUplotHandle:
        """The plot of ω; with ``measured``, three more series: the measured ω as dots."""
        series = [viser.uplot.Series(label="t")]
        for i, color in enumerate(palette.PLOT_SERIES):
            series.append(viser.uplot.Series(label=f"ω{'₁₂₃'[i]}", stroke=color, width=2))
        if measured:
            series += measured_series()
        self._with_measured = measured
        title = "ω: measured (dots), exact fit (lines)" if measured else "ω in the body frame"
        zeros = np.zeros(2)
        # Created with two samples, not empty: viser's uPlot keeps the x range relative to the
        # data's extent, and an empty first data set (extent -inf..inf) leaves it NaN forever.
        with self.tab:
            self.plot = self.gui.add_uplot(
                data=(np.array([0.0, 1.0]), *[zeros] * (len(series) - 1)),
                series=tuple(series),
                title=title,
                scales=self.measured.scales() if measured else palette.plot_scales(),
                axes=palette.plot_axes(),
                legend=LEGEND if measured else None,
                aspect=1.7,
                order=2.0,
            )
        self.clear_plot()
        self.choice.reset()
        self.choice.show(not measured)
        return self.plot

    def show_measured(self, measured: Measured) -> None:
        """The samples of an uploaded toss, drawn by a plot added with ``measured=True``."""
        self.measured = measured
        if self.plot is not None and self._with_measured:
            self.plot.scales = measured.scales()

    def restore_plot(self, plot: viser.GuiUplotHandle) -> None:
        """The plot of ω, put away by the panel, is shown again: record into it afresh."""
        self.plot = plot
        self._with_measured = False
        self.clear_plot()
        self.choice.show(True)

    def forget_plot(self) -> None:
        """The plot was removed (by the panel): stop recording."""
        self.plot = None
        self._with_measured = False
        self.choice.show(False)

    # -- mirroring the session's state ---------------------------------------------------
    def show_readouts(self, text: str) -> None:
        self.readouts.content = text

    def set_body(self, body: FreeRigidBody) -> None:
        """The body whose moments and L the plot's angles are read with (its readouts are
        :meth:`show_readouts`'s)."""
        self.body = body

    def show_time(self, t: float, paused: bool) -> None:
        text = readouts.time_markdown(t, paused)
        if self.time.content != text:
            self.time.content = text

    def clear_plot(self) -> None:
        self._t, self._omega, self._wxyz = [], [], []

    def fill_history(self, t: float, omega: np.ndarray, step: float) -> bool:
        """A page that opens paused at ``t`` (a link) would plot one sample: the window up to
        ``t`` is evaluated from the body instead, one sample every ``step`` seconds, when the
        plot holds fewer than two samples and the body is the one drawn (its ω at ``t`` is the
        frame's ``omega``). True if the plot was filled."""
        body = self.body
        if self.plot is None or body is None or len(self._t) >= 2 or t < 2 * step:
            return False
        if not np.allclose(body.omega(t), omega, rtol=1e-6, atol=1e-9):
            return False
        times = t - step * np.arange(min(PLOT_SAMPLES, int(t / step)))[::-1]
        self._t = [float(v) for v in times]
        self._omega = list(np.asarray(body.omega(times), dtype=np.float64))
        self._wxyz = list(wxyz(body.attitude(times)))
        return True

    def record_plot(self, t: float, omega: np.ndarray, wxyz: np.ndarray | None = None) -> None:
        """Add a sample (the session does, at the plot's refresh rate, then sends)."""
        if self.plot is None:
            return
        if self._t and t < self._t[-1]:
            self.clear_plot()
        if self._t and t == self._t[-1]:
            return
        self._t.append(float(t))
        self._omega.append(np.array(omega, dtype=np.float64))  # a copy: not a batch's view
        self._wxyz.append(np.array((1.0, 0.0, 0.0, 0.0) if wxyz is None else wxyz, np.float64))
        if len(self._t) > PLOT_SAMPLES:
            del self._t[0], self._omega[0], self._wxyz[0]

    def restart_plot(self, t: float, omega: np.ndarray, wxyz: np.ndarray | None = None) -> None:
        """A new motion from ``t``: the plot holds its first sample alone, sent at once (the
        old curve does not stay on screen, even while the clock is paused)."""
        self.clear_plot()
        self.record_plot(t, omega, wxyz)
        self.send_plot()

    def send_plot(self) -> bool:
        """Send the samples kept (a single one drawn as a point: the plot of a new motion)."""
        if self.plot is None or not self._t:
            return False
        single = len(self._t) == 1
        if single:  # uPlot draws no line of one point: the sample twice, as a dot
            self._t.append(self._t[0])
            self._omega.append(self._omega[0])
            self._wxyz.append(self._wxyz[0])
        try:
            return self._send(self.plot)
        finally:
            if single:
                del self._t[1:], self._omega[1:], self._wxyz[1:]

    def _send(self, plot: viser.GuiUplotHandle) -> bool:
        w = np.asarray(self._omega)
        y = w
        if not self._with_measured:
            y = plots.values(self.choice.apply(plot), self.body, w, np.asarray(self._wxyz))
        data: tuple[np.ndarray, ...] = (np.asarray(self._t), *(y[:, i].copy() for i in range(3)))
        if self._with_measured:
            data = merge(data[0], w, self.measured)
        if all(np.all(np.isfinite(a)) for a in data[:4]):  # measured NaN: no sample there
            plot.data = data
            return True
        return False
