"""Odd arguments for the fuzz: numbers at every scale, and everything that is not a number.

Every value is built from a :class:`Source` of choices, so that one set of builders serves
both modes: :class:`RandomSource` (numpy's Generator, the benchmark) and a hypothesis source in
the tests (which then shrinks a failure to its simplest choices; option 0 of every table is
the plainest value).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from decimal import Decimal
from fractions import Fraction
from typing import Any, Protocol

import numpy as np
from scipy.spatial.transform import Rotation

__all__ = [
    "RandomSource",
    "Source",
    "attitude",
    "count",
    "moments",
    "number",
    "odd_scalar",
    "omega",
    "one_of",
    "positive",
    "real",
    "times",
    "vector",
]

#: The largest finite double and the smallest subnormal one.
BIG = float(np.finfo(float).max)
TINY = 5e-324


class Source(Protocol):
    """Where the choices come from."""

    def index(self, n: int) -> int:
        """An integer in ``[0, n)``."""
        ...

    def real(self, lo: float, hi: float) -> float:
        """A float in ``[lo, hi]``."""
        ...


class RandomSource:
    """Choices from numpy's Generator (reproducible from its seed)."""

    def __init__(self, rng: np.random.Generator) -> None:
        self.rng = rng

    def index(self, n: int) -> int:
        return int(self.rng.integers(n))

    def real(self, lo: float, hi: float) -> float:
        return float(self.rng.uniform(lo, hi))


Builder = Callable[[Source], Any]


def one_of(src: Source, *builders: Builder) -> Any:
    """One of the builders, chosen by ``src`` (the first is the plainest)."""
    return builders[src.index(len(builders))](src)


def pick(src: Source, options: Sequence[Any]) -> Any:
    return options[src.index(len(options))]


def real(src: Source) -> float:
    """A finite magnitude > 0 at any scale: ordinary, from 1e-320 to 1.7e308, or an edge."""
    kind = src.index(6)
    if kind <= 1:
        return 10.0 ** src.real(-3.0, 3.0)
    if kind == 2:
        return 10.0 ** src.real(-306.0, 306.0)
    if kind == 3:
        return 10.0 ** src.real(-323.0, 308.25)
    if kind == 4:  # subnormal
        return TINY * (1 + src.index(1 << 20))
    return pick(src, [1.0, 2.0, 0.5, 3.0, BIG, 1e306, 1e-306, 2.2250738585072014e-308, 1e300])


def number(src: Source) -> float:
    """A finite float of either sign, or a zero."""
    if src.index(8) == 0:
        return pick(src, [0.0, -0.0])
    return real(src) * pick(src, [1.0, -1.0])


def odd_scalar(src: Source) -> Any:
    """Something that is not a plain finite float: non-finite, another type, or no number."""
    return pick(
        src,
        [
            math.nan,
            math.inf,
            -math.inf,
            None,
            "1.5",
            "abc",
            b"2",
            True,
            False,
            np.bool_(True),
            1 + 0j,
            2j,
            np.complex128(1.0),
            10**400,
            -(10**400),
            [1.0],
            (),
            [[2.0]],
            [1.0, [2.0, 3.0]],
            np.array(1.5),
            np.array([1.5]),
            np.float32(3.5),
            np.float16(2.0),
            np.int8(3),
            np.uint64(2**64 - 1),
            np.longdouble("1e400"),
            Fraction(1, 3),
            Decimal("2.5"),
            Decimal("nan"),
            object(),
            {},
            {1.0},
            np.datetime64("2020-01-01"),
            np.timedelta64(1, "s"),
            7,
            np.int64(5),
            np.float64(2.5),
        ],
    )


def positive(src: Source) -> Any:
    """Mostly a positive number, sometimes anything."""
    return real(src) if src.index(4) else one_of(src, number, odd_scalar)


def _container(src: Source, values: list[float]) -> Any:
    kind = src.index(6)
    if kind <= 1:
        return tuple(values)
    if kind == 2:
        return list(values)
    if kind == 3:
        return np.array(values)
    if kind == 4:
        return np.array(values, dtype=np.float32)
    ints = [int(x) if math.isfinite(x) and abs(x) < 2**62 else x for x in values]
    return np.array(ints) if all(isinstance(x, int) for x in ints) else tuple(ints)


def _scale_pattern(src: Source, n: int) -> list[float]:
    """``n`` magnitudes: a common scale, independent scales, or with equal ones."""
    kind = src.index(5)
    if kind <= 1:
        scale = pick(src, [1.0, 1.0, 1e306, 1e-306, 1e150, 1e-150, 1e300, 2.0**-1060])
        return [scale * 10.0 ** src.real(-1.0, 1.0) for _ in range(n)]
    if kind == 2:
        return [real(src) for _ in range(n)]
    if kind == 3:  # equal moments, or one ulp apart
        x = real(src)
        step = pick(src, [0.0, 0.0, math.ulp(x), 1e-8 * x])
        return [x + k * step for k in range(n)]
    return [pick(src, [1.0, 2.0, 3.0, 0.5, 1e-3, 1e3]) for _ in range(n)]


