"""The numerical ghost (issue 4): the same body advanced by a numerical integrator, drawn as a
translucent ice-blue cage over the exact ellipsoid, with a live readout and a plot of its error.

What a student sees: at the moment the ghost is switched on it coincides with the body; then
the chosen method carries it along on its own. RK45 at a loose tolerance visibly drifts out of
the ellipsoid (its energy error grows without bound); the symplectic splitting wobbles but its
energy error stays bounded; the implicit midpoint keeps the energy and |L| to rounding yet
still falls behind in phase. The plot shows log₁₀ of the ω error, of the attitude error (the
geodesic angle between the two rotations) and of the energy error against simulated time.

Lifecycle: the session mounts :class:`GhostControls` (a checkbox, the method and its setting)
at start; nothing else exists until the box is ticked. Switching on creates the scene nodes
(``/space/ghost``: a faint shell, the three principal sections and the principal axes, posed
by the ghost's attitude;
``/space/ghost_tip``: the tip of the ghost's ω, which leaves the invariable plane when the
energy drifts), and the readout and the plot below the controls (in the control panel, where
the box was ticked: a floating window would cover the panel or the "Motion" window on a
1280 x 720 projector); switching off removes all of it. Per frame only the two poses travel;
the readout refreshes at 5 Hz and the plot at 4 Hz.

Restarts (what a student expects): the ghost runs on the exact body's simulated time (speed,
pause and step act on both alike). It starts from the exact state at the current time when
switched on and whenever the method or its setting changes (a new race from here); Reset, or
any change of the body, restarts both together at t = 0. The numbers come from
:class:`physics.integrators.Propagation`, which carries the integrator's whole state from frame
to frame (restarting RK45 at every frame would hide its drift, see there). Only the error
metrics are computed here.

Work per frame: each frame advances the propagation to the frame's time with at most as many
steps (or RHS evaluations) as fit into WORK_BUDGET seconds at the measured cost per step. A
setting too fine for the speed leaves the ghost behind the body; it is then drawn, and its
error measured, at the time it has reached, and the readout says so. A non-finite solution
stops the ghost with a message; nothing non-finite is ever sent.

Threads: GUI callbacks only record the wanted configuration (under a lock); the session's
frame thread applies it in :meth:`GhostControls.on_frame` and alone touches the ghost, its
nodes and its widgets.
"""

from __future__ import annotations

import collections
import dataclasses
import math
import threading
import time
from collections.abc import Callable
from contextlib import AbstractContextManager
from typing import Any, Protocol

import numpy as np
import viser
import viser.uplot
from poinsot.app.scene import meshes
from poinsot.app.scene.construction import AXES_OVERSHOOT, Frame, Geometry, PoinsotScene
from poinsot.app.scene.frames import rotation_from_wxyz, wxyz_from_xyzw
from poinsot.physics import FreeRigidBody
from poinsot.physics.integrators import INTEGRATORS, Propagation, State

#: Relative tolerances offered for the adaptive pairs (log scale).
TOLERANCES: tuple[float, ...] = tuple(10.0**-k for k in range(3, 11))
#: Fixed steps offered, as divisions of the time scale T: h = T / n.
DIVISIONS: tuple[int, ...] = (20, 50, 100, 200, 500, 1000, 2000)
#: Defaults: RK45 at a loose tolerance drifts visibly within a minute at speed 1 (energy error
#: 1e-4 at t = 10, 2e-2 at t = 60 on the default preset); T/50 shows the splitting's bounded
#: wobble (energy error ~ 5e-4, flat).
DEFAULT_METHOD = "RK45"
DEFAULT_TOLERANCE = 1e-3
DEFAULT_DIVISIONS = 50

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

#: Index order taking viser's (w, x, y, z) back to scipy's (x, y, z, w).
_XYZW_FROM_WXYZ = [1, 2, 3, 0]

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
#: How long removed widgets stay hidden before they are deleted [s] (see app/panel.py: an
#: update sent just before a removal must not reach the browser after it).
RETIRE_SECONDS = 1.5

