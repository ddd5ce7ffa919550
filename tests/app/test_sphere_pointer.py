"""A start pointed at on Landau's momentum sphere in the polhode-family scene
(app/live/pointing/sphere_pointer.py): a click sets it at |L| kept, a drag draws the polhode through
it on the sphere and on the ellipsoid and starts there on release, the separatrix is reached by
hand, a miss does nothing, the D slider takes the motion back."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import wait_until
from scene_probing import start

from poinsot.app.construction.geometry import POLHODE_INFLATE
from poinsot.app.construction.sampled.frames import rotation_from_wxyz
from poinsot.app.lessons import scene_by_name
from poinsot.app.lessons.polhode_family import INERTIA
from poinsot.app.live.pointing.pointer import SNAP_PX, snap_length
from poinsot.app.live.session.session import Session
from poinsot.physics import Regime

I = np.asarray(INERTIA)  # noqa: E741 (the inertia tensor's usual name)


def _scene(make_app, make_probe) -> Session:
    _, session, _ = start(make_app, make_probe, scene_by_name("polhode-family"))
    assert session.sphere_pointer is not None and session.sphere_pointer.picture() is not None
    return session


def _G(session: Session) -> float:
    assert session.body is not None
    return float(np.linalg.norm(session.body.angular_momentum))


def _ray_at(session: Session, momentum: np.ndarray) -> tuple[tuple, tuple]:
    """A ray from 5 units out towards the drawn point of body-frame L on Landau's sphere."""
    pointer = session.sphere_pointer
    assert pointer is not None
    picture = pointer.picture()
    assert picture is not None
    pose = rotation_from_wxyz(np.asarray(picture.wxyz))
    point = np.asarray(picture.offset) + pose.apply(momentum * picture.scale)
    eye = point + 5.0 * pose.apply(momentum / np.linalg.norm(momentum))
    return tuple(eye), tuple(point - eye)


def _on_sphere(G: float, direction) -> np.ndarray:
    d = np.asarray(direction, dtype=float)
    return d * (G / np.linalg.norm(d))


def _run(session: Session, act) -> None:
    """Run ``act`` on the session's thread and wait until it has run."""
    done: list[bool] = []
    session.post(lambda: (act(), done.append(True)))
    assert wait_until(lambda: done == [True])


def test_a_click_on_the_sphere_starts_the_motion_there_at_g_kept(make_app, make_probe) -> None:
    session = _scene(make_app, make_probe)
    body, G = session.body, _G(session)
    target = _on_sphere(G, [0.7, -0.4, 0.6])
    _run(session, lambda: session.sphere_pointer.release(_ray_at(session, target)))
    assert wait_until(lambda: session.body is not body, 15)
    new = session.body
    assert new is not None and session.sphere_pointer.starts == 1
    np.testing.assert_allclose(I * new.omega0, target, rtol=1e-12)  # L at the point
    assert float(np.linalg.norm(new.angular_momentum)) == pytest.approx(G, rel=1e-12)
    w = target / I  # ω = I⁻¹L, on the energy ellipsoid of its own T
    assert 2.0 * new.energy == pytest.approx(float(w @ (I * w)), rel=1e-12)
    D = G**2 / float(w @ (I * w))
    model = session.showcase.showcase.model
    assert model.D == pytest.approx(D, rel=1e-12) and new.D == pytest.approx(D, rel=1e-12)
    assert wait_until(lambda: f"{D:.4g}" in session.panel.motion.readouts.content)
    assert session.showcase.sliders["D"].value == pytest.approx(D, rel=1e-12)  # it follows


