"""Initial states for a scene: ω0 on the polhode of a given D, and an attitude with L along z.

``D = |L|²/2T`` (Pars' D [Pars65 §13.12], Fasano-Marmi's J₀ [FM06 Eq. 7.57]) picks the
polhode; within the sorted plane ``ω2 = 0`` it crosses the momentum sphere ``|m| = G`` and the
ellipsoid ``Σ mi²/Ii = G²/D`` at ``m1² = G² I1 (I3 - D)/(D (I3 - I1))``,
``m3² = G² I3 (D - I1)/(D (I3 - I1))`` [LL76 §37]. The public functions check their input;
the ``*_checked`` kernels serve :meth:`~poinsot.physics.core.free_body.FreeRigidBody.from_energy`,
which checks it once.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from poinsot.physics.core.exact import pow2_below
from poinsot.physics.core.relabelling import sorting_map
from poinsot.physics.core.validation import (
    check_energy_parameter,
    check_inertia,
    check_moment_span,
    check_positive,
    check_sign,
    check_vector,
)

__all__ = [
    "attitude_checked",
    "attitude_with_L_along_z",
    "omega_checked",
    "omega_from_energy",
]

Array = NDArray[np.float64]


def omega_from_energy(
    inertia: ArrayLike, D: float, omega_norm: float = 1.0, pole_sign: float = 1.0
) -> Array:
    """An initial ω with ``|L|²/2T = D``, on the plane ``ω2 = 0`` of the sorted axes.

    Args:
        inertia: (3,) positive moments in the caller's order [kg m², any unit].
        D: the energy parameter ``|L|²/2T`` in ``[min I, max I]`` (same unit as the moments).
        omega_norm: the length of the returned ω [rad per time unit], > 0.
        pole_sign: +1 or -1, which of the two polhodes with this D (the sign of the component
            on the axis the polhode circles: the largest-moment axis when ``D > I2``, the
            smallest-moment axis otherwise).

    Returns:
        (3,) ω0 in the caller's axes [rad per time unit]. ``D = I1`` or ``I3`` is the pure spin
        about that axis; ``D = I2`` lands on the separatrix up to rounding
        (:meth:`~poinsot.physics.core.free_body.FreeRigidBody.from_energy` builds it exactly).

    Raises:
        ValueError: if the moments are not positive and finite or span more than 300 decades,
            D lies outside ``[min I, max I]``, omega_norm is not positive, or pole_sign is not
            ±1.
    """
    checked = check_inertia(inertia)
    check_moment_span(checked)
    d = check_energy_parameter(D, checked)
    size = check_positive(omega_norm, "|omega0|")
    return omega_checked(checked, d, check_sign(pole_sign, "pole_sign"), omega_norm=size)


def omega_checked(
    inertia: Array,
    D: float,
    pole_sign: float,
    *,
    omega_norm: float | None = None,
    momentum_norm: float | None = None,
) -> Array:
    """:func:`omega_from_energy` on checked input, with ``|ω0| = omega_norm`` or, if that is
    None, ``|L| = |I ω0| = momentum_norm``."""
    sort = sorting_map(inertia)
    # Moments and D relative to the largest moment (a power of two: exact), so that the
    # products below neither overflow (moments ~1e200) nor underflow.
    scale = pow2_below(float(inertia.max()))
    J = np.sort(inertia) / scale
    J1, J2, J3 = J
    D = D / scale
    sign = 1.0 if pole_sign >= 0 else -1.0  # checked: ±1
    if J1 == J3:
        m = np.array([0.0, 0.0, 1.0])
    else:
        m1 = math.sqrt(max(J1 * (J3 - D) / (D * (J3 - J1)), 0.0))
        m3 = math.sqrt(max(J3 * (D - J1) / (D * (J3 - J1)), 0.0))
        if D > J2 or (D == J2 and m3 > 0):
            m = np.array([m1, 0.0, sign * m3])
        else:
            m = np.array([sign * m1, 0.0, m3])
    w_sorted = m / J
    w_sorted /= np.max(np.abs(w_sorted))  # then the norm is in [1, sqrt 3]: no overflow
    if omega_norm is not None:
        w_sorted *= omega_norm / np.linalg.norm(w_sorted)
    else:
        assert momentum_norm is not None
        # |J ω| by hypot: its squares underflow for a smallest moment ~1e-300 of the largest.
        factor = (momentum_norm / math.hypot(*(J * w_sorted).tolist())) / scale
        with np.errstate(under="ignore"):
            w_sorted *= factor if math.isfinite(factor) else 0.0
        if not np.any(w_sorted):
            raise ValueError(
                f"|L| = {momentum_norm:g} with moments up to {scale:g} gives an ω0 beyond the "
                "double range: express |L| or the moments in other units"
            )
    # Back to the caller's axes: a plain permutation (a vector needs no proper relabelling,
    # and the sign flip would reverse the pole component the caller chose).
    out = np.empty(3)
    out[sort.index] = w_sorted
    return out


def attitude_with_L_along_z(inertia: ArrayLike, omega0: ArrayLike) -> Rotation:
    """An attitude ``R0`` (body -> space) with ``R0 · I ω0`` along +z: L vertical in the scene.

    Args:
        inertia: (3,) positive moments (caller's axes).
        omega0: (3,) body-frame ω [rad per time unit].

    Returns:
        A single Rotation, the smallest that takes L̂ to +z; the identity for a body at rest.
    """
    checked = check_inertia(inertia)
    check_moment_span(checked)
    return attitude_checked(checked, check_vector(omega0, "omega0"))


def attitude_checked(inertia: Array, omega0: Array) -> Rotation:
    """:func:`attitude_with_L_along_z` on checked input."""
    w_max = float(np.max(np.abs(omega0)))
    if w_max == 0.0:
        return Rotation.identity()
    # The direction of m = I ω from scaled factors (exact powers of two): I·ω itself may
    # overflow (1e107 · 1e300) or underflow (1e-300 · 1e-300); the largest scaled product is
    # at least (smallest moment / largest) / 2 >= 1e-301.
    m = (inertia / pow2_below(float(inertia.max()))) * (omega0 / pow2_below(w_max))
    m = m / float(np.max(np.abs(m)))
    G = float(np.linalg.norm(m))
    # Smallest rotation taking m̂ to e_z (the roll about L is irrelevant to the scene).
    mhat = m / G
    z = np.array([0.0, 0.0, 1.0])
    axis = np.cross(mhat, z)
    s = math.hypot(*axis.tolist())  # the squares of a 1e-160 component would be subnormal
    c = float(mhat @ z)
    if s < 1e-300:
        return Rotation.identity() if c > 0 else Rotation.from_rotvec([math.pi, 0.0, 0.0])
    return Rotation.from_rotvec(axis / s * math.atan2(s, c))
