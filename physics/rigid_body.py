"""The exact motion of a free rigid body: angular velocity and attitude in closed form.

Solve once, evaluate many: :class:`FreeRigidBody` classifies the motion from the initial state
(:class:`~physics.regime.Regime`), precomputes the constants of the closed form, and then
evaluates ω(t) and the attitude R(t) on whole arrays of times with no integration and no drift.

Frames and conventions (see ``shared/PHYSICS.md``):

* *Body frame*: the caller's principal axes, in the caller's order. Internally the moments
  are sorted with a *proper* relabelling (a signed permutation with det +1) and, for the
  minor-axis family, relabelled once more so that the axis the polhode circles (the *pole*)
  is always the third one. All results are mapped back.
* *Space frame*: the caller's, fixed by ``attitude0`` (``R(0)``). Internally a space frame with
  ``e_z ∥ L`` carries Z-X-Z Euler angles ``R = Rz(φ) Rx(θ) Rz(ψ)`` with
  ``m/G = (sinθ sinψ, sinθ cosψ, cosθ)`` (Landau 37.13-37.14).
* Attitude ``R(t)`` maps body coordinates to space coordinates; quaternions are scipy's
  scalar-last ``(x, y, z, w)``.
* Units are the caller's: ω in rad per time unit, moments in any consistent unit.

To stay finite for any scale (ω0 ~ 1e-200, moments ~ 1e100), the constants are computed in
units where the largest moment and the largest |ω0| component are powers of two near 1. Powers
of two scale floating-point numbers exactly, so the classification (``Δ2 == 0``) is the same
as in the caller's units.
"""

from __future__ import annotations

import functools
import math
from decimal import localcontext
from fractions import Fraction

import numpy as np
from scipy.spatial.transform import Rotation

from physics import elliptic, precise
from physics.regime import Regime

__all__ = ["FreeRigidBody", "omega_from_energy", "attitude_with_L_along_z"]

_HALF_PI = 0.5 * math.pi
# Times evaluated per block (see FreeRigidBody._quat_user): ~20 temporaries of 128 KiB fit in L2.
_BLOCK = 16384


# ---------------------------------------------------------------------------------------------
# Input checks: clear messages for students, raised before anything is computed.
# ---------------------------------------------------------------------------------------------


def _vector3(value, name: str) -> np.ndarray:
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be three real numbers, got {value!r}") from exc
    if arr.shape != (3,):
        raise ValueError(f"{name} must be three numbers (shape (3,)), got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite, got {arr.tolist()}")
    return arr


def _check_inertia(value) -> np.ndarray:
    inertia = _vector3(value, "the moments of inertia")
    if np.any(inertia <= 0.0):
        raise ValueError(
            f"the moments of inertia must be positive, got {inertia.tolist()} "
            "(a principal moment is a sum of m·r², never zero or negative)"
        )
    return inertia


