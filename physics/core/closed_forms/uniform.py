"""The uniform closed form: symmetric body, sphere, permanent rotation, rest.

Two equal moments [FM06 §7.11], [GPS02 §5.6]: the body precesses about L at ``p = G/I`` and
spins about its symmetry axis ``e`` at ``s = ((I - J)/I) ω_e`` relative to the precessing
frame, so ``R(t) = Rot(L̂, p t) · R(0) · Rot(e, s t)`` and ``ω(t) = Rot(e, -s t) ω0``: the
polhode and the herpolhode are circles, the body cone rolls on the space cone. A sphere, a
permanent rotation [FM06 Theorems 7.2-7.3] or a rest is the case ``I = J`` along the
axis of ω. Everything is in the caller's body axes.
"""

from __future__ import annotations

import math
from decimal import localcontext

import numpy as np
from numpy.typing import NDArray

from poinsot.physics.core import precise
from poinsot.physics.core.closed_forms import Columns, Quaternion, ScalarQuaternion, Triple
from poinsot.physics.core.exact import dyadic
from poinsot.physics.core.rotations import axis_angle, hamilton

__all__ = ["Uniform"]

Array = NDArray[np.float64]


def _sin(x: float) -> float:
    return float(np.sin(x))  # numpy's kernel, as on the arrays of the array path


def _cos(x: float) -> float:
    return float(np.cos(x))


