"""A start pointed at on the live ellipsoid (app/live/pointing/pointer.py): a click sets it, a drag
draws the polhode through it and starts there on release, the separatrix is reached by hand, the
Scene folder says that the ellipsoid can be clicked, and a miss changes nothing but says so in one
line; a click adds no folder to the panel, and the ω plot restarts with the motion."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import session_of, wait_until

from poinsot.app.construction.sampled.frames import rotation_from_wxyz
from poinsot.app.live.panel.panel import POINTING_HINT
from poinsot.app.live.pointing.pointer import MISSED, SNAP_PX
from poinsot.app.live.session.session import Session
from poinsot.app.model.elements import OWN_BODY_CONTROLS
from poinsot.physics import FreeRigidBody, Regime


def _ray_at(session: Session, omega: np.ndarray) -> tuple[tuple, tuple]:
    """A ray from a camera 5 units out towards the drawn point of body-frame ``omega``, as the
    body is drawn now (call on the session's thread: the body turns between frames)."""
    assert session.frame is not None and session.scene.geometry is not None
    attitude = rotation_from_wxyz(session.frame.wxyz)
    point = attitude.apply(omega * session.scene.geometry.scale)
    eye = point + 5.0 * point / np.linalg.norm(point)
    return tuple(eye), tuple(point - eye)


def _set(session: Session, act) -> int:
    generation = session.generation
    session.post(act)
    return session.wait_applied(generation)


def test_a_click_on_the_ellipsoid_starts_the_motion_there(poinsot_app, probe) -> None:
    session = session_of(poinsot_app)
    body = session.body
    assert body is not None
    two_T = 2.0 * body.energy
    target = np.array([0.9, 0.5, 0.4])
    target *= np.sqrt(two_T / (target @ (np.asarray(body.inertia) * target)))
    _set(session, lambda: session.pointer.release(_ray_at(session, target)))
    assert wait_until(lambda: session.body is not body)
    new = session.body
    assert new is not None
    np.testing.assert_allclose(new.omega0, target, rtol=1e-12, atol=1e-14)
    assert new.energy == pytest.approx(body.energy, rel=1e-12)
    np.testing.assert_allclose(new.inertia, body.inertia)
    expected_D = float(np.sum((new.inertia * target) ** 2) / two_T)
    assert new.D == pytest.approx(expected_D, rel=1e-12)
    readouts = session.panel.motion.readouts  # written after the body is set: wait for it
    assert wait_until(lambda: f"{expected_D:.4g}" in readouts.content, 30), readouts.content


def test_a_drag_draws_the_polhode_through_the_start_then_plays_it(poinsot_app, probe) -> None:
    session = session_of(poinsot_app)
    body = session.body
    assert body is not None and not session.clock.paused
    target = np.asarray(body.omega(0.7)) * 1.0  # a point of the energy ellipsoid
    target[1] *= -1.0
    session.post(lambda: session.pointer.drag(_ray_at(session, target)))
    assert wait_until(lambda: session.pointer.previews == 1)
    assert session.clock.paused  # the motion stands still while dragging
    preview = session.pointer.preview
    assert preview is not None and preview.visible
    drawn = np.asarray(preview.points, dtype=np.float64).reshape(-1, 3)
    scale = session.scene.geometry.scale
    gap = np.max(np.linalg.norm(np.diff(drawn, axis=0), axis=1))
    assert np.min(np.linalg.norm(drawn - target * scale, axis=1)) <= gap
    _set(session, lambda: session.pointer.release(((0.0, 0.0, 9.0), (0.0, 0.0, 1.0))))
    assert wait_until(lambda: session.body is not body)
    assert not session.clock.paused and not preview.visible
    np.testing.assert_allclose(session.body.omega0, target, rtol=1e-6)  # the last one drawn


def test_the_pointer_reaches_the_exact_separatrix(poinsot_app, probe) -> None:
    session = session_of(poinsot_app)
    body = session.body
    assert body is not None
    exact = np.asarray(FreeRigidBody.from_energy(body.inertia, sorted(body.inertia)[1]).omega0)
    exact *= np.sqrt(2.0 * body.energy / (exact @ (np.asarray(body.inertia) * exact)))
    # A third of a pixel off in each direction, at the ray's distance: within the snap.
    off = 0.3 * session.pointer.snap_world(5.0) / SNAP_PX

    def click_near() -> None:
        origin, direction = _ray_at(session, exact)
        session.pointer.release((origin, np.add(direction, (0.0, off, off))))

    _set(session, click_near)
    assert wait_until(lambda: session.body is not body)
    assert session.body.regime is Regime.SEPARATRIX
    assert session.body.D == sorted(body.inertia)[1]


def test_a_ray_that_misses_changes_nothing_and_says_so(poinsot_app, probe) -> None:
    session = session_of(poinsot_app)
    hint = f"<small>{POINTING_HINT.format(verb='Click')}</small>"
    assert probe.wait_for(lambda p: hint in _texts(p), 10)  # the ellipsoid says it is clickable
    body, status = session.body, session.status
    generation = session.generation
    session.post(lambda: session.pointer.release(((0.0, 0.0, 9.0), (1.0, 0.0, 0.0))))
    session.post(lambda: session.pointer.drag(((0.0, 0.0, 9.0), (0.0, 0.0, 1.0))))
    session.post(lambda: session.pointer.beside(((0.0, 0.0, 9.0), (0.0, 1.0, 0.0))))
    marker = []
    session.post(lambda: marker.append(True))
    assert wait_until(lambda: marker == [True])
    assert session.body is body and session.status == status == ""
    assert session.generation == generation and session.pointer.previews == 0
    assert session.pointer.misses == 2  # the release and the click beside the body
    missed = f"<small>{MISSED.format(verb='click')}</small>"
    assert probe.wait_for(lambda p: missed in _texts(p), 10)
    assert session.stats.errors == 0


def test_a_click_adds_no_folder_and_restarts_the_plot(poinsot_app, probe) -> None:
    session = session_of(poinsot_app)
    plot = session.panel.motion.plot
    assert plot is not None
    assert wait_until(lambda: len(plot.data[0]) > 3, 20)  # an old curve on screen
    _set(session, lambda: setattr(session.clock, "paused", True))  # it stays, paused
    groups = session.panel.groups
    body = session.body
    assert body is not None
    target = np.asarray(body.omega(0.3))
    target[0] *= -1.0
    _set(session, lambda: session.pointer.release(_ray_at(session, target)))
    assert session.preset.key == "custom"
    assert not (OWN_BODY_CONTROLS & session.panel.groups)  # no upload folder came
    assert session.panel.groups == groups
    assert session.clock.paused
    # the rebuild sent the new motion's start alone (a point at t = 0), not the old curve
    np.testing.assert_array_equal(np.asarray(plot.data[0], dtype=float), [0.0, 0.0])
    np.testing.assert_allclose(np.asarray(plot.data[1], dtype=float), session.body.omega0[0])


def _texts(probe) -> list[str]:
    return [w.props.get("_markdown", "") for w in probe.widgets.values()]