#: The ghost's look: an ice-blue, distinct from the amber ellipsoid, the traces and the RGB
#: axes. A faint translucent shell a little larger than the ellipsoid (no z-fighting when they
#: coincide) and, what reads best on a projector, its three principal sections (the ellipses
#: in the planes of two principal axes) as lines, with its principal axes: where the ghost has
#: drifted, its cage visibly leans out of the amber ellipsoid.
GHOST_COLOR = (150, 205, 255)
GHOST_OPACITY = 0.16
GHOST_INFLATE = 1.02
GHOST_LINE_WIDTH_PX = 2.0
GHOST_RING_SEGMENTS = 96
GHOST_TIP_RADIUS = 0.03
#: Plot series colours: ω error, attitude error, energy error.
PLOT_COLORS = ("#ffd84a", "#bfe1ff", "#ff6fb0")
#: Order of the controls folder in the main panel (after "Show", before the lecture folder).
FOLDER_ORDER = 45.0

METHOD_LABELS: dict[str, str] = {
    name: f"{name} ({'adaptive' if i.kind == 'adaptive' else 'fixed step'}, order {i.order})"
    for name, i in INTEGRATORS.items()
}


def tolerance_label(tol: float) -> str:
    return f"1e-{round(-math.log10(tol))}"


def division_label(n: int) -> str:
    return f"T/{n}"


def time_scale(body: FreeRigidBody) -> float:
    """T of the step choices h = T/n: the period of ω, or where ω does not return (separatrix,
    sphere, permanent rotation) the time of one turn, 2π/|ω₀|."""
    if math.isfinite(body.period) and body.period > 0.0:
        return float(body.period)
    return 2.0 * math.pi / float(np.linalg.norm(body.omega0))


@dataclasses.dataclass(frozen=True)
class GhostConfig:
    """What the controls ask for. Each kind of method keeps its own setting."""

    enabled: bool = False
    method: str = DEFAULT_METHOD
    tolerance: float = DEFAULT_TOLERANCE
    divisions: int = DEFAULT_DIVISIONS

    @property
    def adaptive(self) -> bool:
        return INTEGRATORS[self.method].kind == "adaptive"

    def setting(self, body: FreeRigidBody) -> float:
        """The integrator's setting: the tolerance, or the step h = T/n for ``body``."""
        return self.tolerance if self.adaptive else time_scale(body) / self.divisions

    def setting_text(self, body: FreeRigidBody) -> str:
        if self.adaptive:
            return f"tol {tolerance_label(self.tolerance)}"
        return f"h = T/{self.divisions} = {self.setting(body):.3g}"


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


def geodesic_angle(p_xyzw: np.ndarray, q_xyzw: np.ndarray) -> float:
    """Angle [rad] of the rotation taking one attitude to the other, from unit quaternions.

    The 4-vectors p and ±q make an angle a with the rotation angle 2a; a = 2 atan2(|p - q|,
    |p + q|) (q's sign chosen so that p . q >= 0) is accurate at every angle, unlike
    2 acos(|p . q|), which loses half the digits near 0 (the ghost's early errors). Plain
    floats: per frame, on 4-vectors, numpy's call overhead would dominate."""
    p = [float(x) for x in p_xyzw]
    q = [float(x) for x in q_xyzw]
    np_, nq = math.hypot(*p), math.hypot(*q)
    sign = 1.0 if sum(a * b for a, b in zip(p, q, strict=True)) >= 0.0 else -1.0
    diff = math.hypot(*(a / np_ - sign * b / nq for a, b in zip(p, q, strict=True)))
    total = math.hypot(*(a / np_ + sign * b / nq for a, b in zip(p, q, strict=True)))
    return 4.0 * math.atan2(diff, total)


