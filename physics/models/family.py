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

:class:`PolhodeArc` (:mod:`~poinsot.physics.models.polhode_arc`, re-exported here): how far the
contact point has crept along its polhode [FM06 Remark 7.5].
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from poinsot.physics.core.exact import pow2_below
from poinsot.physics.core.regime import Regime
from poinsot.physics.core.validation import (
    MAX_POINTS,
    check_count,
    check_moment_span,
    check_positive,
    check_vector,
    real_array,
    real_number,
)
from poinsot.physics.models.polhode_arc import PolhodeArc, polhode_progress

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
#: polhode_family draws at most this many points in all.
_FAMILY_POINTS = 4 * MAX_POINTS
_OUT_OF_RANGE = (
    "beyond the double-precision range (1.8e308): express the moments, the energy or |L| in "
    "other units"
)


def sorted_moments(inertia: ArrayLike) -> tuple[float, float, float]:
    """The moments as three floats, checked: finite, positive, strictly ascending and at most
    300 decades apart (as for :class:`~poinsot.physics.FreeRigidBody`).

    Raises:
        ValueError: with what is wrong and what to change.
    """
    arr = check_vector(inertia, "the moments of inertia")
    I1, I2, I3 = arr.tolist()
    if I1 <= 0.0:
        raise ValueError(f"the moments of inertia must be positive, got {arr.tolist()}")
    if not I1 < I2 < I3:
        raise ValueError(
            "this construction needs three different moments sorted ascending, I1 < I2 < I3 "
            f"(e1 the minor, e2 the intermediate, e3 the major axis); got {arr.tolist()}"
        )
    check_moment_span(arr)
    return I1, I2, I3


def _check_D(D: float, I1: float, I3: float) -> float:
    x = real_number(D, "D")
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
    n = check_count(per_family, "per_family", 1)
    k = np.arange(1, n + 1) / (n + 1)
    return np.concatenate([I1 + (I2 - I1) * k, [I2], I2 + (I3 - I2) * k])


def _two_T_and_G(D: float, energy: float | None, momentum: float | None) -> tuple[float, float]:
    if energy is not None and momentum is not None:
        raise ValueError("give the energy or the angular momentum |L|, not both")
    if momentum is not None:
        G = check_positive(momentum, "the angular momentum |L|")
        two_T = G * (G / D)
    else:
        two_T = 2.0 * check_positive(0.5 if energy is None else energy, "the kinetic energy T")
        G = math.sqrt(two_T) * math.sqrt(D)
    if not (0.0 < two_T < math.inf):
        raise ValueError(f"2T for this D is {_OUT_OF_RANGE}")
    return two_T, G


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
    n = check_count(n, "n, the number of points of a polhode,", 3)
    two_T, G = _two_T_and_G(D, energy, momentum)
    J = np.array([I1, I2, I3])
    if D in (I1, I3):
        kind, closed, parts = Regime.PERMANENT_ROTATION, False, _pure_spins(J, D, two_T)
    elif D == I2:
        kind, closed, parts = Regime.SEPARATRIX, False, _separatrix_arcs(J, two_T, n)
    else:
        kind = Regime.MAJOR_AXIS if D > I2 else Regime.MINOR_AXIS
        closed, parts = True, _closed_polhodes(J, D, two_T, n)
    with np.errstate(over="ignore"):
        curves = [PolhodeCurve(D, kind, w, w * J, closed, signs, two_T, G) for w, signs in parts]
    if not all(np.all(np.isfinite(c.omega)) and np.all(np.isfinite(c.momentum)) for c in curves):
        raise ValueError(f"the polhodes of this D reach values {_OUT_OF_RANGE}")
    return curves


_Parts = list[tuple[NDArray[np.float64], tuple[int, int, int]]]


