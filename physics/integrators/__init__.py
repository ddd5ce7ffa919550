"""Numerical integrators of the free rigid body, to measure the exact solution against.

Four methods share one interface, :func:`integrate`, and one registry, :data:`INTEGRATORS`,
which the tests and the work-precision report loop over, one module each:

- :mod:`~.runge_kutta`: ``RK45`` [DP80] and ``DOP853`` [HNW93 §II.5], scipy's adaptive pairs on
  Euler's equations plus the quaternion kinematics of the attitude;
- :mod:`~.splitting`: ``splitting``, the symplectic Strang splitting 1-2-3-2-1 [DLM97];
- :mod:`~.midpoint`: ``midpoint``, the implicit midpoint rule on (m, R) with the Cayley
  attitude update [HNW93 §II.10], [HLW06 §IX];
- :mod:`~.games`: the rotation steps of game engines (:data:`GAME_STEPS`: no gyroscopic term,
  its explicit and implicit forms, Jolt's, a fixed-step RK4), registered beside the others
  but kept out of :data:`INTEGRATORS`, the work-precision study's list.

:class:`Propagation` (:mod:`~.propagation`) advances the same methods piece by piece, carrying
their whole state (scipy's stepper for the adaptive pairs, the grid state for the fixed-step
methods): what an animation needs to show a method's solution frame by frame without
restarting it. Conventions: :mod:`~.interface`.
"""

from poinsot.physics.integrators.interface import Integrator, Trajectory
from poinsot.physics.integrators.propagation import Propagation, State
from poinsot.physics.integrators.registry import GAME_STEPS, INTEGRATORS, METHODS, integrate

__all__ = [
    "GAME_STEPS",
    "INTEGRATORS",
    "METHODS",
    "Integrator",
    "Propagation",
    "State",
    "Trajectory",
    "integrate",
]
