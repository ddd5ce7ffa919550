"""The closed forms of torque-free motion, one module each, behind one interface.

* :mod:`~poinsot.physics.core.closed_forms.triaxial`: the two families of Jacobi functions, ω =
  (cn, sn, dn) about the pole axis [LL76 §37, Eq. 37.10], attitude through Π [CFSZ08];
* :mod:`~poinsot.physics.core.closed_forms.separatrix`: the limiting polhode, ω = (sech, tanh, sech)
  [LL76 §37, Problem 2], [FM06 Eq. 7.79];
* :mod:`~poinsot.physics.core.closed_forms.uniform`: the symmetric body, the sphere, permanent
  rotations and rest, in circular functions [FM06 §7.11], [GPS02 §5.6].

Each works in its own *internal* frames and in the dimensionless time ``τ = t·ω_ref``:
:class:`~poinsot.physics.core.free_body.FreeRigidBody` maps the caller's axes and units in and out.
Every evaluation has an array form (``τ`` of shape (N,)) and a scalar twin (one float), which
perform the same operations in the same order and so return the same bits.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

__all__ = ["ClosedForm", "Columns", "Quaternion", "ScalarQuaternion", "Triple"]

#: Three internal components of a vector, each (N,).
Columns = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]
#: A quaternion stack as its four scalar-last components ``(x, y, z, w)``, each (N,).
Quaternion = tuple[
    NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]
]
#: One vector, three plain floats.
Triple = tuple[float, float, float]
#: One scalar-last quaternion, four plain floats.
ScalarQuaternion = tuple[float, float, float, float]


@runtime_checkable
class ClosedForm(Protocol):
    """What :class:`~poinsot.physics.core.free_body.FreeRigidBody` needs from a closed form.

    Internal frames: body axes as given to the constructor (an
    :class:`~poinsot.physics.core.relabelling.AxisMap` away from the caller's), and a space frame
    fixed by the form (``e_z ∥ L`` for the Jacobi forms). ``quat`` is the attitude body ->
    space between them; the caller's attitude follows by constant rotations on either side.
    Rates are per unit of τ, ω is in units of ``ω_ref``.
    """

    @property
    def lam(self) -> float:
        """λ, the rate of the elliptic argument ``u = u0 + σ τ`` (0 for uniform motions)."""
        ...

    @property
    def nu(self) -> float:
        """The mean precession rate about L."""
        ...

    @property
    def parameter(self) -> float:
        """The elliptic parameter ``m = k²`` (0 for uniform motions, 1 on the separatrix)."""
        ...

    @property
    def complementary_parameter(self) -> float:
        """``1 - m``, computed without the subtraction."""
        ...

    @property
    def period_pair(self) -> tuple[float, float]:
        """The period of ω as ``(numerator, rate)``; ``rate = 0`` for a motion that never
        repeats (the quotient itself may overflow: a spin rate ~1e-310)."""
        ...

    @property
    def rates(self) -> tuple[float, ...]:
        """The rates of every linear phase evaluated (their largest bounds the time range)."""
        ...

    @property
    def amplitude(self) -> float:
        """The largest value any component of ω reaches."""
        ...

    def omega(self, tau: NDArray[np.float64]) -> Columns:
        """ω at (N,) times τ, internal body axes."""
        ...

    def omega_scalar(self, tau: float) -> Triple:
        """:meth:`omega` at one float τ (same bits)."""
        ...

    def quat(self, tau: NDArray[np.float64]) -> tuple[Columns, Quaternion]:
        """ω and the attitude (internal body -> internal space) at (N,) times τ."""
        ...

    def quat_scalar(self, tau: float) -> tuple[Triple, ScalarQuaternion]:
        """:meth:`quat` at one float τ (same bits)."""
        ...

    def polhode(self, n: int) -> Columns:
        """``n`` points of the closed curve ω traces in the body, internal axes."""
        ...
