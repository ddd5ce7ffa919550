"""Evaluating a closed form in the caller's axes, units and attitude.

:class:`Evaluator` maps the internal components of a closed form
(:mod:`~poinsot.physics.core.closed_forms`) to the caller's body axes (an
:class:`~poinsot.physics.core.relabelling.AxisMap`), the caller's time and ω units (the exact scale
``ω_ref = 2^w_exp``) and the caller's space frame (``R_user(t) = S · R_int(t) · C``). Arrays of
times go through the vectorised path in cache-sized blocks; one float time goes through the
scalar twins in plain floats, with the same operations and so the same bits.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from poinsot.physics.core.closed_forms import ClosedForm, Columns, ScalarQuaternion
from poinsot.physics.core.relabelling import AxisMap
from poinsot.physics.core.rotations import conjugate, hamilton
from poinsot.physics.core.validation import check_times

__all__ = ["Evaluator"]

Array = NDArray[np.float64]

# The phases rate·τ of the closed forms are kept below this (Evaluator.times).
_PHASE_LIMIT = 1e300
# Times evaluated per block (see Evaluator.state): ~20 temporaries of 128 KiB fit in L2.
_BLOCK = 16384


class Evaluator:
    """A closed form seen from the caller.

    Args:
        form: the closed form, in its internal frames and dimensionless time ``τ = t·ω_ref``.
        frame: the relabelling caller -> the form's internal body axes.
        w_exp: ``ω_ref = 2^w_exp`` [rad per time unit], the unit of the form's ω and rates.
        omega_s: (3,) the scaled ω0 ``ω0/ω_ref`` in the caller's axes.
        q_user: ``R(0)`` (body -> space) as a scalar-last quaternion, 4 floats.

    Attributes:
        out_of_range: why ω(t) cannot be returned in the caller's units, or None.
    """

    def __init__(
        self,
        form: ClosedForm,
        frame: AxisMap,
        w_exp: int,
        omega_s: Sequence[float],
        q_user: Sequence[float],
    ) -> None:
        self.form, self.frame = form, frame
        self.w_exp = w_exp
        self.w_ref = math.ldexp(1.0, w_exp)
        self.out_of_range: str | None = None
        self._set_ranges()
        self._anchor_at_zero(omega_s, q_user)

    def _set_ranges(self) -> None:
        """The ranges of the evaluation (scaled units): the phases rate·τ must stay finite, and
        so must ω(t), whose components reach the largest amplitude of the closed form."""
        fastest = max(abs(x) for x in self.form.rates)
        self._tau_limit = _PHASE_LIMIT / fastest if fastest > 0.0 else math.inf
        amplitude = self.form.amplitude
        if not math.isfinite(amplitude * self.w_ref):
            decades = math.log10(amplitude) + self.w_exp * math.log10(2.0)
            self.out_of_range = (
                f"during this motion a component of ω reaches about 1e{decades:.0f} in your "
                "units, beyond the largest double-precision number (1.8e308): use a shorter "
                "time unit (then ω0 is a smaller number)"
            )

    def _anchor_at_zero(self, omega_s: Sequence[float], q_user: Sequence[float]) -> None:
        """Make ``omega(0)`` return ω0 and ``attitude(0)`` return ``R(0)``.

        The closed form reproduces ω0 only to O(eps · amplitude) (through u0 = F(φ0|m) and back
        through sn, cn, dn); adding the constant ω0 - f(0) makes omega(0) exact and changes no
        other value by more than that rounding. ``R_user(t) = S · R_int(t) · C`` with C the
        relabelling and S fixed so that ``R_user(0)`` is ``q_user``.
        """
        cols0, q0 = self.form.quat_scalar(0.0)
        user0 = self.frame.to_user_tuple(cols0)
        self._anchor_t = tuple(omega_s[k] - user0[k] for k in range(3))
        self._anchor = np.array(self._anchor_t)
        self._anchored = any(self._anchor_t)  # exactly 0 for the uniform forms
        fq = self.frame.quat_tuple
        self._q_space_t = hamilton(hamilton(q_user, conjugate(fq)), conjugate(q0))

    def omega(self, tau: Array) -> Array:
        """ω (N, 3) in the caller's axes and units at (N,) dimensionless times τ."""
        if tau.shape[0] > _BLOCK:  # cache-sized blocks, as in state
            out = np.empty((tau.shape[0], 3))
            for start in range(0, tau.shape[0], _BLOCK):
                out[start : start + _BLOCK] = self.omega(tau[start : start + _BLOCK])
            return out
        return self._to_user(self.form.omega(tau))

    def _to_user(self, cols: Columns) -> Array:
        """Internal ω components (each (N,)) -> (N, 3) in the caller's axes and units."""
        w = self.frame.to_user_columns(cols)
        if self._anchored:
            w += self._anchor
        w *= self.w_ref
        return w

    def state(self, tau: Array) -> tuple[Array, Array]:
        """(ω (N,3) in user axes and caller units, attitude quaternions (N, 4) scalar-last).

        Long arrays are processed in blocks of ``_BLOCK`` times: every temporary then stays in
        the CPU cache, which makes the element-wise numpy work ~2x faster than on whole arrays.
        """
        if tau.shape[0] <= _BLOCK:
            return self._quat_block(tau)
        w = np.empty((tau.shape[0], 3))
        q = np.empty((tau.shape[0], 4))
        for start in range(0, tau.shape[0], _BLOCK):
            block = slice(start, start + _BLOCK)
            w[block], q[block] = self._quat_block(tau[block])
        return w, q

    def _quat_block(self, tau: Array) -> tuple[Array, Array]:
        cols, q_int = self.form.quat(tau)
        q = np.stack(hamilton(self._q_space_t, hamilton(q_int, self.frame.quat_tuple)), axis=-1)
        return self._to_user(cols), q

    def scalar(self, tau: float, attitude: bool) -> tuple[list[float], ScalarQuaternion | None]:
        """ω (user axes, caller units) and, if asked, the attitude quaternion at one τ.

        The single-time path: the operations of :meth:`omega` and :meth:`_quat_block`
        in plain floats, a few microseconds instead of dozens of numpy calls on 1-element
        arrays. Where a phase leaves the float range (τ·rate beyond ~1e308) ``round`` raises
        instead of returning NaN; then, and for any non-finite result, the array path gives
        the value, so both paths return the same thing for every input.
        """
        try:
            w, q = self._scalar_floats(tau, attitude)
            if all(map(math.isfinite, w)) and (q is None or all(map(math.isfinite, q))):
                return w, q
        except (ArithmeticError, ValueError):
            pass
        arr = np.array([tau])
        if attitude:
            w_arr, q_arr = self.state(arr)
            x, y, z, s = q_arr[0].tolist()
            return w_arr[0].tolist(), (x, y, z, s)
        return self.omega(arr)[0].tolist(), None

    def _scalar_floats(
        self, tau: float, attitude: bool
    ) -> tuple[list[float], ScalarQuaternion | None]:
        q: ScalarQuaternion | None = None
        if attitude:
            cols, q_int = self.form.quat_scalar(tau)
            q = hamilton(self._q_space_t, hamilton(q_int, self.frame.quat_tuple))
        else:
            cols = self.form.omega_scalar(tau)
        user, anchor, w_ref = self.frame.to_user_tuple(cols), self._anchor_t, self.w_ref
        if self._anchored:
            return [(user[k] + anchor[k]) * w_ref for k in range(3)], q
        return [user[k] * w_ref for k in range(3)], q

    def polhode(self, n: int) -> Array:
        """(n, 3) points of the polhode in the caller's axes and units."""
        if self.out_of_range is not None:
            raise ValueError(self.out_of_range)
        return self.frame.to_user_columns(self.form.polhode(n)) * self.w_ref

    def evaluate(self, t: ArrayLike) -> tuple[Array, Array]:
        """ω ((3,) or (N, 3)) and unnormalised attitude quaternions ((4,) or (N, 4))."""
        tau = self.times(t)
        if isinstance(tau, float):
            w, q = self.scalar(tau, True)
            return np.array(w), np.array(q)
        return self.state(tau)

    def times(self, t: ArrayLike) -> float | Array:
        """The dimensionless times τ = t·ω_ref, checked against the range of this motion.

        Beyond ``|τ| = _tau_limit`` a phase of the closed form (rate × τ) would exceed 1e300
        rad and overflow on its way through the reduction: a ValueError then says so. (The
        results carry an error ~1e-16 × rate × t, so they mean little long before.)
        """
        tt = check_times(t)
        if self.out_of_range is not None:
            raise ValueError(self.out_of_range)
        if isinstance(tt, float):
            tau_s = tt * self.w_ref
            if abs(tau_s) <= self._tau_limit:
                return tau_s
            t_max = abs(tt)
        else:
            with np.errstate(over="ignore"):  # an overflow to inf is refused just below
                tau = tt * self.w_ref
            if tau.size == 0 or float(np.abs(tau).max()) <= self._tau_limit:
                return tau
            t_max = float(np.abs(tt).max())
        with np.errstate(over="ignore"):
            limit = self._tau_limit / self.w_ref
        raise ValueError(
            f"t = {t_max:g} is too far in time for this motion in double precision: its fastest "
            f"phase (rate × t) would exceed 1e{math.log10(_PHASE_LIMIT):.0f} rad; keep |t| "
            f"below {limit:.3g} (and note that the results drift by ~1e-16 × rate × t)"
        )
