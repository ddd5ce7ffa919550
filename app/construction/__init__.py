"""Poinsot's construction as viser nodes: geometry, sampling, trails, meshes, colours, cameras."""
