"""The numerical ghost: a numerical integrator's body drawn beside the exact one (`ghost.py`: its
cage, errors and plot) and the integrator and setting asked for (`setting.py`)."""
