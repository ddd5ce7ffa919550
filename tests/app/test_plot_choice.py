"""The Motion window's plot shows ω, the angles between L and the body axes, or the Z-X-Z
Euler angles, as a browser chooses; each with its title, legend and unit.

The sent angles are checked against the session's own exact motion by independent means: the
angles to the axes against the columns of scipy's attitude matrix and L (and Σ cos²θᵢ = 1), the
Euler angles by rebuilding the attitude with scipy's ``from_euler("ZXZ")``.
"""

from __future__ import annotations

import numpy as np
from conftest import session_of, wait_until
from scipy.spatial.transform import Rotation

from poinsot.app.live.panel import plots


def _plot(session):
    plot = session.panel.motion.plot
    assert plot is not None
    return plot


def _choose(probe, option: str) -> None:
    uuid, _ = probe.widget(plots.LABEL)
    probe.set_value(uuid, option)


def test_the_plot_shows_the_angles_of_L_to_the_axes(poinsot_app, probe):
    session = session_of(poinsot_app)
    assert _plot(session).title == plots.OMEGA.title
    _choose(probe, plots.AXIS_ANGLES.option)
    assert wait_until(lambda: _plot(session).title == plots.AXIS_ANGLES.title, 10)
    assert wait_until(lambda: len(_plot(session).data[0]) > 5, 10)
    plot = _plot(session)
    labels = [s["label"] for s in plot.series[1:]]
    assert labels == ["∠(L, e₁) [°]", "∠(L, e₂) [°]", "∠(L, e₃) [°]"]
    assert plot.axes[1]["label"] == "angle [°]"
    t, *angles = (np.asarray(a) for a in plot.data)
    theta = np.radians(np.stack(angles, axis=1))
    np.testing.assert_allclose(np.sum(np.cos(theta) ** 2, axis=1), 1.0, atol=1e-9)
    body = session.body
    axes = body.attitude(t).as_matrix()  # column i: e_i in space
    L = body.angular_momentum / np.linalg.norm(body.angular_momentum)
    want = np.arccos(np.clip(np.einsum("nji,j->ni", axes, L), -1.0, 1.0))
    np.testing.assert_allclose(theta, want, atol=1e-6)
    assert session.stats.errors == 0, session.stats.last_error


def test_the_plot_shows_the_euler_angles_and_back_to_omega(poinsot_app, probe):
    session = session_of(poinsot_app)
    _choose(probe, plots.EULER.option)
    assert wait_until(lambda: _plot(session).title == plots.EULER.title, 10)
    assert wait_until(lambda: len(_plot(session).data[0]) > 5, 10)
    plot = _plot(session)
    assert [s["label"] for s in plot.series[1:]] == list(plots.EULER.labels)
    t, *angles = (np.asarray(a) for a in plot.data)
    rebuilt = Rotation.from_euler("ZXZ", np.radians(np.stack(angles, axis=1)))
    attitude = session.body.attitude(t)
    # the app's presets start with L along +z: the L frame is the space frame itself
    assert np.max((rebuilt.inv() * attitude).magnitude()) < 1e-6
    _choose(probe, plots.OMEGA.option)
    assert wait_until(lambda: _plot(session).title == plots.OMEGA.title, 10)
    assert wait_until(lambda: abs(float(np.asarray(_plot(session).data[3])[-1])) < 100.0, 10)
    assert session.stats.errors == 0, session.stats.last_error


def test_an_option_not_offered_changes_nothing(poinsot_app, probe):
    session = session_of(poinsot_app)
    _choose(probe, "the price of tea")
    frames = session.stats.frames
    assert wait_until(lambda: session.stats.frames > frames + 30, 30)
    assert _plot(session).title == plots.OMEGA.title
    assert session.panel.motion.choice.wanted is plots.OMEGA
    assert session.stats.errors == 0, session.stats.last_error
