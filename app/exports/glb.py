"""Poinsot's construction as a GLB mesh, for Blender or any glTF viewer.

The energy ellipsoid (posed at the current attitude), the invariable plane, the polhode (on the
ellipsoid, in the body node), the herpolhode (on the plane), the contact point and the ω and L
arrows, as named trimesh geometries in the app's display units and colours. glTF is y-up: the
root node ``space`` turns the app's z-up space frame (L vertical) into y-up, so that Blender
and glTF viewers show L vertical too. Every number comes from :mod:`poinsot.physics`
(``FreeRigidBody.state``, ``contact_point``, ``polhode``).
"""

from __future__ import annotations

import numpy as np
import trimesh
import trimesh.visual.material

from poinsot.app.construction import meshes, palette
from poinsot.app.construction.ellipsoid import ellipsoid_mesh
from poinsot.app.construction.geometry import (
    CONTACT_RADIUS,
    HERPOLHODE_LIFT,
    L_ARROW,
    L_OVERSHOOT,
    OMEGA_ARROW,
    PLANE_RADIUS,
    POLHODE_INFLATE,
    ArrowShape,
    Geometry,
)
from poinsot.app.exports.run_csv import DEFAULT_SPAN, period_or
from poinsot.app.model.elements import Solid
from poinsot.physics import FreeRigidBody

