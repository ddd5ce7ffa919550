"""The intermediate-axis flip as a clock [ACC91; LL76 §37; FM06 Theorem 7.3].

A body with sorted moments ``I1 < I2 < I3`` spun almost about its intermediate axis ``e2``
turns over again and again (the Dzhanibekov effect, the twisting tennis racket): ``ω2`` keeps
its size ``≈ |ω|`` for a long while, then reverses in a short burst. The motion is exactly
periodic, so the flips tick like a clock.

The perturbation is stated as an angle: :func:`flip_initial_omega` puts ω0 at the angle ``ε``
from ``e2``, tilted towards ``cos β e1 + sin β e3``:

    ``ω0 = Ω (sin ε cos β, cos ε, sin ε sin β)``.

With ``β = 0`` (the default) the tilt is towards the minor axis and the motion belongs to the
minor-axis family; ``β = π/2`` gives the major-axis family. The theory (:func:`flip_theory`)
is computed from the float ω0 itself, not from ``ε``, so it describes exactly the motion that
is measured:

* *time between flips*: the zeros of ``ω2 = A2 sn u`` are ``2K`` apart in ``u = u0 + λt``
  [LL76 §37, Eq. 37.10], so flips come every ``2K(m)/λ``, half the period of ω [LL76 Eq.
  37.12]. ``K`` comes from the complementary parameter ``mc = 1 - m``, formed without
  cancellation from ``Δᵢ = G² - 2T Iᵢ`` (``scipy.special.ellipkm1``).
* *first flip*: ω2 is largest at ``u = K`` (where it is closest to ``e2``); ω0 lies an
  argument ``δ`` away from it with ``sn δ = |ω3 A1/(A3 ω1)|`` (minor family) or
  ``|ω1 A3/(A1 ω3)|`` (major family), so the first flip comes at ``(K ± δ)/λ`` (``+`` if ω2 is
  still growing at ``t = 0``). For ``β = 0`` or ``π/2``, ``δ = 0``.
* *growth rate*: near ``e2`` a perturbation grows like ``e^{σt}`` with
  ``σ = Ω₂ sqrt((I2 - I1)(I3 - I2)/(I1 I3))``, ``Ω₂ = ω2(0)`` [LL76 §37; FM06 Theorem 7.3];
  ``λ → σ`` as ``ε → 0``.
* *asymptote*: ``2K = ln(16/mc) + O(mc ln mc)`` [DLMF 19.12.1], so the time between flips is
  ``ln(16/mc)/λ`` to a relative error below ``mc`` (below 1e-15 once ``ε < 1e-8``). For
  ``β = 0``, ``mc = I1(I3-I1) sin²ε / (I1(I3-I1) sin²ε + I2(I3-I2) cos²ε)``, hence the first
  flip at ``K/λ ≈ [ln(4/ε) + ½ ln(I2(I3-I2)/(I1(I3-I1)))]/λ``: the flip time grows like
  ``ln(1/ε)`` with slope ``1/σ``.

The measurement (:func:`measure_flips`, :func:`measure_growth_rate`) only reads the motion:
the sign changes of ``ω2`` on a grid, each refined by Brent's method on the exact solution, and
a straight-line fit of ``ln |(ω1, ω3)|`` on the early exponential stretch. The exact solution
stays exact down to ``ε = 1e-12`` (``mc = 1e-24``); an integrator does not
(:func:`integrated_flip_times`, DOP853): its absolute error on the tiny components is as large
as the perturbation itself.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import optimize, special
from scipy.integrate import solve_ivp

from poinsot.physics.core.exact import ldexp, pow2_below
from poinsot.physics.core.free_body import FreeRigidBody
from poinsot.physics.core.regime import Regime
from poinsot.physics.core.validation import (
    check_count,
    check_number,
    check_positive,
    check_vector,
    grid_size,
)
from poinsot.physics.models.family import sorted_moments
from poinsot.physics.models.flip_growth import (
    STEPS_PER_RATE,
    GrowthFit,
    check_body,
    fastest_rate,
    measure_growth_rate,
)

__all__ = [
    "FlipTheory",
    "GrowthFit",
    "flip_initial_omega",
    "flip_theory",
    "integrated_flip_times",
    "measure_flips",
    "measure_growth_rate",
]

#: integrated_flip_times integrates at most this many radians of the fastest rotation (DOP853
#: takes a few steps per radian: beyond this it would run for minutes).
_MAX_RADIANS = 1e4
#: Tolerances below this scipy raises to it with a warning: refused instead; above the largest
#: the steps are so long that the solution may run off to infinity.
_MIN_RTOL, _MAX_RTOL = 100.0 * float(np.finfo(float).eps), 1e-2


def flip_initial_omega(
    epsilon: float, spin: float = 1.0, azimuth: float = 0.0
) -> NDArray[np.float64]:
    """``ω0 = spin (sin ε cos β, cos ε, sin ε sin β)`` (3,) [rad/time]: at the angle ``ε`` [rad]
    from the intermediate axis ``e2``, tilted towards ``cos β e1 + sin β e3`` (``β = azimuth``).

    Raises:
        ValueError: unless ``0 < ε < π/2`` and ``spin > 0`` (a spin exactly about e2 never flips).
    """
    eps = check_number(epsilon, "the angle ε from the intermediate axis")
    if not 0.0 < eps < 0.5 * math.pi:
        raise ValueError(
            f"the angle ε from the intermediate axis must lie in (0, π/2) rad, got {epsilon!r} "
            "(ε = 0 is a spin exactly about e2, which never flips)"
        )
    spin = check_positive(spin, "the spin rate")
    beta = check_number(azimuth, "the azimuth β")
    s = math.sin(eps)
    return spin * np.array([s * math.cos(beta), math.cos(eps), s * math.sin(beta)])


@dataclass(frozen=True)
class FlipTheory:
    """The clock of the flip, from the closed form (times in the caller's time unit).

    Attributes:
        regime: ``MINOR_AXIS`` or ``MAJOR_AXIS`` (which side of the separatrix ω0 lies on).
        complementary_parameter: ``mc = 1 - k²`` of the Jacobi functions.
        K: the complete elliptic integral ``K(m)``.
        frequency: λ, the rate of the elliptic argument [rad/time].
        time_between_flips: ``2K/λ``, half the period of ω.
        first_flip_time: ``(K ± δ)/λ``, from ``t = 0`` to the first zero of ω2.
        growth_rate: σ [1/time], the exponent of the linear instability at ``e2``.
        asymptotic_time_between_flips: ``ln(16/mc)/λ`` (relative error < mc).
    """

    regime: Regime
    complementary_parameter: float
    K: float
    frequency: float
    time_between_flips: float
    first_flip_time: float
    growth_rate: float
    asymptotic_time_between_flips: float


def _deltas(J: tuple[float, float, float], w: NDArray[np.float64]) -> tuple[float, float, float]:
    """``Δᵢ = G² - 2T Iᵢ`` as sums of terms of one sign each (no cancellation)."""
    I1, I2, I3 = J
    m1, m2, m3 = (J[k] * float(w[k]) for k in range(3))
    d1 = m2 * m2 * (I2 - I1) / I2 + m3 * m3 * (I3 - I1) / I3
    d2 = m1 * m1 * (I1 - I2) / I1 + m3 * m3 * (I3 - I2) / I3
    d3 = m1 * m1 * (I1 - I3) / I1 + m2 * m2 * (I2 - I3) / I2
    return d1, d2, d3


def flip_theory(inertia: ArrayLike, omega0: ArrayLike) -> FlipTheory:
    """The theory of the flip for sorted moments ``I1 < I2 < I3`` and ω0 near ``±e2``.

    Args:
        inertia: (3,) ``I1 < I2 < I3``. omega0: (3,) [rad/time], e.g. :func:`flip_initial_omega`.

    Raises:
        ValueError: moments not sorted/distinct, ω0 not finite, along a principal axis, or
            exactly on the separatrix (it then flips once and never again).
    """
    moments = sorted_moments(inertia)
    w = check_vector(omega0, "omega0")
    if int(np.count_nonzero(w)) < 2:
        raise ValueError(
            f"omega0 = {w.tolist()} is a spin about a principal axis: it never flips; tilt it "
            "from e2 (see flip_initial_omega)"
        )
    J, ws, w_exp, (d1, d2, d3) = _scaled_deltas(moments, w)
    J1, J2, J3 = J
    major = d2 > 0.0
    # A1² = -Δ3/(I1(I3 - I1)) and A3² = Δ1/(I3(I3 - I1)) in both families [LL76 Eq. 37.10].
    a31 = math.sqrt(d1 / -d3) * math.sqrt(J1 / J3)  # A3/A1
    w1, w3 = abs(float(ws[0])), abs(float(ws[2]))
    if major:
        lam = math.sqrt((J3 - J2) / J3) * math.sqrt(d1 / J1) / math.sqrt(J2)
        mc = d2 / d1 * ((J3 - J1) / (J3 - J2))
        ratio = w1 * a31 / w3 if w3 > 0.0 and w1 > 0.0 else 0.0
    else:
        lam = math.sqrt((J2 - J1) / J1) * math.sqrt(-d3 / J3) / math.sqrt(J2)
        mc = d2 / d3 * ((J3 - J1) / (J2 - J1))
        ratio = w3 / (a31 * w1) if w1 > 0.0 and w3 > 0.0 else 0.0
    K = float(special.ellipkm1(mc))
    delta = float(special.ellipkinc(math.asin(min(ratio, 1.0)), 1.0 - mc))
    # dω2/dt = (I3 - I1) ω3 ω1 / I2: growing means the closest approach to e2 is still ahead.
    growing = (float(w[0]) * float(w[2]) * float(w[1])) > 0.0
    sigma = abs(float(ws[1])) * math.sqrt((J2 - J1) / J1) * math.sqrt((J3 - J2) / J3)
    times = [ldexp(x / lam, -w_exp) for x in (K + delta if growing else K - delta, 2.0 * K)]
    asymptotic = ldexp(math.log(16.0 / mc) / lam, -w_exp) if mc > 0.0 else math.inf
    theory = FlipTheory(
        regime=Regime.MAJOR_AXIS if major else Regime.MINOR_AXIS,
        complementary_parameter=mc,
        K=K,
        frequency=ldexp(lam, w_exp),
        time_between_flips=times[1],
        first_flip_time=times[0],
        growth_rate=ldexp(sigma, w_exp),
        asymptotic_time_between_flips=asymptotic,
    )
    _check_clock(theory)
    return theory


def _scaled_deltas(
    moments: tuple[float, float, float], w: NDArray[np.float64]
) -> tuple[tuple[float, float, float], NDArray[np.float64], int, tuple[float, float, float]]:
    """Moments and ω over exact powers of two (the squares of ω ~ 1e200 or of moments ~1e-200
    would leave the double range; every quantity of the clock is a ratio of factors near 1),
    the exponent of ω's scale, and the Δᵢ; refused on the separatrix or an axis."""
    scale = pow2_below(moments[2])
    J = (moments[0] / scale, moments[1] / scale, moments[2] / scale)
    w_exp = math.frexp(float(np.max(np.abs(w))))[1] - 1
    ws = np.ldexp(w, -w_exp)
    d1, d2, d3 = _deltas(J, ws)
    if d2 == 0.0:
        raise ValueError(
            "omega0 lies on the separatrix (G² = 2T I2 to double precision): the body flips "
            "once and never again; change the azimuth of the tilt"
        )
    if d1 <= 0.0 or d3 >= 0.0:
        raise ValueError(
            f"omega0 = {w.tolist()} is a spin about a principal axis to double precision (its "
            "other components are too small to count): it never flips; tilt it from e2"
        )
    return J, ws, w_exp, (d1, d2, d3)


def _check_clock(theory: FlipTheory) -> None:
    """Refuse a clock that does not fit in doubles in the caller's units."""
    values = (
        theory.K,
        theory.frequency,
        theory.time_between_flips,
        theory.first_flip_time,
        theory.growth_rate,
    )
    if all(map(math.isfinite, values)) and theory.time_between_flips > 0.0:
        return
    raise ValueError(
        "the flip clock of this motion lies beyond the double-precision range in your units "
        f"(K = {theory.K:g}, λ = {theory.frequency:g}, 2K/λ = {theory.time_between_flips:g}): "
        "tilt ω0 further from e2, or use a time unit closer to 1/|ω0|"
    )


def measure_flips(
    body: FreeRigidBody, t_end: float, axis: int = 1, step: float | None = None
) -> NDArray[np.float64]:
    """The flip times in ``(0, t_end]``: the zeros of ``ω_axis(t)`` of the exact motion (k,).

    Sign changes are located on a grid of spacing ``step`` (default: a tenth of the fastest
    time scale of Euler's equations) and each one is refined by Brent's method on
    ``body.omega`` to a few ulps of t. A grid point where ω_axis is exactly 0 is a flip itself.

    Args:
        body: the motion. t_end: the end of the search [time], > 0.
        axis: the body axis whose component flips (the intermediate axis of sorted moments: 1).
        step: the grid spacing [time] (> 0); it must be shorter than half the time between
            flips, which every default is.
    """
    check_body(body, "measure_flips")
    t_end = check_positive(t_end, "t_end")
    axis = check_count(axis, "axis (0, 1 or 2)", 0, 2)
    if step is None:
        rate = fastest_rate(body.inertia, body.omega0)
        if rate == 0.0:  # at rest: nothing changes sign
            return np.empty(0)
        step = 1.0 / (STEPS_PER_RATE * rate)
    else:
        step = check_positive(step, "step")
    n = grid_size(
        t_end, step, "searching for flips up to t_end", "use a shorter t_end or a larger step"
    )
    t = np.linspace(0.0, t_end, n + 1)
    w = body.omega(t)[:, axis]
    sign = np.sign(w)
    exact = t[1:][sign[1:] == 0.0]
    brackets = np.flatnonzero(sign[:-1] * sign[1:] < 0.0)

    def component(x: float) -> float:
        return float(body.omega(float(x))[axis])

    eps = float(np.finfo(float).eps)
    refined = [
        optimize.brentq(component, t[i], t[i + 1], xtol=1e-300, rtol=4.0 * eps) for i in brackets
    ]  # one root per flip: a loop over the flips, not over the samples
    return np.sort(np.concatenate([exact, np.asarray(refined, dtype=float)]))


def integrated_flip_times(
    inertia: ArrayLike, omega0: ArrayLike, t_end: float, rtol: float = 1e-12
) -> NDArray[np.float64]:
    """The flip times (zeros of ω2) of a DOP853 integration of Euler's equations [HNW93 §II.5].

    ``scipy.integrate.solve_ivp(method="DOP853")`` with ``atol = rtol · max|ω0|`` (as in
    :mod:`poinsot.physics.integrators`) and an event on ω2, whose roots scipy finds on the dense
    output. This is what a numerical simulator measures: it agrees with the exact clock at
    ``ε = 1e-3``, but at ``ε = 1e-12`` its absolute error is as large as the perturbation and
    the flip times are wrong by O(1/σ) (the demo ``python -m poinsot.physics.models.flip`` prints
    it).
    """
    J = np.asarray(sorted_moments(inertia))
    w0 = check_vector(omega0, "omega0")
    t_end = check_positive(t_end, "t_end")
    rtol = check_positive(rtol, "rtol")
    if not _MIN_RTOL <= rtol <= _MAX_RTOL:
        raise ValueError(
            f"rtol must lie between {_MIN_RTOL:.3g} (scipy's floor) and {_MAX_RTOL:g}, got {rtol!r}"
        )
    w_max = float(np.max(np.abs(w0)))
    if w_max == 0.0:  # at rest: ω2 stays 0
        return np.empty(0)
    # The same equations for ω/2^e in the time t·2^e (exact powers of two): ω ~ 1e200 would
    # overflow in the products ω_j ω_k.
    w_exp = math.frexp(w_max)[1] - 1
    ws, tau_end = np.ldexp(w0, -w_exp), ldexp(t_end, w_exp)
    radians = fastest_rate(J, ws) * tau_end
    if not radians <= _MAX_RADIANS:
        raise ValueError(
            f"t_end spans {radians:.3g} radians of the fastest rotation, more than "
            f"{_MAX_RADIANS:g} for an integration: use a shorter t_end"
        )
    c = np.array([(J[1] - J[2]) / J[0], (J[2] - J[0]) / J[1], (J[0] - J[1]) / J[2]])

    def euler(_t: float, w: NDArray[np.float64]) -> NDArray[np.float64]:
        return c * np.array([w[1] * w[2], w[2] * w[0], w[0] * w[1]])

    def omega2(_t: float, w: NDArray[np.float64]) -> float:
        return float(w[1])

    with np.errstate(all="ignore"):  # a run that leaves the range is refused just below
        sol = solve_ivp(
            euler,
            (0.0, tau_end),
            ws,
            method="DOP853",
            rtol=rtol,
            atol=rtol * float(np.abs(ws).max()),
            events=omega2,
        )
    times = np.asarray(sol.t_events[0], dtype=float)
    if sol.status < 0 or not (np.all(np.isfinite(sol.y)) and np.all(np.isfinite(times))):
        raise ValueError(f"DOP853 failed ({sol.message}): use a smaller rtol or a shorter t_end")
    return np.ldexp(times, -w_exp)


def _demo() -> None:  # pragma: no cover - a printout for the report
    inertia = (1.0, 2.0, 3.0)
    print(f"intermediate-axis flip, I = {inertia}, ω0 = (sin ε, cos ε, 0); errors are relative")
    print(
        f"{'ε':>7} {'2K/λ':>12} {'measured-2K/λ':>13} {'ln(16/mc)/λ':>11} {'t1 = K/λ':>11} "
        f"{'measured-t1':>11} {'σ':>9} {'σ fit':>9} {'DOP853 t1':>9} {'DOP853 2K/λ':>11}"
    )
    for k in (1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12):
        eps = 10.0**-k
        w0 = flip_initial_omega(eps)
        th = flip_theory(inertia, w0)
        body = FreeRigidBody(inertia, w0)
        t_end = th.first_flip_time + 2.5 * th.time_between_flips
        flips = measure_flips(body, t_end)
        between = float(np.abs(np.diff(flips) / th.time_between_flips - 1.0).max())
        asym = th.asymptotic_time_between_flips / th.time_between_flips - 1.0
        t1 = float(flips[0]) / th.first_flip_time - 1.0
        try:
            fit = f"{measure_growth_rate(body).rate / th.growth_rate - 1.0:9.1e}"
        except ValueError:
            fit = f"{'-':>9}"
        dop = integrated_flip_times(inertia, w0, t_end)
        dop_t1 = float(dop[0]) / th.first_flip_time - 1.0
        dop_between = float(np.abs(np.diff(dop) / th.time_between_flips - 1.0).max())
        print(
            f"{eps:7.0e} {th.time_between_flips:12.6f} {between:13.1e} {asym:11.1e} "
            f"{th.first_flip_time:11.6f} {t1:11.1e} {th.growth_rate:9.6f} {fit} "
            f"{dop_t1:9.1e} {dop_between:11.1e}"
        )


if __name__ == "__main__":  # pragma: no cover
    _demo()
