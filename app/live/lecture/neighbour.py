"""Compare with a neighbour: any preset's body and a second one started ε′ away from it
(:func:`poinsot.physics.models.twins.neighbour_start`: ω₀ turned by ε′, the same |ω₀|), drawn over
the first in bluish green with the preset's own solid (a row of the legend says so), both
exact.

A dropdown of the control panel chooses ε′ (or no neighbour). Near the intermediate axis the
folder reads both first flips, (K ± δ)/λ (:func:`poinsot.physics.models.flip.flip_theory`), and the
lag between them, theory against the lag measured from the two motions (the first zeros of
ω₂); near a stable axis the neighbour simply stays close. The callback only records the
choice (one attribute, assigned atomically); the session's frame thread builds the neighbour
(once per body and choice) and poses it each frame (one more pose message), from
:meth:`on_frame`, called after each frame with the lecture tools'.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Protocol

import numpy as np
import viser

from poinsot.app.construction import updates
from poinsot.app.construction.construction import PoinsotScene
from poinsot.app.construction.geometry import triple
from poinsot.app.construction.palette import Entry
from poinsot.app.construction.sampled.batch import Frame
from poinsot.app.construction.sampled.frames import wxyz_from_xyzw
from poinsot.app.construction.sampled.sampling import MotionSampler, Samples
from poinsot.app.lessons.support import colors
from poinsot.app.lessons.twins import TWIN_STEP
from poinsot.app.live.panel.widgets import Sent, on_user
from poinsot.physics import FreeRigidBody, attitude_with_L_along_z
from poinsot.physics.models.axis_angles import axis_angles
from poinsot.physics.models.flip import FlipTheory, flip_theory, measure_flips
from poinsot.physics.models.twins import neighbour_start

FOLDER = "Compare with a neighbour"
#: The neighbour's row in the legend while it is drawn.
ROW = Entry("neighbour at ε′", (colors.TWIN,), "patch")
LABEL = "Neighbour's start ε′"
OPTIONS = ("no neighbour", "1e-2 rad", "1e-4 rad", "1e-6 rad", "1e-8 rad")
ANGLES = (0.0, 1e-2, 1e-4, 1e-6, 1e-8)
NODE = "/space/neighbour"
#: The flip readouts are given when L comes within this angle of the middle axis [rad]
#: (over one period, surveyed at SURVEY times).
NEAR_MIDDLE = math.radians(30.0)
SURVEY = 256
#: The folder's order in the control panel (after the challenges).
FOLDER_ORDER = 96.0


class NeighbourSession(Protocol):
    client: viser.ClientHandle
    scene: PoinsotScene

    @property
    def body(self) -> FreeRigidBody | None: ...


class Neighbour:
    """The folder, the neighbour's body and its node in one session."""

    def __init__(
        self,
        session: NeighbourSession,
        order: float = FOLDER_ORDER,
        legend: Callable[[str, Sequence[Entry]], None] | None = None,
    ) -> None:
        """``legend``: where the neighbour's row is listed while it is drawn (the legend's
        :meth:`~poinsot.app.live.panel.legend.Legend.show_rows`)."""
        self.session = session
        self._legend = legend
        gui = session.client.gui
        with gui.add_folder(FOLDER, order=order, expand_by_default=False):
            self.choice = gui.add_dropdown(
                LABEL,
                OPTIONS,
                initial_value=OPTIONS[0],
                hint="A second body started ε′ away (ω₀ turned by ε′), drawn in bluish green over "
                "the "
                "first: near the middle axis, ten times closer flips only ln(10)/σ later.",
            )
            self.readout = gui.add_markdown("")
        #: The angle the browser chose (set by the callback; read by the frame thread).
        self.wanted = 0.0
        on_user(self.choice, self._chosen, lambda _exc: None, inline=True)
        self.body: FreeRigidBody | None = None
        self._built: tuple[int, float] | None = None
        self._sampler: MotionSampler | None = None
        self._source: Samples | None = None
        self._wxyz = np.zeros((0, 4))
        #: The neighbour's nodes, made when one is first shown and removed when none is.
        self.frame: viser.FrameHandle | None = None
        self.mesh: viser.MeshHandle | None = None

    def _chosen(self, sent: Sent) -> None:
        value = str(sent.value)
        self.wanted = ANGLES[OPTIONS.index(value)] if value in OPTIONS else 0.0

    def on_frame(self, frame: Frame | None) -> None:
        """Per frame (the frame thread): build the neighbour if the body or ε′ changed, then
        pose it at the frame's time."""
        body, angle = self.session.body, self.wanted
        key = (id(body), angle)
        if key != self._built:
            self._built = key
            self._build(body, angle)
        sampler = self._sampler
        if sampler is None or frame is None or self.frame is None:
            return
        k = max(0, sampler.index(frame.t))
        source = sampler.batch(k, k)
        if source is not self._source:
            self._source, self._wxyz = source, wxyz_from_xyzw(source.quat_xyzw)
        updates.set_wxyz(self.frame, self._wxyz[k - int(source.k[0])])

    def _build(self, body: FreeRigidBody | None, angle: float) -> None:
        geometry = self.session.scene.geometry
        solid = None if geometry is None else geometry.solid_base
        self._sampler, self._source, self.body = None, None, None
        if body is None or angle == 0.0 or solid is None or geometry is None:
            self._remove()
            self.readout.content = "" if angle == 0.0 else "_No body to compare with here._"
            return
        try:
            w1 = neighbour_start(body.omega0, angle)
            self.body = FreeRigidBody(body.inertia, w1, attitude_with_L_along_z(body.inertia, w1))
            sampler = MotionSampler(self.body, TWIN_STEP, 1)
            self._source = sampler.batch(0, 0)
        except ValueError as exc:
            self._remove()
            self.readout.content = f"_No neighbour: {exc}_"
            return
        self._sampler, self._wxyz = sampler, wxyz_from_xyzw(self._source.quat_xyzw)
        self._remove()
        scene = self.session.client.scene
        self.frame = scene.add_frame(NODE, show_axes=False)
        self.mesh = scene.add_mesh_simple(
            f"{NODE}/solid",
            np.asarray(solid.vertices),
            np.asarray(solid.faces),
            color=colors.TWIN,
            flat_shading=True,
            scale=triple(np.asarray(geometry.solid_scale)),
            cast_shadow=False,
            receive_shadow=False,
        )
        self.readout.content = readout(body, self.body, angle)
        self._list(ROW)

    def _remove(self) -> None:
        """Take the neighbour's nodes away (the mesh, then its frame), and its legend row."""
        for node in (self.mesh, self.frame):
            if node is not None:
                node.remove()
        self.frame = self.mesh = None
        self._list()

    def _list(self, *rows: Entry) -> None:
        if self._legend is not None:
            self._legend("neighbour", rows)


