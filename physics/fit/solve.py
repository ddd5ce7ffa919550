"""Fit the exact torque-free solution to a recorded ω(t): :func:`fit_angular_velocity`."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from poinsot.physics.core.free_body import FreeRigidBody
from poinsot.physics.core.validation import check_flag
from poinsot.physics.fit import model
from poinsot.physics.fit.model import Layout
from poinsot.physics.fit.result import (
    AngularVelocityFit,
    covariance,
    flip_period,
    propagate,
    quality_message,
    sensor_reading,
)
from poinsot.physics.fit.samples import (
    MIN_SAMPLES,
    SIGN_THRESHOLD,
    Smoothed,
    check_samples,
    half_width_for,
    sign_change_counts,
    sign_changes,
    smooth,
)
from poinsot.physics.fit.start import Start, euler_estimate, family_starts

#: ω must vary by at least this fraction of |ω| during the segment: a steady spin about one
#: principal axis reveals nothing of the moments.
MIN_VARIATION = 0.01
# The model's sign changes are counted at these multiples of the data's threshold: a component
# that just grazes the threshold may or may not count in noisy data.
_GRAZE = (0.7, 1.3)
# Growing windows: the first covers this many radians of rotation; each start runs
# _SCREEN_NFEV iterations on each window; after each window the starts whose cost exceeds
# _PROMISING times the best's are dropped; the best _POLISHED of the rest are polished (up to
# _POLISH_NFEV iterations each).
_FIRST_WINDOW = 3.0
_SCREEN_NFEV = 5
_PROMISING = 4.0
_POLISHED = 3
_POLISH_NFEV = 100
# A candidate whose sign changes agree with the data's beats a smaller residual that does not
# agree only if its cost is within this factor.
_COMPARABLE = 1.5
# Forward-difference step of the Jacobian, relative (the closed form is exact to rounding).
_STEP = 1.5e-8


class _Problem:
    """The data of one fit, and the model's residuals and Jacobian on them.

    Only the five parameters of the body (moments, ω0) need new closed-form solutions to be
    differentiated; the rotation and the bias act on the body's ω afterwards, so their Jacobian
    columns reuse the last ω computed (cached by parameter vector).
    """

    def __init__(
        self,
        t: NDArray[np.float64],
        omega: NDArray[np.float64],
        smoothed: Smoothed,
        layout: Layout,
        threshold: float,
        counts: NDArray[np.int_],
    ):
        self.t, self.omega, self.smoothed, self.layout = t, omega, smoothed, layout
        self.threshold = threshold  # of the sign changes [rad/s]
        self.counts = counts  # (3,) sign changes of the smoothed data
        self.tau = t - t[0]
        self._penalty = 10.0 * float(np.max(np.abs(omega)))
        self._cache: tuple[bytes, NDArray[np.float64] | None] = (b"", None)

    def window(self, n: int) -> _Problem:
        """The same problem on the first ``n`` samples only."""
        return _Problem(
            self.t[:n], self.omega[:n], self.smoothed, self.layout, self.threshold, self.counts
        )

    def _evaluate(self, core: NDArray[np.float64]) -> NDArray[np.float64] | None:
        """(N, 3) ω of the body with parameters ``core`` (5,), or None if refused."""
        try:
            return model.body_omega(core, self.tau)
        except ValueError:  # parameters the closed form refuses
            return None

    def _body_omega(self, core: NDArray[np.float64]) -> NDArray[np.float64] | None:
        """:meth:`_evaluate`, remembered for the last parameters (least_squares asks for the
        residuals, then the Jacobian, at the same point)."""
        key = core.tobytes()
        if key != self._cache[0]:
            self._cache = (key, self._evaluate(core))
        return self._cache[1]

    def _sensor(self, x: NDArray[np.float64], w: NDArray[np.float64]) -> NDArray[np.float64]:
        matrix = model.rotation_matrix(x, self.layout)
        return w if matrix is None else w @ matrix  # row form of Rᵀ ω

    def residuals(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        w = self._body_omega(x[:5])
        if w is None:  # a large, finite penalty
            return np.full(self.omega.size, self._penalty)
        pred = self._sensor(x, w)
        if self.layout.bias:
            pred = pred + x[self.layout.bias_slice]
        return (pred - self.omega).ravel()

    def moment_jacobian(self, x: NDArray[np.float64], axes: list[int]) -> NDArray[np.float64]:
        """(3N, p): the Jacobian with respect to the moments of ``axes`` (two of them, the
        largest staying 1) in place of the angles ``x[0:2]``: the uncertainties are reported
        for the moments, and a flat body's moments stay measurable at the edge of the angles'
        range, where d(moments)/d(angles) vanishes."""
        jac = self.jacobian(x)
        inertia, omega0 = model.moments(x), x[2:5]
        w = self._body_omega(x[:5])
        for col, k in enumerate(axes):
            h = _STEP * max(1.0, float(inertia[k]))
            shifted = inertia.copy()
            shifted[k] += h
            try:
                wk = model.free_omega(shifted, omega0, self.tau)
            except ValueError:
                wk = None
            if w is None or wk is None:
                jac[:, col] = 0.0
            else:
                jac[:, col] = (self._sensor(x, wk - w) / h).ravel()
        return jac

    def jacobian(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """(3N, p): forward differences for the body's parameters, the rest from the cached ω."""
        w = self._body_omega(x[:5])
        if w is None:
            return np.zeros((self.omega.size, x.size))
        cols = []
        for i in range(x.size):
            h = _STEP * max(1.0, abs(float(x[i])))
            e = np.zeros_like(x)
            e[i] = h
            if i < 5:
                wi = self._evaluate(x[:5] + e[:5])
                d = np.zeros_like(w) if wi is None else self._sensor(x, wi - w) / h
            elif self.layout.rotation and i < 8:
                d = (self._sensor(x + e, w) - self._sensor(x, w)) / h
            else:  # the bias
                d = np.zeros_like(w)
                d[:, i - x.size + 3] = 1.0
            cols.append(d.ravel())
        return np.stack(cols, axis=1)

    def consistent(self, x: NDArray[np.float64]) -> bool:
        """Do the model's components change sign as the data's do (within the grazing range)?"""
        w = self.residuals(x).reshape(-1, 3) + self.omega
        a, b = (sign_change_counts(self.t, w, g * self.threshold) for g in _GRAZE)
        return bool(np.all((np.minimum(a, b) <= self.counts) & (self.counts <= np.maximum(a, b))))


