"""Fit the exact torque-free solution to a recorded angular velocity (a phone's gyroscope).

>>> from poinsot.physics.fit import fit_angular_velocity, synthetic_toss
>>> t, w = synthetic_toss((1.0, 1.9, 2.7), (0.3, 12.0, 0.4), seed=1)
>>> fit = fit_angular_velocity(t, w)
>>> fit.family, fit.inertia.round(2).tolist()
('minor-axis family', [0.37, 0.7, 1.0])
"""

from poinsot.physics.fit.samples import synthetic_toss
from poinsot.physics.fit.solve import AngularVelocityFit, fit_angular_velocity

__all__ = ["AngularVelocityFit", "fit_angular_velocity", "synthetic_toss"]
