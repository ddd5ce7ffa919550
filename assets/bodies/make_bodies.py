"""Writes the bundled bodies (binary STL, metres) with trimesh: ``python assets/bodies/make_bodies.py``.

Each is a union of disjoint closed parts, so the file is watertight and its mass properties at
uniform density are those of the solid. Sizes are typical of the real object.
"""

import pathlib

import numpy as np
import trimesh

HERE = pathlib.Path(__file__).resolve().parent


def book() -> trimesh.Trimesh:
    """A hardback: 24 x 17 x 3 cm."""
    return trimesh.creation.box(extents=(0.24, 0.17, 0.03))


def phone() -> trimesh.Trimesh:
    """A phone: 15 x 7.5 x 0.8 cm with rounded long edges (a box and two half-cylinders)."""
    body = trimesh.creation.box(extents=(0.15, 0.067, 0.008))
    edges = [
        trimesh.creation.cylinder(radius=0.004 - 1e-4, segment=[[-0.075, s * 0.0355, 0], [0.075, s * 0.0355, 0]], sections=32)
        for s in (-1.0, 1.0)
    ]
    return trimesh.util.concatenate([body, *edges])


def _elliptic_ring(a: float, b: float, width: float, height: float) -> trimesh.Trimesh:
    ring = trimesh.creation.annulus(r_min=1.0 - width / a, r_max=1.0, height=height, sections=96)
    ring.apply_scale((a, b, 1.0))
    return ring


def tennis_racquet() -> trimesh.Trimesh:
    """A racquet, 68.5 cm: handle, throat, an elliptical frame and a string bed (a thin plate)."""
    handle = trimesh.creation.cylinder(radius=0.016, segment=[[0, 0, 0], [0.26, 0, 0]], sections=32)
    throat = trimesh.creation.cylinder(radius=0.011, segment=[[0.262, 0, 0], [0.35, 0, 0]], sections=32)
    a, b = 0.167, 0.128
    frame = _elliptic_ring(a, b, 0.012, 0.022)
    frame.apply_translation((0.352 + a, 0, 0))
    strings = trimesh.creation.cylinder(radius=1.0, height=0.002, sections=96)
    strings.apply_scale((a - 0.0125, b - 0.0125, 1.0))
    strings.apply_translation((0.352 + a, 0, 0))
    return trimesh.util.concatenate([handle, throat, frame, strings])


def t_handle() -> trimesh.Trimesh:
    """The wing nut of the intermediate-axis flip: bar 2.0 x r 0.14, stem 0.9 x r 0.14 (dm)."""
    bar = trimesh.creation.cylinder(radius=0.014, segment=[[-0.1, 0, 0], [0.1, 0, 0]], sections=48)
    stem = trimesh.creation.cylinder(radius=0.014, segment=[[0, -0.0141, 0], [0, -0.1041, 0]], sections=48)
    return trimesh.util.concatenate([bar, stem])


if __name__ == "__main__":
    for name, make in (("book", book), ("phone", phone), ("tennis_racquet", tennis_racquet), ("t_handle", t_handle)):
        mesh = make()
        assert mesh.is_watertight, name
        mesh.export(HERE / f"{name}.stl")
        print(name, len(mesh.faces), "faces", np.round(mesh.principal_inertia_components / mesh.principal_inertia_components.max(), 4))
