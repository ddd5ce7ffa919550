"""Any body from its mesh: a closed triangle mesh becomes a rigid body in its principal frame.

A student uploads an STL, OBJ, PLY or GLB (or picks one of the bundled bodies in
``assets/bodies/``: a book, a phone, a tennis racquet, a T-handle). trimesh gives the mass
properties of the closed mesh at uniform density; the mesh is then moved so that its centre of
mass is at the origin and turned so that its principal axes are x, y, z with the moments in
ascending order (a proper rotation: no mirror image). Those moments drive the scene and the
mesh is drawn as the body. This module reads and measures; it does no dynamics.
"""

from __future__ import annotations

import dataclasses
import io
import pathlib

import numpy as np
import trimesh

#: Uploads larger than this are refused before parsing [bytes].
MAX_MESH_BYTES = 20 * 1024 * 1024
#: Meshes with more faces are refused (the browser draws every one of them).
MAX_FACES = 500_000
#: The file types trimesh reads for us, by suffix.
MESH_TYPES = ("stl", "obj", "ply", "glb")
#: Where the bundled bodies live (the repository's top-level assets/ folder).
ASSETS = pathlib.Path(__file__).resolve().parents[2] / "assets" / "bodies"
#: The bundled bodies: key -> (file name, label).
BUNDLED: dict[str, tuple[str, str]] = {
    "book": ("book.stl", "Book (hardback, 24 x 17 x 3 cm)"),
    "phone": ("phone.stl", "Phone (15 x 7.5 x 0.8 cm)"),
    "racquet": ("tennis_racquet.stl", "Tennis racquet"),
    "t_handle": ("t_handle.stl", "T-handle (wing nut)"),
}


@dataclasses.dataclass(frozen=True)
class MeasuredBody:
    """A body known by its measured principal moments rather than by a mesh of its own; it is
    drawn with the bundled mesh of its kind (``mesh_key``).

    Attributes:
        key, label: its name. inertia: (3,) principal moments, ascending [kg m²].
        mesh_key: the :data:`BUNDLED` mesh drawn for it. source: where the moments come from
        (a key of docs/REFERENCES.md).
    """

    key: str
    label: str
    inertia: tuple[float, float, float]
    mesh_key: str
    source: str

    @property
    def ratios(self) -> tuple[float, float, float]:
        """The moments normalised so that the largest is 1."""
        top = self.inertia[2]
        return (self.inertia[0] / top, self.inertia[1] / top, 1.0)


#: Bodies known by their measured moments: Brody's Wilson T-2000 tennis racquet (1985), as
#: quoted by [ACC91, footnote 4], beside the bundled racquet mesh.
MEASURED: dict[str, MeasuredBody] = {
    "brody": MeasuredBody(
        "brody",
        "Tennis racquet (Brody's Wilson T-2000, measured)",
        (0.00121, 0.01638, 0.01748),
        "racquet",
        "[ACC91] footnote 4, Brody (1985)",
    ),
}


class MeshError(ValueError):
    """A mesh that cannot be a rigid body; the message says what to change."""


@dataclasses.dataclass(frozen=True)
class MeshBody:
    """A closed mesh in its principal frame.

    Attributes:
        name: where it came from (file name or bundled label).
        mesh: the mesh, centre of mass at the origin, principal axes along x, y, z [m].
        inertia: (3,) principal moments at unit density, ascending [m⁵ (kg m² per kg/m³)].
        volume: [m³].
        repaired: True if trimesh had to close holes or fix normals to make it watertight.
    """

    name: str
    mesh: trimesh.Trimesh
    inertia: tuple[float, float, float]
    volume: float
    repaired: bool

    @property
    def ratios(self) -> tuple[float, float, float]:
        """The moments normalised so that the largest is 1."""
        top = self.inertia[2]
        return (self.inertia[0] / top, self.inertia[1] / top, 1.0)


def _suffix(name: str) -> str:
    suffix = pathlib.PurePath(name).suffix.lower().lstrip(".")
    if suffix not in MESH_TYPES:
        raise MeshError(
            f"{name!r} is not a mesh file Poinsot reads: use one of "
            + ", ".join(f".{t}" for t in MESH_TYPES)
        )
    return suffix


def _single_mesh(loaded: object, name: str) -> trimesh.Trimesh:
    """One Trimesh from what trimesh.load returned (a GLB is a Scene of several meshes)."""
    if isinstance(loaded, trimesh.Scene):
        meshes = [g for g in loaded.dump() if isinstance(g, trimesh.Trimesh)]
        if not meshes:
            raise MeshError(f"{name!r} holds no triangle mesh")
        merged = trimesh.util.concatenate(meshes)
        assert isinstance(merged, trimesh.Trimesh)
        return merged
    if isinstance(loaded, trimesh.Trimesh):
        return loaded
    raise MeshError(f"{name!r} holds no triangle mesh (found {type(loaded).__name__})")


