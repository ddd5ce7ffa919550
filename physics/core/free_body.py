"""The exact motion of a free rigid body: angular velocity and attitude in closed form.

Solve once, evaluate many. :class:`FreeRigidBody` checks its input, scales it, classifies the
motion (:mod:`~poinsot.physics.core.classification`) and keeps one closed form
(:mod:`~poinsot.physics.core.closed_forms`); it then evaluates ω(t) and the attitude R(t)
(:mod:`~poinsot.physics.core.evaluation`) on whole arrays of times with no integration and no drift.
A single float time takes a plain-float path with the same operations (the same bits), so that
constructing a body and evaluating it once costs a fraction of a millisecond.

Frames and conventions:

* *Body frame*: the caller's principal axes, in the caller's order; the closed forms see them
  through a proper relabelling (:mod:`~poinsot.physics.core.relabelling`) and all results are
  mapped back.
* *Space frame*: the caller's, fixed by ``attitude0`` (``R(0)``). ``R(t)`` maps body
  coordinates to space coordinates; quaternions are scalar-last ``(x, y, z, w)``.
* Units are the caller's: ω in rad per time unit, moments in any consistent unit.

To stay finite for any scale (ω0 ~ 1e-200, moments ~ 1e100), the constants are computed in
units where the largest moment and the largest |ω0| component are powers of two near 1 (exact
scalings); the classification and the constants come from the exact integers of the caller's
own numbers (:mod:`~poinsot.physics.core.exact`). For any finite input the results are finite, or
a ValueError says what is out of range and what to change.
"""

from __future__ import annotations

import math
from typing import overload

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from poinsot.physics.core.classification import SortedState, classify
from poinsot.physics.core.evaluation import Evaluator
from poinsot.physics.core.initial_state import attitude_checked, omega_checked
from poinsot.physics.core.regime import Regime
from poinsot.physics.core.relabelling import sorting_map
from poinsot.physics.core.rotations import rotate, rotate_vector
from poinsot.physics.core.units import SLOWER, in_units, time_in_units, vector_in_units
from poinsot.physics.core.validation import (
    IDENTITY_ATTITUDE,
    MAX_POINTS,
    check_attitude,
    check_count,
    check_energy_parameter,
    check_inertia,
    check_moment_span,
    check_positive,
    check_sign,
    check_vector,
)

__all__ = ["FreeRigidBody"]

#: One vector, shape (3,).
Vector = np.ndarray[tuple[int], np.dtype[np.float64]]
#: A stack of N vectors (or quaternions), shape (N, 3) (or (N, 4)).
Stack = np.ndarray[tuple[int, int], np.dtype[np.float64]]
Array = NDArray[np.float64]

_IDENTITY_QUAT = (0.0, 0.0, 0.0, 1.0)


