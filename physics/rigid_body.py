"""The exact motion of a free rigid body: angular velocity and attitude in closed form.

Solve once, evaluate many: :class:`FreeRigidBody` classifies the motion from the initial state
(:class:`~physics.regime.Regime`), precomputes the constants of the closed form, and then
evaluates ω(t) and the attitude R(t) on whole arrays of times with no integration and no drift.
A single float time takes a plain-float path with the same operations (the same values), so
that constructing a body and evaluating it once costs a fraction of a millisecond.

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
of two scale floating-point numbers exactly, except that a component more than ~1e308 below the
largest underflows: the classification (``Δ2 == 0``), the signs and every constant of the
closed form are therefore taken from the exact integers of the caller's own numbers
(:class:`_Exact`), never from the scaled floats.

Policy: for any finite input the API returns finite results, or raises a ValueError that says
what is out of range and what to change -- a time so far that a phase (rate × t) would pass
1e300 rad, or a quantity of the motion beyond the double range in the caller's units (an
energy ~1e400: read through its property, the rest of the motion stays available).
"""

from __future__ import annotations

import functools
import math
from decimal import Decimal, localcontext

import numpy as np
from poinsot.physics import elliptic, precise
from poinsot.physics.regime import Regime
from scipy import special
from scipy.spatial.transform import Rotation

__all__ = ["FreeRigidBody", "omega_from_energy", "attitude_with_L_along_z"]

_HALF_PI = 0.5 * math.pi
# The phases rate·τ of the closed forms are kept below this (FreeRigidBody._scaled_times).
_PHASE_LIMIT = 1e300
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
    if not all(map(math.isfinite, arr.tolist())):
        raise ValueError(f"{name} must be finite, got {arr.tolist()}")
    return arr


def _check_inertia(value) -> np.ndarray:
    inertia = _vector3(value, "the moments of inertia")
    if min(inertia.tolist()) <= 0.0:
        raise ValueError(
            f"the moments of inertia must be positive, got {inertia.tolist()} "
            "(a principal moment is a sum of m·r², never zero or negative)"
        )
    return inertia


def _check_times(t) -> float | np.ndarray:
    """The times as a float if the caller passed one number, else as a 1-D float array."""
    if isinstance(t, float):  # the common scalar (also numpy.float64): no array round trip
        if not math.isfinite(t):
            raise ValueError("time must be finite (got NaN or infinity)")
        return float(t)
    try:
        arr = np.asarray(t, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"time must be a number or a 1-D array of numbers, got {t!r}") from exc
    if arr.ndim > 1:
        raise ValueError(f"time must be a number or a 1-D array, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError("time must be finite (got NaN or infinity)")
    return float(arr) if arr.ndim == 0 else arr


def _ldexp(x: float, e: int) -> float:
    """``x · 2^e`` exactly (as math.ldexp), inf (not an OverflowError) beyond the range."""
    try:
        return math.ldexp(x, e)
    except OverflowError:
        return math.copysign(math.inf, x)


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
        # Plain-float copies for the single-time path.
        self.pairs = tuple((int(i), float(x)) for i, x in zip(index, sign, strict=True))
        self.quat_tuple = tuple(float(x) for x in self.quat)

    def to_internal(self, x: np.ndarray) -> np.ndarray:
        return self.sign * x[..., self.index]

    def to_user_columns(self, cols: tuple[np.ndarray, ...]) -> np.ndarray:
        """Stack internal components ``cols[k]`` (each (N,)) into user-order (N, 3)."""
        out = np.empty((cols[0].shape[0], 3))
        for k in range(3):
            out[:, self.index[k]] = self.sign[k] * cols[k]
        return out

    def to_user_tuple(self, cols: tuple[float, ...]) -> list[float]:
        """:meth:`to_user_columns` for one sample of plain floats (a list in user order)."""
        out = [0.0, 0.0, 0.0]
        for (i, sign), col in zip(self.pairs, cols, strict=True):
            out[i] = sign * col
        return out

    def compose(self, other: _AxisMap) -> _AxisMap:
        """The map ``other ∘ self`` (apply self first)."""
        return _compose(self, other)


@functools.cache
def _compose(first: _AxisMap, then: _AxisMap) -> _AxisMap:
    """``then ∘ first`` (the maps are singletons, so this table has at most 24² entries)."""
    return _axis_map(
        tuple(int(i) for i in first.index[then.index]),
        tuple(float(x) for x in then.sign * first.sign[then.index]),
    )


@functools.cache
def _axis_map(index: tuple[int, ...], sign: tuple[float, ...]) -> _AxisMap:
    return _AxisMap(index, sign)


def _sorting_map(inertia: np.ndarray) -> _AxisMap:
    """Proper relabelling that sorts the moments ascending (an odd permutation flips axis 1)."""
    values = inertia.tolist()
    order = tuple(sorted(range(3), key=values.__getitem__))  # stable, as argsort(kind="stable")
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
    m1: np.ndarray, m2: np.ndarray, m3: np.ndarray, G: float, phi: np.ndarray, psi=None
) -> np.ndarray:
    """Quaternion of ``Rz(φ) Rx(θ) Rz(ψ)`` with θ, ψ read off ``m/G`` (Landau 37.13-37.14).

    ``cos θ = m3/G``, ``sin θ = ρ/G`` with ``ρ = hypot(m1, m2)``, ``ψ = atan2(m1, m2)``. The
    half-angle of θ is taken from whichever of ``G ± m3`` has no cancellation
    (``G - m3 = ρ²/(G + m3)``), so it is accurate at both poles. ``psi`` may be given when
    m1, m2 are known only up to a common factor more accurately than themselves.
    """
    rho = np.hypot(m1, m2)
    if psi is None:
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


def _zxz_from_chi(m1, m2, m3, G: float, chi, psi_r, sign, upper: bool) -> np.ndarray:
    """:func:`_zxz_from_momentum` from the slow angle ``χ = φ + sψ`` (``s = +1`` if ``upper``).

    ``ψ = ψ_r + π(1 - sign)/2`` with ``sign = ±1`` (the parity of the half-period count j),
    ``ψ_r`` from the reduced argument. With the half-angles ``(φ ± ψ)/2`` written through χ,
    a shift of ψ by π only flips the sign of two quaternion components. For ``s = +1`` (pole
    component > 0, θ < π/2): ``(φ+ψ)/2 = χ/2``, ``(φ-ψ)/2 = χ/2 - ψ``; for ``s = -1``:
    ``(φ-ψ)/2 = χ/2``, ``(φ+ψ)/2 = χ/2 + ψ``.
    """
    rho = np.hypot(m1, m2)
    big = np.sqrt(0.5 * (G + np.abs(m3)) / G)  # the larger of cos(θ/2), sin(θ/2)
    small = rho / (2.0 * G * big)
    half = 0.5 * chi
    if upper:  # cos(θ/2) = big
        a = half - psi_r
        sa = sign * small
        return np.stack(
            [sa * np.cos(a), sa * np.sin(a), big * np.sin(half), big * np.cos(half)], axis=-1
        )
    b = half + psi_r  # sin(θ/2) = big
    sb = sign * small
    return np.stack(
        [big * np.cos(half), big * np.sin(half), sb * np.sin(b), sb * np.cos(b)], axis=-1
    )


# The same four helpers for one sample in plain floats (tuples): a single time costs a few
# microseconds this way instead of dozens of numpy calls on 1-element arrays. Same operations
# in the same order, and numpy's own transcendental functions (on a float they run the same
# kernel as on an array; libm's may differ by an ulp), so they agree with the array versions
# to the last bit.


def _qmul_scalar(p: tuple[float, ...], q: tuple[float, ...]) -> tuple[float, ...]:
    """:func:`_qmul` for two single quaternions."""
    px, py, pz, pw = p
    qx, qy, qz, qw = q
    return (
        pw * qx + px * qw + py * qz - pz * qy,
        pw * qy - px * qz + py * qw + pz * qx,
        pw * qz + px * qy - py * qx + pz * qw,
        pw * qw - px * qx - py * qy - pz * qz,
    )