def _watertight(mesh: trimesh.Trimesh, name: str) -> tuple[trimesh.Trimesh, bool]:
    """The mesh, closed if trimesh can close it; a clear error if it cannot."""
    if mesh.is_watertight and mesh.is_winding_consistent:
        return mesh, False
    mesh = mesh.copy()
    mesh.merge_vertices()
    trimesh.repair.fix_winding(mesh)
    trimesh.repair.fill_holes(mesh)
    trimesh.repair.fix_normals(mesh)
    if not mesh.is_watertight:
        raise MeshError(
            f"{name!r} is not a closed surface (it has holes or loose edges that could not be "
            "repaired), so it has no volume and no moments of inertia: export it as a "
            "watertight solid"
        )
    return mesh, True


def principal_frame(mesh: trimesh.Trimesh) -> tuple[trimesh.Trimesh, np.ndarray]:
    """The mesh moved to its centre of mass and turned onto its principal axes (ascending
    moments, right-handed), and the (3,) moments at unit density."""
    if mesh.volume < 0:
        mesh = mesh.copy()
        mesh.invert()
    moments, axes = np.linalg.eigh(np.asarray(mesh.moment_inertia, dtype=float))
    if np.linalg.det(axes) < 0:  # a proper rotation: flip one axis, never mirror the body
        axes[:, 2] = -axes[:, 2]
    transform = np.eye(4)
    transform[:3, :3] = axes.T
    transform[:3, 3] = -axes.T @ np.asarray(mesh.center_mass, dtype=float)
    placed = mesh.copy()
    placed.apply_transform(transform)
    return placed, moments


def body_from_mesh(mesh: trimesh.Trimesh, name: str) -> MeshBody:
    """Measure a loaded mesh (see :func:`load_mesh_body`)."""
    if len(mesh.faces) > MAX_FACES:
        raise MeshError(f"{name!r} has {len(mesh.faces):,} faces; at most {MAX_FACES:,} please")
    if len(mesh.faces) < 4:
        raise MeshError(f"{name!r} has fewer than 4 faces: it cannot enclose a volume")
    mesh, repaired = _watertight(mesh, name)
    volume = abs(float(mesh.volume))
    extent = float(np.max(mesh.extents))
    if not np.isfinite(volume) or extent <= 0 or volume <= 1e-12 * extent**3:
        raise MeshError(f"{name!r} encloses no volume (a flat or degenerate mesh)")
    placed, moments = principal_frame(mesh)
    if not np.all(np.isfinite(moments)) or moments[0] <= 0:
        raise MeshError(f"{name!r} gives no positive moments of inertia")
    inertia = (float(moments[0]), float(moments[1]), float(moments[2]))
    return MeshBody(name, placed, inertia, volume, repaired)


def load_mesh_body(data: bytes, name: str) -> MeshBody:
    """A :class:`MeshBody` from an uploaded file's bytes; ``name`` (with its suffix) says the
    format. Raises :class:`MeshError` (a ValueError) with a message for the student."""
    file_type = _suffix(name)
    if len(data) > MAX_MESH_BYTES:
        raise MeshError(
            f"{name!r} is {len(data) / 1e6:.1f} MB; meshes up to {MAX_MESH_BYTES // 2**20} MB "
            "are accepted (simplify it first)"
        )
    if not data:
        raise MeshError(f"{name!r} is empty")
    try:
        loaded = trimesh.load(io.BytesIO(data), file_type=file_type, process=True)
    except Exception as exc:  # trimesh raises many kinds on junk input
        raise MeshError(f"{name!r} could not be read as .{file_type}: {exc}") from None
    return body_from_mesh(_single_mesh(loaded, name), name)


def bundled_body(key: str) -> MeshBody:
    """One of the bundled bodies (:data:`BUNDLED`), measured like an upload."""
    if key not in BUNDLED:
        raise MeshError(f"no bundled body {key!r}; choose one of {', '.join(BUNDLED)}")
    file_name, label = BUNDLED[key]
    path = ASSETS / file_name
    if not path.is_file():
        raise MeshError(f"the bundled body {label} is missing ({path})")
    body = load_mesh_body(path.read_bytes(), file_name)
    return dataclasses.replace(body, name=label)
