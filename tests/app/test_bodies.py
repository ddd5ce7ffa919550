"""Any body from its mesh: mass properties at uniform density, the principal frame, the bundled
bodies, every accepted format, repair of small holes and clear errors for the rest."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from scipy.spatial.transform import Rotation

from poinsot.app.model.bodies import (
    BUNDLED,
    MAX_MESH_BYTES,
    MeshError,
    bundled_body,
    load_mesh_body,
)


def _box_moments(a: float, b: float, c: float) -> np.ndarray:
    """A homogeneous box at unit density: I = V (b² + c²)/12 and cyclic."""
    v = a * b * c
    return np.sort(v * np.array([b * b + c * c, a * a + c * c, a * a + b * b]) / 12.0)


def _stl(mesh: trimesh.Trimesh) -> bytes:
    return mesh.export(file_type="stl")


def test_a_turned_and_moved_box_is_measured_in_its_principal_frame():
    box = trimesh.creation.box(extents=(0.3, 0.2, 0.05))
    turn = np.eye(4)
    turn[:3, :3] = Rotation.from_rotvec([0.3, -1.1, 0.7]).as_matrix()
    turn[:3, 3] = (1.0, -2.0, 0.5)
    box.apply_transform(turn)
    body = load_mesh_body(_stl(box), "box.stl")
    assert np.allclose(body.inertia, _box_moments(0.3, 0.2, 0.05), rtol=1e-9)
    assert np.allclose(body.mesh.center_mass, 0.0, atol=1e-12)
    tensor = np.asarray(body.mesh.moment_inertia)
    assert np.allclose(tensor, np.diag(body.inertia), atol=1e-12 * max(body.inertia))
    assert np.allclose(sorted(body.mesh.extents), sorted((0.3, 0.2, 0.05)), atol=1e-12)
    assert not body.repaired
    assert body.ratios[2] == 1.0 and body.ratios[0] < body.ratios[1] < 1.0


@pytest.mark.parametrize("key", sorted(BUNDLED))
def test_every_bundled_body_is_closed_and_principal(key):
    body = bundled_body(key)
    assert body.mesh.is_watertight
    assert body.inertia[0] < body.inertia[1] < body.inertia[2]
    assert np.allclose(body.mesh.center_mass, 0.0, atol=1e-12)
    tensor = np.asarray(body.mesh.moment_inertia)
    off = tensor - np.diag(np.diag(tensor))
    assert np.max(np.abs(off)) < 1e-9 * body.inertia[2]
    # a proper rotation: the body is not mirrored, so its volume stays positive
    assert body.mesh.volume > 0


def test_the_bundled_book_is_the_box_of_its_size():
    body = bundled_body("book")
    assert np.allclose(body.inertia, _box_moments(0.24, 0.17, 0.03), rtol=1e-9)


@pytest.mark.parametrize("file_type", ["stl", "obj", "ply", "glb"])
def test_every_accepted_format_gives_the_same_moments(file_type):
    box = trimesh.creation.box(extents=(0.3, 0.2, 0.05))
    data = box.export(file_type=file_type)
    data = data.encode() if isinstance(data, str) else data
    body = load_mesh_body(data, f"box.{file_type.upper()}")
    assert np.allclose(body.inertia, _box_moments(0.3, 0.2, 0.05), rtol=1e-6)


def test_a_small_hole_is_repaired_and_said():
    box = trimesh.creation.box(extents=(0.3, 0.2, 0.05))
    holed = trimesh.Trimesh(box.vertices, box.faces[1:], process=False)
    assert not holed.is_watertight
    body = load_mesh_body(_stl(holed), "holed.stl")
    assert body.repaired
    assert np.allclose(body.inertia, _box_moments(0.3, 0.2, 0.05), rtol=1e-9)


def test_an_open_surface_is_refused_with_a_reason():
    box = trimesh.creation.box(extents=(0.3, 0.2, 0.05))
    open_box = trimesh.Trimesh(box.vertices, box.faces[6:], process=False)  # three sides gone
    with pytest.raises(MeshError, match="not a closed surface"):
        load_mesh_body(_stl(open_box), "open.stl")


@pytest.mark.parametrize(
    ("data", "name", "message"),
    [
        (b"solid x\nendsolid x\n", "empty.stl", "fewer than 4 faces|no triangle|could not be read"),
        (b"\x00\x01junk" * 10, "junk.ply", "could not be read|no triangle|fewer than"),
        (b"", "nothing.stl", "empty"),
        (b"v 0 0 0\n", "model.step", "not a mesh file"),
    ],
)
def test_bad_files_get_a_clear_message(data, name, message):
    with pytest.raises(MeshError, match=message):
        load_mesh_body(data, name)


def test_oversized_uploads_are_refused_before_parsing():
    with pytest.raises(MeshError, match="MB"):
        load_mesh_body(b"\x00" * (MAX_MESH_BYTES + 1), "big.stl")


def test_unknown_bundled_body():
    with pytest.raises(MeshError, match="choose one of"):
        bundled_body("piano")