def _rotate_scalar(q: tuple[float, ...], v: tuple[float, ...]) -> tuple[float, ...]:
    """:func:`_rotate` for one quaternion and one vector."""
    x, y, z, w = q
    vx, vy, vz = v
    tx = y * vz - z * vy + w * vx
    ty = z * vx - x * vz + w * vy
    tz = x * vy - y * vx + w * vz
    return (
        vx + 2.0 * (y * tz - z * ty),
        vy + 2.0 * (z * tx - x * tz),
        vz + 2.0 * (x * ty - y * tx),
    )


def _axis_angle_scalar(axis: tuple[float, ...], angle: float) -> tuple[float, ...]:
    """:func:`_axis_angle_quat` for one angle."""
    half = 0.5 * angle
    s = float(np.sin(half))
    return (axis[0] * s, axis[1] * s, axis[2] * s, float(np.cos(half)))


def _zxz_scalar(
    m1: float, m2: float, m3: float, G: float, phi: float, psi: float | None = None
) -> tuple[float, ...]:
    """:func:`_zxz_from_momentum` for one sample."""
    rho = float(np.hypot(m1, m2))
    if psi is None:
        psi = float(np.arctan2(m1, m2))
    big = math.sqrt(0.5 * (G + abs(m3)) / G)
    small = rho / (2.0 * G * big)
    cos_half, sin_half = (big, small) if m3 >= 0.0 else (small, big)
    sum_half = 0.5 * (phi + psi)
    dif_half = 0.5 * (phi - psi)
    return (
        sin_half * float(np.cos(dif_half)),
        sin_half * float(np.sin(dif_half)),
        cos_half * float(np.sin(sum_half)),
        cos_half * float(np.cos(sum_half)),
    )


def _zxz_chi_scalar(
    m1: float, m2: float, m3: float, G: float, chi: float, psi_r: float, sign: float, upper: bool
) -> tuple[float, ...]:
    """:func:`_zxz_from_chi` for one sample."""
    rho = float(np.hypot(m1, m2))
    big = math.sqrt(0.5 * (G + abs(m3)) / G)
    small = rho / (2.0 * G * big)
    half = 0.5 * chi
    if upper:
        a = half - psi_r
        sa = sign * small
        return (
            sa * float(np.cos(a)),
            sa * float(np.sin(a)),
            big * float(np.sin(half)),
            big * float(np.cos(half)),
        )
    b = half + psi_r
    sb = sign * small
    return (
        big * float(np.cos(half)),
        big * float(np.sin(half)),
        sb * float(np.sin(b)),
        sb * float(np.cos(b)),
    )


# ---------------------------------------------------------------------------------------------
# The three closed forms. Each works in its internal frame and dimensionless time τ = t·ω_ref.
# ---------------------------------------------------------------------------------------------


def _dyadic(values, exp2: int = 0) -> tuple[tuple[int, ...], int]:
    """Exact integers ``n_k`` and one shift ``e >= 0`` with ``values[k] / 2^exp2 = n_k / 2^e``.

    Every finite double is a dyadic rational, so a few of them share a power-of-two
    denominator; the shift is the smallest that serves them all, which keeps the integers
    (and every product of them below) as short as the data allow. ``exp2`` divides the values
    by an exact power of two (a change of units) without rounding them first.
    """
    ratios = [float(x).as_integer_ratio() for x in values]
    bits = [d.bit_length() - 1 for _, d in ratios]  # each denominator is 2^bits
    top = max(bits)
    ints = tuple(n << (top - b) for (n, _), b in zip(ratios, bits, strict=True))
    shift = top + exp2
    if shift < 0:
        return tuple(n << -shift for n in ints), 0
    return ints, shift


def _asinh_sqrt_ratio(num: int, den: int) -> float:
    """``asinh(sqrt(num/den))`` for integers of the same sign (or ``num = 0``), no overflow.

    Beyond ``sqrt(num/den) = 2^500`` (a separatrix start within 1e-150 of the unstable axis),
    ``asinh x = ln(2x) + O(1/x²)`` is taken in decimal arithmetic from the exact ratio.
    """
    if den < 0:
        num, den = -num, -den
    if num < den << 1000:
        return math.asinh(_sqrt_ratio(num, den))
    with localcontext() as ctx:
        ctx.prec = precise.DIGITS
        return float((4 * precise.ratio(num, den)).ln() / 2)


def _sqrt_ratio(num: int, den: int) -> float:
    """``sqrt(num/den)`` correctly rounded, for integers of the same sign (or ``num = 0``).

    ``q = isqrt(floor(num·4^k/den)) = floor(sqrt(num/den)·2^k)`` with k chosen so that q has
    ~64 bits; when the root is inexact its lowest bit is set (a sticky bit below the rounding
    position), so rounding q to a double rounds the exact root. A result outside the normal
    range (not met by the amplitudes of scaled data) is left to decimal arithmetic.
    """
    if den < 0:
        num, den = -num, -den
    if num <= 0:
        return 0.0 if num == 0 else math.nan
    k = (128 - num.bit_length() + den.bit_length()) // 2
    if k >= 0:
        x, rem = divmod(num << (2 * k), den)
    else:
        x, rem = divmod(num, den << (-2 * k))
    q = math.isqrt(x)
    if rem or q * q != x:
        q |= 1
    if not -1020 <= q.bit_length() - k <= 1023:
        with localcontext() as ctx:
            ctx.prec = precise.DIGITS
            return float(precise.ratio(num, den).sqrt())
    return math.ldexp(float(q), -k)


