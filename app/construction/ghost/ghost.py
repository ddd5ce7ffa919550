"""The numerical ghost: the same body advanced by a numerical integrator, drawn as a translucent
ice-blue cage over the exact ellipsoid, with a live readout and a plot of its error.

What a student sees: at the moment the ghost is switched on it coincides with the body; then
the chosen method carries it along on its own. RK45 at a loose tolerance visibly drifts out of
the ellipsoid (its energy error grows without bound); the symplectic splitting wobbles but its
energy error stays bounded; the implicit midpoint keeps the energy and |L| to rounding yet
still falls behind in phase [HLW06 §IX]. The plot shows log₁₀ of the ω error, of the attitude
error (the geodesic angle between the two rotations) and of the energy error against
simulated time.

A :class:`Ghost` exists only while the ghost is switched on (its controls, which create and
remove it, are :mod:`poinsot.app.live.panel.ghost_controls`). It owns the scene nodes
``/space/ghost`` (a faint shell, the three principal sections and the principal axes, posed
by the ghost's attitude) and ``/space/ghost_tip`` (the tip of the ghost's ω, which leaves the
invariable plane when the energy drifts), and the readout and the plot in the panel folder it
is given. Per frame only the two poses travel; the readout refreshes at 5 Hz and the plot at
4 Hz.

The numbers come from :class:`poinsot.physics.integrators.Propagation`, which carries the
integrator's whole state from frame to frame (restarting RK45 at every frame would hide its
drift, see there), and the error measures from :mod:`poinsot.physics.core.errors`.

Work per frame: each frame advances the propagation to the frame's time with at most as many
steps (or RHS evaluations) as fit into WORK_BUDGET seconds at the measured cost per step. A
setting too fine for the speed leaves the ghost behind the body; it is then drawn, and its
error measured, at the time it has reached, and the readout says so. A non-finite solution
raises :class:`GhostDiverged`; nothing non-finite is ever sent.
"""

from __future__ import annotations

import collections
import dataclasses
import math
import time
from collections.abc import Callable
from contextlib import AbstractContextManager

import numpy as np
import viser
import viser.uplot

from poinsot.app.construction import palette, updates
from poinsot.app.construction.ellipsoid import add_ellipsoid, fit_ellipsoid
from poinsot.app.construction.geometry import Geometry, triple
from poinsot.app.construction.ghost.setting import GhostConfig
from poinsot.app.construction.sampled.batch import Frame
from poinsot.app.construction.sampled.frames import (
    rotation_from_wxyz,
    wxyz_from_xyzw,
    xyzw_from_wxyz,
)
from poinsot.physics import FreeRigidBody
from poinsot.physics.core import errors, rotations
from poinsot.physics.integrators import Propagation, State

#: Seconds of integrator work allowed per frame (a frame at 60 Hz lasts 16.7 ms; the exact
#: scene and viser need about 1 ms of it).
WORK_BUDGET = 0.004
#: Bounds of the per-frame work cap [steps or RHS evaluations], whatever the measured cost.
MIN_WORK, MAX_WORK = 32, 200_000
#: Starting estimate of the cost of one step or RHS evaluation [s] (the slowest measured here,
#: the midpoint's fixed-point solve, is ~12 us); replaced by measurements.
INITIAL_UNIT_COST = 2e-5
#: The ghost counts as behind the body when it lags by more than this fraction of the time
#: (rounding of the times themselves is not a lag).
BEHIND_FRACTION = 1e-6

#: Readout and plot refresh rates [Hz].
READOUT_HZ = 5.0
PLOT_HZ = 4.0
#: Plot samples kept. The plot covers the whole run since the ghost started: a sample is taken
#: every ``interval`` of simulated time; when the buffer is full every other sample is dropped
#: and the interval doubled (so the plot stays small and keeps the early, small errors).
PLOT_POINTS = 400
PLOT_FIRST_INTERVAL = 0.05
# The plot shows log10 of the errors on a linear axis. viser's uPlot does take a log scale
# (``distr: 3``), but its tick labels need a JavaScript formatter, which viser cannot send
# (the default prints 1e-6 as "0"); ticks given as data are also drawn outside the fitted
# range (over the legend), and changing the axis options rebuilds the chart, which then loses
# its x range. log10 values get uPlot's own ticks and a range fitted to the data, so a drift of
# one decade stays visible.
#: Errors below this are drawn at this value (rounding level; log10 needs a positive number).
PLOT_FLOOR = 1e-16
_LOG_FLOOR = math.log10(PLOT_FLOOR)