class Uniform:
    """A uniform motion in the caller's body axes (internal space frame: the body frame at 0).

    Args:
        w: (3,) scaled ω, caller's axes.
        axis: (3,) the symmetry axis ``e``, a signed unit vector of the caller's axes.
        I_t, J_a: the transverse and the axial scaled moment (equal for a sphere, a
            permanent rotation or a rest).
        inertia: (3,) scaled moments, caller's axes.
        w_user: (3,) ω in the caller's units, ``w · 2^w_exp`` (for the exact data: a
            component of ``w`` may have underflowed).
        w_exp: the exponent of the scaling.

    With ``ℓ = m(0)/G`` (L̂ in body coordinates at t = 0),
    ``Rot(L̂, θ) R(0) = R(0) Rot(ℓ, θ)``, so the internal attitude is
    ``Rot(ℓ, p τ) · Rot(e, s τ)``. With the symmetry axis near ±ℓ (``σ = sign ω_e``) the two
    rotations nearly compose into one about ℓ at the slow rate ``p + σ s``, while p and s
    themselves can be huge (transverse moments 1e-100 of the axial one: p ~ -s ~ 1e100 |ω|):
    the attitude is then taken as ``Rot(ℓ, (p + σ s) τ - σ a) · Rot(e, a)``, ``a = s τ``, the
    same rotation mod 2π, in which the noise of ``a`` only moves a rotation of the size of the
    nutation angle. ``p + σ s = I ω⊥²/(G + J |ω_e|) + |ω_e|`` (``G - J|ω_e| = I² ω⊥²/(G +
    J|ω_e|)``) is a sum of positive terms, computed from the exact data.
    """

    def __init__(
        self,
        w: Array,
        axis: Array,
        I_t: float,
        J_a: float,
        inertia: Array,
        w_user: Array,
        w_exp: int,
    ) -> None:
        self.w0 = w
        self.axis = axis
        # Rodrigues' constants e·v and e × v (omega_rotated), also as plain floats.
        self.ev = float(w @ axis)
        (v1, v2, v3), (e1, e2, e3) = w.tolist(), axis.tolist()
        self.w0_tuple = (v1, v2, v3)
        self.axis_tuple = (e1, e2, e3)
        self.exv_tuple = (e2 * v3 - e3 * v2, e3 * v1 - e1 * v3, e1 * v2 - e2 * v1)  # e × v
        self.exv = np.array(self.exv_tuple)
        m = [i * x for i, x in zip(inertia.tolist(), self.w0_tuple, strict=True)]
        G = math.hypot(*m)  # m·m would underflow for a moment ~1e-300
        self.ell_tuple = (m[0] / G, m[1] / G, m[2] / G) if G > 0.0 else (0.0, 0.0, 1.0)
        self.ell = np.array(self.ell_tuple)
        self._init_rates(axis, I_t, J_a, inertia, w_user, w_exp)
        w_perp = w_user - float(w_user @ axis) * axis
        moving = self.spin != 0.0 and bool(np.any(w_perp != 0.0))
        # The period 2π/|s| as a (numerator, rate) pair: a spin rate ~1e-310 overflows it.
        self.period_pair = (2.0 * math.pi, abs(self.spin) if moving else 0.0)
        self.period = 2.0 * math.pi / abs(self.spin) if moving else math.inf
        self.nu = self.p
        self.lam = 0.0
        self.parameter, self.complementary_parameter = 0.0, 1.0
        self.rates = (self.p, self.spin)
        # ω(t) turns ω0 about e, |ω(t)| = |ω0|: nothing refused (a turned component can leave
        # the double range only where |ω0| itself exceeds 1.8e308 in the caller's units).
        self.amplitude = 1.0

    def _init_rates(
        self, axis: Array, I_t: float, J_a: float, inertia: Array, w_user: Array, w_exp: int
    ) -> None:
        """p, s and the slow rate p + σ s to double-double from the exact data, so that the
        angles (reduced mod 2π) stay exact over long runs (:mod:`poinsot.physics.core.precise`).

        With exact integers ``I_k = In_k/2^S``, ``ω_k = wn_k/2^T``,
        ``G² = Σ (In wn)²/2^(2S+2T)``, ``p = G/I_t`` and ``s = (I_t - J_a) ω_e / I_t``, each
        rounded once.
        """
        In, S = dyadic(inertia)
        wn, T = dyadic(w_user, w_exp)
        (It, Ja), S2 = dyadic((I_t, J_a))
        (wa,), Ta = dyadic((float(w_user @ axis),), w_exp)  # axis: a signed unit vector
        G2 = sum((In[k] * wn[k]) ** 2 for k in range(3))
        self.sign_e = -1.0 if wa < 0 else 1.0
        with localcontext() as ctx:
            ctx.prec = precise.DIGITS
            G_dec = precise.ratio(G2, 1 << (2 * S + 2 * T)).sqrt()
            p = precise.double_double(G_dec / precise.ratio(It, 1 << S2))
            spin = precise.double_double(precise.ratio((It - Ja) * wa, It << Ta))
            if spin[0] != 0.0:  # a symmetric body (G > 0): the slow rate p + σ s
                k_axis = int(np.flatnonzero(axis)[0])
                perp2 = sum(wn[k] * wn[k] for k in range(3) if k != k_axis)
                w_e = abs(precise.ratio(wa, 1 << Ta))
                slow = (
                    precise.ratio(It * perp2, 1 << (S2 + 2 * T))
                    / (G_dec + precise.ratio(Ja, 1 << S2) * w_e)
                    + w_e
                )
                self.slow = precise.angle_phase(precise.double_double(slow))
        self.p, self.spin = p[0], spin[0]
        self.precession = precise.angle_phase(p)
        self.spinning = precise.angle_phase(spin)

    def omega_rotated(self, angle: Array) -> Columns:
        """``Rot(e, angle) ω0`` for (N,) angles [rad]."""
        # Rodrigues with a unit axis e: v cos a + (e × v) sin a + e (e·v)(1 - cos a).
        e, v, ev, exv = self.axis, self.w0, self.ev, self.exv
        c, s = np.cos(angle), np.sin(angle)
        x, y, z = (v[k] * c + exv[k] * s + e[k] * ev * (1.0 - c) for k in range(3))
        return x, y, z

    def omega(self, tau: Array) -> Columns:
        if self.spin == 0.0:
            w = self.w0
            return (np.full(tau.shape, w[0]), np.full(tau.shape, w[1]), np.full(tau.shape, w[2]))
        return self.omega_rotated(-self.spinning.reduce(tau)[0])

    def omega_scalar(self, tau: float) -> Triple:
        if self.spin == 0.0:
            return self.w0_tuple
        return self._rotated_scalar(-self.spinning.reduce_scalar(tau)[0])

    def _rotated_scalar(self, angle: float) -> Triple:
        e, v, ev, exv = self.axis_tuple, self.w0_tuple, self.ev, self.exv_tuple
        c, s = _cos(angle), _sin(angle)
        x, y, z = (v[k] * c + exv[k] * s + e[k] * ev * (1.0 - c) for k in range(3))
        return x, y, z

    def quat(self, tau: Array) -> tuple[Columns, Quaternion]:
        if self.spin == 0.0:
            q = axis_angle(self.ell, self.precession.reduce(tau)[0])
            return self.omega(tau), (q[0], q[1], q[2], q[3])
        a = self.spinning.reduce(tau)[0]
        angle = self.slow.reduce(tau)[0] - self.sign_e * a
        q = hamilton(axis_angle(self.ell, angle), axis_angle(self.axis, a))
        return self.omega_rotated(-a), q

    def quat_scalar(self, tau: float) -> tuple[Triple, ScalarQuaternion]:
        if self.spin == 0.0:
            angle = self.precession.reduce_scalar(tau)[0]
            q = axis_angle(self.ell_tuple, angle, sin=_sin, cos=_cos)
            return self.w0_tuple, (q[0], q[1], q[2], q[3])
        a = self.spinning.reduce_scalar(tau)[0]
        angle = self.slow.reduce_scalar(tau)[0] - self.sign_e * a
        q = hamilton(
            axis_angle(self.ell_tuple, angle, sin=_sin, cos=_cos),
            axis_angle(self.axis_tuple, a, sin=_sin, cos=_cos),
        )
        return self._rotated_scalar(-a), q

    def polhode(self, n: int) -> Columns:
        if self.period == math.inf:
            return (np.full(n, self.w0[0]), np.full(n, self.w0[1]), np.full(n, self.w0[2]))
        return self.omega_rotated(np.linspace(0.0, 2.0 * math.pi, n, endpoint=False))