@dataclass(frozen=True)
class _Candidate:
    x: NDArray[np.float64]
    cost: float
    consistent: bool


def fit_angular_velocity(
    t: ArrayLike, omega: ArrayLike, *, fit_rotation: bool = False, fit_bias: bool = False
) -> AngularVelocityFit:
    """Fit the exact free-body solution [LL76 §37] to a recorded angular velocity.

    Args:
        t: (N,) strictly increasing sample times [s], N >= 20 (one flight: no hand, no table).
        omega: (N, 3) angular velocity [rad/s] in the sensor's axes.
        fit_rotation: also fit a (small) rotation between the sensor's and the principal axes.
        fit_bias: also fit a constant gyroscope bias.

    Returns:
        An :class:`AngularVelocityFit`. A motion no torque-free body explains (a torque acted)
        is still returned, with ``explained=False`` and a ``message`` giving the residual
        relative to |ω|.

    Raises:
        ValueError: wrong shapes, too few samples, NaN or infinite values, times that do not
            increase, a body that hardly turns, or a ω that stays constant (a steady spin about
            a principal axis, which does not reveal the moments); also (as
            :class:`~poinsot.physics.core.validation.InputTypeError`) values that are not real
            numbers, or flags that are not True or False.

    Method: Euler's equations, linear in the moments once ω and dω/dt are smoothed out of the
    data, give a first estimate (:mod:`poinsot.physics.fit.start`); nonlinear least squares
    (``scipy.optimize.least_squares``) of the exact solution then start from it and from every
    other assignment of the moments to the axes in both families. The candidates whose
    components change sign where the data's do are preferred, the smallest residual wins.
    """
    fit_rotation = check_flag(fit_rotation, "fit_rotation")
    fit_bias = check_flag(fit_bias, "fit_bias")
    problem = _problem(t, omega, fit_rotation, fit_bias)
    inertia0, matrix0 = euler_estimate(
        problem.smoothed.value, problem.smoothed.derivative, fit_rotation
    )
    rotvec0 = Rotation.from_matrix(matrix0).as_rotvec() if fit_rotation else None
    omega0 = matrix0 @ problem.smoothed.value[0]
    # The data's sign changes in the estimated principal axes (the sensor's without a rotation).
    counts = sign_change_counts(problem.t, problem.smoothed.value @ matrix0.T, problem.threshold)
    starts = _plausible(family_starts(inertia0, omega0), counts)
    x0s = [problem.layout.pack(s.inertia, omega0, rotvec0) for s in starts]
    best = _search(problem, x0s)
    return _result(problem, best)