#: The cage: a faint shell a little larger than the ellipsoid (no z-fighting when they
#: coincide) and, what reads best on a projector, its three principal sections (the ellipses
#: in the planes of two principal axes) as lines, with its principal axes: where the ghost has
#: drifted, its cage visibly leans out of the amber ellipsoid.
GHOST_INFLATE = 1.02
GHOST_RING_SEGMENTS = 96
GHOST_TIP_RADIUS = 0.03


def principal_sections(semi_axes: np.ndarray, segments: int) -> np.ndarray:
    """The ellipsoid's three sections by the planes of two principal axes, as line segments
    (3 * segments, 2, 3) in the body frame (drawing geometry)."""
    theta = np.linspace(0.0, 2.0 * np.pi, segments + 1)
    rings = []
    for i, j in ((0, 1), (1, 2), (2, 0)):
        points = np.zeros((segments + 1, 3))
        points[:, i] = semi_axes[i] * np.cos(theta)
        points[:, j] = semi_axes[j] * np.sin(theta)
        rings.append(np.stack([points[:-1], points[1:]], axis=1))
    return np.concatenate(rings).astype(np.float32)


class GhostDiverged(RuntimeError):
    """The numerical solution stopped being finite (it is never drawn)."""


@dataclasses.dataclass(frozen=True)
class GhostErrors:
    """The ghost against the exact solution at one time (error metrics only)."""

    t: float
    omega: float  # |ω_ghost − ω| / |ω|
    attitude: float  # geodesic angle between the two attitudes [rad]
    energy: float  # (T_ghost − T) / T, signed
    momentum: float  # (|L_ghost| − |L|) / |L|, signed

    @classmethod
    def between(
        cls,
        body: FreeRigidBody,
        t: float,
        omega: np.ndarray,
        quat_xyzw: np.ndarray,
        exact_omega: np.ndarray,
        exact_xyzw: np.ndarray,
    ) -> GhostErrors:
        """The ghost's ``omega`` and attitude quaternion against the exact ones at ``t``
        (:mod:`poinsot.physics.core.errors`). Raises GhostDiverged if any number is not finite."""
        if not (np.all(np.isfinite(omega)) and np.all(np.isfinite(quat_xyzw))):
            raise GhostDiverged(f"the numerical solution is not finite at t = {t:.3g}")
        L = float(np.linalg.norm(body.angular_momentum))
        with np.errstate(divide="ignore", invalid="ignore"):  # a zero reference: not finite
            result = cls(
                float(t),
                float(errors.omega_error(omega, exact_omega)),
                float(errors.attitude_error(quat_xyzw, exact_xyzw)),
                float(errors.energy(body.inertia, omega)) / body.energy - 1.0,
                float(errors.angular_momentum_norm(body.inertia, omega)) / L - 1.0,
            )
        values = (result.omega, result.attitude, result.energy, result.momentum)
        if not all(math.isfinite(v) for v in values):
            raise GhostDiverged(f"the ghost's error is not finite at t = {t:.3g}")
        return result


class ErrorHistory:
    """The errors since the ghost started, thinned to at most PLOT_POINTS samples."""

    def __init__(self, started: float) -> None:
        self.started = started
        self.t: list[float] = []
        self.errors: list[tuple[float, float, float]] = []  # ω, attitude, |energy|
        self.interval = PLOT_FIRST_INTERVAL
        self.dirty = False  # recorded since the plot was last sent

    def record(self, e: GhostErrors) -> None:
        if e.t == self.started:
            return  # the start itself: the exact state, zero error (the axis fits the data)
        if self.t and e.t < self.t[-1] + self.interval:
            return
        self.t.append(e.t)
        self.errors.append((e.omega, e.attitude, abs(e.energy)))
        if len(self.t) > PLOT_POINTS:
            # Keep the first sample and every other one after it; sample half as often.
            self.t, self.errors = self.t[::2], self.errors[::2]
            self.interval *= 2.0
        self.dirty = True

    def plot_data(self) -> tuple[np.ndarray, ...] | None:
        """(t, log10 of the three errors) for the plot, or None before two finite samples."""
        if len(self.t) < 2:
            return None
        e = np.log10(np.maximum(np.asarray(self.errors, dtype=np.float64), PLOT_FLOOR))
        data = (np.asarray(self.t, dtype=np.float64), e[:, 0], e[:, 1], e[:, 2])
        return data if all(np.all(np.isfinite(a)) for a in data) else None


