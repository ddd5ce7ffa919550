"""The free symmetric top: precession, spin, and the body cone rolling on the space cone
[GPS02 §5.6; FM06 §7.11].

Body axes: ``e3`` is the symmetry axis, ``I1 = I2 = I`` (transverse), ``I3 = J`` (axial); the
body is *oblate* if ``J > I`` (a disc, a coin), *prolate* if ``J < I`` (a rod, a cigar). ω3 is
constant and the motion is the sum of two uniform rotations:

* the *precession* of the symmetry axis about ``L`` at ``p = G/I``;
* the *spin* of the body about its own axis relative to the precessing frame at
  ``s = ((I - J)/I) ω3``.

Sign convention: ``R(t) = Rot(L̂, p t) · R(0) · Rot(e3, s t)``, so that in the body ω turns
about ``e3`` by the angle ``-s t``: ``ω⊥(t) = Rot(e3, -s t) ω⊥(0)`` (Euler's equations give
``ω1' = s ω2``, ``ω2' = -s ω1``). The space angular velocity is ``p L̂ + s e3``; ``s`` has the
sign of ω3 for a prolate body and the opposite sign for an oblate one.

The three vectors ``e3``, ``ω`` and ``L`` stay in one plane. ω makes the angle ``α_b`` with
``e3`` (``tan α_b = |ω⊥|/ω3``), the *body cone*, and the angle ``α_s`` with ``L``, the *space
cone*; ``e3`` makes the nutation angle ``θ`` with ``L`` (``tan θ = I |ω⊥|/(J ω3)``). For a prolate
body ω lies between ``e3`` and ``L`` (``θ = α_b + α_s``, the body cone rolls on the outside of
the space cone); for an oblate body ``L`` lies between (``θ = α_b - α_s``, the body cone rolls
around the space cone, which lies inside it); for ω3 < 0 read the angles from ``-e3``
(``π - α_b``, ``π - θ``). The two cones touch along ω, the instantaneous
axis, whose points are at rest: the body cone rolls without slipping [GPS02 §5.6].
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from poinsot.physics.core.exact import ldexp, pow2_below
from poinsot.physics.core.free_body import FreeRigidBody
from poinsot.physics.core.validation import (
    check_attitude,
    check_count,
    check_moment_span,
    check_positive,
    check_vector,
    grid_size,
)
from poinsot.physics.models.flip import check_body

__all__ = [
    "SymmetricTop",
    "measure_precession_rate",
    "measure_spin_rate",
    "symmetric_top",
]

#: Grid steps per fastest rate when unwrapping measured angles (a tenth of a radian each).
_STEPS_PER_RATE = 10.0


def _cone(axis: NDArray[np.float64], half_angle: float, length: float, n: int) -> NDArray:
    """(n, 3) rim points of the cone of ``half_angle`` about the unit ``axis``, at ``length``
    from the apex (the origin); the first point lies in the plane of ``axis`` and the body's
    first transverse direction (or any, for an axis along it)."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = helper - (helper @ axis) * axis
    u /= np.linalg.norm(u)
    v = np.cross(axis, u)
    phi = np.linspace(0.0, 2.0 * math.pi, n, endpoint=False)[:, None]
    ring = np.cos(phi) * u + np.sin(phi) * v
    return length * (math.cos(half_angle) * axis + math.sin(half_angle) * ring)


@dataclass(frozen=True)
class SymmetricTop:
    """A free symmetric top and its two cones.

    Attributes:
        transverse: I [moment]. axial: J [moment]. omega0: (3,) body-frame ω at t = 0
            [rad/time], e3 the symmetry axis. attitude0: R(0), body -> space.
        shape: ``"oblate"`` (J > I) or ``"prolate"`` (J < I).
        precession_rate: ``p = G/I`` [rad/time], about ``L``.
        spin_rate: ``s = ((I - J)/I) ω3`` [rad/time], about ``e3`` (sign convention above).
        body_cone_half_angle: ``α_b``, the angle [rad] between ω and e3, in [0, π].
        space_cone_half_angle: ``α_s``, the angle [rad] between ω and L.
        nutation_angle: ``θ``, the angle [rad] between e3 and L.
        angular_momentum: (3,) ``L`` in space. omega_norm: ``|ω|`` (constant).
    """

    transverse: float
    axial: float
    omega0: NDArray[np.float64]
    attitude0: Rotation
    shape: str
    precession_rate: float
    spin_rate: float
    body_cone_half_angle: float
    space_cone_half_angle: float
    nutation_angle: float
    angular_momentum: NDArray[np.float64]
    omega_norm: float

    @property
    def inertia(self) -> NDArray[np.float64]:
        """(3,) ``(I, I, J)``."""
        return np.array([self.transverse, self.transverse, self.axial])

    def body(self) -> FreeRigidBody:
        """The exact motion, :class:`FreeRigidBody` with moments ``(I, I, J)``."""
        return FreeRigidBody(self.inertia, self.omega0, self.attitude0)

    def body_cone(self, n: int = 64, length: float | None = None) -> NDArray[np.float64]:
        """(n, 3) rim of the body cone (body frame): generators from the origin to these points,
        at ``length`` (default ``|ω|``) along the cone of ω about ``e3``. Draw it in space with
        the attitude: ``R(t).apply(...)``."""
        axis = np.array([0.0, 0.0, 1.0])
        return _cone(axis, self.body_cone_half_angle, self._length(length), self._n(n))

    def space_cone(self, n: int = 64, length: float | None = None) -> NDArray[np.float64]:
        """(n, 3) rim of the space cone (space frame): the cone swept by ω about ``L``."""
        # L̂ from the scaled I ω0 (exact powers of two): L itself may be subnormal.
        m = _scaled(self.inertia) * _scaled(self.omega0)
        axis = self.attitude0.apply(m / math.hypot(*m.tolist()))
        return _cone(axis, self.space_cone_half_angle, self._length(length), self._n(n))

    def _length(self, length: float | None) -> float:
        if length is None:
            return self.omega_norm
        return check_positive(length, "the cone length")

    @staticmethod
    def _n(n: int) -> int:
        return check_count(n, "n, the number of generators of a cone,", 3)