def rotate(q_xyzw: np.ndarray, v: np.ndarray) -> tuple[float, float, float]:
    """v turned by the unit quaternion q (scalar last): v + 2w (u x v) + 2 u x (u x v)."""
    x, y, z, w = (float(c) for c in q_xyzw)
    v1, v2, v3 = (float(c) for c in v)
    c1, c2, c3 = y * v3 - z * v2, z * v1 - x * v3, x * v2 - y * v1
    return (
        v1 + 2.0 * (w * c1 + y * c3 - z * c2),
        v2 + 2.0 * (w * c2 + z * c1 - x * c3),
        v3 + 2.0 * (w * c3 + x * c2 - y * c1),
    )


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
        """The ghost's ``omega`` and attitude quaternion against the exact ones at ``t``.
        Raises GhostDiverged if any number is not finite."""
        w = [float(c) for c in omega]
        if not all(math.isfinite(c) for c in (*w, *(float(c) for c in quat_xyzw))):
            raise GhostDiverged(f"the numerical solution is not finite at t = {t:.3g}")
        m = [i * c for i, c in zip(body.inertia.tolist(), w, strict=True)]
        exact = [float(c) for c in exact_omega]
        norm = math.hypot(*exact)
        energy = 0.5 * sum(a * b for a, b in zip(m, w, strict=True))
        momentum = math.hypot(*m)
        L = math.hypot(*body.angular_momentum.tolist())
        errors = cls(
            float(t),
            math.hypot(*(a - b for a, b in zip(w, exact, strict=True))) / norm
            if norm > 0.0
            else math.nan,
            geodesic_angle(exact_xyzw, quat_xyzw),
            energy / body.energy - 1.0 if body.energy > 0.0 else math.nan,
            momentum / L - 1.0 if L > 0.0 else math.nan,
        )
        values = (errors.omega, errors.attitude, errors.energy, errors.momentum)
        if not all(math.isfinite(v) for v in values):
            raise GhostDiverged(f"the ghost's error is not finite at t = {t:.3g}")
        return errors


class GhostDiverged(RuntimeError):
    """The numerical solution stopped being finite (it is never drawn)."""


def _sci(x: float, signed: bool = False) -> str:
    if x == 0.0:
        return "0"
    return f"{x:+.2e}" if signed else f"{x:.2e}"


