"""A body's motion sampled for drawing: the grid of times (`sampling.py`), a batch of poses
converted once (`batch.py`, `frames.py`), and the `Motion` any number of views draw from
(`motion.py`)."""
