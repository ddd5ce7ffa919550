"""The polhode family of a triaxial body, Landau's momentum-space picture, and the progress of
the contact point along its polhode.

For sorted moments ``I1 < I2 < I3`` and a fixed energy ``2T``, the polhodes are the curves cut on
the energy ellipsoid ``Σ Iᵢ xᵢ² = 2T`` (body frame, ω-space) by the cones
``Σ Iᵢ (Iᵢ - D) xᵢ² = 0``, one for each ``D = G²/2T`` in ``[I1, I3]`` [FM06 §7.8, Eq. 7.57;
Pars65 §13.12]. They fall into three kinds [LL76 §37, Fig. 51; FM06 Fig. 7.7]:

* ``D < I2``: two closed curves around the minor axis ``±e1`` (:attr:`Regime.MINOR_AXIS`);
* ``D > I2``: two closed curves around the major axis ``±e3`` (:attr:`Regime.MAJOR_AXIS`);
* ``D = I2``: the separatrix, two ellipses through the intermediate-axis poles ``±e2``, drawn
  as four arcs from ``-e2`` to ``+e2`` (:attr:`Regime.SEPARATRIX`) [Pars65 §13.12, Eqs.
  13.12.19-20];
* ``D = I1`` or ``I3``: the points ``±e1`` or ``±e3`` (:attr:`Regime.PERMANENT_ROTATION`).

Each curve is given in closed form in the amplitude ``φ`` of the Jacobi functions
(``sn = sin φ``, ``cn = cos φ``, ``dn = sqrt(cos²φ + mc sin²φ)``) [LL76 §37, Eq. 37.10], with the
amplitudes written through ``D`` so that nothing cancels near the separatrix:

* major family: ``ω = (A1 cos φ, A2 sin φ, ±A3 dn)``, ``A1² = 2T(I3 - D)/(I1(I3 - I1))``,
  ``A2² = 2T(I3 - D)/(I2(I3 - I2))``, ``A3² = 2T(D - I1)/(I3(I3 - I1))``,
  ``mc = (I3 - I1)(D - I2)/((I3 - I2)(D - I1))``;
* minor family: the roles of axes 1 and 3 swapped, ``ω = (±A1 dn, A2 sin φ, A3 cos φ)`` with
  ``A2² = 2T(D - I1)/(I2(I2 - I1))`` and ``mc = (I3 - I1)(I2 - D)/((I2 - I1)(I3 - D))``.

Landau's view [LL76 §37] is the same picture in momentum space: ``m = I ω`` lies on the sphere
``|m| = G`` and on the ellipsoid ``Σ mᵢ²/Iᵢ = 2T`` (semi-axes ``sqrt(2T Iᵢ)``); their
intersection is the polhode mapped by ``I``.

:class:`PolhodeArc`: how far the contact point has crept along its polhode [FM06 Remark 7.5].
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import special

from poinsot.physics import FreeRigidBody, Regime

__all__ = [
    "MomentumView",
    "PolhodeArc",
    "PolhodeCurve",
    "family_D_values",
    "momentum_view",
    "polhode_curves",
    "polhode_family",
    "polhode_points",
    "polhode_progress",
]
_EPS = float(np.finfo(float).eps)
#: Fourier samples of |dω/dt| per circuit: start, and the most before giving up.
_ARC_SAMPLES_MIN, _ARC_SAMPLES_MAX = 64, 1 << 21
#: The series of |dω/dt| is converged when its coefficients in the upper quarter of the
#: spectrum fall below this fraction of the mean, or below the rounding noise of the samples,
#: _ARC_NOISE_EPS · eps · max|dω/dt| (a bursty speed, next to the separatrix, has a mean far
#: below its peak; a noise-level term adds < 1e-13 of a circuit to the arc).
_ARC_TAIL = 1e-15
_ARC_NOISE_EPS = 16.0


def sorted_moments(inertia: ArrayLike) -> tuple[float, float, float]:
    """The moments as three floats, checked: finite, positive and strictly ascending.

    Raises:
        ValueError: with what is wrong and what to change.
    """
    try:
        arr = np.asarray(inertia, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"the moments of inertia must be three numbers, got {inertia!r}") from exc
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise ValueError(f"the moments of inertia must be three finite numbers, got {inertia!r}")
    I1, I2, I3 = (float(x) for x in arr)
    if I1 <= 0.0:
        raise ValueError(f"the moments of inertia must be positive, got {arr.tolist()}")
    if not I1 < I2 < I3:
        raise ValueError(
            "this construction needs three different moments sorted ascending, I1 < I2 < I3 "
            f"(e1 the minor, e2 the intermediate, e3 the major axis); got {arr.tolist()}"
        )
    return I1, I2, I3


def _positive(value: float, name: str) -> float:
    x = float(value)
    if not (math.isfinite(x) and x > 0.0):
        raise ValueError(f"{name} must be a positive finite number, got {value!r}")
    return x


def _check_D(D: float, I1: float, I3: float) -> float:
    x = float(D)
    if not (math.isfinite(x) and I1 <= x <= I3):
        raise ValueError(
            f"D = |L|²/2T must lie between the smallest and the largest moment [{I1:g}, {I3:g}], "
            f"got {D!r}"
        )
    return x


@dataclass(frozen=True)
class PolhodeCurve:
    """One polhode of the family, in the body frame.

    Attributes:
        D: ``G²/2T`` of this curve [moment units].
        regime: which kind of curve it is (its label): ``MINOR_AXIS``, ``MAJOR_AXIS``,
            ``SEPARATRIX`` or ``PERMANENT_ROTATION``.
        omega: (n, 3) points ω on the energy ellipsoid [rad/time]; (1, 3) for a permanent
            rotation.
        momentum: (n, 3) the same points as ``m = I ω`` (Landau's sphere and ellipsoid).
        closed: True if the curve closes from the last point back to the first (the separatrix
            arcs run from ``-e2`` to ``+e2``, endpoints included, and do not close).
        signs: (s1, s2, s3), the signs applied to the components of the base parametrisation:
            the pole sign on the pole axis (``(±1, 1, 1)`` minor, ``(1, 1, ±1)`` major), and the
            two arc signs ``(s1, 1, s3)`` of a separatrix arc.
        two_T: ``2T`` [moment × rad²/time²], G: ``|m|`` [moment × rad/time] of this curve.
    """

    D: float
    regime: Regime
    omega: NDArray[np.float64]
    momentum: NDArray[np.float64]
    closed: bool
    signs: tuple[int, int, int]
    two_T: float
    G: float


def family_D_values(inertia: ArrayLike, per_family: int = 4) -> NDArray[np.float64]:
    """A drawing set of D values: ``per_family`` evenly spaced inside ``(I1, I2)``, then ``I2``,
    then ``per_family`` inside ``(I2, I3)``; ascending, shape ``(2 per_family + 1,)``."""
    I1, I2, I3 = sorted_moments(inertia)
    n = int(per_family)
    if n < 1:
        raise ValueError(f"per_family must be at least 1, got {per_family!r}")
    k = np.arange(1, n + 1) / (n + 1)
    return np.concatenate([I1 + (I2 - I1) * k, [I2], I2 + (I3 - I2) * k])


def _two_T_and_G(D: float, energy: float | None, momentum: float | None) -> tuple[float, float]:
    if energy is not None and momentum is not None:
        raise ValueError("give the energy or the angular momentum |L|, not both")
    if momentum is not None:
        G = _positive(momentum, "the angular momentum |L|")
        return G * (G / D), G
    two_T = 2.0 * _positive(0.5 if energy is None else energy, "the kinetic energy T")
    return two_T, math.sqrt(two_T * D)


def polhode_curves(
    inertia: ArrayLike,
    D: float,
    *,
    energy: float | None = None,
    momentum: float | None = None,
    n: int = 256,
) -> list[PolhodeCurve]:
    """All polhodes with one value of D: two closed curves (around ``±e1`` if ``D < I2``, around
    ``±e3`` if ``D > I2``), four separatrix arcs if ``D = I2``, two points if ``D = I1`` or ``I3``.

    Args:
        inertia: (3,) moments ``I1 < I2 < I3`` (sorted, distinct).
        D: ``G²/2T`` in ``[I1, I3]``.
        energy: the kinetic energy T (default 0.5, i.e. ``2T = 1``): the ellipsoid is fixed.
        momentum: or ``|L| = G`` instead (Landau's view: the sphere is fixed, ``2T = G²/D``).
        n: points per curve (>= 3), uniform in the amplitude φ.

    Returns:
        A list of :class:`PolhodeCurve` (pole sign +1 first).
    """
    I1, I2, I3 = sorted_moments(inertia)
    D = _check_D(D, I1, I3)
    n = int(n)
    if n < 3:
        raise ValueError(f"a polhode needs at least 3 points, got n={n}")
    two_T, G = _two_T_and_G(D, energy, momentum)
    J = np.array([I1, I2, I3])
    if D in (I1, I3):
        kind, closed, parts = Regime.PERMANENT_ROTATION, False, _pure_spins(J, D, two_T)
    elif D == I2:
        kind, closed, parts = Regime.SEPARATRIX, False, _separatrix_arcs(J, two_T, n)
    else:
        kind = Regime.MAJOR_AXIS if D > I2 else Regime.MINOR_AXIS
        closed, parts = True, _closed_polhodes(J, D, two_T, n)
    return [PolhodeCurve(D, kind, w, w * J, closed, signs, two_T, G) for w, signs in parts]


_Parts = list[tuple[NDArray[np.float64], tuple[int, int, int]]]


def _pure_spins(J: NDArray[np.float64], D: float, two_T: float) -> _Parts:
    """``D = I1`` or ``I3``: the two points ``±sqrt(2T/Iₖ) eₖ``, each as a (1, 3) array."""
    k = 0 if D == J[0] else 2
    parts: _Parts = []
    for pole in (1, -1):
        w = np.zeros((1, 3))
        w[0, k] = pole * math.sqrt(two_T / J[k])
        parts.append((w, (pole, 1, 1) if k == 0 else (1, 1, pole)))
    return parts


def _branch(
    J: NDArray[np.float64], D: float, two_T: float, phi: NDArray, signs: tuple[int, int, int]
) -> NDArray[np.float64]:
    """The points ω (N, 3) at the amplitudes ``phi`` (N,) on one branch of the polhodes of D:
    ``(A1 cos φ, A2 sin φ, s3 A3 dn)`` if ``D > I2``, ``(s1 A1 dn, A2 sin φ, A3 cos φ)`` if
    ``D < I2``, ``(s1 A1 cos φ, A2 sin φ, s3 A3 cos φ)`` if ``D = I2`` [LL76 §37, Eq. 37.10;
    Pars65 §13.12, Eqs. 13.12.19-20]; amplitudes as in the module docstring. ``D = I1`` or
    ``I3`` gives the pole itself for every φ."""
    I1, I2, I3 = (float(x) for x in J)
    s1, _, s3 = signs
    cos, sin = np.cos(phi), np.sin(phi)
    if D == I2:
        A1 = math.sqrt(two_T * (I3 - I2) / (I1 * (I3 - I1)))
        A3 = math.sqrt(two_T * (I2 - I1) / (I3 * (I3 - I1)))
        return np.stack([s1 * A1 * cos, math.sqrt(two_T / I2) * sin, s3 * A3 * cos], axis=-1)
    A1 = math.sqrt(two_T * (I3 - D) / (I1 * (I3 - I1)))
    A3 = math.sqrt(two_T * (D - I1) / (I3 * (I3 - I1)))
    if D > I2:
        A2 = math.sqrt(two_T * (I3 - D) / (I2 * (I3 - I2)))
        mc = (I3 - I1) * (D - I2) / ((I3 - I2) * (D - I1))
        dn = np.sqrt(cos * cos + mc * sin * sin)
        return np.stack([A1 * cos, A2 * sin, s3 * A3 * dn], axis=-1)
    A2 = math.sqrt(two_T * (D - I1) / (I2 * (I2 - I1)))
    mc = (I3 - I1) * (I2 - D) / ((I2 - I1) * (I3 - D))
    dn = np.sqrt(cos * cos + mc * sin * sin)
    return np.stack([s1 * A1 * dn, A2 * sin, A3 * cos], axis=-1)


def _separatrix_arcs(J: NDArray[np.float64], two_T: float, n: int) -> _Parts:
    """``D = I2``: four arcs from ``-e2`` to ``+e2`` (φ from -π/2 to π/2); ``(s1, s3)`` and
    ``(-s1, -s3)`` make up one of the two ellipses (planes through e2)."""
    phi = np.linspace(-0.5 * math.pi, 0.5 * math.pi, n)
    out: _Parts = []
    for s1, s3 in ((1, 1), (1, -1), (-1, 1), (-1, -1)):
        signs = (s1, 1, s3)
        out.append((_branch(J, float(J[1]), two_T, phi, signs), signs))
    return out


def _closed_polhodes(J: NDArray[np.float64], D: float, two_T: float, n: int) -> _Parts:
    """``D ≠ I2``: the two closed curves around ``±e3`` (``D > I2``) or ``±e1`` (``D < I2``),
    uniform in the amplitude φ."""
    phi = np.linspace(0.0, 2.0 * math.pi, n, endpoint=False)
    out: _Parts = []
    for pole in (1, -1):
        signs = (1, 1, pole) if D > J[1] else (pole, 1, 1)
        out.append((_branch(J, D, two_T, phi, signs), signs))
    return out


def polhode_points(
    inertia: ArrayLike,
    D: float,
    phi: ArrayLike,
    signs: tuple[int, int, int] = (1, 1, 1),
    *,
    energy: float | None = None,
    momentum: float | None = None,
) -> NDArray[np.float64]:
    """Points ω (N, 3) [rad/time] at the amplitudes ``phi`` (N,) [rad] on one branch of the
    polhodes of D, the branch named by the :attr:`PolhodeCurve.signs` of its curve.

    Args:
        inertia: (3,) ``I1 < I2 < I3``. D: ``G²/2T`` in ``[I1, I3]``. phi: (N,) amplitudes
            (on the separatrix, ``-π/2 … π/2`` runs from ``-e2`` to ``+e2``).
        signs: ``(s1, 1, s3)``: the pole sign on the pole axis (``s1`` below the separatrix,
            ``s3`` above it), both arc signs on it. energy, momentum: as in
            :func:`polhode_curves`.
    """
    I1, I2, I3 = sorted_moments(inertia)
    D = _check_D(D, I1, I3)
    s1, s2, s3 = (int(x) for x in signs)
    if s2 != 1 or s1 not in (1, -1) or s3 not in (1, -1):
        raise ValueError(f"signs must be (±1, 1, ±1), got {signs!r}")
    angles = np.atleast_1d(np.asarray(phi, dtype=float))
    if angles.ndim != 1 or not np.all(np.isfinite(angles)):
        raise ValueError("phi must be a finite number or a 1-D array of finite numbers")
    two_T, _ = _two_T_and_G(D, energy, momentum)
    return _branch(np.array([I1, I2, I3]), D, two_T, angles, (s1, 1, s3))


def polhode_family(
    inertia: ArrayLike,
    D_values: ArrayLike | None = None,
    *,
    energy: float | None = None,
    momentum: float | None = None,
    n: int = 256,
) -> list[PolhodeCurve]:
    """The polhode family [LL76 §37 Fig. 51; FM06 Fig. 7.7]: :func:`polhode_curves` for each D.

    Args:
        inertia: (3,) moments ``I1 < I2 < I3``.
        D_values: (k,) values in ``[I1, I3]``; default :func:`family_D_values` (4 per family and
            the separatrix).
        energy, momentum, n: as in :func:`polhode_curves` (at most one of energy and momentum).

    Returns:
        The curves of every D in the order given (two per D, four for ``D = I2``).
    """
    values = family_D_values(inertia) if D_values is None else np.atleast_1d(D_values)
    if values.ndim != 1:
        raise ValueError(f"D_values must be a 1-D list of numbers, got shape {values.shape}")
    curves: list[PolhodeCurve] = []
    for D in values.tolist():  # a handful of curves; each one is vectorised over its points
        curves.extend(polhode_curves(inertia, D, energy=energy, momentum=momentum, n=n))
    return curves


@dataclass(frozen=True)
class MomentumView:
    """Landau's picture for one D [LL76 §37]: the sphere ``|m| = G`` and the ellipsoid
    ``Σ mᵢ²/Iᵢ = 2T``, and their intersection (the curves' ``momentum`` arrays, (n, 3)).

    Attributes:
        D: ``G²/2T``. sphere_radius: ``G``. ellipsoid_semi_axes: (3,) ``sqrt(2T Iᵢ)``.
        two_T: ``2T = G²/D``. curves: the polhodes of this D (:func:`polhode_curves`).
    """

    D: float
    sphere_radius: float
    ellipsoid_semi_axes: NDArray[np.float64]
    two_T: float
    curves: list[PolhodeCurve]


def momentum_view(
    inertia: ArrayLike, D: float, momentum: float = 1.0, n: int = 256
) -> MomentumView:
    """Landau's momentum sphere and energy ellipsoid for one D at fixed ``|L| = momentum``."""
    curves = polhode_curves(inertia, D, momentum=momentum, n=n)
    two_T = curves[0].two_T
    semi = np.sqrt(two_T * np.asarray(sorted_moments(inertia)))
    return MomentumView(curves[0].D, curves[0].G, semi, two_T, curves)


# ---------------------------------------------------------------------------------------------
# Progress of the contact point along its polhode.
# ---------------------------------------------------------------------------------------------


def _omega_dot_norm(inertia: NDArray[np.float64], w: NDArray[np.float64]) -> NDArray[np.float64]:
    """``|dω/dt|`` from Euler's equations ``I1 ω1' = (I2 - I3) ω2 ω3`` and cyclic [LL76 §36,
    Eq. 36.5], for rows of ``w`` (N, 3)."""
    I1, I2, I3 = inertia
    d1 = (I2 - I3) / I1 * w[:, 1] * w[:, 2]
    d2 = (I3 - I1) / I2 * w[:, 2] * w[:, 0]
    d3 = (I1 - I2) / I3 * w[:, 0] * w[:, 1]
    return np.hypot(np.hypot(d1, d2), d3)


class PolhodeArc:
    """The arc length travelled by the tip of ω along its polhode (in the body frame).

    Args:
        body: any :class:`FreeRigidBody`.

    The speed along the polhode is ``|dω/dt|`` (Euler's equations on the exact ω(t)). It is
    periodic with the period of ω, so its Fourier series over one circuit, integrated term by
    term, gives the arc length at any time: ``s(t) = c0 t + Σ_k 2 Re(F_k (e^{ikwt} - 1)/(ikw))``.
    The samples are doubled until the upper quarter of the spectrum is below ``1e-15`` of the
    mean; as a function of time the speed is analytic in a strip of width O(1/λ), so even next
    to the separatrix (1 - m = 1e-24) a few thousand samples reach rounding.

    The separatrix is not periodic: there ``ω = (s1 A1 cos φ, A2 sin φ, s3 A3 cos φ)`` with
    ``sin φ = tanh u``, an arc of an ellipse, whose length is the incomplete elliptic integral
    ``∫ sqrt(a² sin²φ + A2² cos²φ) dφ = A2 E(φ | 1 - a²/A2²)``, ``a² = A1² + A3²``.
    A constant ω (permanent rotation, sphere, rest) travels nothing.
    """

    def __init__(self, body: FreeRigidBody):
        if not isinstance(body, FreeRigidBody):
            raise ValueError(f"PolhodeArc needs a FreeRigidBody, got {type(body).__name__}")
        self.body = body
        self.circuit_time = float(body.period)
        """Time of one circuit of the polhode, the period of ω [time] (inf if none)."""
        self._inertia = np.asarray(body.inertia, dtype=float)
        self._coef = np.zeros(0, dtype=complex)
        self._mean = 0.0
        self._w = 0.0  # 2π / period
        self._sep: tuple[float, float, float] | None = None
        self._sep_axes = (0, 1, 2)
        if body.regime is Regime.SEPARATRIX:
            self._init_separatrix()
        elif math.isfinite(self.circuit_time):
            self._init_series()
        self.circuit_length = self._circuit_length()
        """Length of one circuit [rad/time] (of the whole arc ``-e2 → +e2`` on the separatrix;
        0 for a constant ω)."""

    def _init_series(self) -> None:
        P = self.circuit_time
        M = _ARC_SAMPLES_MIN
        while True:
            t = np.arange(M) * (P / M)
            f = _omega_dot_norm(self._inertia, self.body.omega(t))
            F = np.fft.rfft(f) / M
            mean = float(F[0].real)
            tail = np.abs(F[3 * (M // 8) : M // 2])
            floor = max(_ARC_TAIL * mean, _ARC_NOISE_EPS * _EPS * float(f.max()))
            if mean == 0.0 or float(tail.max()) <= floor:
                break
            if M >= _ARC_SAMPLES_MAX:
                raise ValueError(
                    "the speed along this polhode does not resolve with "
                    f"{_ARC_SAMPLES_MAX} samples per circuit (the motion lies too close to the "
                    "separatrix for its arc length to be tabulated)"
                )
            M *= 2
        self._mean = mean
        coef = 2.0 * F[1 : M // 2]
        keep = np.flatnonzero(np.abs(coef) > 0.1 * floor)
        self._coef = coef[: int(keep[-1]) + 1] if keep.size else coef[:0]
        self._w = 2.0 * math.pi / P

    def _init_separatrix(self) -> None:
        order = np.argsort(self._inertia, kind="stable")  # caller's indices of I1, I2, I3
        Is = self._inertia[order]
        ws = self.body.omega0.astype(float)[order]
        two_T = float(np.sum(Is * ws * ws))
        A1sq = two_T * (Is[2] - Is[1]) / (Is[0] * (Is[2] - Is[0]))
        A3sq = two_T * (Is[1] - Is[0]) / (Is[2] * (Is[2] - Is[0]))
        A2 = math.sqrt(two_T / Is[1])
        self._sep = (A2, math.sqrt(A1sq + A3sq), 1.0 - (A1sq + A3sq) / (A2 * A2))
        self._sep_axes = (int(order[0]), int(order[1]), int(order[2]))

    def _separatrix_arc(self, w: NDArray[np.float64]) -> NDArray[np.float64]:
        """Signed arc length from the arc's midpoint (φ = 0) to the points ``w`` (N, 3)."""
        assert self._sep is not None
        A2, a, m = self._sep
        k1, k2, k3 = self._sep_axes
        # sin φ = ω2/A2, cos φ = hypot(ω1, ω3)/a >= 0: atan2 keeps the digits of both.
        phi = np.arctan2(w[:, k2] / A2, np.hypot(w[:, k1], w[:, k3]) / a)
        return A2 * special.ellipeinc(phi, m)

    def _circuit_length(self) -> float:
        if self._sep is not None:
            A2, _, m = self._sep
            return float(2.0 * A2 * special.ellipe(m))
        return self._mean * self.circuit_time if math.isfinite(self.circuit_time) else 0.0

    def _series(self, r: NDArray[np.float64]) -> NDArray[np.float64]:
        """``∫₀^r |dω/dt| dt`` for ``0 <= r < P`` (N,), from the integrated Fourier series:
        ``Σ_k b_k (z^k - 1)`` with ``z = e^{iwr}``, ``b_k = c_k/(ikw)``, summed by Horner's
        scheme (one complex multiply-add per term and time; ``|z| = 1`` keeps it stable)."""
        out = self._mean * r
        if self._coef.size == 0:
            return out
        kw = np.arange(1, self._coef.size + 1) * self._w
        b = self._coef / (1j * kw)
        z = np.exp(1j * self._w * r)
        acc = np.full(r.shape, b[-1], dtype=complex)
        for bk in b[-2::-1]:  # a loop over the series' terms, each step vectorised over times
            acc = acc * z + bk
        return out + (acc * z).real - float(b.sum().real)

    def arc_length(self, t: ArrayLike) -> NDArray[np.float64]:
        """Arc length [rad/time] travelled along the polhode from ``t = 0`` to ``t`` (N,),
        whole circuits included (negative for ``t < 0``)."""
        tt = np.atleast_1d(np.asarray(t, dtype=float))
        if tt.ndim != 1 or not np.all(np.isfinite(tt)):
            raise ValueError("t must be a finite number or a 1-D array of finite numbers")
        if self._sep is not None:
            # The tip runs monotonically from one pole to the other: the arc travelled is the
            # distance along the arc, signed like t.
            moved = self._separatrix_arc(self.body.omega(tt))
            moved = moved - self._separatrix_arc(self.body.omega0[None, :].astype(float))
            return np.copysign(np.abs(moved), tt)
        if self.circuit_length == 0.0:
            return np.zeros_like(tt)
        P = self.circuit_time
        turns = np.floor(tt / P)
        r = np.clip(tt - turns * P, 0.0, P)
        return turns * self.circuit_length + self._series(r)

    def fraction(self, t: ArrayLike) -> NDArray[np.float64]:
        """The fraction in ``[0, 1)`` of one circuit travelled since ``t = 0``, modulo whole
        circuits (N,). On the separatrix: the arc travelled over the whole arc's length
        (``-e2 → +e2``), in ``(-1, 1)``. 0 for a constant ω."""
        s = self.arc_length(t)
        if self.circuit_length == 0.0:
            return s
        if self._sep is not None:
            return s / self.circuit_length
        frac = np.mod(s / self.circuit_length, 1.0)
        return np.where(frac >= 1.0, 0.0, frac)


def polhode_progress(body: FreeRigidBody, t: ArrayLike) -> tuple[NDArray[np.float64], float]:
    """``(fraction (N,), circuit_time)``: :meth:`PolhodeArc.fraction` at the times ``t`` and the
    time one circuit of the polhode takes (the period of ω; ``inf`` if it never closes)."""
    arc = PolhodeArc(body)
    return arc.fraction(t), arc.circuit_time
