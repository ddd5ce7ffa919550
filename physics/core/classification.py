"""Which closed form describes a motion: the regime, decided once, from exact data.

Uniform motions first (rest, sphere, a permanent rotation, two equal moments), by exact
comparisons of the caller's own numbers; then the sign of ``Δ2 = G² - 2T·I2`` in exact integers
(:class:`~poinsot.physics.core.exact.ExactState`) splits the triaxial motions into the major-axis
family (``D > I2``), the minor-axis family (``D < I2``) and the separatrix (``D = I2``)
[LL76 §37], [FM06 Fig. 7.7].
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from poinsot.physics.core.closed_forms import ClosedForm, Triple
from poinsot.physics.core.closed_forms.separatrix import Separatrix
from poinsot.physics.core.closed_forms.triaxial import Triaxial
from poinsot.physics.core.closed_forms.uniform import Uniform
from poinsot.physics.core.exact import ExactState
from poinsot.physics.core.regime import Regime
from poinsot.physics.core.relabelling import IDENTITY, REVERSE, AxisMap

__all__ = ["Motion", "SortedState", "classify"]

Array = NDArray[np.float64]


class SortedState(NamedTuple):
    """The scaled state in the sorted axes, and what the uniform forms need in the caller's.

    Plain floats (the construction's few numbers cost less as Python floats than as numpy
    arrays of three, and give the same bits).

    Attributes:
        sort: the relabelling caller -> sorted axes (moments ascending).
        J, w: (3,) scaled moments and ω, sorted axes.
        w_exact: (3,) the caller's ω in the sorted axes, unscaled (exact zeros and signs).
        inertia, omega: (3,) scaled moments and ω, caller's axes.
        omega_user: (3,) array, the caller's ω, unscaled; w_exp: ``omega = omega_user / 2^w_exp``.
    """

    sort: AxisMap
    J: Triple
    w: Triple
    w_exact: Triple
    inertia: Triple
    omega: Triple
    omega_user: Array
    w_exp: int


class Motion(NamedTuple):
    """A classified motion: its regime, its closed form, and the relabelling caller ->
    the form's internal body axes."""

    regime: Regime
    form: ClosedForm
    frame: AxisMap


def classify(state: SortedState, on_separatrix: bool = False) -> Motion:
    """The regime and closed form of a scaled state.

    ``on_separatrix`` builds the separatrix for a state ``(ω1, 0, ω3)`` of a triaxial body
    whose float ω lies within rounding of it (:meth:`ExactState.on_separatrix`).
    """
    s = state
    if on_separatrix:
        return _triaxial(s, ExactState.on_separatrix(s.J, s.w_exact, s.w_exp))
    zero = [x == 0.0 for x in s.w_exact]  # the caller's zeros (a scaled one may underflow)
    J1, J2, J3 = s.J
    if all(zero):
        return Motion(Regime.REST, _uniform(s, np.array([0.0, 0.0, 1.0]), 1.0, 1.0), IDENTITY)
    if J1 == J3:
        return Motion(Regime.SPHERE, _uniform(s, np.array([0.0, 0.0, 1.0]), J1, J1), IDENTITY)
    e_user = s.sort.matrix  # row k: sorted axis k in the caller's coordinates
    if sum(zero) == 2:  # along one principal axis of a triaxial body
        k = zero.index(False)
        form = _uniform(s, e_user[k], s.J[k], s.J[k])
        return Motion(Regime.PERMANENT_ROTATION, form, IDENTITY)
    if J1 == J2 or J2 == J3:
        a = 2 if J1 == J2 else 0  # the distinct (symmetry) axis
        t1, t2 = (k for k in range(3) if k != a)
        permanent = zero[a] or (zero[t1] and zero[t2])
        regime = Regime.PERMANENT_ROTATION if permanent else Regime.SYMMETRIC
        return Motion(regime, _uniform(s, e_user[a], J2, s.J[a]), IDENTITY)
    return _triaxial(s, ExactState.from_floats(s.J, s.w_exact, s.w_exp))


def _uniform(s: SortedState, axis: Array, I_t: float, J_a: float) -> Uniform:
    omega, inertia = np.array(s.omega), np.array(s.inertia)
    return Uniform(omega, axis.copy(), I_t, J_a, inertia, s.omega_user, s.w_exp)


def _triaxial(s: SortedState, exact: ExactState) -> Motion:
    """Triaxial and not a permanent rotation: the sign of Δ2, exactly."""
    if exact.D[1] == 0:
        return Motion(Regime.SEPARATRIX, Separatrix(s.J, exact), s.sort)
    if exact.D[1] > 0:
        return Motion(Regime.MAJOR_AXIS, Triaxial(s.J, s.w, exact), s.sort)
    # Minor family: the pole (smallest moment) becomes axis 3, x'' = (x3, x2, -x1).
    J1, J2, J3 = s.J
    w = REVERSE.to_internal_tuple(s.w)
    return Motion(
        Regime.MINOR_AXIS, Triaxial((J3, J2, J1), w, exact.reversed()), s.sort.compose(REVERSE)
    )