class Ghost:
    """The live ghost of one session: its propagation, scene nodes and widgets. Created when
    switched on, :meth:`remove`\\ d when switched off; driven by the frame thread only."""

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
        self._plot_dirty = False
        sphere = meshes.ellipsoid_unit_mesh()
        with atomic():
            self.node = scene.add_frame(f"{root}/ghost", show_axes=False)
            self.shell = scene.add_mesh_simple(
                f"{root}/ghost/ellipsoid",
                sphere.vertices,
                sphere.faces,
                color=GHOST_COLOR,
                opacity=GHOST_OPACITY,
                material="standard",
                side="front",
                cast_shadow=False,
                receive_shadow=False,
            )
            self.axes = scene.add_line_segments(
                f"{root}/ghost/axes",
                np.zeros((3, 2, 3), np.float32),
                GHOST_COLOR,
                thickness=GHOST_LINE_WIDTH_PX,
                thickness_units="screen",
            )
            self.rings = scene.add_line_segments(
                f"{root}/ghost/sections",
                np.zeros((1, 2, 3), np.float32),
                GHOST_COLOR,
                thickness=GHOST_LINE_WIDTH_PX,
                thickness_units="screen",
            )
            self.tip = scene.add_icosphere(
                f"{root}/ghost_tip", radius=GHOST_TIP_RADIUS, color=GHOST_COLOR, cast_shadow=False
            )
        with container:
            self.readout = gui.add_markdown("", order=10.0)
            self.plot = gui.add_uplot(
                data=(frame.t + np.array([0.0, 1.0]), *(np.full(2, _LOG_FLOOR) for _ in range(3))),
                series=(
                    viser.uplot.Series(label="t"),
                    viser.uplot.Series(label="ω", stroke=PLOT_COLORS[0], width=2),
                    viser.uplot.Series(label="attitude", stroke=PLOT_COLORS[1], width=2),
                    viser.uplot.Series(label="|ΔT|/T", stroke=PLOT_COLORS[2], width=2),
                ),
                title="log₁₀ error vs exact solution",
                scales=_SCALES,  # type: ignore[arg-type]
                axes=_AXES,  # type: ignore[arg-type]
                aspect=1.5,
                order=11.0,
            )
        self.restart(body, geometry, frame)

    # -- (re)start -----------------------------------------------------------------------
    def restart(self, body: FreeRigidBody, geometry: Geometry, frame: Frame) -> None:
        """Start again from the exact state shown in ``frame`` (a new body: sizes too)."""
        self.body, self.geometry = body, geometry
        self.started = float(frame.t)
        self.propagation = Propagation(
            self.config.method,
            body.inertia,
            frame.omega,
            rotation_from_wxyz(frame.wxyz),
            self.config.setting(body),
            t0=frame.t,
        )
        self.state = None
        self.errors = None
        self.behind = 0.0
        self._plot_t: list[float] = []
        self._plot_e: list[tuple[float, float, float]] = []
        self._interval = PLOT_FIRST_INTERVAL
        semi = geometry.semi_axes
        with self._atomic():
            self.shell.scale = tuple(float(a) * GHOST_INFLATE for a in semi)
            ends = np.diag(semi * AXES_OVERSHOOT)
            self.axes.points = np.stack([-ends, ends], axis=1).astype(np.float32)
            self.rings.points = principal_sections(semi * GHOST_INFLATE, GHOST_RING_SEGMENTS)
            self.update(frame, force=True)

    # -- per frame -----------------------------------------------------------------------
    def update(self, frame: Frame, force: bool = False) -> None:
        """Advance to the body's time (within the work cap) and pose the ghost."""
        now = time.monotonic()
        caught_up = self.state is not None and self.state.t == frame.t
        if caught_up and not force:
            self._refresh(now)
            return
        start = time.perf_counter()
        cost0 = self.propagation.cost
        state = self.propagation.advance(frame.t, self.work_cap)
        work = state.cost - cost0
        elapsed = time.perf_counter() - start
        if work >= MIN_WORK:  # a per-step cost, not the fixed overhead of a call
            self.unit_cost = 0.7 * self.unit_cost + 0.3 * elapsed / work
        tolerance = BEHIND_FRACTION * max(abs(frame.t), 1.0)
        self.behind = max(frame.t - state.t, 0.0) if frame.t - state.t > tolerance else 0.0
        quat = state.attitude.as_quat()
        if self.behind:
            omega, rotation, _ = self.body.sample(np.array([state.t]))
            exact_omega, exact_xyzw = omega[0], rotation.as_quat()[0]
        else:
            exact_omega, exact_xyzw = frame.omega, frame.wxyz[_XYZW_FROM_WXYZ]
        errors = GhostErrors.between(self.body, state.t, state.omega, quat, exact_omega, exact_xyzw)
        q = wxyz_from_xyzw(quat)
        tip = tuple(x * self.geometry.scale for x in rotate(quat, state.omega))
        if not (np.all(np.isfinite(q)) and all(math.isfinite(x) for x in tip)):
            raise GhostDiverged("the ghost's pose is not finite; the ghost stopped")
        self.node.wxyz = q
        self.tip.position = tip
        self.state, self.errors = state, errors
        self._record(errors)
        self.frame_seconds.append(time.perf_counter() - start)
        self._refresh(now, force=force)

    @property
    def work_cap(self) -> int:
        """Steps (or RHS evaluations) allowed in one frame."""
        return int(min(max(WORK_BUDGET / self.unit_cost, MIN_WORK), MAX_WORK))

    def _record(self, errors: GhostErrors) -> None:
        if errors.t == self.started:
            return  # the start itself: the exact state, zero error (the axis fits the data)
        if self._plot_t and errors.t < self._plot_t[-1] + self._interval:
            return
        self._plot_t.append(errors.t)
        self._plot_e.append((errors.omega, errors.attitude, abs(errors.energy)))
        if len(self._plot_t) > PLOT_POINTS:
            # Keep the first sample and every other one after it; sample half as often.
            self._plot_t = self._plot_t[::2]
            self._plot_e = self._plot_e[::2]
            self._interval *= 2.0
        self._plot_dirty = True

    def _refresh(self, now: float, force: bool = False) -> None:
        if force or now - self._last_readout >= 1.0 / READOUT_HZ:
            self._last_readout = now
            text = self.readout_markdown()
            if self.readout.content != text:
                self.readout.content = text
        if self._plot_dirty and (force or now - self._last_plot >= 1.0 / PLOT_HZ):
            self._last_plot = now
            self.send_plot()

    def send_plot(self) -> bool:
        """Send the recorded errors (needs two samples: see app/panel.py)."""
        if len(self._plot_t) < 2:
            return False
        e = np.log10(np.maximum(np.asarray(self._plot_e, dtype=np.float64), PLOT_FLOOR))
        data = (np.asarray(self._plot_t, dtype=np.float64), e[:, 0], e[:, 1], e[:, 2])
        if not all(np.all(np.isfinite(a)) for a in data):
            return False
        self.plot.data = data
        self._plot_dirty = False
        return True

    def plot_data(self) -> tuple[np.ndarray, np.ndarray]:
        """(times, errors (N, 3): ω, attitude, |energy|) recorded so far (tests)."""
        return np.asarray(self._plot_t), np.asarray(self._plot_e).reshape(-1, 3)

    def readout_markdown(self) -> str:
        """Method, setting, the four errors and the work, as a compact markdown table."""
        config, e = self.config, self.errors
        adaptive = INTEGRATORS[config.method].kind == "adaptive"
        rows = []
        if e is not None:
            rows += [
                ("ω error (rel.)", _sci(e.omega)),
                ("attitude error", f"{e.attitude:.3g} rad ({math.degrees(e.attitude):.2f}°)"),
                ("energy drift", _sci(e.energy, signed=True)),
                ("\\|L\\| drift", _sci(e.momentum, signed=True)),
            ]
        rows.append(("work", f"{self.propagation.cost:,} {'RHS evals' if adaptive else 'steps'}"))
        setting = config.setting_text(self.body)
        head = f"| **{config.method}**, {setting} | since t = {self.started:.2f} |"
        lines = [head, "|:--|--:|"] + [f"| {k} | {v} |" for k, v in rows]
        if self.behind and e is not None:
            lines.append(
                f"\n**⚠ Behind by {self.behind:.2f}:** at most {self.work_cap:,} "
                f"{'evaluations' if adaptive else 'steps'} per frame. Lower the speed or "
                f"choose a coarser setting; the errors are those at t = {e.t:.2f}."
            )
        return "\n".join(lines)

    # -- removal -------------------------------------------------------------------------
    def remove(self) -> list[Any]:
        """Remove the scene nodes now; hide the widgets and return them for a delayed delete."""
        for handle in (self.shell, self.axes, self.rings, self.tip, self.node):
            handle.remove()
        widgets = [self.readout, self.plot]
        for widget in widgets:
            widget.visible = False
        return widgets


