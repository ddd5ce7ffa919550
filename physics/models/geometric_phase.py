"""Montgomery's geometric phase: the turn of a free body about L split into a dynamic part and
the solid angle that L sweeps in the body [Mon91].

After one period P of ω the body has turned about L by ``Δθ = 2TP/G − Ω (mod 2π)``, ``G = |L|``,
where Ω is the solid angle of the cone that ``l = L/G`` sweeps in the body frame, oriented by
the direction in which l runs round it [Mon91]. This module computes Ω from a closed form of the
cone's solid angle itself (never from the precession, which would make the formula agree with
itself whatever the code does), measures the turn from the attitude, and gives the limit of Ω
at the separatrix.

**The closed form.** Sorted moments ``I1 < I2 < I3``, ``D = G²/2T``. Call ``Ip`` the moment of the
axis that the polhode circles (its pole: ``I3`` for ``D > I2``, ``I1`` for ``D < I2``) and ``Ia``
the other end (``I1``, resp. ``I3``). With α the azimuth of l about the pole and ``lp = Lp/G`` its
component on it, the oriented solid angle is ``Ω = ∮ (1 − lp) dα``. Euler's equations in the body,
``L' = L × ω``, give ``α' = 2T (Ip − D) Lp / (Ip (G² − Lp²))``, so that

    Ω = (2T (Ip − D) / (G Ip)) ∫₀ᴾ Lp / (G + Lp) dt.

On the polhode ``Lp = b dn u`` [LL76 §37, Eq. 37.10], ``u = λt``, ``b = Ip A_p``; with
``b dn/(G + b dn) = (bG dn − b² dn²)/(G² − b² dn²)`` the integral over the period ``4K`` is a
complete integral of the third kind plus an elementary one. The transformation ``n → m/n``
[DLMF 19.7.9] removes the elementary term, and Carlson's form [DLMF 19.25.1-19.25.2] gives

    Ω = 4 (Ip − D) √(Ia I2 / (Ip D (Ip − I2)(D − Ia))) · [R_F(0, mc, 1) − (p/3) R_J(0, mc, 1, p)],

    mc = (Ip − Ia)(D − I2) / ((Ip − I2)(D − Ia)),   p = G²/b² = 1 + Ia (Ip − D) / (Ip (D − Ia)),

every factor a product of differences of the given numbers (no cancellation). Ω depends on the
moments and D only: it is geometry. It is positive around the major axis and negative around the
minor one (l runs the other way round its pole). The bracket is the difference of two terms that
grow like K near the separatrix: it loses ``log10 K`` digits there (two at ``1 − m = 1e-300``).

**The separatrix limit.** At ``D = I2`` the cone of l degenerates into the two planes
``l3/l1 = ±√(I3 (I2 − I1) / (I1 (I3 − I2)))`` (the energy and momentum spheres meet in two great
circles), and the cap about e3 becomes a lune of solid angle ``4 atan √(I1 (I3 − I2) / (I3
(I2 − I1)))``; the minor side tends to minus the complementary lune. The two limits differ by 2π:
Montgomery's sum is continuous across the separatrix modulo 2π.

Everything is vectorised over an array of D values; :func:`montgomery_phase` reads one body.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import integrate, special

from poinsot.physics.core.free_body import FreeRigidBody
from poinsot.physics.core.regime import Regime
from poinsot.physics.core.validation import check_inertia, check_moment_span

__all__ = [
    "MontgomeryPhase",
    "cone_of_L",
    "measured_turn",
    "montgomery_phase",
    "separatrix_solid_angles",
    "solid_angle",
    "solid_angle_quadrature",
    "wrap_angle",
]

Array = NDArray[np.float64]

#: Beyond this p = G²/b² the bracket R_F − (p/3) R_J, of size ~1/√p, loses log10 √p digits to
#: cancellation (5 at 1e10); only moments 1e10 apart on the minor side reach it.
_LOPSIDED = 1e10


def _sorted_moments(inertia: ArrayLike) -> tuple[float, float, float]:
    checked = check_inertia(inertia)
    check_moment_span(checked)
    I1, I2, I3 = sorted(checked.tolist())
    if not I1 < I2 < I3:
        raise ValueError("the geometric phase of a free body needs three distinct moments")
    return I1, I2, I3


def _energy_parameters(D: ArrayLike) -> Array:
    """D as a float array, or a ValueError for anything that is not real numbers."""
    try:
        d = np.asarray(D)
    except (TypeError, ValueError):
        d = np.asarray(None)
    if d.dtype.kind not in "iuf":
        raise ValueError(f"D must be a real number or an array of them, got {D!r:.80}")
    with np.errstate(over="ignore"):  # a long double beyond the double range: inf, refused
        return d.astype(float)


def solid_angle(inertia: ArrayLike, D: ArrayLike) -> Array:
    """Ω, the oriented solid angle swept by L/|L| in the body over one period (see the module).

    Args:
        inertia: (3,) distinct positive moments, any order [any unit].
        D: (N,) or scalar ``|L|²/2T`` in ``[I1, I3]``, not ``I2`` [same unit].

    Returns:
        (N,) Ω [sr] (a scalar D gives shape ()): in (0, 2π) around the major axis, in (−2π, 0)
        around the minor one, 0 at either pole.

    Raises:
        ValueError: moments not distinct (or more than 300 decades apart), a D that is not real,
            outside ``[I1, I3]`` or equal to ``I2``, moments so lopsided that the closed form
            would lose more than 5 digits (:data:`_LOPSIDED`), or so close to each other that Ω
            leaves the double range.
    """
    I1, I2, I3 = _sorted_moments(inertia)
    d = _energy_parameters(D)
    if not np.all(np.isfinite(d)) or np.any((d < I1) | (d > I3) | (d == I2)):
        raise ValueError(f"D must lie in [{I1}, {I3}] and differ from I2 = {I2}")
    # In units of I3 (the solid angle depends on the ratios only): no overflow.
    j1, j2, x = I1 / I3, I2 / I3, d / I3
    major = d > I2
    jp = np.where(major, 1.0, j1)
    ja = np.where(major, j1, 1.0)
    with np.errstate(all="ignore"):
        mc = ((jp - ja) / (jp - j2)) * ((x - j2) / (x - ja))
        p = 1.0 + (ja / jp) * ((jp - x) / (x - ja))
        # (Ip − I2)(D − Ia) > 0 on either side: the product of the magnitudes.
        root = np.sqrt(np.abs(x - ja)) * np.sqrt(np.abs(jp - j2) / j2) * np.sqrt(x)
        scale = (jp - x) / root * np.sqrt(ja / jp)
        bracket = special.elliprf(0.0, mc, 1.0) - (p / 3.0) * special.elliprj(0.0, mc, 1.0, p)
        # At a pole (D = Ip) the cone is a line: Ω = 0 (the formula's 0·finite).
        omega = np.where(d == np.where(major, I3, I1), 0.0, 4.0 * scale * bracket)
    if np.any(p > _LOPSIDED):
        raise ValueError(
            "the moments are so lopsided (I1/I2 or 1 - I2/I3 below about 1e-10) that the closed "
            "form of the solid angle would lose more than 5 digits"
        )
    if not np.all(np.isfinite(omega)):
        raise ValueError(
            "the moments lie so close together that the solid angle leaves the double range; "
            "spread them further apart"
        )
    return omega


def separatrix_solid_angles(inertia: ArrayLike) -> tuple[float, float]:
    """The limits of Ω as D tends to I2 from above (major side) and from below (minor side):
    ``(4 atan √(I1(I3−I2)/(I3(I2−I1))), −4 atan √(I3(I2−I1)/(I1(I3−I2))))`` [sr], whose
    difference is 2π (see the module)."""
    I1, I2, I3 = _sorted_moments(inertia)
    major = 4.0 * math.atan(math.sqrt(I1 * (I3 - I2) / (I3 * (I2 - I1))))
    minor = -4.0 * math.atan(math.sqrt(I3 * (I2 - I1) / (I1 * (I3 - I2))))
    return major, minor


def wrap_angle(x: ArrayLike) -> Array:
    """Angles [rad] wrapped into ``[−π, π)``."""
    return np.mod(np.asarray(x, dtype=float) + math.pi, 2.0 * math.pi) - math.pi


def _check_periodic(body: FreeRigidBody) -> None:
    if body.regime not in (Regime.MAJOR_AXIS, Regime.MINOR_AXIS):
        raise ValueError(
            f"the geometric phase needs a polhode around the major or minor axis, not a "
            f"{body.regime.label} motion"
        )


def cone_of_L(body: FreeRigidBody, n: int = 256) -> tuple[Array, Array]:
    """The cone that L sweeps in the body: ``(rim, pole)``, the (n, 3) unit vectors
    ``L/|L|`` along one period (body frame, the caller's axes, uniform in the amplitude) and the
    (3,) unit principal axis it circles (signed: the side the cone is on)."""
    _check_periodic(body)
    w = body.polhode(n)
    m = w * body.inertia
    rim = m / np.linalg.norm(m, axis=1, keepdims=True)
    axis = int(np.argmax(body.inertia)) if body.regime is Regime.MAJOR_AXIS else None
    if axis is None:
        axis = int(np.argmin(body.inertia))
    pole = np.zeros(3)
    pole[axis] = math.copysign(1.0, float(np.mean(rim[:, axis])))
    return rim, pole


def solid_angle_quadrature(body: FreeRigidBody, t0: float = 0.0) -> float:
    """Ω by quadrature of ``∮ (1 − l·p) dα`` over the motion itself: α the azimuth of
    ``l = L/|L|`` about the pole p, ``α' = p·(l × l')/|p × l|²`` with ``l' = l × ω`` from
    ``body.omega`` (scipy's adaptive Gauss-Kronrod on each quarter period). An independent check
    of :func:`solid_angle`; the sign of the pole drops out."""
    _check_periodic(body)
    _, pole = cone_of_L(body, 8)
    J = body.inertia

    def integrand(t: float) -> float:
        w = body.omega(t)
        m = J * w
        unit = m / np.linalg.norm(m)
        rate_of_unit = np.cross(unit, w)
        across = np.cross(pole, unit)
        rate = float(np.dot(pole, np.cross(unit, rate_of_unit))) / float(np.dot(across, across))
        return (1.0 - float(np.dot(unit, pole))) * rate

    quarter = body.period / 4.0
    total = 0.0
    for k in range(4):  # a loop over four quarters, not over samples
        start = t0 + k * quarter
        value, _ = integrate.quad(
            integrand, start, start + quarter, epsabs=1e-13, epsrel=1e-12, limit=400
        )
        total += value
    return total


def measured_turn(body: FreeRigidBody, t0: float, span: float) -> float:
    """The angle [rad] in ``[−π, π)`` by which the attitude turns about L between ``t0`` and
    ``t0 + span``: ``R(t0 + span) R(t0)ᵀ`` applied to a vector ``u ⊥ L``, read as a signed angle
    about ``L/|L|`` (right-handed)."""
    R = body.attitude(np.array([t0, t0 + span]))
    n = np.asarray(body.plane_normal, dtype=float)
    u = np.cross(n, np.eye(3)[int(np.argmin(np.abs(n)))])
    u /= np.linalg.norm(u)
    v = R[1].apply(R[0].inv().apply(u))
    return float(math.atan2(float(np.dot(n, np.cross(u, v))), float(np.dot(u, v))))


@dataclass(frozen=True)
class MontgomeryPhase:
    """One body's turn about L per period of ω, split [Mon91].

    Attributes:
        period: P [time]. dynamic: ``2TP/G`` [rad]. solid_angle: Ω [sr] (closed form).
        predicted: ``2TP/G − Ω`` wrapped into ``[−π, π)`` [rad].
        measured: the attitude's turn about L over ``[t0, t0 + P]``, in ``[−π, π)`` [rad].
        gap: ``measured − predicted`` wrapped into ``[−π, π)`` [rad].
    """

    period: float
    dynamic: float
    solid_angle: float
    predicted: float
    measured: float

    @property
    def geometric(self) -> float:
        """The geometric part −Ω [rad]."""
        return -self.solid_angle

    @property
    def gap(self) -> float:
        return float(wrap_angle(self.measured - self.predicted))


def montgomery_phase(body: FreeRigidBody, t0: float = 0.0) -> MontgomeryPhase:
    """Montgomery's split of one body's turn per period, and the turn measured from its attitude
    from ``t0``; a ValueError for a motion with no period (symmetric, separatrix, rest)."""
    _check_periodic(body)
    P = body.period
    G = float(np.linalg.norm(body.angular_momentum))
    dynamic = 2.0 * body.energy * P / G
    omega = float(solid_angle(body.inertia, body.D))
    predicted = float(wrap_angle(dynamic - omega))
    return MontgomeryPhase(P, dynamic, omega, predicted, measured_turn(body, t0, P))
