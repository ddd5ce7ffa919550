"""Helpers for the upload tests: recordings and meshes as bytes, and uploads sent by a probe the
way viser's browser client sends them (announce the file, then parts of 512 KiB)."""

from __future__ import annotations

import uuid

import numpy as np
import trimesh

from poinsot.app import viser_private
from poinsot.app.devtools.probe import Probe
from poinsot.physics.fit import synthetic_toss

#: The T-handle of the presets, tossed spinning about its intermediate axis (it flips).
TOSS_INERTIA = (1.0, 2.2782, 3.1839)
TOSS_OMEGA0 = (0.3, 10.0, 0.3)
HEADER = (
    '"Time (s)","Gyroscope x (rad/s)","Gyroscope y (rad/s)","Gyroscope z (rad/s)",'
    '"Absolute (rad/s)"'
)
RECORDING = "Upload a recording (.zip, .csv)"
MESH = "Upload a mesh (STL, OBJ, PLY, GLB)"
PART = 512 * 1024


def phyphox_csv(t: np.ndarray, omega: np.ndarray) -> bytes:
    """A phyphox gyroscope table: quoted header, |ω| in the last column."""
    lines = [HEADER]
    for ti, wi in zip(t, omega, strict=True):
        lines.append(",".join(f"{v:.12E}" for v in (ti, *wi, np.linalg.norm(wi))))
    return ("\n".join(lines) + "\n").encode()


def toss_recording(seed: int = 1, duration: float = 2.0) -> bytes:
    t, w = synthetic_toss(TOSS_INERTIA, TOSS_OMEGA0, duration=duration, seed=seed)
    return phyphox_csv(t, w)


def expected_moments() -> np.ndarray:
    """The tossed body's moments as the app shows them: the largest is 1."""
    moments = np.asarray(TOSS_INERTIA)
    return moments / moments.max()


def box_stl(extents=(3.0, 2.0, 1.0), drop_faces: int = 0) -> bytes:
    """A box as binary STL, turned off its principal axes; ``drop_faces`` triangles left out."""
    box = trimesh.creation.box(extents=extents)
    box.apply_transform(trimesh.transformations.rotation_matrix(0.4, (1.0, 2.0, 0.5)))
    if drop_faces:
        box = trimesh.Trimesh(box.vertices, box.faces[drop_faces:], process=False)
    return box.export(file_type="stl")


def open_bowl_stl() -> bytes:
    """Half a sphere: a hole far too large to close."""
    sphere = trimesh.creation.icosphere(subdivisions=2)
    keep = sphere.triangles_center[:, 2] > 0.0
    return trimesh.Trimesh(sphere.vertices, sphere.faces[keep]).export(file_type="stl")


def upload(
    probe: Probe,
    label: str,
    name: str,
    content: bytes,
    *,
    declared: int | None = None,
    mime: str = "application/octet-stream",
) -> str:
    """Send ``content`` to the upload button labelled ``label``, as the browser does; returns
    the transfer's id. ``declared``: the size announced (default: the true size)."""
    button, _ = probe.widget(label)
    transfer = uuid.uuid4().hex
    parts = [content[i : i + PART] for i in range(0, len(content), PART)]
    size = len(content) if declared is None else declared
    probe.send(
        viser_private.wire_message(
            "FileTransferStartUpload", button, transfer, name, mime, len(parts), size
        )
    )
    for k, part in enumerate(parts):
        probe.send(viser_private.wire_message("FileTransferPart", button, transfer, k, part))
    return transfer
