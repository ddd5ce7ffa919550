"""Exact torque-free rigid-body motion (numpy/scipy only).

The closed-form elliptic-function solution of Euler's equations and the attitude, for every
regime, plus the geometry of Poinsot's construction (polhode, herpolhode, invariable plane).

    >>> from physics import FreeRigidBody
    >>> body = FreeRigidBody(inertia=(1.0, 2.0, 3.0), omega0=(1.0, 0.1, 0.5))
    >>> body.omega([0.0, 1.0]).shape
    (2, 3)
"""

from poinsot.physics.regime import Regime
from poinsot.physics.rigid_body import FreeRigidBody, attitude_with_L_along_z, omega_from_energy
from poinsot.physics.solids import box_dimensions, check_real_body

__all__ = [
    "FreeRigidBody",
    "Regime",
    "attitude_with_L_along_z",
    "box_dimensions",
    "check_real_body",
    "omega_from_energy",
]
