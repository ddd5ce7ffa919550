"""What the Motion window's plot shows: ω in the body frame (the default), the angles between
L and the body axes (the intermediate axis's flip is ∠(L, e₂) swinging through 90°), or the
Z-X-Z Euler angles of the attitude about L. A dropdown above the plot chooses.

Each is three series over the recorded samples (t, ω, attitude), computed when the plot is
sent by :mod:`poinsot.physics.models.axis_angles` (no physics here): its title, legend and y axis
say what and in which unit. The dropdown's callback only records the choice (one attribute,
assigned atomically); the session's frame thread applies it when it next sends the plot.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import viser
import viser.uplot

from poinsot.app.construction import palette
from poinsot.app.live.panel.widgets import Sent, on_user
from poinsot.physics import FreeRigidBody
from poinsot.physics.models.axis_angles import axis_angles, zxz_angles

LABEL = "Plot"


@dataclasses.dataclass(frozen=True)
class Quantity:
    """One choice: its option text, the plot's title, the y axis and the series' labels."""

    option: str
    title: str
    y_label: str
    labels: tuple[str, str, str]


OMEGA = Quantity("ω", "ω in the body frame", "ω [rad/time]", ("ω₁", "ω₂", "ω₃"))
AXIS_ANGLES = Quantity(
    "angles of L to the axes",
    "angle between L and each body axis (a flip swings ∠(L, e₂) through 90°)",
    "angle [°]",
    ("∠(L, e₁) [°]", "∠(L, e₂) [°]", "∠(L, e₃) [°]"),
)
EULER = Quantity(
    "Euler angles (z-x-z about L)",
    "Z-X-Z Euler angles about L: precession φ, nutation θ, spin ψ",
    "angle [°]",
    ("φ precession [°]", "θ nutation [°]", "ψ spin [°]"),
)
QUANTITIES = (OMEGA, AXIS_ANGLES, EULER)
BY_OPTION = {q.option: q for q in QUANTITIES}


def series(quantity: Quantity) -> tuple[viser.uplot.Series, ...]:
    """The plot's series: t, then the three in the axes' colours."""
    out = [viser.uplot.Series(label="t")]
    for label, color in zip(quantity.labels, palette.PLOT_SERIES, strict=True):
        out.append(viser.uplot.Series(label=label, stroke=color, width=2))
    return tuple(out)


def axes(quantity: Quantity) -> tuple[viser.uplot.Axis, viser.uplot.Axis]:
    x_axis, y_axis = palette.plot_axes()
    return (
        viser.uplot.Axis(**{**x_axis, "label": "t"}),
        viser.uplot.Axis(**{**y_axis, "label": quantity.y_label}),
    )


def values(
    quantity: Quantity, body: FreeRigidBody | None, omega: np.ndarray, wxyz: np.ndarray
) -> np.ndarray:
    """The three series (N, 3) of ``quantity`` at the samples: ω (N, 3) and attitudes (N, 4)
    as viser takes them (w, x, y, z); ω itself without a body to read the angles from."""
    if quantity is OMEGA or body is None:
        return omega
    if quantity is AXIS_ANGLES:
        return np.degrees(axis_angles(body.inertia, omega))
    xyzw = wxyz[:, [1, 2, 3, 0]]
    return np.degrees(zxz_angles(body.inertia, omega, xyzw, body.angular_momentum))


class PlotChoice:
    """The dropdown above the plot (shown while the ω plot is) and the choice it holds."""

    def __init__(self, gui: viser.GuiApi, order: float) -> None:
        self.dropdown = gui.add_dropdown(
            LABEL,
            [q.option for q in QUANTITIES],
            initial_value=OMEGA.option,
            hint="What the plot draws: ω, the angle between L and each body axis, or the "
            "Euler angles about L (degrees).",
            visible=False,
            order=order,
        )
        #: The choice the browser made (set by the callback) and the one the plot shows.
        self.wanted: Quantity = OMEGA
        self.shown: Quantity = OMEGA
        on_user(self.dropdown, self._chosen, lambda _exc: None, inline=True)

    def _chosen(self, sent: Sent) -> None:
        self.wanted = BY_OPTION.get(str(sent.value), OMEGA)

    def show(self, visible: bool) -> None:
        if self.dropdown.visible != visible:
            self.dropdown.visible = visible

    def apply(self, plot: viser.GuiUplotHandle) -> Quantity:
        """Give ``plot`` the title, legend and axes of the wanted quantity if it changed."""
        wanted = self.wanted
        if wanted is not self.shown:
            plot.title, plot.series, plot.axes = wanted.title, series(wanted), axes(wanted)
            self.shown = wanted
        return wanted

    def reset(self) -> None:
        """A new ω plot: it starts as ω (its series), whatever was chosen before."""
        self.shown = OMEGA