class GhostCage:
    """The ghost's scene nodes: its shell, principal sections and axes, and the tip of its ω."""

    def __init__(self, scene: viser.SceneApi, root: str) -> None:
        self.node = scene.add_frame(f"{root}/ghost", show_axes=False)
        self.shell = add_ellipsoid(
            scene, f"{root}/ghost/ellipsoid", palette.GHOST, palette.GHOST_OPACITY
        )
        self.axes, self.rings = (
            scene.add_line_segments(
                f"{root}/ghost/{name}",
                np.zeros((1, 2, 3), np.float32),
                palette.GHOST,
                thickness=palette.GHOST_WIDTH_PX,
                thickness_units="screen",
            )
            for name in ("axes", "sections")
        )
        self.tip = scene.add_icosphere(
            f"{root}/ghost_tip", radius=GHOST_TIP_RADIUS, color=palette.GHOST, cast_shadow=False
        )

    def fit(self, geometry: Geometry) -> None:
        """Size the cage as the body's ellipsoid (a new body)."""
        semi = geometry.semi_axes
        fit_ellipsoid(self.shell, semi * GHOST_INFLATE)
        ends = geometry.axis_ends()
        self.axes.points = np.stack([-ends, ends], axis=1).astype(np.float32)
        self.rings.points = principal_sections(semi * GHOST_INFLATE, GHOST_RING_SEGMENTS)

    def pose(self, wxyz: np.ndarray, tip: tuple[float, float, float]) -> None:
        updates.set_wxyz(self.node, wxyz)
        updates.set_position(self.tip, np.asarray(tip))

    def remove(self) -> None:
        for handle in (self.shell, self.axes, self.rings, self.tip, self.node):
            handle.remove()


def add_error_plot(gui: viser.GuiApi, t0: float) -> viser.GuiUplotHandle:
    """The plot of log₁₀ of the errors, created with two samples at the floor (see
    :meth:`poinsot.app.live.panel.panel.ControlPanel`: an empty first data set breaks uPlot's
    range)."""
    return gui.add_uplot(
        data=(t0 + np.array([0.0, 1.0]), *(np.full(2, _LOG_FLOOR) for _ in range(3))),
        series=(
            viser.uplot.Series(label="t"),
            *(
                viser.uplot.Series(label=label, stroke=color, width=2)
                for label, color in zip(
                    ("ω", "attitude", "|ΔT|/T"), palette.GHOST_PLOT_SERIES, strict=True
                )
            ),
        ),
        title="log₁₀ error vs exact solution",
        scales=palette.plot_scales(),
        axes=palette.plot_axes(),
        aspect=1.5,
        order=11.0,
    )