def test_a_drag_draws_the_polhode_on_sphere_and_ellipsoid_then_plays(make_app, make_probe):
    session = _scene(make_app, make_probe)
    body, G = session.body, _G(session)
    pointer = session.sphere_pointer
    assert body is not None and not session.clock.paused
    target = _on_sphere(G, [0.9, 0.4, -0.2])  # far from the separatrix
    _run(session, lambda: pointer.drag(_ray_at(session, target)))
    assert pointer.previews == 1 and session.clock.paused  # the motion stands still
    sphere, ellipsoid = pointer.previews_drawn
    assert sphere.visible and ellipsoid.visible
    on_sphere = np.asarray(sphere.points, dtype=float).reshape(-1, 3)
    scale = pointer.picture().scale
    gap = np.max(np.linalg.norm(np.diff(on_sphere, axis=0), axis=1))
    assert np.min(np.linalg.norm(on_sphere - target * scale, axis=1)) <= gap  # through it
    np.testing.assert_allclose(np.linalg.norm(on_sphere, axis=1), G * scale, rtol=1e-5)
    # The twin lies on the ellipsoid as drawn (the body's T) and through ω's direction.
    drawn = np.asarray(ellipsoid.points, dtype=float).reshape(-1, 3)
    shown = session.scene.geometry.scale * POLHODE_INFLATE
    x = drawn / shown
    np.testing.assert_allclose(np.sum(x * I * x, axis=1), 2.0 * body.energy, rtol=1e-5)
    w = target / I
    w_drawn = w * np.sqrt(2.0 * body.energy / float(w @ (I * w))) * shown
    gap = np.max(np.linalg.norm(np.diff(drawn, axis=0), axis=1))
    assert np.min(np.linalg.norm(drawn - w_drawn, axis=1)) <= gap
    _run(session, lambda: pointer.release(((0.0, 0.0, 9.0), (0.0, 0.0, 1.0))))  # off it
    assert wait_until(lambda: session.body is not body, 15)
    assert not session.clock.paused and not sphere.visible and not ellipsoid.visible
    np.testing.assert_allclose(I * session.body.omega0, target, rtol=1e-12)  # the last drawn


def test_the_sphere_pointer_reaches_the_exact_separatrix(make_app, make_probe) -> None:
    session = _scene(make_app, make_probe)
    body, G = session.body, _G(session)
    I1, I2, I3 = INERTIA
    mu = np.sqrt(I3 * (I2 - I1) / (I1 * (I3 - I2)))  # L₃ = ±μ L₁ on the separatrix
    exact = _on_sphere(G, [-1.0, 0.6, -mu])
    # A third of a pixel off in each direction, at the ray's distance: within the snap.
    off = 0.3 * snap_length(session.client.camera, 5.0) / SNAP_PX

    def click_near() -> None:
        origin, direction = _ray_at(session, exact)
        session.sphere_pointer.release((origin, np.add(direction, (0.0, off, off))))

    _run(session, click_near)
    assert wait_until(lambda: session.body is not body, 15)
    new = session.body
    assert new.regime is Regime.SEPARATRIX and new.D == I2
    assert float(np.linalg.norm(new.angular_momentum)) == pytest.approx(G, rel=1e-12)
    snap = snap_length(session.client.camera, 5.0) / session.sphere_pointer.picture().scale
    assert np.linalg.norm(I * new.omega0 - exact) <= snap  # near where it was pointed


def test_a_ray_that_misses_the_sphere_does_nothing_and_the_slider_takes_over(
    make_app, make_probe
) -> None:
    session = _scene(make_app, make_probe)
    body, status, generation = session.body, session.status, session.generation
    pointer = session.sphere_pointer
    _run(session, lambda: pointer.release(((0.0, 0.0, 9.0), (1.0, 0.0, 0.0))))
    _run(session, lambda: pointer.drag(((0.0, 0.0, 9.0), (0.0, 0.0, 1.0))))
    _run(session, lambda: None)
    assert session.body is body and session.status == status == ""
    assert session.generation == generation and pointer.previews == pointer.starts == 0
    assert session.stats.errors == 0
    # A pointed start, then the D slider: the slider's D is shown again.
    _run(session, lambda: pointer.release(_ray_at(session, _on_sphere(_G(session), [1, 1, 1]))))
    assert wait_until(lambda: session.body is not body, 15)
    session.configure_scene("D", 2.3)
    assert wait_until(lambda: session.showcase.showcase.model.D == 2.3, 15)
    assert "start" not in session.showcase.desired


@pytest.mark.filterwarnings("error::UserWarning")
def test_the_sphere_of_a_scene_shown_again_takes_a_start(make_app, make_probe) -> None:
    session = _scene(make_app, make_probe)
    pointer = session.sphere_pointer
    target = [0.9, 0.4, -0.2]
    _run(session, lambda: pointer.drag(_ray_at(session, _on_sphere(_G(session), target))))
    assert pointer.previews == 1 and session.clock.paused
    family = scene_by_name("polhode-family")
    for spec in (scene_by_name("dzhanibekov"), family):  # a drag cut short by a change of scene
        session.choose_scene(spec)
        assert wait_until(
            lambda s=spec: session.showcase is not None and session.showcase.spec is s, 15
        )
    assert wait_until(lambda: session.showcase.loaded, 15)
    _run(session, lambda: None)
    assert pointer.previews_drawn == [] and not session.clock.paused
    body = session.body
    _run(session, lambda: pointer.release(_ray_at(session, _on_sphere(_G(session), target))))
    assert wait_until(lambda: session.body is not body, 15)
    assert pointer.starts == 1 and session.stats.errors == 0 and session.status == ""
