"""Meshes the scene draws: the unit icosphere behind the ellipsoid, the plane disc, and the
solid bodies of the presets. Geometry only (trimesh); the physical sizes come from
:mod:`poinsot.physics` and the presets."""

from __future__ import annotations

import functools

import numpy as np
import trimesh

from poinsot.app.model.elements import Solid

#: Icosphere subdivisions of the ellipsoid mesh: 2562 vertices, chord error ~ 2e-3.
ELLIPSOID_SUBDIVISIONS = 4


@functools.cache
def unit_sphere_vertices_faces() -> tuple[np.ndarray, np.ndarray]:
    """Vertices (on the unit sphere) and faces of the ellipsoid mesh before scaling."""
    sphere = trimesh.creation.icosphere(subdivisions=ELLIPSOID_SUBDIVISIONS, radius=1.0)
    return np.asarray(sphere.vertices), np.asarray(sphere.faces)


def disc_mesh(radius: float, sections: int = 96) -> tuple[np.ndarray, np.ndarray]:
    """A flat disc in the local xy plane (triangle fan), as (vertices, faces)."""
    angles = np.linspace(0.0, 2.0 * np.pi, sections, endpoint=False)
    rim = np.stack([radius * np.cos(angles), radius * np.sin(angles), np.zeros(sections)], 1)
    vertices = np.vstack([np.zeros((1, 3)), rim])
    i = np.arange(sections)
    faces = np.stack([np.zeros(sections, dtype=int), 1 + i, 1 + (i + 1) % sections], 1)
    return vertices, faces


def disc_grid_segments(radius: float, spacing: float) -> np.ndarray:
    """Grid lines clipped to a disc in the local xy plane, shape (N, 2, 3)."""
    n = int(np.floor(radius / spacing))
    offsets = spacing * np.arange(-n, n + 1)
    offsets = offsets[np.abs(offsets) < radius * 0.999]
    half = np.sqrt(radius**2 - offsets**2)
    zeros = np.zeros_like(offsets)
    vertical = np.stack(
        [np.stack([offsets, -half, zeros], 1), np.stack([offsets, half, zeros], 1)], 1
    )
    horizontal = np.stack(
        [np.stack([-half, offsets, zeros], 1), np.stack([half, offsets, zeros], 1)], 1
    )
    return np.concatenate([vertical, horizontal]).astype(np.float32)


def circle_segments(radius: float, sections: int = 128) -> np.ndarray:
    """A circle in the local xy plane as line segments, shape (sections, 2, 3)."""
    angles = np.linspace(0.0, 2.0 * np.pi, sections + 1)
    pts = np.stack([radius * np.cos(angles), radius * np.sin(angles), np.zeros_like(angles)], 1)
    return np.stack([pts[:-1], pts[1:]], 1).astype(np.float32)


def _cylinder_between(radius: float, start, end, sections: int = 64) -> trimesh.Trimesh:
    return trimesh.creation.cylinder(radius=radius, segment=[start, end], sections=sections)


def solid_mesh(solid: Solid) -> trimesh.Trimesh:
    """The solid in its principal axes (centre of mass at the origin), untextured."""
    if solid.mesh is not None:  # a body made from its mesh: drawn as it is
        shape = solid.mesh
        return trimesh.Trimesh(shape.vertices.copy(), shape.faces.copy(), process=False)
    if solid.kind == "box":
        mesh = trimesh.creation.box(extents=solid.dims)
    elif solid.kind == "cylinder":
        radius, length = solid.dims
        start = np.zeros(3)
        start[solid.axis] = -length / 2
        mesh = _cylinder_between(radius, start, -start)
    elif solid.kind == "t_handle":
        bar_length, bar_radius, stem_length, stem_radius = solid.dims
        bar = _cylinder_between(bar_radius, [-bar_length / 2, 0, 0], [bar_length / 2, 0, 0])
        stem = _cylinder_between(
            stem_radius, [0, -bar_radius, 0], [0, -bar_radius - stem_length, 0]
        )
        mesh = trimesh.util.concatenate([bar, stem])
    else:  # pragma: no cover - Literal type guards this
        raise ValueError(f"unknown solid kind {solid.kind!r}")
    mesh.apply_translation(solid.offset)
    return mesh


@functools.cache
def _unit_cube() -> trimesh.Trimesh:
    """The cube of side 1 every box is drawn from (made once: it is only read, or copied)."""
    return trimesh.creation.box(extents=(1.0, 1.0, 1.0))


def solid_shape(solid: Solid) -> tuple[tuple, trimesh.Trimesh, np.ndarray]:
    """``(key, mesh, scale)``: the mesh to send for ``solid`` and the node scale that turns it
    into the solid. Boxes share one unit cube scaled by their sides, so a box that changes
    with a slider costs a scale update, not a new mesh; other solids are sent as they are.
    ``key`` is equal for solids that share a mesh."""
    if solid.kind == "box":
        return ("box",), _unit_cube(), np.asarray(solid.dims)
    if solid.mesh is not None:
        return ("mesh", solid.mesh.digest), solid_mesh(solid), np.ones(3)
    return (solid.kind, solid.dims, solid.axis, solid.offset), solid_mesh(solid), np.ones(3)


def fit_scale(vertices: np.ndarray, semi_axes: np.ndarray, fill: float = 0.62) -> float:
    """Uniform scale that puts the farthest vertex at ``fill`` of the ellipsoid's 'radius'
    (the ellipsoid norm sqrt(sum x_i^2 / a_i^2)), so the solid sits inside the ellipsoid."""
    norm = np.sqrt(np.max(np.sum((vertices / semi_axes) ** 2, axis=1)))
    return float(fill / norm) if norm > 0 else 1.0