def readout(first: FreeRigidBody, second: FreeRigidBody, angle: float) -> str:
    """The two first flips and their lag, theory against the motions (markdown)."""
    J = np.asarray(first.inertia)
    head = f"Neighbour at ε′ = {angle:g} rad from this start, in bluish green."
    if not (bool(np.all(np.diff(J) > 0.0)) and _closest_to_middle(first) < NEAR_MIDDLE):
        return head + " It never comes near the middle axis: it stays close (no flip to time)."
    try:
        t1, t2 = (_first_after_start(flip_theory(J, b.omega0)) for b in (first, second))
    except ValueError as exc:
        return head + f" No flip clock: {exc}"
    end = 1.2 * max(t1, t2) + 1.0
    a, b = measure_flips(first, end), measure_flips(second, end)
    measured = f"{b[0] - a[0]:.6g}" if len(a) and len(b) else "—"
    return (
        f"{head}\n\n| | theory | measured |\n|:--|--:|--:|\n"
        f"| first flip, (K ± δ)/λ | {t1:.6g} | {a[0] if len(a) else math.nan:.6g} |\n"
        f"| neighbour's first flip | {t2:.6g} | {b[0] if len(b) else math.nan:.6g} |\n"
        f"| lag | {t2 - t1:.6g} | {measured} |"
    )


def _first_after_start(theory: FlipTheory) -> float:
    """The first zero of ω₂ after t = 0 (a start with ω₂ = 0 is a zero itself, (K − δ)/λ = 0
    to rounding: the first flip after it is the next one, 2K/λ later)."""
    t = theory.first_flip_time
    return t + theory.time_between_flips if t <= 1e-9 * theory.time_between_flips else t


def _closest_to_middle(body: FreeRigidBody) -> float:
    """The smallest angle between L and ±e₂ (the middle axis) over one period [rad]."""
    period = body.period if math.isfinite(body.period) else 50.0
    angles = axis_angles(body.inertia, body.omega(np.linspace(0.0, period, SURVEY)))[:, 1]
    return float(np.min(np.minimum(angles, math.pi - angles)))


def add_neighbour(
    session: NeighbourSession, legend: Callable[[str, Sequence[Entry]], None] | None = None
) -> Neighbour:
    return Neighbour(session, legend=legend)
