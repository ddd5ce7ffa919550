"""The data a user works with, and never draws: the catalogue of presets, what a user edits
(`parameters.py`), a body from a mesh, a gyro recording and the motion fitted to it, a physics
engine's log, a body of one's own, and the vocabulary of what a scene shows (`elements.py`)."""
