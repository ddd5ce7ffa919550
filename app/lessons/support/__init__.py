"""What the textbook scenes are built from: the scene's declaration as data (`spec.py`), the base of
a scene's model and drawing (`base.py`), their colours, drawings and tabulated motions, and the
runtime that drives one on any scene API (`runtime.py`)."""