def _check_times(t) -> tuple[np.ndarray, bool]:
    """Return the times as a 1-D float array and whether the caller passed a scalar."""
    try:
        arr = np.asarray(t, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"time must be a number or a 1-D array of numbers, got {t!r}") from exc
    if arr.ndim > 1:
        raise ValueError(f"time must be a number or a 1-D array, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError("time must be finite (got NaN or infinity)")
    return arr.reshape(-1), arr.ndim == 0


def _pow2(x: float) -> float:
    """The power of two nearest below ``x > 0`` (scaling by it is exact)."""
    return math.ldexp(1.0, math.frexp(x)[1] - 1)


# ---------------------------------------------------------------------------------------------
# Proper relabellings of the body axes (signed permutations with det +1).
# ---------------------------------------------------------------------------------------------


class _AxisMap:
    """``x_internal = C @ x_user`` for a signed permutation ``C`` with det +1.

    Stored as ``index`` and ``sign`` so that ``x_internal[k] = sign[k] * x_user[index[k]]``.
    There are only 24 of them, so each is built once (:func:`_axis_map`).
    """

    def __init__(self, index: tuple[int, ...], sign: tuple[float, ...]):
        self.index = np.asarray(index, dtype=int)
        self.sign = np.asarray(sign, dtype=float)
        self.matrix = np.zeros((3, 3))
        self.matrix[np.arange(3), self.index] = self.sign
        if round(np.linalg.det(self.matrix)) != 1:
            raise AssertionError("an axis relabelling must be a proper rotation")
        # Quaternion of the user->internal map, used on the right of the internal attitude.
        self.quat = Rotation.from_matrix(self.matrix).as_quat()

    def to_internal(self, x: np.ndarray) -> np.ndarray:
        return self.sign * x[..., self.index]

    def to_user_columns(self, cols: tuple[np.ndarray, ...]) -> np.ndarray:
        """Stack internal components ``cols[k]`` (each (N,)) into user-order (N, 3)."""
        out = np.empty((cols[0].shape[0], 3))
        for k in range(3):
            out[:, self.index[k]] = self.sign[k] * cols[k]
        return out

    def compose(self, other: _AxisMap) -> _AxisMap:
        """The map ``other ∘ self`` (apply self first)."""
        return _axis_map(
            tuple(int(i) for i in self.index[other.index]),
            tuple(float(x) for x in other.sign * self.sign[other.index]),
        )


@functools.cache
def _axis_map(index: tuple[int, ...], sign: tuple[float, ...]) -> _AxisMap:
    return _AxisMap(index, sign)


def _sorting_map(inertia: np.ndarray) -> _AxisMap:
    """Proper relabelling that sorts the moments ascending (an odd permutation flips axis 1)."""
    order = tuple(int(i) for i in np.argsort(inertia, kind="stable"))
    inversions = sum(order[i] > order[j] for i in range(3) for j in range(i + 1, 3))
    parity = -1.0 if inversions % 2 else 1.0  # an odd permutation gets axis 1 reversed
    return _axis_map(order, (parity, 1.0, 1.0))


# Reverse the sorted axes, pole = smallest moment becomes axis 3: x'' = (x3, x2, -x1).
_REVERSE = _axis_map((2, 1, 0), (1.0, 1.0, -1.0))


# ---------------------------------------------------------------------------------------------
# Quaternion helpers (scalar-last, vectorised over leading axes).
# ---------------------------------------------------------------------------------------------


def _qmul(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Hamilton product ``p ⊗ q`` of scalar-last quaternions (broadcasting (..., 4))."""
    px, py, pz, pw = p[..., 0], p[..., 1], p[..., 2], p[..., 3]
    qx, qy, qz, qw = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack(
        [
            pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx,
            pw * qz + px * qy - py * qx + pz * qw,
            pw * qw - px * qx - py * qy - pz * qz,
        ],
        axis=-1,
    )


def _rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate vectors v (N, 3) by unit quaternions q (N, 4), scalar-last: v + 2 q×(q×v + w v)."""
    x, y, z, w = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    vx, vy, vz = v[:, 0], v[:, 1], v[:, 2]
    tx = y * vz - z * vy + w * vx  # t = q×v + w v (explicit: np.cross costs ~50 µs per call)
    ty = z * vx - x * vz + w * vy
    tz = x * vy - y * vx + w * vz
    return np.stack(
        [vx + 2.0 * (y * tz - z * ty), vy + 2.0 * (z * tx - x * tz), vz + 2.0 * (x * ty - y * tx)],
        axis=-1,
    )


def _axis_angle_quat(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Quaternions (N, 4) of rotations by ``angle`` (N,) about the unit ``axis`` (3,)."""
    half = 0.5 * angle
    s = np.sin(half)
    return np.stack([axis[0] * s, axis[1] * s, axis[2] * s, np.cos(half)], axis=-1)


def _zxz_from_momentum(
    m1: np.ndarray, m2: np.ndarray, m3: np.ndarray, G: float, phi: np.ndarray
) -> np.ndarray:
    """Quaternion of ``Rz(φ) Rx(θ) Rz(ψ)`` with θ, ψ read off ``m/G`` (Landau 37.13-37.14).

    ``cos θ = m3/G``, ``sin θ = ρ/G`` with ``ρ = hypot(m1, m2)``, ``ψ = atan2(m1, m2)``. The
    half-angle of θ is taken from whichever of ``G ± m3`` has no cancellation
    (``G - m3 = ρ²/(G + m3)``), so it is accurate at both poles.
    """
    rho = np.hypot(m1, m2)
    psi = np.arctan2(m1, m2)
    # cos(θ/2) = sqrt((G + m3)/2G), sin(θ/2) = ρ / (2G cos(θ/2)); swap roles when m3 < 0.
    upper = m3 >= 0.0
    big = np.sqrt(0.5 * (G + np.abs(m3)) / G)
    small = rho / (2.0 * G * big)
    cos_half = np.where(upper, big, small)
    sin_half = np.where(upper, small, big)
    sum_half = 0.5 * (phi + psi)
    dif_half = 0.5 * (phi - psi)
    return np.stack(
        [
            sin_half * np.cos(dif_half),
            sin_half * np.sin(dif_half),
            cos_half * np.sin(sum_half),
            cos_half * np.cos(sum_half),
        ],
        axis=-1,
    )


# ---------------------------------------------------------------------------------------------
# The three closed forms. Each works in its internal frame and dimensionless time τ = t·ω_ref.
# ---------------------------------------------------------------------------------------------


def _amplitudes(F: tuple[Fraction, ...], e1: Fraction, e3: Fraction) -> np.ndarray:
    """``(A1, A2, A3)`` of Landau 37.10 from exact moments and Δ1, Δ3 (pole frame).

    ``A1² = Δ3/(J1(J1-J3))``, ``A2² = Δ3/(J2(J2-J3))``, ``A3² = Δ1/(J3(J3-J1))``: each a quotient
    of same-signed quantities in both families. Evaluated in decimal (call inside a
    45-digit context) so that a spin a hair off an axis, with Δ ~ 1e-600, still gets its
    representable amplitude ~1e-300 instead of 0/0.
    """
    F1, F2, F3 = F
    dec = precise.decimal
    return np.array(
        [
            float(dec(e3 / (F1 * (F1 - F3))).sqrt()),
            float(dec(e3 / (F2 * (F2 - F3))).sqrt()),
            float(dec(e1 / (F3 * (F3 - F1))).sqrt()),
        ]
    )


class _Elliptic:
    """Major- or minor-axis family, in the pole frame (pole = axis 3), Landau 37.10.

    ``ω = (A1 cn u, A2 sn u, s A3 dn u)`` with ``u = u0 + σ τ``, ``σ = s λ`` in the major
    family. In the minor family the pole frame has its moments in decreasing order, which turns
    the sign of every right-hand side of Euler's equations, so ``σ = -s λ``.
    """

    def __init__(self, J: np.ndarray, w: np.ndarray, delta: tuple[Fraction, Fraction, Fraction]):
        J1, J2, J3 = (float(x) for x in J)
        F1, F2, F3 = (Fraction(x) for x in (J1, J2, J3))
        e1, e2, e3 = delta  # exact
        self.J = J
        # λ, m, 1 - m, K and the mean precession rate ν from the exact rationals of the data,
        # at 45 digits: m and mc correctly rounded (no subtraction near the separatrix), λ, K
        # and ν as double-double pairs so that the phases u = u0 + σ τ (mod 2K) and ν τ
        # (mod 2π) stay exact to the rounding of τ itself over long runs (physics.precise).
        lam2 = (F3 - F2) * e1 / (F1 * F2 * F3)
        m_exact = (F1 - F2) * e3 / ((F3 - F2) * e1)
        mc_exact = (F3 - F1) * e2 / ((F3 - F2) * e1)
        N_exact = -F3 * (F2 - F1) / (F1 * (F3 - F2))
        wf = [Fraction(float(x)) for x in w]
        G2 = sum((Fk * wk) ** 2 for Fk, wk in zip((F1, F2, F3), wf, strict=True))
        m, mc = float(m_exact), float(mc_exact)
        with localcontext() as ctx:
            ctx.prec = precise.DIGITS
            dec = precise.decimal
            # Amplitudes (Landau 37.10, with Δi = G² - 2T Ii so that each ratio is a quotient
            # of same-signed quantities in both families); in decimal, so that a spin a hair
            # off an axis (Δ ~ 1e-600) still gets its representable amplitude ~1e-300.
            self.A = _amplitudes((F1, F2, F3), e1, e3)
            sqrt_mc = float(dec(mc_exact).sqrt())
            K_dec = elliptic.ellipk_decimal(mc_exact)
            pi_dec = elliptic.ellippi_complete_decimal(N_exact, mc_exact)
            G_dec = precise.decimal(G2).sqrt()
            c_dec = G_dec * precise.decimal((F3 - F1) / (F1 * F3))
            nu_dec = G_dec / precise.decimal(F3) + c_dec * pi_dec / K_dec
            lam, lam_lo = precise.double_double(precise.decimal(lam2).sqrt())
            K_hi, K_lo = precise.double_double(K_dec)
            nu = precise.double_double(nu_dec)
            pi_complete = float(pi_dec)
        self.par = elliptic.JacobiParameter.from_pair(m, mc, sqrt_mc=sqrt_mc, K=K_hi)
        self.s = 1.0 if w[2] > 0.0 else -1.0
        direction = 1.0 if J3 > J1 else -1.0
        self.lam = lam
        self.sigma = direction * self.s * lam
        K = K_hi
        # Initial phase u0 = F(φ0 | m), φ0 = atan2(sn0, cn0) (Landau after 37.10).
        sn0, cn0 = w[1] / self.A[1], w[0] / self.A[0]
        self.u0 = elliptic.ellipf_from_angle(sn0, cn0, self.par, sqrt_mc)
        self.phase = precise.LinearPhase(
            self.u0, self.sigma, direction * self.s * lam_lo, 2.0 * K_hi, 2.0 * K_lo
        )
        # Precession (Landau 37.16): φ' = G/J3 + c / (1 - N sn²u), N < 0, c = G(J3-J1)/(J1 J3).
        # Π(N; am u) = (Πc/K) u + P(u) with P 2K-periodic: the secular part joins G/J3 in the
        # mean rate ν, the periodic part is evaluated on the reduced argument.
        self.G = math.sqrt(float(G2))
        self.N = float(N_exact)
        self.c = self.G * ((J3 - J1) / J1 / J3)
        self.pi_slope = pi_complete / K
        self.nu = nu[0]
        self.precession = precise.angle_phase(nu)
        self.period = 4.0 * K / lam
        self.phase_scale = self.c / self.sigma
        self.P0 = self._periodic_pi(np.array([self.u0]))[0]
        self._series: np.ndarray | None | bool = False  # built on first long evaluation

    @property
    def sine_series(self) -> np.ndarray | None:
        """Sine coefficients of the precession wobble, or None where they converge too slowly.

        Built lazily (512 samples, ~0.2 ms): a body evaluated only at a few times never pays it.
        """
        if self._series is False:
            K = self.par.K
            self._series = _sine_series(lambda u: self.phase_scale * self._periodic_pi(u), K)
        return self._series

    def _reduced(self, tau: np.ndarray):
        r, j = self.phase.reduce(tau)
        sn, cn, dn = elliptic.sncndn_reduced(r, self.par)
        sign = 1.0 - 2.0 * np.mod(j, 2.0)
        return r, sign, sn, cn, dn

    def _periodic_pi(self, u: np.ndarray) -> np.ndarray:
        r, _ = elliptic.reduce_argument(u, self.par.K)
        sn, cn, dn = elliptic.sncndn_reduced(r, self.par)
        return elliptic.periodic_third_kind(self.N, self.pi_slope, self.par, r, sn, cn, dn)

    def omega(self, tau: np.ndarray) -> tuple[np.ndarray, ...]:
        _, sign, sn, cn, dn = self._reduced(tau)
        A1, A2, A3 = self.A
        return (A1 * sign * cn, A2 * sign * sn, (self.s * A3) * dn)

    def quat(self, tau: np.ndarray) -> tuple[tuple[np.ndarray, ...], np.ndarray]:
        r, sign, sn, cn, dn = self._reduced(tau)
        A1, A2, A3 = self.A
        w = (A1 * sign * cn, A2 * sign * sn, (self.s * A3) * dn)
        J1, J2, J3 = self.J
        phi = self.precession.reduce(tau)[0] + self.precession_wobble(r, sn, cn, dn)
        return w, _zxz_from_momentum(J1 * w[0], J2 * w[1], J3 * w[2], self.G, phi)

    def precession_wobble(self, r, sn, cn, dn) -> np.ndarray:
        """The periodic part of φ: ``(c/σ) (P(u) - P(u0))`` at the reduced argument ``r``.

        ``P`` is analytic and 2K-periodic, so away from the separatrix its sine series
        converges geometrically (the nome q decays the coefficients) and a few terms summed
        by Clenshaw's recurrence reproduce Carlson's ``R_F``/``R_J`` evaluation to rounding at
        a fraction of the cost. Where more terms would be needed (1 - m small), ``Π`` is
        evaluated directly per point.
        """
        # A handful of times (a renderer's frame) is cheaper through two Carlson calls than
        # through a Clenshaw sum of ~25 tiny-array steps; both agree to rounding.
        if r.shape[0] < _SERIES_MIN_POINTS or self.sine_series is None:
            P = elliptic.periodic_third_kind(self.N, self.pi_slope, self.par, r, sn, cn, dn)
            return self.phase_scale * (P - self.P0)
        theta = r * (math.pi / self.par.K)
        return _clenshaw_sine(self.sine_series, theta) - self.phase_scale * self.P0

    def polhode(self, n: int) -> tuple[np.ndarray, ...]:
        # Uniform in the amplitude φ = am u: sn = sin φ, cn = cos φ, dn² = cos²φ + mc sin²φ.
        ang = np.linspace(0.0, 2.0 * math.pi, n, endpoint=False)
        s, c = np.sin(ang), np.cos(ang)
        dn = np.sqrt(c * c + self.par.mc * s * s)
        A1, A2, A3 = self.A
        return (A1 * c, A2 * s, (self.s * A3) * dn)


# A periodic wobble of φ is represented by its sine series when this many terms or fewer reach
# the rounding floor of its samples (|b_k| <= _SERIES_TOL_EPS · eps · max|f|: below that the FFT
# coefficients are noise); _SERIES_SAMPLES >= 12 × the terms kept leaves aliasing negligible.
_SERIES_MAX_TERMS = 40
_SERIES_MIN_POINTS = 256
_SERIES_SAMPLES = 512
_SERIES_TOL_EPS = 4.0


def _sine_series(f, K: float) -> np.ndarray | None:
    """Sine coefficients ``b_1..b_n`` of an odd 2K-periodic ``f(u) = Σ b_k sin(kπu/K)``.

    Returns None when more than ``_SERIES_MAX_TERMS`` terms stand above the rounding floor (or
    the samples show ``f`` is not odd to rounding), so the caller evaluates ``f`` directly.
    """
    theta = 2.0 * math.pi * np.arange(_SERIES_SAMPLES) / _SERIES_SAMPLES
    values = f(theta * (K / math.pi))
    spectrum = np.fft.rfft(values)
    b = -2.0 * spectrum.imag / _SERIES_SAMPLES
    scale = float(np.abs(values).max())
    tol = _SERIES_TOL_EPS * np.finfo(float).eps * scale
    if np.abs(spectrum.real).max() / _SERIES_SAMPLES > 100.0 * tol:
        return None  # not odd to rounding: evaluate directly
    big = np.flatnonzero(np.abs(b[1:]) > tol)
    n = int(big[-1]) + 1 if big.size else 0
    if n > _SERIES_MAX_TERMS:
        return None
    return b[1 : n + 1].copy()


def _clenshaw_sine(b: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """``Σ_k b_k sin(k θ)`` by Clenshaw's recurrence (k = 1..len(b))."""
    if b.size == 0:
        return np.zeros_like(theta)
    two_cos = 2.0 * np.cos(theta)
    y1 = np.full_like(theta, b[-1])
    y2 = np.zeros_like(theta)
    for bk in b[-2::-1]:
        y1, y2 = bk + two_cos * y1 - y2, y1
    return y1 * np.sin(theta)


class _Separatrix:
    """The limiting polhode, ``Δ2 = 0`` exactly (seed 000 eq. 7.79, Landau §37 problem 2).

    ``ω = (s1 A1 sech u, A2 tanh u, s3 A3 sech u)``, ``u = u0 + s1 s3 λ τ``; with m = 1 the
    precession integral is elementary: ``∫ du / (1 - N tanh²u) = (u + a atan(a tanh u))/(1 - N)``
    with ``a = sqrt(-N)``.
    """

    def __init__(self, J: np.ndarray, w: np.ndarray, delta: tuple[float, float, float]):
        J1, J2, J3 = (float(x) for x in J)
        d1 = float(delta[0])
        self.J = J
        with localcontext() as ctx:
            ctx.prec = precise.DIGITS
            self.A = _amplitudes(tuple(Fraction(float(x)) for x in J), delta[0], delta[2])
        lam = math.sqrt((J3 - J2) / J1 * (d1 / J2) / J3)
        self.s1 = 1.0 if w[0] > 0.0 else -1.0
        self.s3 = 1.0 if w[2] > 0.0 else -1.0
        self.lam = lam
        self.sigma = self.s1 * self.s3 * lam
        # tanh u0 = ω2/A2 and sech u0 = |ω1|/A1, so sinh u0 = (ω2/A2) / (|ω1|/A1).
        self.u0 = math.asinh((w[1] / self.A[1]) / (abs(w[0]) / self.A[0]))
        self.G = float(np.linalg.norm(J * w))
        N = -J3 / J1 * ((J2 - J1) / (J3 - J2))
        self.a = math.sqrt(-N)
        c = self.G * ((J3 - J1) / J1 / J3)
        # The mean rate ν = G/J3 + c/(1 - N) to double-double, as in _Elliptic.
        F1, F2, F3 = (Fraction(float(x)) for x in J)
        G2 = sum((Fk * Fraction(float(wk))) ** 2 for Fk, wk in zip((F1, F2, F3), w, strict=True))
        with localcontext() as ctx:
            ctx.prec = precise.DIGITS
            G_dec = precise.decimal(G2).sqrt()
            N_dec = precise.decimal(-F3 * (F2 - F1) / (F1 * (F3 - F2)))
            nu_dec = G_dec / precise.decimal(F3) + G_dec * precise.decimal(
                (F3 - F1) / (F1 * F3)
            ) / (1 - N_dec)
            nu = precise.double_double(nu_dec)
        self.nu = nu[0]
        self.precession = precise.angle_phase(nu)
        self.amp = c * self.a / (self.sigma * (1.0 - N))
        self.period = math.inf
        self.atan0 = math.atan(self.a * math.tanh(self.u0))

    def omega(self, tau: np.ndarray) -> tuple[np.ndarray, ...]:
        th, sech = elliptic.tanh_sech(self.u0 + self.sigma * tau)
        A1, A2, A3 = self.A
        return ((self.s1 * A1) * sech, A2 * th, (self.s3 * A3) * sech)

    def quat(self, tau: np.ndarray) -> tuple[tuple[np.ndarray, ...], np.ndarray]:
        th, sech = elliptic.tanh_sech(self.u0 + self.sigma * tau)
        A1, A2, A3 = self.A
        w = ((self.s1 * A1) * sech, A2 * th, (self.s3 * A3) * sech)
        phi = self.precession.reduce(tau)[0] + self.amp * (np.arctan(self.a * th) - self.atan0)
        J1, J2, J3 = self.J
        return w, _zxz_from_momentum(J1 * w[0], J2 * w[1], J3 * w[2], self.G, phi)

    def polhode(self, n: int) -> tuple[np.ndarray, ...]:
        # The heteroclinic arc from -e2 to +e2: with φ = gd(u), tanh u = sin φ, sech u = cos φ.
        ang = np.linspace(-_HALF_PI, _HALF_PI, n)
        c, s = np.cos(ang), np.sin(ang)
        A1, A2, A3 = self.A
        return ((self.s1 * A1) * c, A2 * s, (self.s3 * A3) * c)


class _Circular:
    """Uniform motions: symmetric body, sphere, permanent rotation, rest (seed 003).

    The body precesses about L at ``p = G/I`` and spins about its symmetry axis ``e`` at
    ``s = ((I - J)/I) ω_e`` relative to the precessing frame, so in the internal frame (which
    here is the sorted body frame, with space = the caller's space)
    ``R(t) = Rot(L̂, p t) · R(0) · Rot(e, s t)`` and ``ω(t) = Rot(e, -s t) ω0``. A permanent
    rotation or a rest is the case ``I = J`` along the axis of ω.
    """

    def __init__(
        self, w: np.ndarray, axis: np.ndarray, I_t: float, J_a: float, inertia: np.ndarray
    ):
        self.w0 = w
        self.axis = axis
        self.G = float(np.linalg.norm(inertia * w))
        w_axial = float(w @ axis)
        # The two rates to double-double from the exact data, so that the angles p τ and s τ
        # (reduced mod 2π) stay exact over long runs (physics.precise).
        G2 = sum(
            (Fraction(float(i)) * Fraction(float(x))) ** 2 for i, x in zip(inertia, w, strict=True)
        )
        It, Ja = Fraction(I_t), Fraction(J_a)
        with localcontext() as ctx:
            ctx.prec = precise.DIGITS
            p = precise.double_double(precise.decimal(G2).sqrt() / precise.decimal(It))
            spin = precise.double_double(precise.decimal((It - Ja) / It * Fraction(w_axial)))
        self.p, self.spin = p[0], spin[0]
        self.precession = precise.angle_phase(p)
        self.spinning = precise.angle_phase(spin)
        w_perp = w - w_axial * axis
        moving = self.spin != 0.0 and np.any(w_perp != 0.0)
        self.period = 2.0 * math.pi / abs(self.spin) if moving else math.inf
        self.nu = self.p

    def omega_rotated(self, angle: np.ndarray) -> tuple[np.ndarray, ...]:
        # Rodrigues with a unit axis e: v cos a + (e × v) sin a + e (e·v)(1 - cos a).
        e, v = self.axis, self.w0
        c, s = np.cos(angle), np.sin(angle)
        ev = float(e @ v)
        exv = np.cross(e, v)
        return tuple(v[k] * c + exv[k] * s + e[k] * ev * (1.0 - c) for k in range(3))

    def omega(self, tau: np.ndarray) -> tuple[np.ndarray, ...]:
        if self.spin == 0.0:
            return tuple(np.full(tau.shape, self.w0[k]) for k in range(3))
        return self.omega_rotated(-self.spinning.reduce(tau)[0])

    def polhode(self, n: int) -> tuple[np.ndarray, ...]:
        if self.period == math.inf:
            return tuple(np.full(n, self.w0[k]) for k in range(3))
        return self.omega_rotated(np.linspace(0.0, 2.0 * math.pi, n, endpoint=False))


# ---------------------------------------------------------------------------------------------
# The public object.
# ---------------------------------------------------------------------------------------------


class FreeRigidBody:
    """Exact torque-free motion of a rigid body from its principal moments and initial ω.

    Args:
        inertia: (3,) principal moments ``(I1, I2, I3)``, positive and finite, in any order;
            they name the caller's body axes and every result uses the same axes.
        omega0: (3,) body-frame angular velocity at ``t = 0`` [rad per time unit].
        attitude0: attitude at ``t = 0`` as a single :class:`scipy.spatial.transform.Rotation`
            (body -> space); ``None`` means the identity (space axes = body axes at t = 0).

    Raises:
        ValueError: moments not positive or not finite, ω0 not finite, wrong shapes, or an
            ``attitude0`` that is not a single rotation.

    The constructor classifies the motion (:attr:`regime`) and precomputes the constants;
    :meth:`omega` and :meth:`attitude` then cost O(1) per time, for any time, with no drift.
    The moments need not obey the triangle inequality ``I1 + I2 >= I3``: the mathematics holds
    for any positive moments, only real mass distributions must obey it.
    """

    def __init__(self, inertia, omega0, attitude0: Rotation | None = None):
        self.inertia = _check_inertia(inertia)
        self.omega0 = _vector3(omega0, "the initial angular velocity omega0")
        if attitude0 is None:
            attitude0 = Rotation.identity()
        if not isinstance(attitude0, Rotation) or not attitude0.single:
            raise ValueError("attitude0 must be one scipy Rotation (body -> space) or None")
        self.attitude0 = attitude0

        if self.inertia.max() / 1e300 > self.inertia.min():
            raise ValueError(
                "the moments of inertia span more than 300 decades "
                f"({self.inertia.min():g} to {self.inertia.max():g}): beyond double precision"
            )
        # Exact power-of-two scaling: moments and ω near 1 whatever the caller's units.
        self._I_ref = _pow2(float(self.inertia.max()))
        w_max = float(np.abs(self.omega0).max())
        self._w_ref = _pow2(w_max) if w_max > 0.0 else 1.0
        inertia_s = self.inertia / self._I_ref
        omega_s = self.omega0 / self._w_ref

        sort = _sorting_map(self.inertia)
        J = sort.to_internal(inertia_s) * sort.sign  # moments are not signed
        w = sort.to_internal(omega_s)
        self._classify_and_build(sort, J, w, inertia_s, omega_s)

        # Invariants: computed in the scaled units, then scaled back by exact powers of two, so
        # they over/underflow only where the physical value itself is out of double range.
        L_scaled = self.attitude0.apply(inertia_s * omega_s)
        two_T_scaled = float(omega_s @ (inertia_s * omega_s))
        G_scaled = float(np.linalg.norm(L_scaled))
        self._two_T_scaled, self._inertia_scaled = two_T_scaled, inertia_s
        self.angular_momentum = L_scaled * self._I_ref * self._w_ref
        self.energy = 0.5 * two_T_scaled * self._I_ref * self._w_ref * self._w_ref
        if self.regime is Regime.REST:
            self.D = 0.0
            self.plane_distance = 0.0
            self.plane_normal = np.array([0.0, 0.0, 1.0])
        else:
            self.D = self._scaled_D * self._I_ref
            self.plane_distance = self._scaled_h * self._w_ref
            self.plane_normal = L_scaled / G_scaled

    # -- construction ---------------------------------------------------------------------

    def _classify_and_build(self, sort, J, w, inertia_s, omega_s) -> None:
        J1, J2, J3 = J
        m = J * w
        G2 = float(m @ m)
        two_T = float(w @ m)
        self._scaled_D = G2 / two_T if two_T > 0 else 0.0
        self._scaled_h = two_T / math.sqrt(G2) if G2 > 0 else 0.0
        self._frame = sort
        self._solver: _Elliptic | _Separatrix | _Circular
        self.parameter = 0.0
        self.complementary_parameter = 1.0
        self.frequency = 0.0

        zero = w == 0.0
        if zero.all():
            regime = Regime.REST
            axis = np.array([0.0, 0.0, 1.0])
            circ = _Circular(omega_s, axis, 1.0, 1.0, inertia_s)
        elif J1 == J3:
            regime = Regime.SPHERE
            circ = _Circular(omega_s, np.array([0.0, 0.0, 1.0]), float(J1), float(J1), inertia_s)
        else:
            circ = self._circular_or_none(sort, J, w, zero, inertia_s, omega_s)
            regime = None if circ is None else circ[0]
            circ = None if circ is None else circ[1]
        if circ is not None:
            self.regime = regime
            self._solver = circ
            self._frame = None  # _Circular works in the caller's own body frame
            self._q_space = self.attitude0.as_quat()
            self.period = circ.period / self._w_ref
            self._finish_precession(circ.nu)
            return

        # Triaxial and not a permanent rotation: Δi = G² - 2T·Ii, exactly rounded (below).
        delta = _deltas(J, w)
        if delta[1] == 0.0:
            self.regime = Regime.SEPARATRIX
            solver = _Separatrix(J, w, delta)
            self.parameter, self.complementary_parameter = 1.0, 0.0
        else:
            if delta[1] > 0.0:
                self.regime = Regime.MAJOR_AXIS
                pole = sort
                Jp, wp, dp = J, w, delta
            else:
                self.regime = Regime.MINOR_AXIS
                pole = sort.compose(_REVERSE)
                Jp, wp = _REVERSE.to_internal(J) * _REVERSE.sign, _REVERSE.to_internal(w)
                dp = (delta[2], delta[1], delta[0])
            solver = _Elliptic(Jp, wp, dp)
            self._frame = pole
            self.parameter = solver.par.m
            self.complementary_parameter = solver.par.mc
        self._solver = solver
        self.frequency = solver.lam * self._w_ref
        self.period = solver.period / self._w_ref
        self._finish_precession(solver.nu)
        # Anchor ω at t = 0: the closed form reproduces ω0 only to O(eps · amplitude) (through
        # u0 = F(φ0|m) and back through sn, cn, dn); adding the constant ω0 - f(0) makes
        # omega(0) return ω0 exactly and changes no other value by more than that rounding.
        cols0, q0 = solver.quat(np.zeros(1))
        self._anchor = omega_s - self._frame.to_user_columns(cols0)[0]
        # R_user(t) = S · R_int(t) · C with S fixed so that R_user(0) = attitude0.
        conj = np.array([-1.0, -1.0, -1.0, 1.0])
        self._q_space = _qmul(
            _qmul(self.attitude0.as_quat(), self._frame.quat * conj), q0[0] * conj
        )

    def _circular_or_none(self, sort, J, w, zero, inertia_s, omega_s):
        """Permanent rotations and symmetric bodies: (regime, _Circular), else None."""
        J1, J2, J3 = J
        e_user = [sort.matrix[k] for k in range(3)]  # internal axis k in user coordinates
        if zero.sum() == 2:  # along one principal axis of a triaxial body
            k = int(np.flatnonzero(~zero)[0])
            return Regime.PERMANENT_ROTATION, _Circular(
                omega_s, e_user[k], float(J[k]), float(J[k]), inertia_s
            )
        if J1 == J2 or J2 == J3:
            a = 2 if J1 == J2 else 0  # the distinct (symmetry) axis
            I_t = float(J[1])
            transverse = [k for k in range(3) if k != a]
            if zero[a] or (zero[transverse[0]] and zero[transverse[1]]):
                regime = Regime.PERMANENT_ROTATION
            else:
                regime = Regime.SYMMETRIC
            return regime, _Circular(omega_s, e_user[a], I_t, float(J[a]), inertia_s)
        return None

    def _finish_precession(self, nu_scaled: float) -> None:
        self.mean_precession_rate = nu_scaled * self._w_ref
        if math.isfinite(self.period):
            self.precession_per_period = self.mean_precession_rate * self.period
            self.second_period = (
                2.0 * math.pi / self.mean_precession_rate
                if self.mean_precession_rate != 0.0
                else math.inf
            )
        else:
            self.precession_per_period = 0.0
            self.second_period = math.inf

    # -- evaluation -----------------------------------------------------------------------

    def _omega_user(self, tau: np.ndarray) -> np.ndarray:
        if tau.shape[0] > _BLOCK:  # cache-sized blocks, as in _quat_user
            out = np.empty((tau.shape[0], 3))
            for start in range(0, tau.shape[0], _BLOCK):
                out[start : start + _BLOCK] = self._omega_user(tau[start : start + _BLOCK])
            return out
        cols = self._solver.omega(tau)
        if self._frame is None:
            return np.stack(cols, axis=-1) * self._w_ref
        return (self._frame.to_user_columns(cols) + self._anchor) * self._w_ref

    def omega(self, t):
        """Body-frame angular velocity ω(t) in the caller's axes [rad per time unit].

        Args:
            t: time, a float or a (N,) array.

        Returns:
            (3,) for a scalar ``t``, (N, 3) for an array.
        """
        tt, scalar = _check_times(t)
        out = self._omega_user(tt * self._w_ref)
        return out[0] if scalar else out

    def _quat_user(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
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

    def _quat_block(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        solver = self._solver
        if isinstance(solver, _Circular):
            q = _axis_angle_quat(self.plane_normal, solver.precession.reduce(tau)[0])
            q = _qmul(q, self._q_space)
            if solver.spin != 0.0:
                q = _qmul(q, _axis_angle_quat(solver.axis, solver.spinning.reduce(tau)[0]))
            return self._omega_user(tau), q
        cols, q_int = solver.quat(tau)
        q = _qmul(self._q_space, _qmul(q_int, self._frame.quat))
        return (self._frame.to_user_columns(cols) + self._anchor) * self._w_ref, q

    def attitude(self, t) -> Rotation:
        """Attitude R(t), body -> space, as a scipy Rotation (single, or a stack of N).

        ``attitude(0)`` equals ``attitude0`` to rounding.
        """
        tt, scalar = _check_times(t)
        _, q = self._quat_user(tt * self._w_ref)
        rot = Rotation.from_quat(q)
        return rot[0] if scalar else rot

    def state(self, t) -> tuple[np.ndarray, Rotation]:
        """ω(t) and R(t) from one evaluation: ((N,3) or (3,), Rotation); see :meth:`sample`."""
        w, rot, _ = self.sample(t)
        return w, rot

    def contact_point(self, t) -> np.ndarray:
        """The tip of ω in space, ``R(t) ω(t)`` (the herpolhode): (3,) or (N, 3).

        It lies on the invariable plane ``x·L = 2T``, where the energy ellipsoid touches it.
        """
        return self.sample(t)[2]

    def sample(self, t) -> tuple[np.ndarray, Rotation, np.ndarray]:
        """ω(t), R(t) and the contact point ``R(t) ω(t)`` from one evaluation.

        Args:
            t: a float or a (N,) array of times.

        Returns:
            ``(omega, attitude, contact)``: (3,) or (N, 3) body-frame ω; a Rotation (single or
            stack); (3,) or (N, 3) space-frame contact point. This is what a renderer needs per
            frame, at the cost of one :meth:`attitude` call.
        """
        tt, scalar = _check_times(t)
        w, q = self._quat_user(tt * self._w_ref)
        contact = _rotate(q, w)
        rot = Rotation.from_quat(q)
        if scalar:
            return w[0], rot[0], contact[0]
        return w, rot, contact

    herpolhode = contact_point

    def polhode(self, n: int = 256) -> np.ndarray:
        """The polhode: the closed curve ω traces in the body frame (caller's axes), (n, 3).

        Points are spaced uniformly in the amplitude (not in time, which would crowd them near
        the separatrix); the curve closes from the last point back to the first. On the
        separatrix it is the arc between the two intermediate-axis poles, endpoints included;
        for a constant ω it is that one point repeated.
        """
        if int(n) < 2:
            raise ValueError(f"the polhode needs at least 2 points, got n={n}")
        cols = self._solver.polhode(int(n))
        if self._frame is None:
            return np.stack(cols, axis=-1) * self._w_ref
        return self._frame.to_user_columns(cols) * self._w_ref

    @property
    def semi_axes(self) -> np.ndarray:
        """(3,) semi-axes ``sqrt(2T/Ii)`` of the energy ellipsoid ``x·I·x = 2T`` (caller order)."""
        # From the scaled state (2T/I_i = w_ref² · 2T_s/I_s,i): no underflow at ω ~ 1e-200.
        return np.sqrt(self._two_T_scaled / self._inertia_scaled) * self._w_ref

    def __repr__(self) -> str:
        return (
            f"FreeRigidBody(inertia={self.inertia.tolist()}, omega0={self.omega0.tolist()}, "
            f"regime={self.regime.value!r})"
        )


def _deltas(J: np.ndarray, w: np.ndarray) -> tuple[Fraction, Fraction, Fraction]:
    """``Δi = G² - 2T·Ii = Σ_j Ij ωj² (Ij - Ii)`` (sorted axes, PHYSICS.md "Cancellation"), exactly.

    Δ2 is the small difference that decides the regime and gives ``1 - m``; near the separatrix
    its two terms cancel. Summed in rational arithmetic (a few scalars, once per body), the
    classification ``Δ2 == 0`` and every constant derived from the Δs are those of the exact
    data, rounded once.
    """
    # Every double is an integer multiple of 2^-1074: scaled by 2^_EXACT_SHIFT they become
    # Python integers, and sums of products of integers are exact (and cheaper than Fractions).
    Ji = [_exact_int(x) for x in J]
    wi = [_exact_int(x) for x in w]
    sq = [Ji[j] * wi[j] * wi[j] for j in range(3)]
    scale = 1 << (4 * _EXACT_SHIFT)
    return (
        Fraction(sq[1] * (Ji[1] - Ji[0]) + sq[2] * (Ji[2] - Ji[0]), scale),
        Fraction(sq[0] * (Ji[0] - Ji[1]) + sq[2] * (Ji[2] - Ji[1]), scale),
        Fraction(sq[0] * (Ji[0] - Ji[2]) + sq[1] * (Ji[1] - Ji[2]), scale),
    )


_EXACT_SHIFT = 1100


def _exact_int(x: float) -> int:
    """``x · 2^_EXACT_SHIFT`` as an exact integer (finite doubles are multiples of 2^-1074)."""
    n, d = float(x).as_integer_ratio()
    return n * ((1 << _EXACT_SHIFT) // d)


# ---------------------------------------------------------------------------------------------
# Initial states for the scene.
# ---------------------------------------------------------------------------------------------


def omega_from_energy(
    inertia, D: float, omega_norm: float = 1.0, pole_sign: float = 1.0
) -> np.ndarray:
    """An initial ω with ``|L|²/2T = D``, on the plane ``ω2 = 0`` of the sorted axes.

    Args:
        inertia: (3,) positive moments in the caller's order.
        D: the energy parameter ``|L|²/2T`` in ``[min I, max I]`` (same units as the moments).
        omega_norm: the length of the returned ω [rad per time unit], > 0.
        pole_sign: +1 or -1, which of the two polhodes with this D (the sign of the component
            on the axis the polhode circles: the largest-moment axis when ``D > I2``, the
            smallest-moment axis otherwise).

    Returns:
        (3,) ω0 in the caller's axes.

    With ``m2 = 0`` the momentum sphere ``|m| = G`` and the ellipsoid ``Σ mi²/Ii = G²/D`` meet
    where ``m1² = G² I1 (I3 - D)/(D (I3 - I1))`` and ``m3² = G² I3 (D - I1)/(D (I3 - I1))``
    (sorted axes). ``D = I1`` or ``I3`` is the pure spin about that axis; ``D = I2`` lands on
    the separatrix up to rounding.

    Raises:
        ValueError: if D lies outside ``[min I, max I]``, or omega_norm is not positive.
    """
    inertia = _check_inertia(inertia)
    D = float(D)
    if not math.isfinite(D):
        raise ValueError(f"D must be a finite number, got {D}")
    if not (math.isfinite(omega_norm) and omega_norm > 0.0):
        raise ValueError(f"|omega0| must be positive and finite, got {omega_norm}")
    lo, hi = float(inertia.min()), float(inertia.max())
    if not (lo <= D <= hi):
        raise ValueError(
            "D = |L|²/2T must lie between the smallest and largest moments "
            f"[{lo:g}, {hi:g}], got {D:g}"
        )
    sort = _sorting_map(inertia)
    J1, J2, J3 = np.sort(inertia)
    sign = 1.0 if pole_sign >= 0 else -1.0
    if J1 == J3:
        m = np.array([0.0, 0.0, 1.0])
    else:
        m1 = math.sqrt(max(J1 * (J3 - D) / (D * (J3 - J1)), 0.0))
        m3 = math.sqrt(max(J3 * (D - J1) / (D * (J3 - J1)), 0.0))
        if D > J2 or (D == J2 and m3 > 0):
            m = np.array([m1, 0.0, sign * m3])
        else:
            m = np.array([sign * m1, 0.0, m3])
    w_sorted = m / np.array([J1, J2, J3])
    w_sorted *= omega_norm / np.linalg.norm(w_sorted)
    # Back to the caller's axes: a plain permutation (a vector needs no proper relabelling,
    # and the sign flip would reverse the pole component the caller chose).
    out = np.empty(3)
    out[sort.index] = w_sorted
    return out


def attitude_with_L_along_z(inertia, omega0) -> Rotation:
    """An attitude ``R0`` (body -> space) with ``R0 · I ω0`` along +z: L vertical in the scene.

    Args:
        inertia: (3,) positive moments (caller's axes). omega0: (3,) body-frame ω.

    Returns:
        A single Rotation; the identity for a body at rest.
    """
    inertia = _check_inertia(inertia)
    omega0 = _vector3(omega0, "omega0")
    m = inertia * omega0
    G = float(np.linalg.norm(m))
    if G == 0.0:
        return Rotation.identity()
    # Smallest rotation taking m̂ to e_z (the roll about L is irrelevant to the scene).
    mhat = m / G
    z = np.array([0.0, 0.0, 1.0])
    axis = np.cross(mhat, z)
    s = float(np.linalg.norm(axis))
    c = float(mhat @ z)
    if s < 1e-300:
        return Rotation.identity() if c > 0 else Rotation.from_rotvec([math.pi, 0.0, 0.0])
    return Rotation.from_rotvec(axis / s * math.atan2(s, c))
