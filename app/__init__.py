"""Poinsot's web app: a viser server that shows the exact solution from :mod:`poinsot.physics`."""
