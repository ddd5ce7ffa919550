"""The 3D labels of the construction: laid out for the browser's camera so that they avoid each
other (`layout.py`), and their viser nodes (`nodes.py`)."""
