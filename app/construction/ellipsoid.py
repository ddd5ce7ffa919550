"""The energy ellipsoid, built in one place: the unit icosphere of :mod:`.meshes` scaled by the
semi-axes of a :class:`~poinsot.app.construction.geometry.Geometry` (display units).

Every picture of it comes from here: the construction's element
(:class:`Ellipsoid`), the body-frame picture
(:mod:`poinsot.app.construction.body_view`), the numerical ghost's shell
(:mod:`poinsot.app.construction.ghost.ghost`), the GLB export and the strobe picture
(:func:`ellipsoid_mesh`).
"""

from __future__ import annotations

import numpy as np
import trimesh
import viser

from poinsot.app.construction import meshes, palette
from poinsot.app.construction.drawing import Drawing
from poinsot.app.construction.geometry import Geometry, triple
from poinsot.app.construction.palette import RGB, Look


def add_ellipsoid(api: viser.SceneApi, name: str, color: RGB, opacity: float) -> viser.MeshHandle:
    """The ellipsoid as a viser node at ``name``: the unit icosphere, which :func:`fit_ellipsoid`
    scales. Sent as a plain mesh (the browser computes smooth normals; a GLB with normals and a
    non-uniform node scale did not render in viser 1.1)."""
    vertices, faces = meshes.unit_sphere_vertices_faces()
    return api.add_mesh_simple(
        name,
        vertices,
        faces,
        color=color,
        opacity=opacity,
        material="standard",
        side="front",
        cast_shadow=False,
        receive_shadow=False,
    )


def fit_ellipsoid(handle: viser.MeshHandle, semi_axes: np.ndarray) -> None:
    """Scale the node of :func:`add_ellipsoid` to ``semi_axes`` (3,) [display units]."""
    handle.scale = triple(semi_axes)


def ellipsoid_mesh(semi_axes: np.ndarray) -> trimesh.Trimesh:
    """The ellipsoid as a mesh in body coordinates, scaled by ``semi_axes`` (3,) [display
    units]: what an export writes or projects."""
    vertices, faces = meshes.unit_sphere_vertices_faces()
    scaled = vertices * np.asarray(semi_axes, dtype=np.float64)
    return trimesh.Trimesh(vertices=scaled, faces=faces.copy(), process=False)


class Ellipsoid(Drawing):
    """The energy ellipsoid: the unit icosphere, scaled by the semi-axes."""

    def __init__(self, api: viser.SceneApi, root: str) -> None:
        self.mesh = add_ellipsoid(
            api, f"{root}/body/ellipsoid", palette.ELLIPSOID, palette.ELLIPSOID_OPACITY
        )
        super().__init__([self.mesh])

    def fit(self, geometry: Geometry) -> None:
        fit_ellipsoid(self.mesh, geometry.semi_axes)

    def restyle(self, look: Look) -> None:
        self.mesh.color, self.mesh.opacity = look.ellipsoid, look.ellipsoid_opacity