_AXIS = {
    "stroke": "#c8d0da",
    "grid": {"stroke": "#3a4048", "width": 1},
    "ticks": {"stroke": "#3a4048"},
}


_SCALES = {"x": {"time": False, "auto": True}, "y": {"auto": True}}
_AXES = (_AXIS, _AXIS)


class GhostSession(Protocol):
    """What the ghost uses of a session."""

    client: viser.ClientHandle
    scene: PoinsotScene


class GhostControls:
    """The ghost's controls in the session's panel, and the ghost itself while it is on."""

    def __init__(self, session: GhostSession, order: float = FOLDER_ORDER) -> None:
        self.session = session
        self.client = session.client
        self._lock = threading.Lock()
        self._wanted = GhostConfig()
        self._applied = GhostConfig()
        self._callback_error = ""
        self.ghost: Ghost | None = None
        self._retired: list[tuple[float, Any]] = []
        gui = self.client.gui
        self.folder = gui.add_folder("Numerical ghost", order=order, expand_by_default=False)
        with self.folder:
            self.enabled = gui.add_checkbox(
                "Show numerical ghost",
                False,
                order=0.0,
                hint="The same body advanced by a numerical integrator, drawn as a pale shell "
                "over the exact one. It starts from the exact state now; Reset or a new body "
                "restarts both at t = 0.",
            )
            self.method = gui.add_dropdown(
                "Method",
                tuple(METHOD_LABELS.values()),
                initial_value=METHOD_LABELS[DEFAULT_METHOD],
                order=1.0,
                hint="An integrator from physics/integrators.py; changing it restarts the ghost "
                "from the exact state.",
            )
            self.setting = gui.add_dropdown(
                "Tolerance",
                tuple(tolerance_label(t) for t in TOLERANCES),
                initial_value=tolerance_label(DEFAULT_TOLERANCE),
                order=2.0,
                hint="Relative tolerance (adaptive) or step h = T/n, T the period of ω.",
            )
            self.message = gui.add_markdown("", order=3.0)
        self.enabled.on_update(self._guarded(self._on_enabled))
        self.method.on_update(self._guarded(self._on_method))
        self.setting.on_update(self._guarded(self._on_setting))

    # -- callbacks (viser's threads): record the wish only -------------------------------
    def _guarded(self, callback: Callable[[Any], None]) -> Callable[[viser.GuiEvent], None]:
        def wrapped(event: viser.GuiEvent) -> None:
            if event.client is None:  # a value set by the server
                return
            try:
                callback(event.target)
            except Exception as exc:  # shown by the frame thread, never raised into viser
                with self._lock:
                    self._callback_error = f"{type(exc).__name__}: {exc}"

        return wrapped

    def _on_enabled(self, handle: Any) -> None:
        self.configure(enabled=bool(handle.value))

    def _on_method(self, handle: Any) -> None:
        for name, label in METHOD_LABELS.items():
            if label == handle.value:
                self.configure(method=name)

    def _on_setting(self, handle: Any) -> None:
        value = str(handle.value)
        if value.startswith("T/"):
            self.configure(divisions=int(value[2:]))
        else:
            self.configure(tolerance=float(value))

    def configure(self, **changes: Any) -> None:
        """Ask for a configuration (any thread); the frame thread applies it."""
        with self._lock:
            self._wanted = dataclasses.replace(self._wanted, **changes)

    @property
    def wanted(self) -> GhostConfig:
        with self._lock:
            return self._wanted

    # -- frame thread --------------------------------------------------------------------
    def on_frame(self, frame: Frame | None) -> None:
        """Per frame, after the exact scene: apply the wanted configuration, advance the ghost.
        Never raises: a failure switches the ghost off and says why in the panel."""
        try:
            self._collect()
            with self._lock:
                wanted, error = self._wanted, self._callback_error
                self._callback_error = ""
            if error:
                self._show(f"**⚠ {error}**")
            scene = self.session.scene
            body, geometry = scene.body, scene.geometry
            if wanted != self._applied:
                self._apply(wanted)
            if not wanted.enabled or frame is None or body is None or geometry is None:
                return
            ghost = self.ghost
            if ghost is None:
                with self.client.atomic():
                    self.ghost = Ghost(
                        self.client.scene,
                        self.client.gui,
                        self.folder,
                        wanted,
                        body,
                        geometry,
                        frame,
                        self.client.atomic,
                    )
                self._show("")
            elif ghost.config != wanted or ghost.body is not body:
                ghost.config = wanted
                ghost.restart(body, geometry, frame)
            elif ghost.state is not None and frame.t < ghost.state.t:
                ghost.restart(body, geometry, frame)  # the clock went back (Reset)
            else:
                with self.client.atomic():
                    ghost.update(frame)
        except Exception as exc:  # GhostDiverged, a midpoint that cannot converge, ...
            self._fail(exc)

    def _apply(self, wanted: GhostConfig) -> None:
        """Mirror the configuration into the widgets (it may come from :meth:`configure`, not
        the browser); create nothing, remove the ghost if off."""
        if wanted.adaptive:
            options = tuple(tolerance_label(t) for t in TOLERANCES)
            label, value = "Tolerance", tolerance_label(wanted.tolerance)
        else:
            options = tuple(division_label(n) for n in DIVISIONS)
            label, value = "Step h", division_label(wanted.divisions)
        if self.setting.options != options:
            self.setting.options = options
            self.setting.label = label
        for handle, shown in (
            (self.enabled, wanted.enabled),
            (self.method, METHOD_LABELS[wanted.method]),
            (self.setting, value),
        ):
            if handle.value != shown:
                handle.value = shown
        self._applied = wanted
        if not wanted.enabled and self.ghost is not None:
            self._remove()

    def _remove(self) -> None:
        ghost, self.ghost = self.ghost, None
        if ghost is not None:
            due = time.monotonic() + RETIRE_SECONDS
            self._retired += [(due, handle) for handle in ghost.remove()]

    def _collect(self) -> None:
        if self._retired:
            now = time.monotonic()
            for _, handle in [r for r in self._retired if r[0] <= now]:
                handle.remove()
            self._retired = [r for r in self._retired if r[0] > now]

    def _fail(self, exc: BaseException) -> None:
        try:
            self._remove()
        finally:
            self.configure(enabled=False)
            self._applied = dataclasses.replace(self._applied, enabled=False)
            self.enabled.value = False
            self._show(f"**⚠ Ghost stopped: {type(exc).__name__}: {exc}**")

    def _show(self, text: str) -> None:
        if self.message.content != text:
            self.message.content = text


def add_ghost_controls(session: GhostSession, **kwargs: Any) -> GhostControls:
    """Mount the ghost's folder on ``session``'s panel; call ``on_frame(frame)`` after each
    frame (the ghost itself exists only while switched on)."""
    return GhostControls(session, **kwargs)