def _pure_spins(J: NDArray[np.float64], D: float, two_T: float) -> _Parts:
    """``D = I1`` or ``I3``: the two points ``±sqrt(2T/Iₖ) eₖ``, each as a (1, 3) array."""
    k = 0 if D == J[0] else 2
    parts: _Parts = []
    for pole in (1, -1):
        w = np.zeros((1, 3))
        w[0, k] = pole * (math.sqrt(two_T) / math.sqrt(J[k]))  # 2T/I_k may leave the range
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
    # sqrt(2T num/(a b)) in moments scaled by a power of two near I3, dividing one factor at a
    # time: 2T·num, a·b and 1/I1 would each leave the double range somewhere (moments ~1e300
    # or ~1e-300, or 300 decades apart).
    scale = pow2_below(I3)
    j1, j2, j3, d = I1 / scale, I2 / scale, I3 / scale, D / scale
    root = math.sqrt(two_T) / math.sqrt(scale)

    def amplitude(num: float, a: float, b: float) -> float:
        return root * math.sqrt(num / b / a)

    if D == I2:
        A1 = amplitude(j3 - j2, j1, j3 - j1)
        A2 = amplitude(1.0, j2, 1.0)
        A3 = amplitude(j2 - j1, j3, j3 - j1)
        _check_amplitudes(A1, A2, A3)
        return np.stack([s1 * A1 * cos, A2 * sin, s3 * A3 * cos], axis=-1)
    A1 = amplitude(j3 - d, j1, j3 - j1)
    A3 = amplitude(d - j1, j3, j3 - j1)
    A2 = amplitude(j3 - d, j2, j3 - j2) if D > I2 else amplitude(d - j1, j2, j2 - j1)
    _check_amplitudes(A1, A2, A3)
    if D > I2:
        mc = (I3 - I1) / (I3 - I2) * ((D - I2) / (D - I1))
        dn = np.sqrt(cos * cos + mc * sin * sin)
        return np.stack([A1 * cos, A2 * sin, s3 * A3 * dn], axis=-1)
    mc = (I3 - I1) / (I2 - I1) * ((I2 - D) / (I3 - D))
    dn = np.sqrt(cos * cos + mc * sin * sin)
    return np.stack([s1 * A1 * dn, A2 * sin, A3 * cos], axis=-1)


def _check_amplitudes(*amplitudes: float) -> None:
    if not all(map(math.isfinite, amplitudes)):
        raise ValueError(f"the polhodes of this D reach values {_OUT_OF_RANGE}")


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
    given = real_array(signs, "signs", "three signs (±1, 1, ±1)")
    s1, s2, s3 = given.tolist() if given.shape == (3,) else (0.0, 0.0, 0.0)
    if s2 != 1 or s1 not in (1, -1) or s3 not in (1, -1):
        raise ValueError(f"signs must be (±1, 1, ±1), got {signs!r}")
    angles = np.atleast_1d(real_array(phi, "phi", "angles in radians"))
    if angles.ndim != 1 or not np.all(np.isfinite(angles)):
        raise ValueError("phi must be a finite number or a 1-D array of finite numbers")
    two_T, _ = _two_T_and_G(D, energy, momentum)
    with np.errstate(over="ignore"):
        points = _branch(np.array([I1, I2, I3]), D, two_T, angles, (int(s1), 1, int(s3)))
    if not np.all(np.isfinite(points)):
        raise ValueError(f"the polhode of this D reaches values {_OUT_OF_RANGE}")
    return points


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
    if D_values is None:
        values = family_D_values(inertia)
    else:
        values = np.atleast_1d(real_array(D_values, "D_values", "numbers in [I1, I3]"))
    if values.ndim != 1:
        raise ValueError(f"D_values must be a 1-D list of numbers, got shape {values.shape}")
    points = 4 * values.size * check_count(n, "n, the number of points of a polhode,", 3)
    if points > _FAMILY_POINTS:
        raise ValueError(
            f"{values.size} values of D with n = {n} points per curve would make {points:,} "
            f"points (at most {_FAMILY_POINTS:,}): ask for fewer D values or fewer points"
        )
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
    semi = math.sqrt(two_T) * np.sqrt(np.asarray(sorted_moments(inertia)))
    if not np.all(np.isfinite(semi)):
        raise ValueError(f"the energy ellipsoid of this |L| has semi-axes {_OUT_OF_RANGE}")
    return MomentumView(curves[0].D, curves[0].G, semi, two_T, curves)
