"""ω(t) alone, fast, for the fit's inner loop: the Jacobi form with ``scipy.special.ellipj``.

A least-squares fit evaluates ω(t) a few hundred to a few thousand times at parameters that all
differ. :class:`~poinsot.physics.FreeRigidBody` prepares the attitude too (elliptic integrals of
the third kind to 45 digits, exact integer invariants), which costs ~0.3 ms a body; the fit
needs only ω, which here costs ~30 µs for a hundred times. Where ``scipy.special.ellipj`` is
not accurate (``1 - m < 1e-6``, next to the separatrix: it takes ``m`` rather than ``1 - m``
and switches to a first-order expansion above ``1 - 1e-9``), and for symmetric bodies and
permanent rotations, the function hands over to :class:`FreeRigidBody`. The fit's result is
always the exact :class:`FreeRigidBody`; tests check that both agree.

Formulas [LL76 §37, Eq. 37.10] with sorted moments ``I1 < I2 < I3``, ``Δi = G² - 2T Ii``
written as sums of terms of one sign (no cancellation near the separatrix):

- major-axis family (``Δ2 > 0``): ``ω = (A1 cn u, A2 sn u, s A3 dn u)``, ``s = sign ω3(0)``,
  ``A1² = -Δ3 / (I1 (I3 - I1))``, ``A2² = -Δ3 / (I2 (I3 - I2))``, ``A3² = Δ1 / (I3 (I3 - I1))``,
  ``λ² = (I3 - I2) Δ1 / (I1 I2 I3)``, ``1 - m = Δ2 (I3 - I1) / (Δ1 (I3 - I2))``;
- minor-axis family (``Δ2 < 0``): ``ω = (s A1 dn u, A2 sn u, A3 cn u)``, ``s = sign ω1(0)``,
  ``A2² = Δ1 / (I2 (I2 - I1))``, ``λ² = (I2 - I1)(-Δ3) / (I1 I2 I3)``,
  ``1 - m = -Δ2 (I3 - I1) / (-Δ3 (I2 - I1))``, ``A1``, ``A3`` as above;

and ``u = u0 + s λ t``, ``u0 = F(φ0 | m)`` with ``φ0`` the angle of ``(cn, sn)`` at t = 0.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray
from scipy import special

from poinsot.physics.core.free_body import FreeRigidBody

#: Below this complementary parameter ``ellipj`` loses digits: FreeRigidBody takes over.
_MC_FLOOR = 1e-6
# The proper relabellings (det +1) that sort the moments: for an odd permutation the middle
# sorted axis changes sign, which keeps Euler's equations in the same form.
_EVEN = {(0, 1, 2), (1, 2, 0), (2, 0, 1)}


def free_omega(
    inertia: NDArray[np.float64], omega0: NDArray[np.float64], tau: NDArray[np.float64]
) -> NDArray[np.float64]:
    """(N, 3) body-frame ω [rad/s] at times ``tau`` (N,) [s] of the free body ``(I (3,), ω0 (3,))``.

    The moments are positive, in the caller's axis order; the result is in the same axes.
    """
    order = np.argsort(inertia, kind="stable")
    sign = np.ones(3)
    if tuple(int(k) for k in order) not in _EVEN:
        sign[1] = -1.0
    i1, i2, i3 = (float(x) for x in inertia[order])
    w1, w2, w3 = (float(x) for x in omega0[order] * sign)
    columns = _sorted_columns(i1, i2, i3, w1, w2, w3, tau)
    if columns is None:
        return FreeRigidBody(inertia, omega0).omega(tau)
    out = np.empty((tau.size, 3))
    out[:, order] = np.stack(columns, axis=1) * sign
    return out


def _sorted_columns(i1, i2, i3, w1, w2, w3, tau) -> tuple[NDArray, NDArray, NDArray] | None:
    """ω1, ω2, ω3 (N,) each, in the sorted axes, or None where FreeRigidBody must take over."""
    if not (0.0 < i1 < i2 < i3):
        return None  # a symmetric body or a sphere: circular functions (FreeRigidBody)
    m1, m2, m3 = i1 * w1, i2 * w2, i3 * w3
    d1 = m2 * m2 * (i2 - i1) / i2 + m3 * m3 * (i3 - i1) / i3  # Δ1 >= 0
    d2 = m1 * m1 * (i1 - i2) / i1 + m3 * m3 * (i3 - i2) / i3  # Δ2, the family
    d3 = m1 * m1 * (i1 - i3) / i1 + m2 * m2 * (i2 - i3) / i2  # Δ3 <= 0
    if d1 <= 0.0 or d3 >= 0.0 or d2 == 0.0:
        return None  # a permanent rotation or the separatrix itself
    a1 = math.sqrt(-d3 / (i1 * (i3 - i1)))
    a3 = math.sqrt(d1 / (i3 * (i3 - i1)))
    if d2 > 0.0:  # major-axis family
        a2 = math.sqrt(-d3 / (i2 * (i3 - i2)))
        lam = math.sqrt((i3 - i2) * d1 / (i1 * i2 * i3))
        mc = d2 * (i3 - i1) / (d1 * (i3 - i2))
        s = 1.0 if w3 >= 0.0 else -1.0
        phi0 = math.atan2(w2 / a2, w1 / a1)
    else:  # minor-axis family
        a2 = math.sqrt(d1 / (i2 * (i2 - i1)))
        lam = math.sqrt((i2 - i1) * -d3 / (i1 * i2 * i3))
        mc = -d2 * (i3 - i1) / (-d3 * (i2 - i1))
        s = 1.0 if w1 >= 0.0 else -1.0
        phi0 = math.atan2(w2 / a2, w3 / a3)
    if mc < _MC_FLOOR:
        return None
    m = 1.0 - mc
    u = float(special.ellipkinc(phi0, m)) + s * lam * tau
    sn, cn, dn, _ = special.ellipj(u, m)
    if d2 > 0.0:
        return a1 * cn, a2 * sn, s * a3 * dn
    return s * a1 * dn, a2 * sn, a3 * cn
