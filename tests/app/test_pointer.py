"""A start pointed at on the live ellipsoid (app/live/pointing/pointer.py): a click sets it, a drag
draws the polhode through it and starts there on release, the separatrix is reached by hand, a miss
does nothing."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import session_of, wait_until

from poinsot.app.construction.sampled.frames import rotation_from_wxyz
from poinsot.app.live.pointing.pointer import SNAP_PX
from poinsot.app.live.session.session import Session
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
    assert wait_until(lambda: f"{expected_D:.6g}" in readouts.content, 30), readouts.content


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


def test_a_ray_that_misses_does_nothing_and_says_nothing(poinsot_app, probe) -> None:
    session = session_of(poinsot_app)
    body, status = session.body, session.status
    generation = session.generation
    session.post(lambda: session.pointer.release(((0.0, 0.0, 9.0), (1.0, 0.0, 0.0))))
    session.post(lambda: session.pointer.drag(((0.0, 0.0, 9.0), (0.0, 0.0, 1.0))))
    marker = []
    session.post(lambda: marker.append(True))
    assert wait_until(lambda: marker == [True])
    assert session.body is body and session.status == status == ""
    assert session.generation == generation and session.pointer.previews == 0
    assert session.stats.errors == 0
