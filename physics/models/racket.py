"""The tennis racket effect: the head's twist while the handle makes one full turn [VMS17; VMS20;
ACC91].

A racket (moments ``I1 < I2 < I3``: the handle e1, the head's normal e3, e2 in the head's plane
across the handle) tossed about its middle axis e2 turns its handle once about L, and its head
turns by almost π about the handle: the faces swap. Following [VMS17] the attitude is read in
Euler angles about L with the handle as the body's pole: θ the angle from L to the handle, φ the
handle's turn about L, ψ the head's turn about the handle. With ``l = L/|L|`` in the body,
``cos θ = l1`` and ``ψ = atan2(l2, l3)``, and by [LL76 §37, Eq. 37.16] with the handle as pole,
``φ' = G (m2²/I2 + m3²/I3)/(m2² + m3²)``.

**What is measured** (:func:`measure_twist`, from the exact attitude): the first flip ``t_f`` (ω2
changes sign), the window ``[t_a, t_b]`` around it over which the handle's direction ``R e1`` turns
by π about L on each side (one full turn), and the head's twist ``Δψ`` over it, ψ read from
``l = Rᵀ L/|L|``.

**The formula** (:func:`separatrix_twist`). The papers' own text was not available to us; this is
our derivation from the exact solution, in the papers' limit of a toss close to e2. On the
separatrix [LL76 §37, Problem 2], with ``τ = σ t`` measured from the flip,
``σ/Ω = r = √((I3 − I2)(I2 − I1)/(I1 I3))`` (Ω = G/I2):

    l = (c1 sech τ, tanh τ, c3 sech τ),   c3² = I3 (I2 − I1) / (I2 (I3 − I1)),
    φ'/Ω = (1 − a sech²τ)/(1 − b sech²τ),   a = (I3 − I2)/(I3 − I1),   b = (I1/I2) a.

So ``ψ = atan(sinh τ / c3)`` and, with ``x = tanh τ`` in the integral,
``φ(τ) − φ(−τ) = (2/r) [τ − A(tanh τ)]``, ``A(x) = ((a − b)/√(b(1 − b))) atan(√(b/(1 − b)) x)``.
One full turn of the handle centred on the flip ends at ``τ1``, the root of
``τ1 − A(tanh τ1) = π r`` (increasing in τ1: one root, found by Newton's method from above), and

    Δψ = 2 atan(sinh τ1 / c3),   defect  δ = π − Δψ = 2 atan(c3 / sinh τ1).

Bounds: ``0 ≤ A < C = A(1)`` gives ``π r ≤ τ1 < π r + C``, so
``2 atan(c3 / sinh(π r + C)) < δ ≤ 2 atan(c3 / sinh(π r))``. The defect vanishes like
``4 c3 e^{−π r}`` as r grows: a perfect twist in the limit ``I1 → 0`` (an ideal racket), as
[VMS20] state. A toss at a finite angle from e2 lies on a polhode with ``1 − k² > 0``; its window
differs from the separatrix's by ``O(1 − k²)`` (sn − tanh and dn − sech are
``O((1 − k²) sinh 2τ)`` [DLMF 22.20]), the accuracy :data:`LIMIT_ACCURACY` states.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import optimize

from poinsot.physics.core.free_body import FreeRigidBody
from poinsot.physics.core.validation import check_inertia, check_moment_span
from poinsot.physics.models.flip import measure_flips

__all__ = [
    "LIMIT_ACCURACY",
    "TwistMeasurement",
    "TwistTheory",
    "measure_twist",
    "separatrix_twist",
]

Array = NDArray[np.float64]

#: The separatrix formula's stated accuracy for a toss with complementary parameter ``1 − k²``:
#: ``|Δψ − Δψ_sep| ≤ LIMIT_ACCURACY · (1 − k²) · cosh²τ1`` (the size of the first correction to
#: the Jacobi functions at the window's ends; tests/physics/test_racket.py checks it holds).
LIMIT_ACCURACY = 1.0
#: Grid points per side searched for the window's ends before Brent's method refines them.
_GRID = 2048
_NEWTON_STEPS = 60


@dataclass(frozen=True)
class TwistTheory:
    """The twist over one turn of the handle in the separatrix limit (see the module); every
    field is an array of the shape of the stack of bodies given (or a float).

    Attributes:
        ratio: r = σ/Ω. tau: τ1. twist: Δψ [rad]. defect: π − Δψ [rad].
        defect_low, defect_high: the bounds ``2 atan(c3/sinh(π r + C))`` and
            ``2 atan(c3/sinh(π r))`` [rad].
    """

    ratio: Array
    tau: Array
    twist: Array
    defect: Array
    defect_low: Array
    defect_high: Array


def _moment_rows(inertia: ArrayLike) -> tuple[Array, tuple[int, ...]]:
    """The checked moments as rows (N, 3) sorted and divided by the largest (the twist depends on
    the ratios only), and the shape of the stack given ((): one body)."""
    try:
        stacked = np.ndim(inertia) == 2
    except (TypeError, ValueError):  # ragged or odd input: checked as one body below
        stacked = False
    given = list(inertia) if stacked else [inertia]  # type: ignore[arg-type]
    rows = []
    for row in given:
        checked = check_inertia(row)
        check_moment_span(checked)
        moments = np.sort(checked)
        if moments[0] == moments[1] or moments[1] == moments[2]:
            raise ValueError("the racket's twist needs three distinct moments")
        rows.append(moments / moments[2])
    return np.array(rows), ((len(rows),) if stacked else ())


def _atanc(z: Array) -> Array:
    """atan(z)/z, 1 at z = 0 (z >= 0)."""
    small = z < 1e-8
    safe = np.where(small, 1.0, z)
    return np.where(small, 1.0 - z * z / 3.0, np.arctan(safe) / safe)


def separatrix_twist(inertia: ArrayLike) -> TwistTheory:
    """:class:`TwistTheory` of the moments ``inertia``: (3,) or a stack (N, 3) of distinct positive
    moments, any order within a row [any unit]; a ValueError for moments that are not three
    distinct positive numbers (or span more than 300 decades)."""
    rows, shape = _moment_rows(inertia)
    i1, i2, _ = rows.T
    r = np.sqrt((1.0 - i2) * ((i2 - i1) / i1))
    c3 = np.sqrt((i2 - i1) / (i2 * (1.0 - i1)))
    a = (1.0 - i2) / (1.0 - i1)
    b = (i1 / i2) * a
    q = np.sqrt(b / (1.0 - b))
    slope = (a - b) / (1.0 - b)

    def excess(x: Array) -> Array:  # A(x) = ((a - b)/sqrt(b(1 - b))) atan(q x)
        return slope * x * _atanc(q * x)

    C = excess(np.ones_like(r))
    with np.errstate(over="ignore"):  # sinh, cosh of a huge τ: inf, and 1/inf = 0 is right
        tau = math.pi * r + C  # f is convex and increasing: Newton from above stays above
        for _ in range(_NEWTON_STEPS):
            sech2 = 1.0 / np.cosh(tau) ** 2
            f = tau - excess(np.tanh(tau)) - math.pi * r
            step = f / (1.0 - (a - b) * sech2 / (1.0 - b * sech2))
            tau = tau - step
            if np.all(np.abs(step) <= 1e-15 * tau):
                break
        defect = 2.0 * np.arctan(c3 / np.sinh(tau))
        low = 2.0 * np.arctan(c3 / np.sinh(math.pi * r + C))
        high = 2.0 * np.arctan(c3 / np.sinh(math.pi * r))
    return TwistTheory(
        ratio=np.reshape(r, shape),
        tau=np.reshape(tau, shape),
        twist=np.reshape(math.pi - defect, shape),
        defect=np.reshape(defect, shape),
        defect_low=np.reshape(low, shape),
        defect_high=np.reshape(high, shape),
    )


@dataclass(frozen=True)
class TwistMeasurement:
    """One toss read off the exact attitude (see the module).

    Attributes:
        flip: t_f, the first zero of ω2 [time]. start, end: t_a and t_b [time].
        handle_turn: the handle's turn about L over the window, 2π to rounding [rad].
        twist: |Δψ|, the head's turn about the handle [rad]. defect: π − twist [rad].
    """

    flip: float
    start: float
    end: float
    handle_turn: float
    twist: float

    @property
    def defect(self) -> float:
        return math.pi - self.twist


def _axes(body: FreeRigidBody) -> tuple[int, int, int]:
    order = np.argsort(body.inertia)
    return int(order[0]), int(order[1]), int(order[2])


def _handle_azimuth(body: FreeRigidBody, handle: int, t: Array) -> Array:
    """Azimuth [rad] of the handle's direction ``R(t) e_handle`` about L, in (−π, π], (N,)."""
    n = np.asarray(body.plane_normal, dtype=float)
    u = np.cross(n, np.eye(3)[int(np.argmin(np.abs(n)))])
    u /= np.linalg.norm(u)
    v = np.cross(n, u)
    h = body.attitude(t).apply(np.eye(3)[handle])
    return np.arctan2(h @ v, h @ u)


