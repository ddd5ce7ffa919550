"""Explorer 1 and the major-axis rule: internal dissipation at fixed |L| [BG58; LL76 §37].

A body that loses kinetic energy inside itself (flexing antennas, sloshing fuel) keeps its
total angular momentum ``L``, so ``G = |m|`` is fixed while ``2T`` drops. ``D = G²/2T`` then
rises from wherever it starts towards ``I3``: the spin about the minor axis ``e1`` (Explorer 1,
spun about its long axis in 1958) widens into a tumble, crosses the separatrix ``D = I2`` and
ends as a flat spin about the major axis ``e3`` [BG58].

**The stated law.** The energy drains at a rate proportional to its excess over the minimum
allowed at this |L|, ``G²/I3``:

    ``dT/dt = -κ (2T - G²/I3)``   ⇒   ``2T(t) = G²/I3 + (2T₀ - G²/I3) e^{-2κt}``

(with ``x = 2T - G²/I3``: ``x' = 2T' = -2κ x``), so ``D(t) = G²/2T(t)`` rises monotonically to
``I3``, and crosses ``I2`` once, at ``t* = ln[(2T₀ - G²/I3) I2 I3/(G² (I3 - I2))]/(2κ)``
(negative if ``D₀ > I2``: the crossing lies in the past). The excess ``2T₀ - G²/I3 =
Σ Iᵢ ωᵢ² (I3 - Iᵢ)/I3`` is a sum of non-negative terms, formed without cancellation.

**The motion along the drift: piecewise exact.** Time is cut into windows of length ``h``. In
window k, ``[t_k, t_k + h)``, the body moves *exactly* (:class:`FreeRigidBody`) on the polhode
of ``D(t_k)``, the law's value at the window's start. At ``t_{k+1}`` the state is carried
across: the body-frame momentum ``m`` at the window's end is moved to the *nearest point* of
the polhodes of ``D(t_{k+1})`` on the same sphere ``|m| = G`` (nearest among the amplitude
samples of every branch of :func:`~poinsot.physics.models.family.polhode_curves`, then refined along
that branch), and the attitude is turned by the smallest rotation that takes the new ``m`` to
the old one, so that ``L = R m`` stays fixed in space (the damper exchanges momentum with the
body, not with the outside). Hence, by construction:

* ``|m| = G`` and ``L`` are kept to rounding;
* within window k the energy is exactly that of the law at ``t_k`` (a staircase that follows
  ``D(t)`` to within its change over one window);
* the polhode of each window is an exact closed curve of the family, and the label
  (minor → separatrix side → major) switches where ``D(t_k)`` passes ``I2``, i.e. within one
  window of ``t*``.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from poinsot.physics.core.exact import pow2_below
from poinsot.physics.core.free_body import FreeRigidBody
from poinsot.physics.core.validation import (
    check_attitude,
    check_number,
    check_positive,
    check_time_array,
    check_times,
    check_vector,
)
from poinsot.physics.models.family import polhode_curves, polhode_points, sorted_moments

__all__ = ["EnergySink"]

#: Amplitude samples per branch when looking for the nearest point of the next polhode.
_PROJECTION_SAMPLES = 512
#: Sweeps and points per sweep refining the amplitude (the bracket shrinks 16x per sweep).
_ZOOM_SWEEPS = 4
_ZOOM_POINTS = 33
#: Default window: at most this fraction of the decay time 1/κ ...
_WINDOW_DECAY_FRACTION = 0.01
#: ... and at most this many radians of the initial spin.
_WINDOW_SPIN_ANGLE = 0.5
#: The most windows a motion is built from (each is one exact body, ~0.5 ms and a few kB).
MAX_WINDOWS = 20_000
#: |L|² must lie between these: the law and the search for the nearest polhode point square
#: momenta, whose squares must stay normal doubles (with room for the factor 4 of a distance).
_G2_RANGE = (1e-300, 4e307)


def _smallest_rotation(a: NDArray[np.float64], b: NDArray[np.float64]) -> Rotation:
    """The rotation by the smallest angle that takes the direction of ``a`` to that of ``b``."""
    # Directions only: over their largest components, the products of momenta ~1e150 in the
    # cross and dot products would overflow (and those of ~1e-150 underflow).
    a, b = (x / pow2_below(float(np.max(np.abs(x)))) for x in (a, b))
    axis = np.cross(a, b)
    s = float(np.linalg.norm(axis))
    c = float(a @ b)
    if s == 0.0:
        return Rotation.identity()
    return Rotation.from_rotvec(axis / s * math.atan2(s, c))


def _nearest_on_polhodes(
    J: NDArray[np.float64], D: float, G: float, m: NDArray[np.float64]
) -> NDArray[np.float64]:
    """The point (3,) nearest to ``m`` on the polhodes of D drawn on the sphere ``|m| = G``."""
    curves = polhode_curves(J, D, momentum=G, n=_PROJECTION_SAMPLES)
    gaps = [np.linalg.norm(c.momentum - m, axis=1) for c in curves]
    best = int(np.argmin([float(g.min()) for g in gaps]))
    curve, index = curves[best], int(np.argmin(gaps[best]))
    if curve.momentum.shape[0] == 1:  # a pure spin: the point itself
        return curve.momentum[0]
    if curve.closed:
        spacing = 2.0 * math.pi / _PROJECTION_SAMPLES
        centre = index * spacing
    else:  # separatrix arc from -π/2 to π/2
        spacing = math.pi / (_PROJECTION_SAMPLES - 1)
        centre = -0.5 * math.pi + index * spacing

    # Zoom in on the nearest amplitude: a few vectorised sweeps of the bracket around it.
    lo, hi = centre - spacing, centre + spacing
    for _ in range(_ZOOM_SWEEPS):
        phi = np.linspace(lo, hi, _ZOOM_POINTS)
        if not curve.closed:
            phi = np.clip(phi, -0.5 * math.pi, 0.5 * math.pi)
        points = J * polhode_points(J, D, phi, curve.signs, momentum=G)
        j = int(np.argmin(np.sum((points - m) ** 2, axis=1)))
        step = (hi - lo) / (_ZOOM_POINTS - 1)
        lo, hi = float(phi[j]) - step, float(phi[j]) + step
    return points[j]


class EnergySink:
    """The motion of a body that dissipates energy internally at fixed |L| (see the module).

    Args:
        inertia: (3,) moments ``I1 < I2 < I3`` (sorted, distinct).
        omega0: (3,) body-frame ω at t = 0 [rad/time], not a spin about the major axis.
        kappa: κ [1/time] > 0, the rate of the stated law.
        t_end: the motion is built on ``[0, t_end]`` [time].
        window: the length h [time] of the exact windows; default
            ``min(0.01/κ, 0.5/|ω0|)``.
        attitude0: R(0), body -> space (identity if None).

    Raises:
        ValueError: moments not sorted/distinct, ω0 zero or not finite, ω0 already a spin about
            ``e3`` (D = I3: nothing left to dissipate), κ, t_end or window not positive.
    """

    def __init__(
        self,
        inertia: ArrayLike,
        omega0: ArrayLike,
        kappa: float,
        t_end: float,
        window: float | None = None,
        attitude0: Rotation | None = None,
    ):
        J = np.array(sorted_moments(inertia))
        w0 = check_vector(omega0, "omega0")
        if not np.any(w0):
            raise ValueError(f"omega0 must be three finite numbers, not all zero, got {omega0!r}")
        self.kappa = check_positive(kappa, "κ (the dissipation rate)")
        self.t_end = check_positive(t_end, "t_end")
        attitude0 = check_attitude(attitude0)
        self.inertia = J
        self._set_law(J, w0)
        if window is None:
            spin = math.hypot(*w0.tolist())
            window = min(_WINDOW_DECAY_FRACTION / self.kappa, _WINDOW_SPIN_ANGLE / spin)
        self.window = check_positive(window, "the window")
        windows = self.t_end / self.window
        if not windows <= MAX_WINDOWS:
            raise ValueError(
                f"t_end/window = {windows:.3g} windows, more than {MAX_WINDOWS:,} (each is one "
                "exact motion): use a longer window or a shorter t_end"
            )
        count = int(math.ceil(windows))
        self.starts = self.window * np.arange(count)
        """(K,) the windows' start times t_k [time]."""
        self.bodies = self._build(w0, attitude0)
        """The exact motion of each window (local time ``t - t_k``)."""
        self.regimes = [b.regime for b in self.bodies]
        """The regime (polhode family) of each window."""

    def _set_law(self, J: NDArray[np.float64], w0: NDArray[np.float64]) -> None:
        """G, the excess 2T₀ - G²/I3, D₀ and t* of the stated law, refused where they leave
        the range of doubles."""
        with np.errstate(over="ignore"):
            m0 = J * w0
        self.G = math.hypot(*m0.tolist())
        """|m| = |L| [moment × rad/time], fixed."""
        G2 = self.G * self.G
        if not _G2_RANGE[0] <= G2 <= _G2_RANGE[1]:
            raise ValueError(
                f"|L|² = {G2:g} in your units is outside [{_G2_RANGE[0]:g}, {_G2_RANGE[1]:g}], "
                "where the law squares it: express the moments or ω0 in other units"
            )
        with np.errstate(over="ignore", invalid="ignore"):
            # 2T₀ - G²/I3 = Σ Iᵢ ωᵢ² (I3 - Iᵢ)/I3: non-negative terms.
            self.excess0 = float(np.sum(m0 * w0 * ((J[2] - J) / J[2])))
        two_T0 = G2 / float(J[2]) + self.excess0
        if not math.isfinite(two_T0):
            raise ValueError(
                f"the energy 2T of this body is beyond the double-precision range in your units "
                f"(|L|² = {G2:g} with a largest moment {float(J[2]):g}): express the moments or "
                "ω0 in other units"
            )
        if self.excess0 == 0.0:
            raise ValueError(
                "omega0 is a spin about the major axis e3 (D = I3): there is no energy left "
                "to dissipate at this |L|"
            )
        self.D0 = float(self.D(0.0))
        # excess0 I2 I3/(G² (I3 - I2)), one factor at a time: products of moments ~1e-150
        # underflow.
        I2, I3 = float(J[1]), float(J[2])
        ratio = self.excess0 / G2 * (I2 / (I3 - I2)) * I3
        self.crossing_time = math.log(ratio) / (2.0 * self.kappa) if ratio > 0.0 else -math.inf
        """t* [time] where D(t) = I2 (negative if the motion starts above the separatrix)."""
        if not all(map(math.isfinite, (self.excess0, self.D0, self.crossing_time))):
            raise ValueError(
                "the energy of this body lies beyond the double-precision range in your units "
                f"(2T₀ - |L|²/I3 = {self.excess0:g}): express the moments or ω0 in other units"
            )

    def two_T(self, t: ArrayLike) -> NDArray[np.float64]:
        """``2T(t) = G²/I3 + (2T₀ - G²/I3) e^{-2κt}`` (the stated law), same shape as t."""
        tt = np.asarray(check_times(t, "t"), dtype=float)
        with np.errstate(over="ignore"):
            # κt first: 2κ alone may overflow (κ ~ 1e308), and inf · 0 is NaN.
            out = self.G**2 / self.inertia[2] + self.excess0 * np.exp(-2.0 * (self.kappa * tt))
        if not np.all(np.isfinite(out)):
            raise ValueError(
                "t lies so far before the start that 2T(t) of the law passes the double range; "
                "use times closer to 0"
            )
        return out

    def D(self, t: ArrayLike) -> NDArray[np.float64]:
        """``D(t) = G²/2T(t)`` [moment], rising to I3; same shape as t."""
        return self.G * (self.G / self.two_T(t))

    def _build(self, w0: NDArray[np.float64], R0: Rotation) -> list[FreeRigidBody]:
        J, h = self.inertia, self.window
        bodies = [FreeRigidBody(J, w0, R0)]
        D_next = self.D(self.starts[1:])
        self.jumps = np.zeros(self.starts.size)
        """(K,) |Δm|/G where the state was carried into each window (0 for the first)."""
        for k, D in enumerate(D_next.tolist(), start=1):  # the state is carried window by window
            w_end, R_end = bodies[-1].state(h)
            m_end = J * w_end
            D = min(max(float(D), float(J[0])), float(J[2]))  # the law's rounding at either end
            m_new = _nearest_on_polhodes(J, D, self.G, m_end)
            self.jumps[k] = float(np.linalg.norm(m_new - m_end)) / self.G
            R_new = R_end * _smallest_rotation(m_new, m_end)  # keeps R m = L
            bodies.append(FreeRigidBody(J, m_new / J, R_new))
        return bodies

    def _locate(self, t: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
        tt = check_time_array(t)
        if tt.size and (tt.min() < 0.0 or tt.max() > self.t_end):
            raise ValueError(f"t must lie in [0, t_end = {self.t_end:g}] where the motion is built")
        k = np.minimum((tt // self.window).astype(np.int64), self.starts.size - 1)
        return tt, k

    def state(self, t: ArrayLike) -> tuple[NDArray[np.float64], Rotation]:
        """ω (N, 3) [rad/time] and R (N rotations) at the times ``t`` (N,) in ``[0, t_end]``:
        each from the exact motion of its window."""
        tt, k = self._locate(t)
        w = np.empty((tt.size, 3))
        q = np.empty((tt.size, 4))
        for j in np.unique(k).tolist():  # one vectorised evaluation per window present
            sel = np.flatnonzero(k == j)
            wj, Rj = self.bodies[j].state(tt[sel] - self.starts[j])
            w[sel], q[sel] = wj, Rj.as_quat()
        return w, Rotation.from_quat(q)

    def omega(self, t: ArrayLike) -> NDArray[np.float64]:
        """ω (N, 3) [rad/time] at the times ``t`` (N,) in ``[0, t_end]``."""
        return self.state(t)[0]

    def window_D(self, t: ArrayLike) -> NDArray[np.float64]:
        """(N,) the D on which the motion runs at ``t``: the law at its window's start."""
        _, k = self._locate(t)
        return self.D(self.starts[k])

    def body_at(self, t: float) -> FreeRigidBody:
        """The exact torque-free motion of the window containing ``t``: its ``polhode()`` is the
        curve the tip of ω runs on at that time, its ``regime`` the family label."""
        _, k = self._locate(check_number(t, "t"))
        return self.bodies[int(k[0])]


def _positive(value: float | None, name: str) -> float:
    x = float("nan") if value is None else float(value)
    if not (math.isfinite(x) and x > 0.0):
        raise ValueError(f"{name} must be a positive finite number, got {value!r}")
    return x


def _demo() -> None:  # pragma: no cover - a printout for the report
    sink = EnergySink((1.0, 2.0, 3.0), (1.0, 0.15, 0.1), kappa=0.05, t_end=250.0, window=0.5)
    t = np.linspace(0.0, sink.t_end, 25001)
    w, R = sink.state(t)
    m = sink.inertia * w
    D = sink.G**2 / np.sum(sink.inertia * w * w, axis=1)
    labels = sink.regimes
    k = next(j for j in range(1, len(labels)) if labels[j] is not labels[j - 1])
    L = R.apply(m)
    print("Explorer 1: I = (1, 2, 3), ω0 = (1, 0.15, 0.1), κ = 0.05, windows of 0.5")
    print(
        f"  |m|/G - 1 (max)             {np.abs(np.linalg.norm(m, axis=1) / sink.G - 1).max():.1e}"
    )
    print(f"  |L(t) - L(0)|/G (max)       {np.abs(L - L[0]).max() / sink.G:.1e}")
    print(f"  D vs law at window start    {np.abs(D / sink.window_D(t) - 1).max():.1e}")
    print(f"  D vs law D(t) (max, abs)    {np.abs(D - sink.D(t)).max():.2e}")
    print(f"  crossing t* (theory)        {sink.crossing_time:.4f}")
    print(
        f"  family switch (windows)     {labels[k - 1].value} -> {labels[k].value} "
        f"between t = {sink.starts[k - 1]:.2f} and {sink.starts[k]:.2f}"
    )
    print(f"  final |m3|/G                {abs(m[-1, 2]) / sink.G:.12f}")


if __name__ == "__main__":  # pragma: no cover
    _demo()