def moments(src: Source) -> Any:
    """Principal moments: mostly three positive numbers at some scale, else anything."""
    if src.index(5):
        values = _scale_pattern(src, 3)
        order = pick(src, [(0, 1, 2), (2, 1, 0), (1, 0, 2), (0, 2, 1)])
        return _container(src, [values[k] for k in order])
    return odd_vector(src, positive)


def omega(src: Source) -> Any:
    """An angular velocity: mostly three finite numbers (some zero), else anything."""
    if src.index(5):
        values = _scale_pattern(src, 3)
        signs = [pick(src, [1.0, -1.0]) for _ in range(3)]
        zeros = pick(src, [(), (), (), (0,), (1,), (2,), (0, 2), (0, 1), (0, 1, 2)])
        w = [0.0 if k in zeros else signs[k] * values[k] for k in range(3)]
        return _container(src, w)
    return odd_vector(src, number)


def vector(src: Source) -> Any:
    """Three numbers of any kind (for the integrators' and textbook modules' vectors)."""
    return one_of(src, omega, moments)


def odd_vector(src: Source, element: Builder) -> Any:
    """A vector that is wrong: a bad element, a wrong shape, a wrong kind."""
    kind = src.index(8)
    good = [element(src) for _ in range(3)]
    if kind == 0:
        good[src.index(3)] = odd_scalar(src)
        return pick(src, [tuple, list])(good)
    if kind == 1:
        return pick(src, [good[:2], good + [1.0], [good], [[x] for x in good], []])
    if kind == 2:
        return [good[0], [good[1], good[2]]]
    if kind == 3:
        dtype = pick(src, [complex, bool, object, str, np.int8, np.float16, np.longdouble])
        try:
            return np.array(good, dtype=dtype)
        except (TypeError, ValueError, OverflowError):
            return np.array(good, dtype=object)
    if kind == 4:
        return pick(src, [np.zeros((3, 1)), np.zeros((1, 3)), np.zeros(0), np.ones((2, 3))])
    if kind == 5:
        return pick(src, [{1.0, 2.0, 3.0}, {"a": 1.0}, "1 2 3", Rotation.identity(), range(3)])
    return odd_scalar(src)


def count(src: Source) -> Any:
    """A number of points: small and valid, large, or not a count at all."""
    return pick(
        src,
        [
            16,
            256,
            2,
            3,
            1,
            0,
            -1,
            10**9,
            10**30,
            1e9,
            math.inf,
            math.nan,
            2.5,
            256.0,
            True,
            False,
            np.int64(16),
            np.float64(16.0),
            np.uint8(7),
            "16",
            None,
            1j,
            16 + 0j,
            [16],
            np.array(16),
            np.array([16]),
            Fraction(16),
            Decimal(16),
            -(10**30),
        ],
    )


def _time_array(src: Source) -> Any:
    n = pick(src, [0, 1, 2, 5, 17])
    scale = pick(src, [1.0, 10.0, 1e-300, 1e3, 1e9, 1e150, 1e300, 1.7e308])
    t = np.array([number(src) if src.index(8) == 0 else scale * src.real(-1, 1) for _ in range(n)])
    if n and src.index(3) == 0:
        t[src.index(n)] = pick(src, [math.nan, math.inf, -math.inf])
    kind = src.index(6)
    if kind == 0:
        return t.tolist()
    if kind == 1 and n:
        return t.reshape(n, 1) if src.index(2) else t.reshape(1, n)
    if kind == 2:
        return t.astype(pick(src, [np.float32, np.int64, complex, bool, object, str]))
    return np.sort(t) if kind == 3 else t


def times(src: Source) -> Any:
    """Times: a float at any scale, an array (possibly with NaN or inf), or anything."""
    kind = src.index(6)
    if kind <= 1:
        return pick(src, [0.0, 1.0, 0.5, -2.0, 37.5]) if kind else number(src)
    if kind <= 3:
        return _time_array(src)
    if kind == 4:
        return pick(src, [1, -3, np.int32(2), np.float32(0.25), [0.0, 1.0], (0.0,), [[0.0]]])
    return odd_scalar(src)


def attitude(src: Source) -> Any:
    """An initial attitude: None, one rotation, or something that is not one rotation."""
    kind = src.index(8)
    if kind <= 3:
        return None
    if kind <= 5:
        rotvec = [src.real(-4.0, 4.0) for _ in range(3)]
        return Rotation.from_rotvec(rotvec)
    return pick(
        src,
        [
            Rotation.identity(),
            Rotation.from_quat([[0.0, 0.0, 0.0, 1.0]]),
            Rotation.from_rotvec([[0.1, 0.0, 0.0], [0.0, 0.2, 0.0]]),
            Rotation.from_rotvec([1e300, 0.0, 0.0]),
            np.eye(3),
            "identity",
            (0.0, 0.0, 0.0, 1.0),
            1.0,
        ],
    )