def _scaled(x: NDArray[np.float64]) -> NDArray[np.float64]:
    """``x`` over the power of two below its largest magnitude (exact)."""
    return x / pow2_below(float(np.max(np.abs(x))))


def symmetric_top(
    transverse: float, axial: float, omega0: ArrayLike, attitude0: Rotation | None = None
) -> SymmetricTop:
    """The symmetric top with moments ``(I, I, J)`` and initial ω (body frame, e3 = axis).

    Raises:
        ValueError: moments not positive and finite, ``I = J`` (a sphere: no cone, every axis
            is principal), ω0 not three finite numbers or zero.
    """
    It = check_positive(transverse, "the transverse moment I")
    J = check_positive(axial, "the axial moment J")
    if It == J:
        raise ValueError(
            "I = J is a sphere: every axis is principal and ω is constant; a symmetric top "
            "needs an axial moment J different from the transverse I"
        )
    check_moment_span(np.array([It, J, J]))
    w = check_vector(omega0, "omega0")
    if not np.any(w):
        raise ValueError("omega0 is zero: a body at rest has no precession and no spin")
    attitude0 = check_attitude(attitude0)
    # Moments and ω over exact powers of two: I ω and ω² would leave the double range for
    # ω ~ 1e200 or moments ~1e-200; the angles are ratios and the rates scale back exactly.
    i_exp = math.frexp(max(It, J))[1] - 1
    w_exp = math.frexp(float(np.max(np.abs(w))))[1] - 1
    i_s, j_s, ws = math.ldexp(It, -i_exp), math.ldexp(J, -i_exp), np.ldexp(w, -w_exp)
    w_perp = math.hypot(float(ws[0]), float(ws[1]))
    w3 = float(ws[2])
    G = math.hypot(i_s * w_perp, j_s * w3)
    L = attitude0.apply(np.array([i_s * ws[0], i_s * ws[1], j_s * w3]))
    top = SymmetricTop(
        transverse=It,
        axial=J,
        omega0=w.copy(),
        attitude0=attitude0,
        shape="oblate" if J > It else "prolate",
        precession_rate=ldexp(G / i_s, w_exp),
        spin_rate=ldexp((i_s - j_s) / i_s * w3, w_exp),
        body_cone_half_angle=math.atan2(w_perp, w3),
        # angle between ω and m = (It ω⊥, J ω3): |ω × m| = |J - It| |ω⊥ ω3|
        space_cone_half_angle=math.atan2(
            abs(j_s - i_s) * w_perp * abs(w3), i_s * w_perp**2 + j_s * w3**2
        ),
        nutation_angle=math.atan2(i_s * w_perp, j_s * w3),
        angular_momentum=np.array([ldexp(x, i_exp + w_exp) for x in L.tolist()]),
        omega_norm=ldexp(math.hypot(*ws.tolist()), w_exp),
    )
    rates = (top.precession_rate, top.spin_rate, top.omega_norm, *L.tolist())
    if not all(math.isfinite(x) for x in (*rates, *top.angular_momentum.tolist())):
        raise ValueError(
            "the rates or the angular momentum of this top lie beyond the double-precision "
            "range (1.8e308) in your units: express the moments or ω0 in other units"
        )
    return top