class Ghost:
    """The live ghost of one session: its propagation, scene nodes and widgets. Created when
    switched on, :meth:`remove`\\ d when switched off; driven by one thread (the session's
    frame thread)."""

    def __init__(
        self,
        scene: viser.SceneApi,
        gui: viser.GuiApi,
        container: viser.GuiFolderHandle,
        config: GhostConfig,
        body: FreeRigidBody,
        geometry: Geometry,
        frame: Frame,
        atomic: Callable[[], AbstractContextManager[None]],
        root: str = "/space",
    ) -> None:
        self.config = config
        self._atomic = atomic
        self.unit_cost = INITIAL_UNIT_COST
        self.behind = 0.0  # simulated time the ghost lags the body by (0: in step)
        self.errors: GhostErrors | None = None
        self.state: State | None = None
        # The ghost's own time per advancing frame [s] (benchmark, tests).
        self.frame_seconds: collections.deque[float] = collections.deque(maxlen=2000)
        self._last_readout = self._last_plot = -math.inf
        with atomic():
            self.cage = GhostCage(scene, root)
        with container:
            self.readout = gui.add_markdown("", order=10.0)
            self.plot = add_error_plot(gui, frame.t)
        self.restart(body, geometry, frame)

    # -- (re)start -----------------------------------------------------------------------
    def restart(self, body: FreeRigidBody, geometry: Geometry, frame: Frame) -> None:
        """Start again from the exact state shown in ``frame`` (a new body: sizes too)."""
        self.body, self.geometry = body, geometry
        self.propagation = Propagation(
            self.config.method,
            body.inertia,
            frame.omega,
            rotation_from_wxyz(frame.wxyz),
            self.config.setting(body),
            t0=frame.t,
        )
        self.started = float(frame.t)  # after its propagation: a new start has it (other threads)
        self.state = None
        self.errors = None
        self.behind = 0.0
        self.history = ErrorHistory(self.started)
        with self._atomic():
            self.cage.fit(geometry)
            self.update(frame, force=True)

    # -- per frame -----------------------------------------------------------------------
    def update(self, frame: Frame, force: bool = False) -> None:
        """Advance to the body's time (within the work cap) and pose the ghost."""
        now = time.monotonic()
        if not force and self.state is not None and self.state.t == frame.t:
            self._refresh(now)
            return
        start = time.perf_counter()
        state = self._advance(frame.t)
        errors = self._measure(state, frame)
        self._pose(state)
        self.state, self.errors = state, errors
        self.history.record(errors)
        self.frame_seconds.append(time.perf_counter() - start)
        self._refresh(now, force=force)

    @property
    def work_cap(self) -> int:
        """Steps (or RHS evaluations) allowed in one frame."""
        return int(min(max(WORK_BUDGET / self.unit_cost, MIN_WORK), MAX_WORK))

    def _advance(self, t: float) -> State:
        """Advance the propagation towards ``t`` within the work cap; learn the cost per step
        and how far behind ``t`` the ghost stayed."""
        start = time.perf_counter()
        cost0 = self.propagation.cost
        state = self.propagation.advance(t, self.work_cap)
        work = state.cost - cost0
        if work >= MIN_WORK:  # a per-step cost, not the fixed overhead of a call
            elapsed = time.perf_counter() - start
            self.unit_cost = 0.7 * self.unit_cost + 0.3 * elapsed / work
        tolerance = BEHIND_FRACTION * max(abs(t), 1.0)
        self.behind = max(t - state.t, 0.0) if t - state.t > tolerance else 0.0
        return state

    def _measure(self, state: State, frame: Frame) -> GhostErrors:
        """The errors at the ghost's own time (the frame's, unless the ghost is behind)."""
        if self.behind:
            omega, rotation, _ = self.body.sample(np.array([state.t]))
            exact_omega, exact_xyzw = omega[0], rotation.as_quat()[0]
        else:
            exact_omega, exact_xyzw = frame.omega, xyzw_from_wxyz(frame.wxyz)
        quat = state.attitude.as_quat()
        return GhostErrors.between(self.body, state.t, state.omega, quat, exact_omega, exact_xyzw)

    def _pose(self, state: State) -> None:
        quat = state.attitude.as_quat()
        q = wxyz_from_xyzw(quat)
        tip = triple(np.multiply(rotations.rotate_vector(quat, state.omega), self.geometry.scale))
        if not (np.all(np.isfinite(q)) and all(math.isfinite(x) for x in tip)):
            raise GhostDiverged("the ghost's pose is not finite; the ghost stopped")
        self.cage.pose(q, tip)

    def _refresh(self, now: float, force: bool = False) -> None:
        if force or now - self._last_readout >= 1.0 / READOUT_HZ:
            self._last_readout = now
            text = self.readout_markdown()
            if self.readout.content != text:
                self.readout.content = text
        if self.history.dirty and (force or now - self._last_plot >= 1.0 / PLOT_HZ):
            self._last_plot = now
            self.send_plot()

    def send_plot(self) -> bool:
        """Send the recorded errors (needs two finite samples)."""
        data = self.history.plot_data()
        if data is None:
            return False
        self.plot.data = data
        self.history.dirty = False
        return True

    def plot_data(self) -> tuple[np.ndarray, np.ndarray]:
        """(times, errors (N, 3): ω, attitude, |energy|) recorded so far (tests)."""
        return np.asarray(self.history.t), np.asarray(self.history.errors).reshape(-1, 3)

    def readout_markdown(self) -> str:
        """Method, setting, the four errors and the work, as a compact markdown table."""
        config, e = self.config, self.errors
        work = "RHS evals" if config.adaptive else "steps"
        rows = []
        if e is not None:
            rows += [
                ("ω error (rel.)", _sci(e.omega)),
                ("attitude error", f"{e.attitude:.3g} rad ({math.degrees(e.attitude):.2f}°)"),
                ("energy drift", _sci(e.energy, signed=True)),
                ("\\|L\\| drift", _sci(e.momentum, signed=True)),
            ]
        rows.append(("work", f"{self.propagation.cost:,} {work}"))
        setting = config.setting_text(self.body)
        head = f"| **{config.method}**, {setting} | since t = {self.started:.2f} |"
        lines = [head, "|:--|--:|"] + [f"| {k} | {v} |" for k, v in rows]
        if self.behind and e is not None:
            lines.append(
                f"\n**⚠ Behind by {self.behind:.2f}:** at most {self.work_cap:,} "
                f"{'evaluations' if config.adaptive else 'steps'} per frame. Lower the speed or "
                f"choose a coarser setting; the errors are those at t = {e.t:.2f}."
            )
        return "\n".join(lines)

    # -- removal -------------------------------------------------------------------------
    def remove(self) -> list[viser.GuiMarkdownHandle | viser.GuiUplotHandle]:
        """Remove the scene nodes now; return the widgets, for the caller to retire (hide now,
        delete later: :mod:`poinsot.app.live.panel.widgets`)."""
        self.cage.remove()
        return [self.readout, self.plot]


def _sci(x: float, signed: bool = False) -> str:
    if x == 0.0:
        return "0"
    return f"{x:+.2e}" if signed else f"{x:.2e}"
