"""Fit the exact torque-free solution to a recorded angular velocity (a phone's gyroscope).

    >>> from poinsot.physics.fit import fit_angular_velocity, synthetic_toss
    >>> t, w = synthetic_toss((1.0, 1.9, 2.7), (12.0, 1.0, 1.0), seed=1)
    >>> fit = fit_angular_velocity(t, w)
    >>> fit.family, (fit.inertia * 2.7).round(1).tolist()
    ('minor-axis family', [1.0, 1.9, 2.7])

Rooms: :mod:`~.samples` (input checks, smoothing, sign changes, synthetic recordings),
:mod:`~.start` (Euler's equations as a linear first estimate), :mod:`~.model` (the
parameters), :mod:`~.omega` (fast ω for the inner loop), :mod:`~.solve` (the search),
:mod:`~.result` (the result and its uncertainties), :mod:`~.benchmark` (timing:
``python -m poinsot.physics.fit.benchmark``).
"""

from poinsot.physics.fit.result import AngularVelocityFit
from poinsot.physics.fit.samples import sign_changes, smooth, synthetic_toss
from poinsot.physics.fit.solve import fit_angular_velocity

__all__ = [
    "AngularVelocityFit",
    "fit_angular_velocity",
    "sign_changes",
    "smooth",
    "synthetic_toss",
]
