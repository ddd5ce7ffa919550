"""In Chromium at 1280×800: a click on Landau's momentum sphere in the polhode-family scene
sets the start there, at |L| kept (app/live/pointing/sphere_pointer.py)."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import css_pixel, session_of, wait_until

from poinsot.app.lessons import scene_by_name

#: viser's drag binding on a node answers a mouse press so (the same on the energy ellipsoid).
DRAG_BINDING = "Unable to preventDefault inside passive event listener invocation."


def test_a_click_on_landaus_sphere_sets_the_start(make_app, open_page) -> None:
    app = make_app(scene=scene_by_name("polhode-family"))
    page = open_page(app.url, 1280, 800)
    session = session_of(app)
    assert wait_until(lambda: session.showcase is not None and session.showcase.loaded, 20)
    pointer = session.sphere_pointer
    assert pointer is not None
    picture = pointer.picture()
    assert picture is not None and session.body is not None
    body, G = session.body, float(np.linalg.norm(session.body.angular_momentum))
    box = page.settled_canvas(session.client)  # the sphere is drawn where the camera says
    camera = session.client.camera
    centre = np.asarray(picture.offset)
    toward = np.asarray(camera.position, float) - centre
    toward /= np.linalg.norm(toward)
    aim = toward + np.array([0.5, 0.0, 0.35])
    x, y = css_pixel(camera, box, centre + picture.radius * aim / np.linalg.norm(aim))
    page.page.mouse.click(x, y)
    assert wait_until(lambda: session.body is not body, 15), "the click set no start"
    assert pointer.starts == 1
    new = session.body
    assert float(np.linalg.norm(new.angular_momentum)) == pytest.approx(G, rel=1e-12)
    assert wait_until(lambda: f"{new.D:.4g}" in session.panel.motion.readouts.content, 10)
    assert set(page.errors) <= {DRAG_BINDING}, page.errors