class FreeRigidBody:
    """Exact torque-free motion of a rigid body from its principal moments and initial ω.

    Args:
        inertia: (3,) principal moments ``(I1, I2, I3)``, positive and finite, in any order;
            they name the caller's body axes and every result uses the same axes.
        omega0: (3,) body-frame angular velocity at ``t = 0`` [rad per time unit].
        attitude0: attitude at ``t = 0`` as a single :class:`scipy.spatial.transform.Rotation`
            (body -> space); ``None`` means the identity (space axes = body axes at t = 0).

    Raises:
        ValueError: moments not positive or not finite (or more than 300 decades apart), ω0
            not finite, wrong shapes, or an ``attitude0`` that is not a single rotation. Later,
            from the evaluation methods: a time so far that a phase of the motion (rate × t)
            would pass 1e300 rad, or a body whose ω(t) leaves the double range in the caller's
            units; from the properties (``energy``, ``angular_momentum``, ``semi_axes``,
            ``frequency``, ``period``, ...): a value beyond the double range in those units.

    The constructor classifies the motion (:attr:`regime`) and precomputes the constants;
    :meth:`omega` and :meth:`attitude` then cost O(1) per time, for any time, with no drift.
    The moments need not obey the triangle inequality ``I1 + I2 >= I3``: the mathematics holds
    for any positive moments, only real mass distributions must obey it
    (:func:`~poinsot.physics.models.solids.check_real_body`).

    Attributes:
        inertia, omega0: (3,) the checked input; attitude0: the initial Rotation.
        regime: the :class:`~poinsot.physics.core.regime.Regime` of the motion.
        D: ``|L|²/2T`` [moment units], in ``[min I, max I]``; exactly ``I2`` on the separatrix.
        parameter, complementary_parameter: ``m = k²`` and ``1 - m`` of the Jacobi functions.
        plane_normal: (3,) ``L̂`` in space; plane_distance: ``2T/G`` [rad per time unit], the
            invariable plane ``x·L = 2T`` [FM06 Eq. 7.55].
    """

    def __init__(
        self,
        inertia: ArrayLike,
        omega0: ArrayLike,
        attitude0: Rotation | None = None,
        *,
        on_separatrix: bool = False,
    ) -> None:
        """``on_separatrix``: ``omega0`` was put on the separatrix ``D = I2`` to rounding (no
        float ω lies on it exactly, e.g. by
        :func:`~poinsot.physics.models.pointing.snap_to_separatrix`): the motion is the separatrix
        itself through it, with ``D == I2``, as :meth:`from_energy` builds it for ``D = I2``.
        Ignored for a body with two equal moments, or an ``omega0`` with no component on the
        axis of the smallest or the largest moment."""
        checked = check_inertia(inertia)
        omega = check_vector(omega0, "the initial angular velocity omega0")
        self._build(checked, omega, check_attitude(attitude0), on_separatrix)

    @classmethod
    def from_energy(
        cls,
        inertia: ArrayLike,
        D: float,
        *,
        omega_norm: float | None = None,
        momentum_norm: float | None = None,
        pole_sign: float = 1.0,
        attitude0: Rotation | None = None,
    ) -> FreeRigidBody:
        """A body started on the polhode of a given ``D``, as a scene is set up from sliders.

        Args:
            inertia: (3,) positive moments, any order [kg m², any unit].
            D: ``|L|²/2T`` in ``[min I, max I]`` (moment units): which polhode.
            omega_norm: ``|ω0|`` [rad per time unit], > 0; or else
            momentum_norm: ``|L| = |I ω0|`` [moment units × rad per time unit], > 0. Neither:
                ``|ω0| = 1``.
            pole_sign: +1 or -1, which of the two polhodes of this D (the sign of the component
                on the axis the polhode circles; on the separatrix, of the largest-moment one).
            attitude0: ``R(0)``, body -> space; None puts L along +z (the smallest rotation
                that does), the frame of Poinsot's construction.

        Returns:
            The body with ``ω0`` from :func:`~poinsot.physics.core.initial_state.omega_from_energy`
            (on the plane ``ω2 = 0`` of the sorted axes). When ``D`` equals the intermediate
            moment exactly, the motion is the separatrix itself (no float ω0 lies on it:
            ``ω0`` is its rounding), with ``D == I2``.

        Raises:
            ValueError: bad moments, D outside ``[min I, max I]``, a norm that is not positive
                and finite (or both norms given), a ``pole_sign`` other than ±1, or an
                ``attitude0`` that is not one Rotation (also as
                :class:`~poinsot.physics.core.validation.InputTypeError` for an argument that is no
                real number).
        """
        checked = check_inertia(inertia)
        check_moment_span(checked)
        d = check_energy_parameter(D, checked)
        sign = check_sign(pole_sign, "pole_sign")
        if omega_norm is not None and momentum_norm is not None:
            raise ValueError("give |omega0| (omega_norm) or |L| (momentum_norm), not both")
        if momentum_norm is None:
            size = check_positive(1.0 if omega_norm is None else omega_norm, "|omega0|")
            omega0 = omega_checked(checked, d, sign, omega_norm=size)
        else:
            size = check_positive(momentum_norm, "|L|")
            omega0 = omega_checked(checked, d, sign, momentum_norm=size)
        if attitude0 is None:
            rotation = attitude_checked(checked, omega0)
        else:
            rotation = check_attitude(attitude0)
        moments = sorted(checked.tolist())
        on_separatrix = moments[0] < d < moments[2] and d == moments[1]
        body = cls.__new__(cls)
        body._build(checked, omega0, rotation, on_separatrix)
        return body

    # -- construction ---------------------------------------------------------------------

    def _build(
        self, inertia: Array, omega0: Array, attitude0: Rotation, on_separatrix: bool = False
    ) -> None:
        """Scale, classify, anchor; inputs checked. ``on_separatrix``: see :meth:`from_energy`."""
        self.inertia, self.omega0, self.attitude0 = inertia, omega0, attitude0
        check_moment_span(inertia)
        moments, w_user = inertia.tolist(), omega0.tolist()
        # Exact power-of-two scaling: moments and ω near 1 whatever the caller's units.
        self._I_exp = math.frexp(max(moments))[1] - 1
        self._I_ref = math.ldexp(1.0, self._I_exp)
        w_max = max(map(abs, w_user))
        self._w_exp = math.frexp(w_max)[1] - 1 if w_max > 0.0 else 0
        self._w_ref = math.ldexp(1.0, self._w_exp)
        inertia_s = tuple(x / self._I_ref for x in moments)
        omega_s = tuple(x / self._w_ref for x in w_user)  # 1e308 below the largest is lost
        sort = sorting_map(moments)
        state = SortedState(
            sort=sort,
            J=sort.to_internal_tuple(inertia_s, signed=False),
            w=sort.to_internal_tuple(omega_s),
            w_exact=sort.to_internal_tuple(w_user),  # unscaled: exact zeros, signs, integers
            inertia=inertia_s,
            omega=omega_s,
            omega_user=omega0,
            w_exp=self._w_exp,
        )
        J1, J2, J3 = state.J  # ascending
        on_separatrix = (
            on_separatrix and J1 < J2 < J3 and state.w_exact[0] != 0.0 and state.w_exact[2] != 0.0
        )
        motion = classify(state, on_separatrix)
        self.regime, self._form = motion.regime, motion.form
        self.parameter = motion.form.parameter
        self.complementary_parameter = motion.form.complementary_parameter
        # The identity (attitude0 None), the usual start, needs no scipy call.
        identity = attitude0 is IDENTITY_ATTITUDE
        q_user = _IDENTITY_QUAT if identity else attitude0.as_quat().tolist()
        self._eval = Evaluator(motion.form, motion.frame, self._w_exp, omega_s, q_user)
        self._set_invariants(state, identity)

    def _set_invariants(self, s: SortedState, identity: bool) -> None:
        """D, the invariable plane, 2T and L in the scaled units, read back by exact powers of
        two: they over/underflow only where the physical value itself is out of double range,
        and an overflowing one raises a ValueError when it is read
        (:func:`~poinsot.physics.core.units.in_units`)."""
        (J1, J2, J3), (w1, w2, w3) = s.J, s.w
        m = (J1 * w1, J2 * w2, J3 * w3)
        G = math.hypot(*m)  # m·m would underflow for a moment ~1e-300
        # The dot products as numpy takes them (its summation order, kept bit for bit).
        two_T = float(np.array(s.w) @ np.array(m))
        m_user = np.array([i * x for i, x in zip(s.inertia, s.omega, strict=True)])
        self._L_scaled = m_user if identity else self.attitude0.apply(m_user)
        L = self._L_scaled.tolist()
        self._two_T_scaled = float(np.array(s.omega) @ m_user)
        self._inertia_scaled = s.inertia
        if self.regime is Regime.REST:
            self.D = 0.0
            self._plane_distance_scaled = 0.0
            self.plane_normal = np.array([0.0, 0.0, 1.0])
            return
        # D = G²/2T lies in [min I, max I]; on the separatrix it is I2 exactly (Δ2 = 0).
        if self.regime is Regime.SEPARATRIX:
            scaled_D = J2
        else:
            # In [min J, max J] exactly, not just to rounding: one ulp above the largest
            # moment 1.8e308 would read back as inf.
            ratio = G * (G / two_T) if two_T > 0 else 0.0
            scaled_D = min(max(ratio, J1), J3)  # J sorted ascending
        self.D = scaled_D * self._I_ref
        self._plane_distance_scaled = two_T / G  # 2T/G <= |ω|: may pass 1.8e308 with |ω|
        G_space = math.hypot(*L)  # no underflow of G² for moments ~1e-300
        self.plane_normal = np.array([x / G_space for x in L])

    @overload
    def omega(self, t: float) -> Vector: ...
    @overload
    def omega(self, t: ArrayLike) -> Stack: ...
    def omega(self, t: ArrayLike) -> Vector | Stack:
        """Body-frame angular velocity ω(t) in the caller's axes [rad per time unit].

        Args:
            t: time, a float or a (N,) array [time units].

        Returns:
            (3,) for a scalar ``t``, (N, 3) for an array.
        """
        tau = self._eval.times(t)
        if isinstance(tau, float):
            return np.array(self._eval.scalar(tau, False)[0])
        return self._eval.omega(tau)

    def attitude(self, t: ArrayLike) -> Rotation:
        """Attitude R(t), body -> space, as a scipy Rotation: a single one for a float ``t``,
        a stack of N for a (N,) array. ``attitude(0)`` equals ``attitude0`` to rounding."""
        return Rotation.from_quat(self._eval.evaluate(t)[1])

    @overload
    def state(self, t: float) -> tuple[Vector, Rotation]: ...
    @overload
    def state(self, t: ArrayLike) -> tuple[Stack, Rotation]: ...
    def state(self, t: ArrayLike) -> tuple[Vector | Stack, Rotation]:
        """ω(t) and R(t) from one evaluation: ((3,) or (N, 3), Rotation); see :meth:`sample`."""
        w, q = self._eval.evaluate(t)
        return w, Rotation.from_quat(q)

    @overload
    def contact_point(self, t: float) -> Vector: ...
    @overload
    def contact_point(self, t: ArrayLike) -> Stack: ...
    def contact_point(self, t: ArrayLike) -> Vector | Stack:
        """The tip of ω in space, ``R(t) ω(t)`` (the herpolhode): (3,) or (N, 3)
        [rad per time unit].

        It lies on the invariable plane ``x·L = 2T``, where the energy ellipsoid touches it
        [FM06 Eq. 7.55].
        """
        return self.sample(t)[2]

    herpolhode = contact_point

    @overload
    def sample(self, t: float) -> tuple[Vector, Rotation, Vector]: ...
    @overload
    def sample(self, t: ArrayLike) -> tuple[Stack, Rotation, Stack]: ...
    def sample(self, t: ArrayLike) -> tuple[Vector | Stack, Rotation, Vector | Stack]:
        """ω(t), R(t) and the contact point ``R(t) ω(t)`` from one evaluation.

        Args:
            t: a float or a (N,) array of times [time units].

        Returns:
            ``(omega, attitude, contact)``: (3,) or (N, 3) body-frame ω; a Rotation (single or
            stack); (3,) or (N, 3) space-frame contact point. This is what a renderer needs per
            frame, at the cost of one :meth:`attitude` call.
        """
        w, q = self._eval.evaluate(t)
        # Rotated in the scaled units (an exact power of two): the products inside the
        # rotation would overflow for ω ~ 1e308 and lose digits for a subnormal ω.
        w_ref = self._eval.w_ref
        if q.ndim == 1:
            contact = np.array(rotate_vector(q.tolist(), (w / w_ref).tolist())) * w_ref
            return w, Rotation.from_quat(q), contact
        return w, Rotation.from_quat(q), rotate(q, w / w_ref) * w_ref

    def polhode(self, n: int = 256) -> Stack:
        """The polhode: the closed curve ω traces in the body frame (caller's axes), (n, 3)
        [rad per time unit].

        Points are spaced uniformly in the amplitude (not in time, which would crowd them near
        the separatrix); the curve closes from the last point back to the first. On the
        separatrix it is the arc between the two intermediate-axis poles, endpoints included;
        for a constant ω it is that one point repeated.
        """
        points = check_count(n, "n, the number of polhode points,", 2, MAX_POINTS)
        return self._eval.polhode(points)

    # -- properties in the caller's units ---------------------------------------------------
    # Each may exceed the double range for extreme units (ω0 ~ 1e200 with moments ~1e100 has an
    # energy ~1e500): it is computed when read, from its exact scaled value, and raises a
    # ValueError saying so rather than returning inf.

    @property
    def plane_distance(self) -> float:
        """``2T/G`` [rad per time unit], the distance of the invariable plane ``x·L = 2T`` from
        the fixed point [FM06 Eq. 7.55]."""
        return in_units(
            self._plane_distance_scaled, self._w_exp, "the distance 2T/|L| of the plane", SLOWER
        )

    @property
    def energy(self) -> float:
        """Kinetic energy ``T = ω·I·ω / 2`` (constant) [moment units × (rad/time)²]."""
        exp2 = self._I_exp + 2 * self._w_exp
        return in_units(0.5 * self._two_T_scaled, exp2, "the kinetic energy")

    @property
    def angular_momentum(self) -> Vector:
        """(3,) angular momentum ``L = R(0) I ω0`` in the space frame (constant)."""
        exp2 = self._I_exp + self._w_exp
        return vector_in_units(self._L_scaled, exp2, "the angular momentum L")

    @property
    def semi_axes(self) -> Vector:
        """(3,) semi-axes ``sqrt(2T/Ii)`` of the energy ellipsoid ``x·I·x = 2T`` (caller order)
        [rad per time unit]."""
        # From the scaled state (2T/I_i = w_ref² · 2T_s/I_s,i): no underflow at ω ~ 1e-200.
        return vector_in_units(
            np.sqrt(self._two_T_scaled / np.array(self._inertia_scaled)),
            self._w_exp,
            "the largest semi-axis of the energy ellipsoid",
        )

    @property
    def frequency(self) -> float:
        """λ, the rate of the elliptic argument ``u = u0 + λ t`` [1/time] (0 if uniform)."""
        return in_units(self._form.lam, self._w_exp, "the frequency λ", SLOWER)

    @property
    def mean_precession_rate(self) -> float:
        """Mean rate of the precession angle φ about L [rad per time unit]."""
        return in_units(self._form.nu, self._w_exp, "the mean precession rate", SLOWER)

    @property
    def period(self) -> float:
        """Period of ω(t) [time units] (``inf`` for a motion that never repeats, e.g. the
        separatrix) [LL76 §37, Eq. 37.12]."""
        num, rate = self._form.period_pair
        if rate == 0.0:
            return math.inf
        return time_in_units(
            num / rate, -self._w_exp, "the period of ω", math.log10(num) - math.log10(rate)
        )

    @property
    def precession_per_period(self) -> float:
        """Angle [rad] the body precesses about L during one period of ω (0 if aperiodic)."""
        num, rate = self._form.period_pair
        if rate == 0.0:
            return 0.0
        nu = self._form.nu
        return in_units(
            nu * (num / rate),  # dimensionless: no scale
            0,
            "the precession angle per period",
            "ω0 lies so close to a uniform rotation that it takes that long to come back",
            lambda: math.log10(abs(nu) or 1.0) + math.log10(num) - math.log10(rate),
            " rad",
        )

    @property
    def second_period(self) -> float:
        """``2π / mean_precession_rate`` [time units], Landau's second period T'
        [LL76 §37] (``inf`` if no precession)."""
        nu = self._form.nu
        if self._form.period_pair[1] == 0.0 or nu == 0.0:
            return math.inf
        return time_in_units(
            2.0 * math.pi / nu,
            -self._w_exp,
            "the precession period",
            math.log10(2.0 * math.pi) - math.log10(abs(nu)),
        )

    def __repr__(self) -> str:
        return (
            f"FreeRigidBody(inertia={self.inertia.tolist()}, omega0={self.omega0.tolist()}, "
            f"regime={self.regime.value!r})"
        )