def _problem(t, omega, fit_rotation: bool, fit_bias: bool) -> _Problem:
    t_arr, w_arr = check_samples(t, omega)
    smoothed = smooth(t_arr, w_arr, half_width_for(t_arr, w_arr))
    speed = np.linalg.norm(smoothed.value, axis=1)
    variation = float(np.max(np.ptp(smoothed.value, axis=0)))
    if variation < max(MIN_VARIATION * float(np.mean(speed)), 5.0 * smoothed.noise):
        raise ValueError(
            f"ω stays constant during this segment (it varies by {variation:.2g} rad/s at "
            f"|ω| ≈ {np.mean(speed):.3g} rad/s): a steady spin about one principal axis does "
            "not reveal the moments of inertia; throw the body with a visible wobble"
        )
    threshold = SIGN_THRESHOLD * float(np.max(speed))
    counts = sign_change_counts(t_arr, smoothed.value, threshold)
    return _Problem(t_arr, w_arr, smoothed, Layout(fit_rotation, fit_bias), threshold, counts)


def _plausible(starts: list[Start], counts: NDArray[np.int_]) -> list[Start]:
    """The starts whose family lets the data's sign changes (``counts`` (3,), principal axes)
    happen.

    In each family one component never changes sign (``dn``, [LL76 §37, Eq. 37.10]): a start
    that gives that role to a component the data see changing sign cannot be right. Of the 12
    starts this keeps 4 once the data show two components changing sign (both families, either
    of the two as the intermediate axis); all of them if the data show none.
    """
    kept = [s for s in starts if counts[s.steady] == 0]
    return kept or starts


def _search(problem: _Problem, x0s: list[NDArray[np.float64]]) -> _Candidate:
    """Fit from every start on growing windows of the data, keep the promising, choose.

    Near the separatrix a small error in the parameters shifts the flips by a time that grows
    like ``exp(σ t)``, ``σ <= |ω|`` [LL76 §37; FM06 Theorem 7.3]: fitting the first
    ``3/|ω|`` seconds first, then windows twice as long, brings each start close enough at
    every step for the longer record to be fitted without crawling along a narrow valley. The
    rotation and the bias are held at their starts on the shorter windows (on a short stretch
    they trade off against the moments and ω0) and fitted on the whole record. After each
    window the candidates whose cost exceeds :data:`_PROMISING` times the best's are dropped;
    the rest are polished on the whole record. The smallest residual wins, unless its
    components change sign where the data's do not (or the reverse) and a candidate that
    agrees with the data has a comparable residual.
    """
    xs = x0s
    for count in _window_counts(problem):
        window = problem.window(count)
        core = 5 if count < problem.t.size else None
        fits = sorted((_solve(window, x, _SCREEN_NFEV, core) for x in xs), key=lambda f: f[1])
        xs = _distinct([x for x, cost in fits if cost <= _PROMISING * fits[0][1]])
    polished = []
    for x in xs[:_POLISHED]:
        x, cost = _solve(problem, x, _POLISH_NFEV)
        polished.append(_Candidate(x, cost, problem.consistent(x)))
    polished.sort(key=lambda c: c.cost)
    best = polished[0]
    if not best.consistent:
        agreeing = [c for c in polished if c.consistent and c.cost <= _COMPARABLE * best.cost]
        best = agreeing[0] if agreeing else best
    return best


def _distinct(xs: list[NDArray[np.float64]]) -> list[NDArray[np.float64]]:
    """``xs`` without the candidates that converged onto one met before (same moments, ω0)."""
    kept: list[NDArray[np.float64]] = []
    for x in xs:
        inertia = model.moments(x)
        if not any(
            np.allclose(inertia, model.moments(k), rtol=0, atol=1e-6)
            and np.allclose(x[2:5], k[2:5], rtol=1e-6, atol=1e-9)
            for k in kept
        ):
            kept.append(x)
    return kept


def _window_counts(problem: _Problem) -> list[int]:
    """Sample counts of the growing windows: durations ``3 · 2^k / max|ω|``, then all."""
    n = problem.t.size
    duration = _FIRST_WINDOW / float(np.max(np.linalg.norm(problem.smoothed.value, axis=1)))
    counts = []
    while True:
        count = int(np.searchsorted(problem.tau, duration)) + 1
        if count >= n:
            break
        counts.append(max(count, min(MIN_SAMPLES, n)))
        duration *= 2.0
    return counts + [n]


def _solve(
    problem: _Problem, x0: NDArray[np.float64], max_nfev: int, first: int | None = None
) -> tuple[NDArray[np.float64], float]:
    """Levenberg–Marquardt from ``x0``: the parameters reached and their cost ``½ Σ r²``.

    With ``first``, only ``x[:first]`` moves; the other parameters keep their values.
    """
    if first is not None and first < x0.size:
        rest = x0[first:]
        z, cost = _solve_all(
            lambda z: problem.residuals(np.concatenate([z, rest])),
            lambda z: problem.jacobian(np.concatenate([z, rest]))[:, :first],
            x0[:first],
            max_nfev,
        )
        return np.concatenate([z, rest]), cost
    return _solve_all(problem.residuals, problem.jacobian, x0, max_nfev)