#: Tube radius of the exported polhode and herpolhode, and its number of sides [display units].
TUBE_RADIUS = 0.008
TUBE_SIDES = 10
#: Points of the exported herpolhode (one period of omega before the current time).
HERPOLHODE_POINTS = 1200
#: Opacity of the exported plane (a viewer's lighting differs from the app's).
PLANE_OPACITY = 0.35
#: Names of the geometries in the GLB (tests and users look for them).
GLB_NAMES = ("ellipsoid", "plane", "polhode", "herpolhode", "contact", "omega", "L")
#: glTF is y-up; the app's space frame is z-up (L vertical): x -> x, z -> y, y -> -z.
Z_UP_TO_Y_UP = np.array(
    [[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, -1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
)


def _pbr(rgb: palette.RGB, opacity: float = 1.0) -> trimesh.visual.material.PBRMaterial:
    return trimesh.visual.material.PBRMaterial(
        baseColorFactor=[*(c / 255.0 for c in rgb), opacity],
        metallicFactor=0.0,
        roughnessFactor=0.5,
        alphaMode="BLEND" if opacity < 1.0 else "OPAQUE",
        doubleSided=opacity < 1.0,
    )


def _painted(mesh: trimesh.Trimesh, rgb: palette.RGB, opacity: float = 1.0) -> trimesh.Trimesh:
    mesh.visual = trimesh.visual.TextureVisuals(material=_pbr(rgb, opacity))
    return mesh


def _frames(tangents: np.ndarray) -> np.ndarray:
    """Rotation-minimising normals along a polyline's unit tangents (N, 3): each normal is the
    previous one with its tangential part removed, so that a tube does not twist."""
    normals = np.empty_like(tangents)
    axis = np.eye(3)[int(np.argmin(np.abs(tangents[0])))]
    n = axis - tangents[0] * (axis @ tangents[0])
    # Sequential by nature (each frame comes from the previous one); a loop over the polyline's
    # vertices, a few thousand at most, run once per export.
    for i, tangent in enumerate(tangents):
        n = n - tangent * (n @ tangent)
        norm = np.linalg.norm(n)
        if norm < 1e-9:  # the tangent turned onto the old normal: take any perpendicular
            axis = np.eye(3)[int(np.argmin(np.abs(tangent)))]
            n = axis - tangent * (axis @ tangent)
            norm = np.linalg.norm(n)
        n = n / norm
        normals[i] = n
    return normals


def tube(
    points: np.ndarray, radius: float = TUBE_RADIUS, sides: int = TUBE_SIDES
) -> trimesh.Trimesh:
    """A tube of ``radius`` around the polyline ``points`` (N, 3), with rotation-minimising
    frames, so that it does not twist."""
    pts = np.asarray(points, dtype=np.float64)
    keep = np.concatenate([[True], np.linalg.norm(np.diff(pts, axis=0), axis=1) > 1e-12])
    pts = pts[keep]
    if len(pts) < 2:
        raise ValueError("a tube needs at least two distinct points")
    tangents = np.gradient(pts, axis=0)
    tangents /= np.linalg.norm(tangents, axis=1, keepdims=True)
    normals = _frames(tangents)
    binormals = np.cross(tangents, normals)
    angles = np.linspace(0.0, 2.0 * np.pi, sides, endpoint=False)
    ring = (
        np.cos(angles)[None, :, None] * normals[:, None]
        + np.sin(angles)[None, :, None] * binormals[:, None]
    )
    vertices = (pts[:, None, :] + radius * ring).reshape(-1, 3)
    i = np.arange(len(pts) - 1)[:, None]
    j = np.arange(sides)[None, :]
    a, b = i * sides + j, i * sides + (j + 1) % sides
    c, d = a + sides, b + sides
    faces = np.concatenate([np.stack([a, b, d], -1), np.stack([a, d, c], -1)]).reshape(-1, 3)
    return trimesh.Trimesh(vertices=vertices, faces=faces, process=False)


def _arrow(tip: np.ndarray, shape: ArrowShape) -> trimesh.Trimesh:
    """An arrow from the origin to ``tip``."""
    tip = np.asarray(tip, dtype=np.float64)
    length = float(np.linalg.norm(tip))
    direction = tip / length
    shaft_end = direction * (length - shape.head_length)
    cylinder = trimesh.creation.cylinder(
        radius=shape.shaft_radius, segment=[np.zeros(3), shaft_end], sections=24
    )
    cone = trimesh.creation.cone(radius=shape.head_radius, height=shape.head_length, sections=24)
    align = trimesh.geometry.align_vectors([0.0, 0.0, 1.0], direction)
    align[:3, 3] = shaft_end
    cone.apply_transform(align)
    arrow = trimesh.util.concatenate([cylinder, cone])
    assert isinstance(arrow, trimesh.Trimesh)  # two meshes concatenate into one
    return arrow


def _body_parts(g: Geometry) -> dict[str, trimesh.Trimesh]:
    """What the body node carries, in body coordinates: the ellipsoid, the polhode, the solid."""
    ellipsoid = ellipsoid_mesh(g.semi_axes)
    polhode = g.polhode * POLHODE_INFLATE
    if g.polhode_closed:
        polhode = np.concatenate([polhode, polhode[:1]])
    parts = {
        "ellipsoid": _painted(ellipsoid, palette.ELLIPSOID, palette.ELLIPSOID_OPACITY),
        "polhode": _painted(tube(polhode), palette.POLHODE),
    }
    if g.solid_mesh is not None:
        parts["solid"] = g.solid_mesh.copy()
    return parts


def _space_parts(body: FreeRigidBody, t: float, g: Geometry) -> dict[str, trimesh.Trimesh]:
    """What the space frame carries at time ``t``: the plane, the herpolhode of the last period,
    the contact point and the ω and L arrows."""
    contact = np.asarray(body.contact_point(np.array([t])))[0] * g.scale
    span = period_or(body, DEFAULT_SPAN)
    herpolhode = body.contact_point(np.linspace(t - span, t, HERPOLHODE_POINTS))
    lifted = np.asarray(herpolhode, dtype=np.float64) * g.scale + [0.0, 0.0, HERPOLHODE_LIFT]
    vertices, faces = meshes.disc_mesh(PLANE_RADIUS)
    plane = trimesh.Trimesh(
        vertices=vertices + [0.0, 0.0, g.plane_height], faces=faces, process=False
    )
    marker = trimesh.creation.icosphere(2, radius=CONTACT_RADIUS).apply_translation(contact)
    top = np.array([0.0, 0.0, g.plane_height + L_OVERSHOOT])
    return {
        "plane": _painted(plane, palette.PLANE, PLANE_OPACITY),
        "herpolhode": _painted(tube(lifted), palette.HERPOLHODE),
        "contact": _painted(marker, palette.CONTACT),
        "omega": _painted(_arrow(contact, OMEGA_ARROW), palette.OMEGA),
        "L": _painted(_arrow(top, L_ARROW), palette.ANGULAR_MOMENTUM),
    }


def scene_glb(
    body: FreeRigidBody,
    t: float,
    geometry: Geometry | None = None,
    solid: Solid | None = None,
) -> bytes:
    """Poinsot's construction at time ``t`` as GLB bytes, in the app's display units.

    ``geometry``: what the app's scene already computed for ``body`` (sizes, polhode, solid
    mesh); computed here from ``body`` and ``solid`` if omitted.
    """
    g = geometry if geometry is not None else Geometry.from_body(body, solid)
    t = float(t)
    _, rotation = body.state(np.array([t]))
    attitude = np.eye(4)
    attitude[:3, :3] = rotation.as_matrix()[0]
    scene = trimesh.Scene(base_frame="world")
    scene.graph.update(frame_from="world", frame_to="space", matrix=Z_UP_TO_Y_UP)
    scene.graph.update(frame_from="space", frame_to="body", matrix=attitude)
    for parent, parts in (("body", _body_parts(g)), ("space", _space_parts(body, t, g))):
        for name, mesh in parts.items():
            scene.add_geometry(mesh, geom_name=name, node_name=name, parent_node_name=parent)
    return scene.export(file_type="glb")
