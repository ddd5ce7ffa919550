"""What a fit returns: :class:`AngularVelocityFit`, with uncertainties and the flip periods."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from poinsot.physics.core.free_body import FreeRigidBody
from poinsot.physics.core.regime import Regime

#: A fit is "explained" when its rms residual is within 3 noise levels, or at most this
#: fraction of the rms of |ω|: a free flight recorded by a phone fits to a few tenths of a
#: percent, while a torque that changes |L| by a few percent over the segment does not fit.
EXPLAINED_FRACTION = 0.02
#: The family is named only when the fitted motion lies at least this many sigmas from the
#: separatrix; closer, the data cannot tell the two families apart and ``family`` says so.
FAMILY_SIGMAS = 3.0


@dataclass(frozen=True)
class AngularVelocityFit:
    """The exact free motion that best matches a recorded ω(t), with its uncertainties.

    Axes: the moments and ω0 are given in the principal axes, ordered as the sensor's axes
    (without a fitted rotation they *are* the sensor's axes; with one, principal axis k is the
    one nearest sensor axis k). Sigmas are 1-σ, from the fit's Jacobian ``J``: covariance
    ``s² (JᵀJ)⁻¹``, ``s²`` the residual variance. They are linearised: where one is large (more
    than ~10 % of its moment, as for a spin close to one axis with a small wobble) the error is
    not Gaussian and can exceed it. No field is ever NaN.

    Attributes:
        inertia: (3,) principal moments up to scale, the largest normalised to 1.
        inertia_sigma: (3,) their 1-σ uncertainties (0 for the largest, the unit).
        omega0: (3,) ω at the first sample [rad/s], principal axes.
        omega0_sigma: (3,) [rad/s].
        rotation: sensor -> principal axes, or ``None`` if not fitted.
        rotation_sigma: (3,) 1-σ of the rotation vector's components [rad], or ``None``.
        bias: (3,) constant gyroscope bias [rad/s] in the sensor's axes, or ``None``.
        bias_sigma: (3,) [rad/s], or ``None``.
        body: the fitted :class:`FreeRigidBody` (principal axes), time origin at ``t0``.
        t0: the first sample's time [s].
        rms: root-mean-square residual per component [rad/s].
        relative_rms: ``rms`` over the rms of |ω| of the data.
        noise: the data's noise per component, estimated without the model [rad/s].
        regime: the fitted motion's :class:`Regime`: the family.
        intermediate_axis: index (0, 1, 2) of the intermediate moment's axis.
        period: period of ω [s] (``inf`` if it never repeats).
        flip_period: predicted time between successive sign changes of the intermediate
            component, ``2 K(k) / λ``, half the period of ω [ACC91; LL76 §37] [s]; ``inf`` for
            a motion with no repeated flip (separatrix, symmetric body, permanent rotation).
        flip_period_sigma: its 1-σ [s] (``inf`` when it cannot be propagated).
        measured_flip_period: the same, measured from the data's sign changes of the
            intermediate component (mean spacing) [s]; ``None`` if fewer than two show.
        separatrix_distance: ``(D - I2) / (I3 - I1)``, ``D = |L|²/2T`` [Pars65 §13.12]: > 0 in
            the major-axis family, < 0 in the minor-axis family.
        separatrix_sigma: its 1-σ; ``|distance| / sigma`` says how surely the data set the
            family (``inf`` when it cannot be propagated).
        family_confirmed: the fitted motion changes sign in the same components as the data.
        explained: the residual is small enough for a torque-free motion (see ``message``).
        message: a sentence on the fit's quality, for the student.
        n_samples: N.
    """

    inertia: NDArray[np.float64]
    inertia_sigma: NDArray[np.float64]
    omega0: NDArray[np.float64]
    omega0_sigma: NDArray[np.float64]
    rotation: Rotation | None
    rotation_sigma: NDArray[np.float64] | None
    bias: NDArray[np.float64] | None
    bias_sigma: NDArray[np.float64] | None
    body: FreeRigidBody
    t0: float
    rms: float
    relative_rms: float
    noise: float
    regime: Regime
    intermediate_axis: int
    period: float
    flip_period: float
    flip_period_sigma: float
    measured_flip_period: float | None
    separatrix_distance: float
    separatrix_sigma: float
    family_confirmed: bool
    explained: bool
    message: str
    n_samples: int

    @property
    def family(self) -> str:
        """``"major-axis family"`` or ``"minor-axis family"`` when the data set it (the fitted
        motion lies at least :data:`FAMILY_SIGMAS` sigmas from the separatrix), else
        ``"separatrix"`` (within the uncertainty); the label of :attr:`regime` for the other
        regimes (``"symmetric"``, ...)."""
        if self.regime not in (Regime.MAJOR_AXIS, Regime.MINOR_AXIS):
            return self.regime.label
        if abs(self.separatrix_distance) < FAMILY_SIGMAS * self.separatrix_sigma:
            return Regime.SEPARATRIX.label
        return self.regime.label

    def predict(self, t: ArrayLike) -> NDArray[np.float64]:
        """(N, 3) the fitted sensor reading [rad/s], rotation and bias included, at times
        ``t`` (N,) [s]."""
        return sensor_reading(
            self.body,
            None if self.rotation is None else self.rotation.as_matrix(),
            self.bias,
            np.asarray(t, dtype=float) - self.t0,
        )


def sensor_reading(
    body: FreeRigidBody,
    matrix: NDArray[np.float64] | None,
    bias: NDArray[np.float64] | None,
    tau: NDArray[np.float64],
) -> NDArray[np.float64]:
    """(N, 3) ``Rᵀ ω(τ) + bias`` for times ``tau`` (N,) [s] after the body's origin; ``matrix``
    is R (sensor -> principal, 3×3) or ``None`` (identity), ``bias`` (3,) or ``None``."""
    w = body.omega(tau)
    if matrix is not None:
        w = w @ matrix  # row form of Rᵀ ω
    if bias is not None:
        w = w + bias
    return w


def covariance(jacobian: NDArray[np.float64], residual: NDArray[np.float64]) -> NDArray:
    """``s² (JᵀJ)⁻¹`` (p, p) from the Jacobian (M, p) and the residuals (M,), through the SVD:
    a direction the data leave undetermined gets no variance rather than a division by zero."""
    _, s, vt = np.linalg.svd(jacobian, full_matrices=False)
    keep = s > s[0] * 1e-12 if s.size and s[0] > 0.0 else np.zeros(s.shape, bool)
    inv = (vt[keep].T / s[keep] ** 2) @ vt[keep]
    dof = max(residual.size - jacobian.shape[1], 1)
    return inv * float(residual @ residual) / dof


def propagate(
    f: Callable[[NDArray[np.float64]], ArrayLike],
    x: NDArray[np.float64],
    cov: NDArray[np.float64],
) -> NDArray[np.float64]:
    """1-σ of each component of ``f(x)`` by linear propagation of ``cov``, with central
    differences; ``inf`` for a component that is not finite near ``x`` (across the separatrix
    a period jumps to infinity)."""
    cols = []
    for i in range(x.size):
        h = 1e-6 * max(1.0, abs(float(x[i])))
        e = np.zeros_like(x)
        e[i] = h
        with np.errstate(invalid="ignore"):  # inf - inf: not finite, handled below
            cols.append((np.atleast_1d(f(x + e)) - np.atleast_1d(f(x - e))) / (2.0 * h))
    grad = np.stack(cols, axis=1)
    finite = np.isfinite(grad).all(axis=1)
    safe = np.where(finite[:, None], grad, 0.0)
    var = np.maximum(np.einsum("ij,jk,ik->i", safe, cov, safe), 0.0)
    return np.where(finite, np.sqrt(var), math.inf)


def flip_period(body: FreeRigidBody) -> float:
    """Half the period of ω [s]: the time between flips; ``inf`` if the intermediate component
    does not flip again and again (separatrix, symmetric body, permanent rotation)."""
    if body.regime not in (Regime.MAJOR_AXIS, Regime.MINOR_AXIS):
        return math.inf
    return 0.5 * body.period


def quality_message(rms: float, scale: float, noise: float, confirmed: bool) -> tuple[bool, str]:
    """``(explained, message)`` for a fit of rms residual ``rms`` to data of rms |ω| ``scale``
    with sensor noise ``noise`` [rad/s]; ``confirmed``: the family agrees with the data."""
    percent = 100.0 * rms / scale
    noise = max(noise, 1e-15 * scale)  # noise-free synthetic data
    explained = rms <= max(EXPLAINED_FRACTION * scale, 3.0 * noise)
    if explained:
        text = (
            f"a torque-free motion fits: rms residual {rms:.3g} rad/s, {percent:.2g}% of |ω|, "
            f"{rms / noise:.2g}× the sensor noise (≈ {noise:.2g} rad/s)"
        )
    else:
        text = (
            "no torque-free motion explains this segment: the best fit leaves an rms residual "
            f"of {rms:.3g} rad/s, {percent:.2g}% of |ω| and {rms / noise:.2g}× the sensor noise "
            f"(≈ {noise:.2g} rad/s), where a free flight fits to the noise: a torque acted (the "
            "hand at the throw or the catch, air, a string), or the segment is not one flight"
        )
    if not confirmed:
        text += (
            "; the fitted motion does not change sign in the same components as the data, "
            "so its family is uncertain"
        )
    return explained, text