def _half_turn_end(body: FreeRigidBody, handle: int, flip: float, reach: float) -> float:
    """The time on the side ``sign(reach)`` of the flip where the handle has turned by π."""
    t = flip + np.linspace(0.0, reach, _GRID)
    az = _handle_azimuth(body, handle, t)
    turned = np.abs(np.unwrap(az) - az[0])
    beyond = np.nonzero(turned >= math.pi)[0]
    if len(beyond) == 0:
        raise ValueError("the handle does not make a half turn on this side of the flip")
    k = int(beyond[0])
    base = float(np.unwrap(az)[k - 1] - az[0])

    def gap(s: float) -> float:
        a = float(_handle_azimuth(body, handle, np.array([s]))[0])
        here = base + math.remainder(a - (az[0] + base), 2.0 * math.pi)
        return abs(here) - math.pi

    return float(optimize.brentq(gap, float(t[k - 1]), float(t[k]), xtol=1e-15, rtol=1e-15))


def _psi(body: FreeRigidBody, mid: int, normal: int, t: Array) -> Array:
    """ψ = atan2(l_mid, l_normal) of ``l = Rᵀ L/|L|`` at the times t, unwrapped (N,)."""
    n = np.asarray(body.plane_normal, dtype=float)
    unit = body.attitude(t).inv().apply(n)
    return np.unwrap(np.arctan2(unit[:, mid], unit[:, normal]))


def measure_twist(body: FreeRigidBody) -> TwistMeasurement:
    """The handle's full turn around the first flip and the head's twist over it, from the
    exact attitude of ``body`` (a toss near the middle axis: a major- or minor-axis polhode whose
    half period holds one turn of the handle on each side of the flip, else a ValueError)."""
    handle, mid, normal = _axes(body)
    if not math.isfinite(body.period):
        raise ValueError("the racket's twist is measured on a periodic motion near e2")
    flips = measure_flips(body, 0.6 * body.period, axis=mid)
    if len(flips) == 0:
        raise ValueError("no flip within the first half period")
    flip = float(flips[0])
    reach = min(
        0.5 * body.period,
        8.0 * math.pi * body.inertia[mid] / float(np.linalg.norm(body.angular_momentum)),
    )
    start = _half_turn_end(body, handle, flip, -reach)
    end = _half_turn_end(body, handle, flip, reach)
    t = np.linspace(start, end, _GRID)
    az = np.unwrap(_handle_azimuth(body, handle, t))
    psi = _psi(body, mid, normal, t)
    return TwistMeasurement(
        flip, start, end, float(abs(az[-1] - az[0])), float(abs(psi[-1] - psi[0]))
    )