class _Exact:
    """The scaled moments and ω of a body frame as exact integers, and its exact ``Δi``.

    ``J_k = Jn_k / 2^S`` and ``ω_k = wn_k / 2^T``; ``Δi = G² - 2T·Ii = Σ_j Ij ωj² (Ij - Ii)``
    (PHYSICS.md "Cancellation") is ``D_i / 2^(2S+2T)`` and ``G² = G2 / 2^(2S+2T)``. Δ2 is the
    small difference that decides the regime and gives ``1 - m``; near the separatrix its two
    terms cancel. In integers (a few scalars, once per body) the classification ``Δ2 == 0``
    and every constant derived from the Δs are those of the exact data, rounded once: each
    constant below is a quotient of two such integers, divided once, correctly rounded
    (Python's ``int / int``, or :func:`physics.precise.ratio` at 45 digits).
    """

    def __init__(self, J, w, w_exp: int = 0):
        # ``w`` is ω in the caller's units (sorted axes) and the scaled ω is ``w / 2^w_exp``:
        # the scaled floats may have lost a component to underflow (ω0 = (1e150, 0, 1e-300)
        # scales to (~1, 0, 0)), but their exact integers lose nothing (_dyadic with exp2).
        self.Jn, self.S = _dyadic(J)
        self.wn, self.T = _dyadic(w, w_exp)
        Jn, wn = self.Jn, self.wn
        sq = [Jn[k] * wn[k] * wn[k] for k in range(3)]
        self.D = (
            sq[1] * (Jn[1] - Jn[0]) + sq[2] * (Jn[2] - Jn[0]),
            sq[0] * (Jn[0] - Jn[1]) + sq[2] * (Jn[2] - Jn[1]),
            sq[0] * (Jn[0] - Jn[2]) + sq[1] * (Jn[1] - Jn[2]),
        )
        self.G2 = sum((Jn[k] * wn[k]) ** 2 for k in range(3))

    def reversed(self) -> _Exact:
        """The same data in the minor family's pole frame ``x'' = (x3, x2, -x1)``."""
        out = object.__new__(_Exact)
        out.Jn, out.S, out.T = self.Jn[::-1], self.S, self.T
        out.wn = (self.wn[2], self.wn[1], -self.wn[0])
        out.D, out.G2 = self.D[::-1], self.G2
        return out

    def amplitudes(self) -> tuple[float, float, float]:
        """``(A1, A2, A3)`` of Landau 37.10 in this frame.

        ``A1² = Δ3/(J1(J1-J3))``, ``A2² = Δ3/(J2(J2-J3))``, ``A3² = Δ1/(J3(J3-J1))``: each a
        quotient of same-signed quantities in both families, whose square root is taken
        exactly (:func:`_sqrt_ratio`), so that a spin a hair off an axis, with Δ ~ 1e-600,
        still gets its representable amplitude ~1e-300 instead of 0/0.
        """
        (J1, J2, J3), (D1, _, D3), sh = self.Jn, self.D, 2 * self.T
        return (
            _sqrt_ratio(D3, (J1 * (J1 - J3)) << sh),
            _sqrt_ratio(D3, (J2 * (J2 - J3)) << sh),
            _sqrt_ratio(D1, (J3 * (J3 - J1)) << sh),
        )

    def G_decimal(self) -> Decimal:
        """``G = |m|`` at the context precision."""
        return precise.ratio(self.G2, 1 << (2 * self.S + 2 * self.T)).sqrt()

    def G_float(self) -> float:
        """``G = |m|`` (no underflow of ``G²`` when a moment is ~1e-300)."""
        g2 = self.G2 / (1 << (2 * self.S + 2 * self.T))  # int / int: correctly rounded
        if g2 > 1e-300:
            return math.sqrt(g2)
        return _sqrt_ratio(self.G2, 1 << (2 * self.S + 2 * self.T))

    def sign(self, k: int) -> float:
        """The sign of ``ω_k`` (+1 for zero), from the exact data."""
        return -1.0 if self.wn[k] < 0 else 1.0

    def unit_ratio_sq(self, k: int) -> tuple[int, int]:
        """``(ω_k / A_k)²`` as an exact ratio of integers, for ``k`` = 0 or 1.

        ``A_k² = Δ3/(J_k(J_k - J3))``, so ``(ω_k/A_k)² = ω_k² J_k (J_k - J3)/Δ3`` (the scales
        cancel); on the polhode the two add up to exactly 1 (``cn² + sn²``).
        """
        n, w = self.Jn, self.wn
        return w[k] * w[k] * n[k] * (n[k] - n[2]), self.D[2]


# ν_χ = ν ∓ πλ/(2K) as a difference keeps >= 35 of the 45 digits above this ratio (_Elliptic).
_CANCELLED = Decimal("1e-10")
# Below this sqrt(1 - m), u0 is taken from exact ratios (_u0_beyond_double).
_TINY_SQRT_MC = 1e-280
# Amplitudes above this give sn0 = ω2/A2, cn0 = ω1/A1 in floats (_Elliptic).
_NORMAL_AMPLITUDE = 1e-290


def _u0_beyond_double(exact: _Exact, mc_num: int, mc_den: int, par) -> float:
    """``u0 = F(φ0 | m)`` for ``|sin φ0| > |cos φ0|`` when ``sqrt(1 - m)`` leaves the double range.

    :func:`physics.elliptic.ellipf_from_angle` takes the complementary amplitude there, with
    ``sn v = c/d``, ``cn v = sqrt(mc)|s|/d``, ``dn v = sqrt(mc)/d``, ``d = hypot(c, sqrt(mc)|s|)``
    (``s = sin φ0``, ``c = cos φ0``): ratios of numbers that may all underflow (a spin within
    1e-320 of the intermediate axis). Here they come from the exact ratio
    ``ρ² = c²/(mc s²)``: ``cn²v = 1/(1 + ρ²)``, ``dn²v = 1/(s²(1 + ρ²))``, ``sn²v = ρ²/(1+ρ²)``,
    and ``F = K - F(v)``. Where ``ρ² > 1e40`` the m = 1 limit ``F = atanh s = ln((1 + |s|)/c)``
    is exact to rounding (the correction is O(1/ρ²)) and is taken in decimal arithmetic, since
    ``c`` itself may be far below the double range.
    """
    C, D3 = exact.unit_ratio_sq(0)  # c² = C/D3
    S, _ = exact.unit_ratio_sq(1)  # s² = S/D3
    if D3 < 0:
        C, S, D3 = -C, -S, -D3
    K = par.K
    sign_s = exact.sign(1)
    with localcontext() as ctx:
        ctx.prec = precise.DIGITS
        if C == 0:
            f = K  # at the turning point itself
        elif C * mc_den > S * mc_num * 10**40:
            s_dec = precise.ratio(S, D3).sqrt()
            f = float((1 + s_dec).ln() - precise.ratio(C, D3).ln() / 2)
        else:
            rho2 = precise.ratio(C * mc_den, S * mc_num)
            cnv2 = float(1 / (1 + rho2))
            dnv2 = float(precise.ratio(D3, S) / (1 + rho2))
            snv = float((rho2 / (1 + rho2)).sqrt())
            f = K - snv * float(special.elliprf(cnv2, dnv2, 1.0))
    f = math.copysign(f, sign_s)
    if exact.wn[0] >= 0:  # cos φ0 >= 0
        return f
    return math.copysign(2.0 * K, sign_s) - f