def _solve_all(fun, jac, x0: NDArray[np.float64], max_nfev: int) -> tuple[NDArray, float]:
    result = least_squares(
        fun,
        x0,
        jac=jac,
        method="lm",
        x_scale="jac",
        max_nfev=max_nfev,
        ftol=1e-12,
        xtol=1e-12,
        gtol=1e-12,
    )
    return result.x, float(result.cost)


@dataclass(frozen=True)
class _Uncertainty:
    """The covariance of ``y = (the two smaller moments, ω0, rotation, bias)`` at the fit.

    Reported for the moments themselves rather than the angles the search moves: at the edge
    of the triangle inequality d(moments)/d(angles) vanishes and a covariance of the angles
    would make a flat body's moments look exact.
    """

    inertia: NDArray[np.float64]  # (3,) the fitted moments, largest 1
    free: list[int]  # the axes of the two smaller moments
    y: NDArray[np.float64]
    cov: NDArray[np.float64]

    def moments(self, y: NDArray[np.float64]) -> NDArray[np.float64]:
        out = self.inertia.copy()
        out[self.free] = y[:2]
        return out

    def sigma_of(self, f: Callable[[NDArray[np.float64], NDArray[np.float64]], float]) -> float:
        """1-σ of ``f(moments (3,), ω0 (3,))`` by propagation (through ``y[:5]`` only: the
        rotation and the bias do not enter)."""
        body = self.y[:5]
        return float(propagate(lambda y: f(self.moments(y), y[2:5]), body, self.cov[:5, :5])[0])


def _uncertainty(problem: _Problem, x: NDArray[np.float64]) -> _Uncertainty:
    inertia = model.moments(x)
    free = [k for k in range(3) if k != int(np.argmax(inertia))]
    cov = covariance(problem.moment_jacobian(x, free), problem.residuals(x))
    return _Uncertainty(inertia, free, np.concatenate([inertia[free], x[2:]]), cov)


def _result(problem: _Problem, best: _Candidate) -> AngularVelocityFit:
    """The result at the chosen parameters, its axes labelled after the sensor's."""
    layout = problem.layout
    x = model.relabelled(best.x, layout)
    unc = _uncertainty(problem, x)
    sigma = np.sqrt(np.maximum(np.diag(unc.cov), 0.0))
    inertia_sigma = np.zeros(3)
    inertia_sigma[unc.free] = sigma[:2]
    fitted = model.body(x)
    matrix = model.rotation_matrix(x, layout)
    bias = x[layout.bias_slice].copy() if layout.bias else None
    residual = sensor_reading(fitted, matrix, bias, problem.tau) - problem.omega
    rms = float(np.sqrt(np.mean(residual**2)))
    scale = float(np.sqrt(np.mean(np.sum(problem.omega**2, axis=1))))
    explained, message = quality_message(rms, scale, problem.smoothed.noise, best.consistent)
    intermediate = int(np.argsort(unc.inertia)[1])
    return AngularVelocityFit(
        inertia=unc.inertia,
        inertia_sigma=inertia_sigma,
        omega0=x[2:5].copy(),
        omega0_sigma=sigma[2:5],
        rotation=None if matrix is None else Rotation.from_matrix(matrix),
        rotation_sigma=sigma[layout.rotation_slice] if layout.rotation else None,
        bias=bias,
        bias_sigma=sigma[layout.bias_slice] if layout.bias else None,
        body=fitted,
        t0=float(problem.t[0]),
        rms=rms,
        relative_rms=rms / scale,
        noise=problem.smoothed.noise,
        regime=fitted.regime,
        intermediate_axis=intermediate,
        period=float(fitted.period),
        flip_period=flip_period(fitted),
        flip_period_sigma=unc.sigma_of(lambda i, w: flip_period(FreeRigidBody(i, w))),
        measured_flip_period=_measured_flip(problem, x, intermediate),
        separatrix_distance=model.separatrix_distance(unc.inertia, x[2:5]),
        separatrix_sigma=unc.sigma_of(model.separatrix_distance),
        family_confirmed=best.consistent,
        explained=explained,
        message=message,
        n_samples=int(problem.t.size),
    )


def _measured_flip(problem: _Problem, x: NDArray[np.float64], axis: int) -> float | None:
    """Mean spacing [s] of the sign changes of the data's intermediate component (principal
    axes, bias removed), or ``None`` if it changes sign fewer than twice."""
    w = problem.smoothed.value
    if problem.layout.bias:
        w = w - x[problem.layout.bias_slice]
    matrix = model.rotation_matrix(x, problem.layout)
    if matrix is not None:
        w = w @ matrix.T
    times = sign_changes(problem.t, w[:, axis], problem.threshold)
    if times.size < 2:
        return None
    return float((times[-1] - times[0]) / (times.size - 1))
