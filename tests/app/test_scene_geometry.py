"""The rolling is visibly right, checked on the geometry the browser actually receives.

A websocket probe (app/devtools/probe.py) decodes viser's wire messages and rebuilds the scene
as the browser would: the ellipsoid mesh vertices, its node scale, the body pose, the plane height,
the contact marker and the omega arrow. From those alone:
- the ellipsoid mesh is the unit sphere scaled by the sent semi-axes;
- no vertex pokes through the plane (n.x <= h), and the highest vertex reaches it up to the
  mesh's chord error, next to the contact point;
- the smooth surface the mesh samples (the ellipsoid with the sent semi-axes, in the sent
  pose) has its support height along n = e_z exactly h, attained exactly at the contact point;
- the contact point is the tip of the omega arrow and lies on the plane.
Every preset, at several times (the clock is stepped with the Step button, as a user would).
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import session_of, wait_until

from poinsot.app.construction.meshes import ELLIPSOID_SUBDIVISIONS
from poinsot.app.construction.sampled.frames import rotation_from_wxyz
from poinsot.app.devtools.probe import Probe
from poinsot.app.model.elements import Control
from poinsot.app.model.presets import PRESETS

#: Wire floats: poses and scales travel as float64, mesh vertices and arrow points as float32.
FLOAT32_REL = 2e-6
#: Chord error of the icosphere (subdivision 4) on an ellipsoid of aspect <= 4, relative to
#: the largest semi-axis: the highest vertex is at most this far below the plane.
CHORD_REL = 4e-3
#: Exact incidence of the smooth surface: physics is ~1e-12, the wire float64.
EXACT = 1e-9


def check_finite(probe: Probe) -> None:
    """No NaN or infinity anywhere in what the browser holds."""
    nodes, _ = probe.snapshot()
    for name, node in nodes.items():
        assert np.all(np.isfinite(node.wxyz)) and np.all(np.isfinite(node.position)), name
        for key, value in node.props.items():
            if isinstance(value, np.ndarray) and value.dtype.kind == "f":
                assert np.all(np.isfinite(value)), f"{name}.{key}"
            elif isinstance(value, float):
                assert np.isfinite(value), f"{name}.{key}"


def sent_geometry(probe: Probe) -> dict[str, np.ndarray | float]:
    nodes, _ = probe.snapshot()
    for parent in ("/space",):
        assert np.allclose(nodes[parent].wxyz, (1, 0, 0, 0))
        assert np.allclose(nodes[parent].position, 0)
    ellipsoid = nodes["/space/body/ellipsoid"]
    assert np.allclose(ellipsoid.wxyz, (1, 0, 0, 0)) and np.allclose(ellipsoid.position, 0)
    arrow = np.asarray(nodes["/space/omega"].props["points"], dtype=np.float64).reshape(-1, 2, 3)
    return {
        "vertices": np.asarray(ellipsoid.props["vertices"], dtype=np.float64).reshape(-1, 3),
        "scale": np.broadcast_to(np.asarray(ellipsoid.props["scale"], np.float64), (3,)),
        "wxyz": np.asarray(nodes["/space/body"].wxyz),
        "h": float(nodes["/space/plane"].position[2]),
        "plane_xy": np.asarray(nodes["/space/plane"].position[:2]),
        "tip": np.asarray(nodes["/space/tip"].position),
        "arrow": arrow,
    }


def check_rolling_contact(g: dict) -> None:
    vertices, scale, h, tip = g["vertices"], g["scale"], g["h"], g["tip"]
    rotation = rotation_from_wxyz(g["wxyz"])
    # The mesh is the unit sphere, so the sent surface is the ellipsoid with semi-axes `scale`.
    assert np.allclose(np.linalg.norm(vertices, axis=1), 1.0, atol=FLOAT32_REL)
    assert len(vertices) == 10 * 4**ELLIPSOID_SUBDIVISIONS + 2
    assert np.allclose(g["plane_xy"], 0.0)
    world = rotation.apply(vertices * scale)
    height = world[:, 2]
    a = float(scale.max())
    # No penetration, and no gap beyond the mesh's chord error, near the contact point.
    assert height.max() <= h + FLOAT32_REL * a
    assert height.max() >= h - CHORD_REL * a
    top = world[np.argmax(height)]
    assert np.linalg.norm(top - tip) < 0.12 * a
    # The smooth ellipsoid: support along e_z (in body axes n = R^T e_z) is h, at the tip.
    n = rotation.inv().apply([0.0, 0.0, 1.0])
    support = float(np.sqrt(np.sum((scale * n) ** 2)))
    assert support == pytest.approx(h, rel=EXACT)
    touching = rotation.apply(scale**2 * n / support)
    assert np.allclose(touching, tip, atol=EXACT * a * 10)
    # The contact point is on the plane, and it is the tip of the omega arrow from the origin.
    assert tip[2] == pytest.approx(h, rel=EXACT)
    assert g["arrow"].shape == (1, 2, 3)
    assert np.allclose(g["arrow"][0, 0], 0.0)
    assert np.allclose(g["arrow"][0, 1], tip, atol=FLOAT32_REL * a)


@pytest.mark.parametrize("preset", PRESETS, ids=[p.key for p in PRESETS])
def test_ellipsoid_touches_the_plane_exactly_at_the_tip_of_omega(preset, make_app, make_probe):
    app = make_app(preset)
    probe = make_probe(app)
    assert probe.wait_for(lambda p: "/space/body/ellipsoid" in p.nodes, 15)
    session = session_of(app)
    assert Control.PLAYBACK in preset.controls
    assert wait_until(lambda: session.stats.frames > 5, 30)
    pause, _ = probe.widget("Pause")
    probe.set_value(pause, True)
    assert wait_until(lambda: session.clock.paused, 30)
    step, _ = probe.widget("Step")
    for k in range(3):
        t = session.clock.now()
        if k:
            probe.set_value(step, True)
            assert wait_until(lambda t=t: session.clock.now() > t, 30)
        t = session.scene.shown_time(session.clock.now())
        # Paused: once the browser holds the frame of time t, nothing moves any more.
        assert wait_until(lambda t=t: session.frame is not None and session.frame.t == t, 30)
        expected_tip = session.frame.contact
        assert probe.wait_for(
            lambda p, e=expected_tip: np.allclose(p.nodes["/space/tip"].position, e), 30
        )
        check_finite(probe)
        check_rolling_contact(sent_geometry(probe))
    assert session.stats.errors == 0, session.stats.last_error
