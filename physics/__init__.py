"""Exact torque-free rigid-body motion (numpy/scipy only).

The closed-form elliptic-function solution of Euler's equations and the attitude, for every
regime, plus the geometry of Poinsot's construction (polhode, herpolhode, invariable plane).

    >>> from poinsot.physics import FreeRigidBody
    >>> body = FreeRigidBody(inertia=(1.0, 2.0, 3.0), omega0=(1.0, 0.1, 0.5))
    >>> body.omega([0.0, 1.0]).shape
    (2, 3)
    >>> FreeRigidBody.from_energy((1.0, 2.0, 2.6), 2.0).regime.label
    'separatrix'

Rooms: :mod:`~poinsot.physics.core` (the solver: :mod:`~.core.free_body` is the public object,
:mod:`~.core.classification` and :mod:`~.core.closed_forms` the regimes and their solutions,
:mod:`~.core.evaluation` a solution in the caller's axes, units and attitude,
:mod:`~.core.elliptic` the Jacobi functions and integrals, :mod:`~.core.exact` and
:mod:`~.core.precise` exact and extra-precise arithmetic, :mod:`~.core.rotations` and
:mod:`~.core.errors` the quaternion algebra and the error measures, :mod:`~.core.validation`
every input check: a ValueError, or an InputTypeError for what is no real number),
:mod:`~poinsot.physics.models` (the textbook models: the polhode family, the flip, the
symmetric top, the gyroscope, the energy sink, :mod:`~.models.geometric_phase` (Montgomery's
split of the turn per period, the solid angle of the cone of L in closed form),
:mod:`~.models.racket` (the tennis racket effect: the head's twist over one turn of the
handle), :mod:`~.models.solids`, ...), :mod:`~poinsot.physics.fit` (the fit to a gyro
recording), :mod:`~poinsot.physics.integrators` (numerical methods to compare against) and
:mod:`~poinsot.physics.tools` (the fuzz, odd input of every kind against the whole API:
``python -m poinsot.physics.tools.fuzz --cases 100000``; the benchmark).
"""

from poinsot.physics.core.free_body import FreeRigidBody
from poinsot.physics.core.initial_state import attitude_with_L_along_z, omega_from_energy
from poinsot.physics.core.regime import Regime
from poinsot.physics.models.geometric_phase import montgomery_phase, solid_angle
from poinsot.physics.models.racket import measure_twist, separatrix_twist
from poinsot.physics.models.solids import box_dimensions, check_real_body

__all__ = [
    "FreeRigidBody",
    "Regime",
    "attitude_with_L_along_z",
    "box_dimensions",
    "check_real_body",
    "measure_twist",
    "montgomery_phase",
    "omega_from_energy",
    "separatrix_twist",
    "solid_angle",
]