class _Elliptic:
    """Major- or minor-axis family, in the pole frame (pole = axis 3), Landau 37.10.

    ``ω = (A1 cn u, A2 sn u, s A3 dn u)`` with ``u = u0 + σ τ``, ``σ = s λ`` in the major
    family. In the minor family the pole frame has its moments in decreasing order, which turns
    the sign of every right-hand side of Euler's equations, so ``σ = -s λ``.
    """

    def __init__(self, J: np.ndarray, w: np.ndarray, exact: _Exact):
        J1, J2, J3 = (float(x) for x in J)
        (n1, n2, n3), (e1, e2, e3) = exact.Jn, exact.D  # exact integers (see _Exact)
        S, sh = exact.S, 2 * exact.T
        self.J = J
        self.J_tuple = (J1, J2, J3)
        # λ, m, 1 - m, K and the mean precession rate ν from the exact rationals of the data,
        # at 45 digits: m and mc correctly rounded (no subtraction near the separatrix), λ, K
        # and ν as double-double pairs so that the phases u = u0 + σ τ (mod 2K) and ν τ
        # (mod 2π) stay exact to the rounding of τ itself over long runs (physics.precise).
        # Each is a quotient of integers: λ² = (J3-J2)Δ1/(J1 J2 J3), m = (J1-J2)Δ3/((J3-J2)Δ1),
        # 1 - m = (J3-J1)Δ2/((J3-J2)Δ1), N = -J3(J2-J1)/(J1(J3-J2)), scales as in _Exact.
        m = (n1 - n2) * e3 / ((n3 - n2) * e1)  # int / int: correctly rounded
        mc_num, mc_den = (n3 - n1) * e2, (n3 - n2) * e1
        mc = mc_num / mc_den
        N_num, N_den = -n3 * (n2 - n1), n1 * (n3 - n2)
        # Amplitudes (Landau 37.10, with Δi = G² - 2T Ii so that each ratio is a quotient of
        # same-signed quantities in both families), exact square roots of exact ratios, so
        # that a spin a hair off an axis (Δ ~ 1e-600) still gets its amplitude ~1e-300.
        self.A = exact.amplitudes()
        ratio = precise.ratio
        with localcontext() as ctx:
            ctx.prec = precise.DIGITS
            sqrt_mc_dec = ratio(mc_num, mc_den).sqrt()
            sqrt_mc = float(sqrt_mc_dec)
            N_dec = ratio(N_num, N_den)
            dual = N_dec < -1  # m itself is needed only then (the n -> m/n transformation)
            m_dec = ratio((n1 - n2) * e3, (n3 - n2) * e1) if dual else None
            K_dec, pi_dec, excess_dec = elliptic.complete_integrals_excess_decimal(
                N_dec, sqrt_mc_dec, m_dec
            )
            G_dec = exact.G_decimal()
            c_dec = G_dec * ratio((n3 - n1) << S, n1 * n3)
            if dual:
                nu_dec = G_dec / ratio(n3, 1 << S) + c_dec * pi_dec / K_dec
            else:
                # G/J3 + c = G/J1 exactly: with a pole moment far below the others (J3 ~ 1e-77
                # J1 in the minor family) G/J3 and c·Π/K are both huge and nearly cancel.
                nu_dec = G_dec / ratio(n1, 1 << S) + c_dec * excess_dec / K_dec
            lam_dec = ratio((n3 - n2) * e1, (n1 * n2 * n3) << sh).sqrt()
            # The slow angle χ = φ + sψ (s = sign of the pole component) turns at the mean rate
            # ν_χ = ν - π σ s/(2K) = ν - d π λ/(2K) (d = +1 in the major family, -1 in the
            # minor). Near the pole of a body with moments 1e200 apart, ν and πλ/(2K) are
            # ~1e225 while ν_χ ~ |ω|: φ and ψ separately are noise there, χ is not; the
            # difference would cancel all digits. Then (cost ~30 µs, so only then) ν_χ comes
            # from ν_χ = G/J3 + c (Π(N) - π/(2q))/K, using c/q = ±λ exactly (q² = (1 - N)
            # (1 - m/N), an identity of the data), with c = G/J1 - G/J3:
            # ν_χ = [G/J3 · copole + G/J1 · pole]/K, two terms >= 0 (ThirdKindConstants).
            drift = precise.PI * lam_dec / (2 * K_dec)
            nu_chi_dec = nu_dec - drift if J3 > J1 else nu_dec + drift
            if abs(nu_chi_dec) < _CANCELLED * max(abs(nu_dec), drift):
                third = elliptic.third_kind_constants(
                    N_dec, sqrt_mc_dec, ratio((n1 - n2) * e3, (n3 - n2) * e1)
                )
                nu_chi_dec = (
                    G_dec / ratio(n3, 1 << S) * third.copole
                    + G_dec / ratio(n1, 1 << S) * third.pole
                ) / K_dec
            nu_chi = precise.double_double(nu_chi_dec)
            lam, lam_lo = precise.double_double(lam_dec)
            K_hi, K_lo = precise.double_double(K_dec)
            nu = precise.double_double(nu_dec)
            pi_float, excess_float = float(pi_dec), float(excess_dec)
        # sqrt(1 - m) as a Decimal: below ~1e-308 (a start within 1e-308 of the separatrix)
        # the AGM's first steps are taken in decimal arithmetic (JacobiParameter.from_pair).
        self.par = elliptic.JacobiParameter.from_pair(
            m, mc, sqrt_mc=sqrt_mc_dec if sqrt_mc < _TINY_SQRT_MC else sqrt_mc, K=K_hi
        )
        self.s = exact.sign(2)
        direction = 1.0 if J3 > J1 else -1.0
        self.lam = lam
        self.sigma = direction * self.s * lam
        K = K_hi
        # Initial phase u0 = F(φ0 | m), φ0 = atan2(sn0, cn0) (Landau after 37.10), with
        # sn0 = ω2/A2 and cn0 = ω1/A1: from the scaled floats where both amplitudes are normal
        # doubles (a scaled ω component lost to underflow is then ~1e-308 of its amplitude,
        # invisible in u0), else from their exact squares: an amplitude may underflow
        # (A1 ~ 1e-400 for a spin a hair off the pole) where the ratio is still O(1).
        if min(self.A[0], self.A[1]) > _NORMAL_AMPLITUDE:
            sn0, cn0 = float(w[1]) / self.A[1], float(w[0]) / self.A[0]
        else:
            sn0 = exact.sign(1) * _sqrt_ratio(*exact.unit_ratio_sq(1))
            cn0 = exact.sign(0) * _sqrt_ratio(*exact.unit_ratio_sq(0))
        if sqrt_mc < _TINY_SQRT_MC and sn0 * sn0 > cn0 * cn0:
            self.u0 = _u0_beyond_double(exact, mc_num, mc_den, self.par)
        else:
            self.u0 = elliptic.ellipf_from_angle(sn0, cn0, self.par, sqrt_mc)
        self.phase = precise.LinearPhase(
            self.u0, self.sigma, direction * self.s * lam_lo, 2.0 * K_hi, 2.0 * K_lo
        )
        # Precession (Landau 37.16): φ' = G/J3 + c / (1 - N sn²u), N < 0, c = G(J3-J1)/(J1 J3).
        # Π(N; am u) = (Πc/K) u + P(u) with P 2K-periodic: the secular part joins G/J3 in the
        # mean rate ν, the periodic part is evaluated on the reduced argument.
        self.G = exact.G_float()
        self.N = N_num / N_den
        # Π/K and (Π - K)/K: quotients of correctly rounded doubles, no cancellation.
        self.pp = elliptic.PeriodicPi(self.N, pi_float / K, excess_float / K)
        self.c = self.G * ((J3 - J1) / J1 / J3)
        self.nu = nu[0]
        self.nu_chi = nu_chi[0]
        self.chi = precise.angle_phase(nu_chi)
        # ψ = atan2(m1, m2) = atan2(k cn, sn) (times the sign (-1)^j of both): the ratio
        # k = J1 A1/(J2 A2) of the data, so that ψ stays exact where m1, m2 are subnormal.
        self.k_psi = _sqrt_ratio(n1 * (n3 - n2), n2 * (n3 - n1))
        self.half_pi_over_K = 0.5 * math.pi / K
        self.period = 4.0 * K / lam
        self.phase_scale = self.c / self.sigma
        self.P0 = self._periodic_pi_scalar(self.u0)
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
        return elliptic.periodic_third_kind(self.pp, self.par, r, sn, cn, dn)

    def _periodic_pi_scalar(self, u: float) -> float:
        r, _ = elliptic.reduce_argument_scalar(u, self.par.K)
        sn, cn, dn = elliptic.sncndn_reduced_scalar(r, self.par)
        return elliptic.periodic_third_kind_scalar(self.pp, self.par, r, sn, cn, dn)

    def omega(self, tau: np.ndarray) -> tuple[np.ndarray, ...]:
        _, sign, sn, cn, dn = self._reduced(tau)
        A1, A2, A3 = self.A
        return (A1 * sign * cn, A2 * sign * sn, (self.s * A3) * dn)

    def quat(self, tau: np.ndarray) -> tuple[tuple[np.ndarray, ...], np.ndarray]:
        """ω and the Z-X-Z quaternion from the slow angle χ = φ + sψ.

        With ``u = r + 2Kj``: ``φ = ν τ + W(r)`` and ``ψ = ψ_r(r) + π j`` (ψ_r from the
        reduced sn, cn), ``ν τ = ν_χ τ + s(π/2K)(u - u0)``, so modulo 2π (and up to the
        constant ``-s(π/2K) u0``, absorbed by the fixed space rotation)
        ``χ = ν_χ τ + W(r) + s(ψ_r(r) + (π/2K) r)``: every term but the slow ``ν_χ τ`` is
        bounded, and nothing depends on the parity of j.
        """
        r, sign, sn, cn, dn = self._reduced(tau)
        A1, A2, A3 = self.A
        w = (A1 * sign * cn, A2 * sign * sn, (self.s * A3) * dn)
        J1, J2, J3 = self.J
        psi_r = np.arctan2(self.k_psi * cn, sn)
        chi = (
            self.chi.reduce(tau)[0]
            + self.precession_wobble(r, sn, cn, dn)
            + self.s * (psi_r + self.half_pi_over_K * r)
        )
        return w, _zxz_from_chi(
            J1 * w[0], J2 * w[1], J3 * w[2], self.G, chi, psi_r, sign, self.s > 0.0
        )

    # One time in plain floats: the operations of omega/quat above, in the same order.

    def _reduced_scalar(self, tau: float) -> tuple[float, ...]:
        r, j = self.phase.reduce_scalar(tau)
        sn, cn, dn = elliptic.sncndn_reduced_scalar(r, self.par)
        return r, 1.0 - 2.0 * (j % 2.0), sn, cn, dn

    def omega_scalar(self, tau: float) -> tuple[float, ...]:
        _, sign, sn, cn, dn = self._reduced_scalar(tau)
        A1, A2, A3 = self.A
        return (A1 * sign * cn, A2 * sign * sn, (self.s * A3) * dn)

    def quat_scalar(self, tau: float) -> tuple[tuple[float, ...], tuple[float, ...]]:
        r, sign, sn, cn, dn = self._reduced_scalar(tau)
        A1, A2, A3 = self.A
        w = (A1 * sign * cn, A2 * sign * sn, (self.s * A3) * dn)
        J1, J2, J3 = self.J_tuple
        P = elliptic.periodic_third_kind_scalar(self.pp, self.par, r, sn, cn, dn)
        psi_r = float(np.arctan2(self.k_psi * cn, sn))
        chi = (
            self.chi.reduce_scalar(tau)[0]
            + self.phase_scale * (P - self.P0)
            + self.s * (psi_r + self.half_pi_over_K * r)
        )
        return w, _zxz_chi_scalar(
            J1 * w[0], J2 * w[1], J3 * w[2], self.G, chi, psi_r, sign, self.s > 0.0
        )

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
            P = elliptic.periodic_third_kind(self.pp, self.par, r, sn, cn, dn)
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

    def __init__(self, J: np.ndarray, exact: _Exact):
        J1, J2, J3 = (float(x) for x in J)
        n1, n2, n3 = exact.Jn
        self.J = J
        self.J_tuple = (J1, J2, J3)
        self.A = exact.amplitudes()
        # λ² = (J3-J2)Δ1/(J1 J2 J3), rounded once from the exact data (as in _Elliptic).
        lam = _sqrt_ratio((n3 - n2) * exact.D[0], (n1 * n2 * n3) << (2 * exact.T))
        self.s1 = exact.sign(0)
        self.s3 = exact.sign(2)
        self.lam = lam
        self.sigma = self.s1 * self.s3 * lam
        # tanh u0 = ω2/A2 and sech u0 = |ω1|/A1, so sinh²u0 = (ω2/A2)² / (ω1/A1)², exactly.
        self.u0 = exact.sign(1) * _asinh_sqrt_ratio(
            exact.unit_ratio_sq(1)[0], exact.unit_ratio_sq(0)[0]
        )
        self.G = exact.G_float()
        # ψ = atan2(J1 s1 A1 sech, J2 A2 tanh) = atan2(k s1 sech, tanh), k = J1 A1/(J2 A2) a
        # ratio of the moments (as in _Elliptic): exact where m1, m2 are subnormal.
        self.k_psi = _sqrt_ratio(n1 * (n3 - n2), n2 * (n3 - n1))
        N = -J3 / J1 * ((J2 - J1) / (J3 - J2))
        self.a = math.sqrt(-N)
        c = self.G * ((J3 - J1) / J1 / J3)
        # The mean rate ν = G/J3 + c/(1 - N) to double-double, as in _Elliptic.
        n1, n2, n3 = exact.Jn
        ratio = precise.ratio
        with localcontext() as ctx:
            ctx.prec = precise.DIGITS
            G_dec = exact.G_decimal()
            N_dec = ratio(-n3 * (n2 - n1), n1 * (n3 - n2))
            nu_dec = G_dec / ratio(n3, 1 << exact.S) + G_dec * ratio(
                (n3 - n1) << exact.S, n1 * n3
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
        psi = np.arctan2((self.s1 * self.k_psi) * sech, th)
        return w, _zxz_from_momentum(J1 * w[0], J2 * w[1], J3 * w[2], self.G, phi, psi)

    def omega_scalar(self, tau: float) -> tuple[float, ...]:
        th, sech = elliptic.tanh_sech_scalar(self.u0 + self.sigma * tau)
        A1, A2, A3 = self.A
        return ((self.s1 * A1) * sech, A2 * th, (self.s3 * A3) * sech)

    def quat_scalar(self, tau: float) -> tuple[tuple[float, ...], tuple[float, ...]]:
        th, sech = elliptic.tanh_sech_scalar(self.u0 + self.sigma * tau)
        A1, A2, A3 = self.A
        w = ((self.s1 * A1) * sech, A2 * th, (self.s3 * A3) * sech)
        phi = self.precession.reduce_scalar(tau)[0] + self.amp * (
            float(np.arctan(self.a * th)) - self.atan0
        )
        J1, J2, J3 = self.J_tuple
        psi = float(np.arctan2((self.s1 * self.k_psi) * sech, th))
        return w, _zxz_scalar(J1 * w[0], J2 * w[1], J3 * w[2], self.G, phi, psi)

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

    With the symmetry axis near ±L̂ (``e_s = R(0) e``, ``σ = sign ω_e``) the two rotations
    nearly compose into one about L̂ at the slow rate ``p + σ s``, while p and s themselves can
    be huge (transverse moments 1e-100 of the axial one: p ~ -s ~ 1e100 |ω|): the attitude is
    then taken as ``R(t) = Rot(L̂, (p + σ s) t - σ a) · R(0) · Rot(e, a)``, ``a = s t``, the
    same rotation mod 2π, in which the noise of ``a`` only moves a rotation of the size of the
    nutation angle. ``p + σ s = I ω⊥²/(G + J |ω_e|) + |ω_e|`` (``G - J|ω_e| = I² ω⊥²/(G +
    J|ω_e|)``) is a sum of positive terms, computed from the exact data.
    """

    def __init__(
        self,
        w: np.ndarray,
        axis: np.ndarray,
        I_t: float,
        J_a: float,
        inertia: np.ndarray,
        w_user: np.ndarray,
        w_exp: int,
    ):
        # w: the scaled ω (caller's axes); w_user = w · 2^w_exp unscaled, for the exact data
        # (a component of w may have underflowed).
        self.w0 = w
        self.axis = axis
        w_axial = float(w @ axis)
        # Rodrigues' constants e·v and e × v (omega_rotated), also as plain floats.
        self.ev = w_axial
        self.exv = np.cross(axis, w)
        self.w0_tuple = tuple(float(x) for x in w)
        self.axis_tuple = tuple(float(x) for x in axis)
        self.exv_tuple = tuple(float(x) for x in self.exv)
        # The two rates to double-double from the exact data, so that the angles p τ and s τ
        # (reduced mod 2π) stay exact over long runs (physics.precise): with exact integers
        # I_k = In_k/2^S, ω_k = wn_k/2^T, G² = Σ (In wn)²/2^(2S+2T), p = G/I_t and
        # s = (I_t - J_a) ω_e / I_t, each rounded once.
        In, S = _dyadic(inertia)
        wn, T = _dyadic(w_user, w_exp)
        (It, Ja), S2 = _dyadic((I_t, J_a))
        (wa,), Ta = _dyadic((float(w_user @ axis),), w_exp)  # axis: a signed unit vector
        G2 = sum((In[k] * wn[k]) ** 2 for k in range(3))
        self.sign_e = -1.0 if wa < 0 else 1.0
        with localcontext() as ctx:
            ctx.prec = precise.DIGITS
            G_dec = precise.ratio(G2, 1 << (2 * S + 2 * T)).sqrt()
            p = precise.double_double(G_dec / precise.ratio(It, 1 << S2))
            spin = precise.double_double(precise.ratio((It - Ja) * wa, It << Ta))
            if spin[0] != 0.0:  # a symmetric body (G > 0): the slow rate p + σ s
                k_axis = int(np.flatnonzero(axis)[0])
                perp2 = sum(wn[k] * wn[k] for k in range(3) if k != k_axis)
                w_e = abs(precise.ratio(wa, 1 << Ta))
                slow = (
                    precise.ratio(It * perp2, 1 << (S2 + 2 * T))
                    / (G_dec + precise.ratio(Ja, 1 << S2) * w_e)
                    + w_e
                )
                self.slow = precise.angle_phase(precise.double_double(slow))
        self.p, self.spin = p[0], spin[0]
        self.precession = precise.angle_phase(p)
        self.spinning = precise.angle_phase(spin)
        w_perp = w_user - float(w_user @ axis) * axis
        moving = self.spin != 0.0 and bool(np.any(w_perp != 0.0))
        # The period 2π/|s| as a (numerator, rate) pair: a spin rate ~1e-310 overflows it.
        self.period_pair = (2.0 * math.pi, abs(self.spin) if moving else 0.0)
        self.period = 2.0 * math.pi / abs(self.spin) if moving else math.inf
        self.nu = self.p

    def omega_rotated(self, angle: np.ndarray) -> tuple[np.ndarray, ...]:
        # Rodrigues with a unit axis e: v cos a + (e × v) sin a + e (e·v)(1 - cos a).
        e, v, ev, exv = self.axis, self.w0, self.ev, self.exv
        c, s = np.cos(angle), np.sin(angle)
        return tuple(v[k] * c + exv[k] * s + e[k] * ev * (1.0 - c) for k in range(3))

    def omega(self, tau: np.ndarray) -> tuple[np.ndarray, ...]:
        if self.spin == 0.0:
            return tuple(np.full(tau.shape, self.w0[k]) for k in range(3))
        return self.omega_rotated(-self.spinning.reduce(tau)[0])

    def omega_scalar(self, tau: float) -> tuple[float, ...]:
        if self.spin == 0.0:
            return self.w0_tuple
        angle = -self.spinning.reduce_scalar(tau)[0]
        e, v, ev, exv = self.axis_tuple, self.w0_tuple, self.ev, self.exv_tuple
        c, s = float(np.cos(angle)), float(np.sin(angle))
        return tuple(v[k] * c + exv[k] * s + e[k] * ev * (1.0 - c) for k in range(3))

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
        ValueError: moments not positive or not finite (or more than 300 decades apart), ω0
            not finite, wrong shapes, or an ``attitude0`` that is not a single rotation. Later,
            from the evaluation methods: a time so far that a phase of the motion (rate × t)
            would pass 1e300 rad, or a body whose ω(t) leaves the double range in the caller's
            units; from the properties (``energy``, ``angular_momentum``, ``semi_axes``,
            ``frequency``, ``period``, ...): a value beyond the double range in those units.

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
        self._q0 = attitude0.as_quat().tolist()

        i_min, i_max = min(self.inertia.tolist()), max(self.inertia.tolist())
        if i_max / 1e300 > i_min:
            raise ValueError(
                "the moments of inertia span more than 300 decades "
                f"({i_min:g} to {i_max:g}): beyond double precision"
            )
        # Exact power-of-two scaling: moments and ω near 1 whatever the caller's units.
        self._I_exp = math.frexp(i_max)[1] - 1
        self._I_ref = math.ldexp(1.0, self._I_exp)
        w_max = max(abs(x) for x in self.omega0.tolist())
        self._w_exp = math.frexp(w_max)[1] - 1 if w_max > 0.0 else 0
        self._w_ref = math.ldexp(1.0, self._w_exp)
        inertia_s = self.inertia / self._I_ref
        omega_s = self.omega0 / self._w_ref  # a component 1e308 times below the largest is lost

        sort = _sorting_map(self.inertia)
        J = sort.to_internal(inertia_s) * sort.sign  # moments are not signed
        w = sort.to_internal(omega_s)
        # The caller's ω in the sorted axes, unscaled: exact zeros, signs and integers.
        w_exact = sort.to_internal(self.omega0)
        self._out_of_range: str | None = None  # why ω(t) cannot be returned (_set_rates)
        self._classify_and_build(sort, J, w, w_exact, inertia_s, omega_s)

        # Invariants: computed in the scaled units, then scaled back by exact powers of two, so
        # they over/underflow only where the physical value itself is out of double range;
        # an overflowing one raises a ValueError when it is read (see _in_units).
        L_scaled = self.attitude0.apply(inertia_s * omega_s)
        two_T_scaled = float(omega_s @ (inertia_s * omega_s))
        G_scaled = math.hypot(*L_scaled.tolist())  # no underflow of G² for moments ~1e-300
        self._two_T_scaled, self._inertia_scaled = two_T_scaled, inertia_s
        self._L_scaled = L_scaled
        if self.regime is Regime.REST:
            self.D = 0.0
            self.plane_distance = 0.0
            self.plane_normal = np.array([0.0, 0.0, 1.0])
        else:
            self.D = self._scaled_D * self._I_ref  # within [min I, max I]
            self.plane_distance = self._scaled_h * self._w_ref  # 2T/G <= |ω|
            self.plane_normal = L_scaled / G_scaled
        self._plane_normal_t = tuple(float(x) for x in self.plane_normal)

    def _in_units(
        self,
        scaled,
        exp2: int,
        what: str,
        advice: str = "express the moments or ω0 in larger units",
        log10_scaled=None,
        units: str = " in your units",
    ):
        """``scaled · 2^exp2`` (a float or an array), or a ValueError if that overflows.

        The scaled value is exact and finite; only its size in the caller's units may exceed
        the double range (ω0 ~ 1e200 with moments ~1e100 has an energy ~1e500): reading it then
        raises a ValueError that says so instead of returning inf, while the motion itself,
        ω(t) and R(t), stays available. ``log10_scaled()`` gives the size of a scaled value
        that itself overflowed (a period ~1e320 of a spin ~1e-320).
        """
        if isinstance(scaled, np.ndarray):
            value = np.array([_ldexp(x, exp2) for x in scaled.tolist()])
            finite = all(map(math.isfinite, value.tolist()))
        else:
            value = _ldexp(scaled, exp2)
            finite = math.isfinite(value)
        if finite:
            return value
        if log10_scaled is None:
            size = math.log10(float(np.max(np.abs(scaled))))
        else:
            size = log10_scaled()
        decades = size + exp2 * math.log10(2.0)
        raise ValueError(
            f"{what} of this body is about 1e{decades:.0f}{units}, beyond the largest "
            f"double-precision number (1.8e308): {advice} (omega(t) and attitude(t) are "
            "still available)"
        )

    # -- construction ---------------------------------------------------------------------

    def _classify_and_build(self, sort, J, w, w_exact, inertia_s, omega_s) -> None:
        J1, J2, J3 = J
        m = J * w
        G = math.hypot(*m.tolist())  # m·m would underflow for a moment ~1e-300
        two_T = float(w @ m)
        self._scaled_D = G * (G / two_T) if two_T > 0 else 0.0
        self._scaled_h = two_T / G if G > 0 else 0.0
        self._frame = sort
        self._solver: _Elliptic | _Separatrix | _Circular
        self.parameter = 0.0
        self.complementary_parameter = 1.0

        zero = w_exact == 0.0  # the caller's zeros (a scaled component may underflow)
        exact_user = (self.omega0, self._w_exp)
        if zero.all():
            regime = Regime.REST
            axis = np.array([0.0, 0.0, 1.0])
            circ = _Circular(omega_s, axis, 1.0, 1.0, inertia_s, *exact_user)
        elif J1 == J3:
            regime = Regime.SPHERE
            circ = _Circular(
                omega_s, np.array([0.0, 0.0, 1.0]), float(J1), float(J1), inertia_s, *exact_user
            )
        else:
            circ = self._circular_or_none(sort, J, zero, inertia_s, omega_s)
            regime = None if circ is None else circ[0]
            circ = None if circ is None else circ[1]
        if circ is not None:
            self.regime = regime
            self._solver = circ
            self._frame = None  # _Circular works in the caller's own body frame
            self._q_space_t = tuple(self._q0)
            self._q_space = np.array(self._q_space_t)
            self._set_rates(0.0, circ.period_pair, circ.nu, (circ.p, circ.spin), 1.0)
            return

        # Triaxial and not a permanent rotation: Δi = G² - 2T·Ii, exactly (_Exact).
        exact = _Exact(J, w_exact, self._w_exp)
        if exact.D[1] == 0:
            self.regime = Regime.SEPARATRIX
            solver = _Separatrix(J, exact)
            self.parameter, self.complementary_parameter = 1.0, 0.0
        else:
            if exact.D[1] > 0:
                self.regime = Regime.MAJOR_AXIS
                pole = sort
                Jp, wp, ep = J, w, exact
            else:
                self.regime = Regime.MINOR_AXIS
                pole = sort.compose(_REVERSE)
                Jp, wp = _REVERSE.to_internal(J) * _REVERSE.sign, _REVERSE.to_internal(w)
                ep = exact.reversed()
            solver = _Elliptic(Jp, wp, ep)
            self._frame = pole
            self.parameter = solver.par.m
            self.complementary_parameter = solver.par.mc
        self._solver = solver
        periodic = (4.0 * solver.par.K, solver.lam) if isinstance(solver, _Elliptic) else (0, 0)
        rates = (solver.sigma, solver.nu, getattr(solver, "nu_chi", 0.0))
        self._set_rates(solver.lam, periodic, solver.nu, rates, max(solver.A))
        # Anchor ω at t = 0: the closed form reproduces ω0 only to O(eps · amplitude) (through
        # u0 = F(φ0|m) and back through sn, cn, dn); adding the constant ω0 - f(0) makes
        # omega(0) return ω0 exactly and changes no other value by more than that rounding.
        cols0, q0 = solver.quat_scalar(0.0)
        user0 = self._frame.to_user_tuple(cols0)
        self._anchor_t = tuple(float(omega_s[k]) - user0[k] for k in range(3))
        self._anchor = np.array(self._anchor_t)
        # R_user(t) = S · R_int(t) · C with S fixed so that R_user(0) = attitude0.
        fq = self._frame.quat_tuple
        self._q_space_t = _qmul_scalar(
            _qmul_scalar(self._q0, (-fq[0], -fq[1], -fq[2], fq[3])),
            (-q0[0], -q0[1], -q0[2], q0[3]),
        )
        self._q_space = np.array(self._q_space_t)

    def _circular_or_none(self, sort, J, zero, inertia_s, omega_s):
        """Permanent rotations and symmetric bodies: (regime, _Circular), else None."""
        J1, J2, J3 = J
        e_user = [sort.matrix[k] for k in range(3)]  # internal axis k in user coordinates
        if zero.sum() == 2:  # along one principal axis of a triaxial body
            k = int(np.flatnonzero(~zero)[0])
            return Regime.PERMANENT_ROTATION, _Circular(
                omega_s, e_user[k], float(J[k]), float(J[k]), inertia_s, self.omega0, self._w_exp
            )
        if J1 == J2 or J2 == J3:
            a = 2 if J1 == J2 else 0  # the distinct (symmetry) axis
            I_t = float(J[1])
            transverse = [k for k in range(3) if k != a]
            if zero[a] or (zero[transverse[0]] and zero[transverse[1]]):
                regime = Regime.PERMANENT_ROTATION
            else:
                regime = Regime.SYMMETRIC
            return regime, _Circular(
                omega_s, e_user[a], I_t, float(J[a]), inertia_s, self.omega0, self._w_exp
            )
        return None

    def _set_rates(
        self,
        lam: float,
        period: tuple[float, float],
        nu: float,
        rates: tuple[float, ...],
        amplitude: float,
    ) -> None:
        """Keep the scaled rates (read in the caller's units by the properties) and set the
        ranges of the evaluation.

        ``period`` is the scaled period as ``(numerator, rate)``, ``rate = 0`` for a motion that
        never repeats (whose period stays ``inf``, as documented).
        """
        self._lam_s, self._nu_s, self._period_s = lam, nu, period
        # Evaluation ranges (scaled units): the phases rate·τ must stay finite, and so must
        # ω(t), whose components reach the largest amplitude of the closed form.
        fastest = max(abs(x) for x in rates)
        self._tau_limit = _PHASE_LIMIT / fastest if fastest > 0.0 else math.inf
        if not math.isfinite(amplitude * self._w_ref):
            decades = math.log10(amplitude) + self._w_exp * math.log10(2.0)
            self._out_of_range = (
                f"during this motion a component of ω reaches about 1e{decades:.0f} in your "
                "units, beyond the largest double-precision number (1.8e308): use a longer "
                "time unit (ω0 in smaller numbers)"
            )

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

    def _scalar(self, tau: float, attitude: bool) -> tuple[list[float], tuple[float, ...] | None]:
        """ω (user axes, caller units) and, if asked, the attitude quaternion at one τ.

        The single-time path: the operations of :meth:`_omega_user` and :meth:`_quat_block`
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
            w_arr, q_arr = self._quat_user(arr)
            return w_arr[0].tolist(), tuple(q_arr[0].tolist())
        return self._omega_user(arr)[0].tolist(), None

    def _scalar_floats(self, tau: float, attitude: bool):
        solver = self._solver
        w_ref = self._w_ref
        if isinstance(solver, _Circular):
            w = [x * w_ref for x in solver.omega_scalar(tau)]
            if not attitude:
                return w, None
            if solver.spin == 0.0:
                angle = solver.precession.reduce_scalar(tau)[0]
                q = _qmul_scalar(_axis_angle_scalar(self._plane_normal_t, angle), self._q_space_t)
            else:  # see _Circular: Rot(L̂, (p + σ s) τ - σ a) R(0) Rot(e, a)
                a = solver.spinning.reduce_scalar(tau)[0]
                angle = solver.slow.reduce_scalar(tau)[0] - solver.sign_e * a
                q = _qmul_scalar(_axis_angle_scalar(self._plane_normal_t, angle), self._q_space_t)
                q = _qmul_scalar(q, _axis_angle_scalar(solver.axis_tuple, a))
            return w, q
        if attitude:
            cols, q_int = solver.quat_scalar(tau)
            q = _qmul_scalar(self._q_space_t, _qmul_scalar(q_int, self._frame.quat_tuple))
        else:
            cols, q = solver.omega_scalar(tau), None
        user, anchor = self._frame.to_user_tuple(cols), self._anchor_t
        return [(user[k] + anchor[k]) * w_ref for k in range(3)], q

    def omega(self, t):
        """Body-frame angular velocity ω(t) in the caller's axes [rad per time unit].

        Args:
            t: time, a float or a (N,) array.

        Returns:
            (3,) for a scalar ``t``, (N, 3) for an array.
        """
        tau = self._scaled_times(t)
        if isinstance(tau, float):
            return np.array(self._scalar(tau, False)[0])
        return self._omega_user(tau)

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
            if solver.spin == 0.0:
                q = _axis_angle_quat(self.plane_normal, solver.precession.reduce(tau)[0])
                q = _qmul(q, self._q_space)
            else:  # see _Circular: Rot(L̂, (p + σ s) τ - σ a) R(0) Rot(e, a)
                a = solver.spinning.reduce(tau)[0]
                angle = solver.slow.reduce(tau)[0] - solver.sign_e * a
                q = _qmul(_axis_angle_quat(self.plane_normal, angle), self._q_space)
                q = _qmul(q, _axis_angle_quat(solver.axis, a))
            return self._omega_user(tau), q
        cols, q_int = solver.quat(tau)
        q = _qmul(self._q_space, _qmul(q_int, self._frame.quat))
        return (self._frame.to_user_columns(cols) + self._anchor) * self._w_ref, q

    def _evaluate(self, t) -> tuple[np.ndarray, np.ndarray]:
        """ω ((3,) or (N, 3)) and unnormalised attitude quaternions ((4,) or (N, 4))."""
        tau = self._scaled_times(t)
        if isinstance(tau, float):
            w, q = self._scalar(tau, True)
            return np.array(w), np.array(q)
        return self._quat_user(tau)

    def _scaled_times(self, t) -> float | np.ndarray:
        """The dimensionless times τ = t·ω_ref, checked against the range of this motion.

        Beyond ``|τ| = _tau_limit`` a phase of the closed form (rate × τ) would exceed 1e300
        rad and overflow on its way through the reduction: a ValueError then says so. (The
        results carry an error ~1e-16 × rate × t, so they mean little long before.)
        """
        tt = _check_times(t)
        if self._out_of_range is not None:
            raise ValueError(self._out_of_range)
        if isinstance(tt, float):
            tau = tt * self._w_ref
            if abs(tau) <= self._tau_limit:
                return tau
            t_max = abs(tt)
        else:
            with np.errstate(over="ignore"):  # an overflow to inf is refused just below
                tau = tt * self._w_ref
            if tau.size == 0 or float(np.abs(tau).max()) <= self._tau_limit:
                return tau
            t_max = float(np.abs(tt).max())
        with np.errstate(over="ignore"):
            limit = self._tau_limit / self._w_ref
        raise ValueError(
            f"t = {t_max:g} is too far in time for this motion in double precision: its fastest "
            f"phase (rate × t) would exceed 1e{math.log10(_PHASE_LIMIT):.0f} rad; keep |t| "
            f"below {limit:.3g} (and note that the results drift by ~1e-16 × rate × t)"
        )

    def attitude(self, t) -> Rotation:
        """Attitude R(t), body -> space, as a scipy Rotation (single, or a stack of N).

        ``attitude(0)`` equals ``attitude0`` to rounding.
        """
        return Rotation.from_quat(self._evaluate(t)[1])

    def state(self, t) -> tuple[np.ndarray, Rotation]:
        """ω(t) and R(t) from one evaluation: ((N,3) or (3,), Rotation); see :meth:`sample`."""
        w, q = self._evaluate(t)
        return w, Rotation.from_quat(q)

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
        w, q = self._evaluate(t)
        if q.ndim == 1:
            return w, Rotation.from_quat(q), np.array(_rotate_scalar(q.tolist(), w.tolist()))
        return w, Rotation.from_quat(q), _rotate(q, w)

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
        if self._out_of_range is not None:
            raise ValueError(self._out_of_range)
        cols = self._solver.polhode(int(n))
        if self._frame is None:
            return np.stack(cols, axis=-1) * self._w_ref
        return self._frame.to_user_columns(cols) * self._w_ref

    # Quantities in the caller's units that may exceed the double range for extreme units
    # (ω0 ~ 1e200 with moments ~1e100 has an energy ~1e500): each is computed when read, from
    # its exact scaled value, and raises a ValueError saying so rather than returning inf.

    _SLOWER = "use a longer time unit (ω0 and the times in smaller numbers)"
    _FASTER = "use a shorter time unit (ω0 and the times in larger numbers)"

    @property
    def energy(self) -> float:
        """Kinetic energy ``T = ω·I·ω / 2`` (constant)."""
        exp2 = self._I_exp + 2 * self._w_exp
        return self._in_units(0.5 * self._two_T_scaled, exp2, "the kinetic energy")

    @property
    def angular_momentum(self) -> np.ndarray:
        """(3,) angular momentum ``L = R(0) I ω0`` in the space frame (constant)."""
        exp2 = self._I_exp + self._w_exp
        return self._in_units(self._L_scaled, exp2, "the angular momentum L")

    @property
    def semi_axes(self) -> np.ndarray:
        """(3,) semi-axes ``sqrt(2T/Ii)`` of the energy ellipsoid ``x·I·x = 2T`` (caller order)."""
        # From the scaled state (2T/I_i = w_ref² · 2T_s/I_s,i): no underflow at ω ~ 1e-200.
        return self._in_units(
            np.sqrt(self._two_T_scaled / self._inertia_scaled),
            self._w_exp,
            "the largest semi-axis of the energy ellipsoid",
        )

    @property
    def frequency(self) -> float:
        """λ, the rate of the elliptic argument ``u = u0 + λ t`` (0 for uniform motions)."""
        return self._in_units(self._lam_s, self._w_exp, "the frequency λ", self._SLOWER)

    @property
    def mean_precession_rate(self) -> float:
        """Mean rate of the precession angle φ about L."""
        return self._in_units(self._nu_s, self._w_exp, "the mean precession rate", self._SLOWER)

    @property
    def period(self) -> float:
        """Period of ω(t) (``inf`` for a motion that never repeats, e.g. the separatrix)."""
        num, rate = self._period_s
        if rate == 0.0:
            return math.inf
        return self._in_units(
            num / rate,
            -self._w_exp,
            "the period of ω",
            self._FASTER,
            lambda: math.log10(num) - math.log10(rate),
        )

    @property
    def precession_per_period(self) -> float:
        """Angle [rad] the body precesses about L during one period of ω (0 if aperiodic)."""
        num, rate = self._period_s
        if rate == 0.0:
            return 0.0
        nu = self._nu_s
        return self._in_units(
            nu * (num / rate),  # dimensionless: no scale
            0,
            "the precession angle per period",
            "ω0 lies so close to a uniform rotation that it takes that long to come back",
            lambda: math.log10(abs(nu) or 1.0) + math.log10(num) - math.log10(rate),
            " rad",
        )

    @property
    def second_period(self) -> float:
        """``2π / mean_precession_rate``, Landau's second period T' (``inf`` if no precession)."""
        nu = self._nu_s
        if self._period_s[1] == 0.0 or nu == 0.0:
            return math.inf
        return self._in_units(
            2.0 * math.pi / nu,
            -self._w_exp,
            "the precession period",
            self._FASTER,
            lambda: math.log10(2.0 * math.pi) - math.log10(abs(nu)),
        )

    def __repr__(self) -> str:
        return (
            f"FreeRigidBody(inertia={self.inertia.tolist()}, omega0={self.omega0.tolist()}, "
            f"regime={self.regime.value!r})"
        )


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
    # Moments and D relative to the largest moment (a power of two: exact), so that the
    # products below neither overflow (moments ~1e200) nor underflow.
    scale = _pow2(hi)
    J1, J2, J3 = np.sort(inertia) / scale
    D = D / scale
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
    w_sorted /= np.max(np.abs(w_sorted))  # then the norm is in [1, sqrt 3]: no overflow
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
    w_max = float(np.max(np.abs(omega0)))
    if w_max == 0.0:
        return Rotation.identity()
    # The direction of m = I ω from scaled factors (exact powers of two): I·ω itself may
    # overflow (1e107 · 1e300) or underflow (1e-300 · 1e-300); the largest scaled product is
    # at least (smallest moment / largest) / 2 >= 1e-301.
    m = (inertia / _pow2(float(inertia.max()))) * (omega0 / _pow2(w_max))
    m = m / float(np.max(np.abs(m)))
    G = float(np.linalg.norm(m))
    # Smallest rotation taking m̂ to e_z (the roll about L is irrelevant to the scene).
    mhat = m / G
    z = np.array([0.0, 0.0, 1.0])
    axis = np.cross(mhat, z)
    s = math.hypot(*axis.tolist())  # the squares of a 1e-160 component would be subnormal
    c = float(mhat @ z)
    if s < 1e-300:
        return Rotation.identity() if c > 0 else Rotation.from_rotvec([math.pi, 0.0, 0.0])
    return Rotation.from_rotvec(axis / s * math.atan2(s, c))