def _grid(body: FreeRigidBody, t_end: float) -> NDArray[np.float64]:
    """A time grid on ``[0, t_end]`` fine enough to unwrap every angle of a symmetric motion:
    the rates p = G/I and |s| are at most ``|ω| max(1, J/I, |I - J|/I)``."""
    t_end = check_positive(t_end, "t_end")
    J = body.inertia
    rate = math.hypot(*body.omega0.tolist()) * max(1.0, float(J.max()) / float(J.min()))
    step = 1.0 / (rate * _STEPS_PER_RATE) if rate > 0.0 else t_end
    n = grid_size(t_end, step, "measuring up to t_end", "use a shorter t_end") + 1
    return np.linspace(0.0, t_end, max(n, 2))


def _symmetry_axis(body: FreeRigidBody) -> int:
    J = np.asarray(body.inertia, dtype=float)
    for k in range(3):
        others = [J[i] for i in range(3) if i != k]
        if others[0] == others[1] and J[k] != others[0]:
            return k
    raise ValueError(f"the body is not a symmetric top: moments {J.tolist()}")


def _slope(t: NDArray[np.float64], angle: NDArray[np.float64]) -> float:
    """The rate of an unwrapped angle sampled densely: (last - first)/(t_end - t0)."""
    unwrapped = np.unwrap(angle)
    return float((unwrapped[-1] - unwrapped[0]) / (t[-1] - t[0]))


def measure_precession_rate(body: FreeRigidBody, t_end: float) -> float:
    """The angle per unit time [rad/time] swept by the symmetry axis about ``L``, read off the
    attitude: the azimuth of ``R(t) e_axis`` about ``L̂`` on a fine grid over ``[0, t_end]``,
    unwrapped, total over elapsed time.

    Raises:
        ValueError: the body is not symmetric, or its axis lies along L (nothing precesses).
    """
    k = _symmetry_axis(check_body(body, "measure_precession_rate"))
    t = _grid(body, t_end)
    e = np.zeros(3)
    e[k] = 1.0
    axis = body.attitude(t).apply(e)
    Lhat = body.plane_normal  # L̂, computed without over- or underflow of L
    helper = np.array([1.0, 0.0, 0.0]) if abs(Lhat[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = helper - (helper @ Lhat) * Lhat
    u /= np.linalg.norm(u)
    v = np.cross(Lhat, u)
    x, y = axis @ u, axis @ v
    if float(np.hypot(x, y).min()) < 1e-8:
        raise ValueError("the symmetry axis lies along L: there is no precession to measure")
    return _slope(t, np.arctan2(y, x))


def measure_spin_rate(body: FreeRigidBody, t_end: float) -> float:
    """``s`` [rad/time], read off ω(t) in the body: ω turns about the symmetry axis by ``-s t``
    (the convention of this module), so ``s = -`` (the unwrapped azimuth of ω⊥)/(elapsed time).

    Raises:
        ValueError: the body is not symmetric, or ω lies along its axis (ω⊥ = 0).
    """
    k = _symmetry_axis(check_body(body, "measure_spin_rate"))
    i, j = (k + 1) % 3, (k + 2) % 3  # (i, j, k) cyclic: the azimuth from e_i towards e_j
    t = _grid(body, t_end)
    w = body.omega(t)
    if float(np.hypot(w[:, i], w[:, j]).min()) == 0.0:
        raise ValueError("ω lies along the symmetry axis: there is no spin of ω to measure")
    return -_slope(t, np.arctan2(w[:, j], w[:, i]))


def _demo() -> None:  # pragma: no cover - a printout for the report
    print("free symmetric top: theory against the rates measured on the exact motion (t = 60)")
    print(
        f"{'I':>5} {'J':>5} {'shape':>8} {'p = G/I':>12} {'measured':>12} {'rel.err':>8}"
        f" {'s':>12} {'measured':>12} {'rel.err':>8} {'α_b°':>7} {'α_s°':>7} {'θ°':>7}"
    )
    for It, J, w0 in [
        (2.0, 3.0, (0.5, 0.2, 1.0)),
        (3.0, 1.0, (0.5, 0.2, 1.0)),
        (1.0, 10.0, (1.0, 0.0, 0.05)),
        (10.0, 0.5, (0.05, 0.0, 3.0)),
    ]:
        top = symmetric_top(It, J, w0)
        body = top.body()
        p, s = measure_precession_rate(body, 60.0), measure_spin_rate(body, 60.0)
        angles = np.degrees(
            [top.body_cone_half_angle, top.space_cone_half_angle, top.nutation_angle]
        )
        print(
            f"{It:5g} {J:5g} {top.shape:>8} {top.precession_rate:12.9f} {p:12.9f} "
            f"{p / top.precession_rate - 1:8.0e} {top.spin_rate:12.9f} {s:12.9f} "
            f"{s / top.spin_rate - 1:8.0e} {angles[0]:7.2f} {angles[1]:7.2f} {angles[2]:7.2f}"
        )


if __name__ == "__main__":  # pragma: no cover
    _demo()
