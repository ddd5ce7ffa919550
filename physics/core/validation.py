"""Input checks: a readable error, raised before anything is computed.

Every public entry point of :mod:`poinsot.physics` checks its arguments here once, so that the
core sees one canonical case (finite arrays of the right shape, positive moments) and a student
reads what is wrong and what to change.

Two kinds of refusal:

* a number that is out of range (negative, NaN, infinite, beyond the double range), or an
  array of the wrong shape: ``ValueError``;
* something that is not a real number at all (text, ``None``, a complex number, ``True``/
  ``False``, a date, an arbitrary object): :class:`InputTypeError`, which is a ``TypeError``
  and also a ``ValueError``, so that one ``except ValueError`` catches every refusal of the
  package.

Nothing is converted silently: a complex number is refused rather than cut to its real part,
a string rather than parsed, a bool rather than read as 0 or 1.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

__all__ = [
    "InputTypeError",
    "check_attitude",
    "check_count",
    "check_energy_parameter",
    "check_flag",
    "check_inertia",
    "check_moment_span",
    "check_number",
    "check_positive",
    "check_sign",
    "check_time_array",
    "check_times",
    "check_vector",
    "grid_size",
    "real_array",
    "real_number",
]

#: The moments may span at most this factor: beyond it a scaled moment leaves double precision.
MOMENT_SPAN = 1e300
#: The most points a curve may be asked for (a drawing needs a few thousand; 10⁶ is 24 MB).
MAX_POINTS = 1_000_000
#: The most times a measurement may sample, or steps a method may take (each is one
#: evaluation of the motion: 10⁷ take seconds and hundreds of MB).
MAX_SAMPLES = 10_000_000

_BOOLS = (bool, np.bool_)
_TEXT = (str, bytes)
_COMPLEX = (complex, np.complexfloating)
#: dtype kinds that hold real numbers.
_REAL_KINDS = "iuf"
_KIND_NAMES = {
    "b": "True/False values",
    "c": "complex numbers",
    "U": "text",
    "S": "text",
    "M": "dates",
    "m": "durations",
    "V": "structured records",
}


class InputTypeError(TypeError, ValueError):
    """An argument that is not a real number where one belongs (text, None, a complex number,
    a bool, an object). A ``TypeError``, and a ``ValueError`` too: ``except ValueError`` catches
    every refusal of :mod:`poinsot.physics`."""


def _show(value: object) -> str:
    """A short repr of ``value`` for a message."""
    text = " ".join(repr(value).split())
    return text if len(text) <= 80 else text[:72] + " …" + text[-6:]


def _not_real(value: object) -> str | None:
    """What ``value`` is if it is certainly no real number (None, bool, text, complex)."""
    if value is None:
        return "None"
    if isinstance(value, _BOOLS):
        return f"{value!r} (a bool; write 1.0 or 0.0 if a number is meant)"
    if isinstance(value, _TEXT):
        return f"the text {_show(value)} (convert it with float() first)"
    if isinstance(value, _COMPLEX):
        return f"the complex number {value!r} (only real numbers have a meaning here)"
    return None


def _has_bool_or_text(seq: list[object] | tuple[object, ...]) -> bool:
    """A bool or a text anywhere in nested lists/tuples (numpy would read True as 1.0)."""
    for x in seq:
        if isinstance(x, _BOOLS + _TEXT) or (isinstance(x, list | tuple) and _has_bool_or_text(x)):
            return True
    return False


def _object_elements(arr: NDArray, name: str, expected: str) -> NDArray[np.float64]:
    """An object array of real numbers (Python ints beyond int64, Fractions, Decimals)."""
    out = np.empty(arr.shape)
    flat = out.reshape(-1)
    for k, x in enumerate(arr.reshape(-1).tolist()):
        bad = _not_real(x)
        if bad is None and isinstance(x, list | tuple | np.ndarray | dict | set):
            raise ValueError(f"{name} must be {expected}; it holds a nested {type(x).__name__}")
        if bad is not None:
            raise InputTypeError(f"{name} must be {expected}, not {bad}")
        try:
            flat[k] = float(x)
        except OverflowError:
            raise ValueError(
                f"{name} holds {_show(x)}, beyond the double-precision range (1.8e308): "
                "express it in other units"
            ) from None
        except (TypeError, ValueError):
            raise InputTypeError(
                f"{name} must be {expected}, not {_show(x)} (a {type(x).__name__})"
            ) from None
    return out


def real_array(value: object, name: str, expected: str = "real numbers") -> NDArray[np.float64]:
    """``value`` as a float64 array (any shape), refusing everything that is not a real number.

    Raises:
        InputTypeError: text, None, bools, complex numbers, dates, other objects.
        ValueError: ragged nesting, or a number beyond the double range.
    """
    if type(value) is np.ndarray and value.dtype == np.float64:
        return value
    if isinstance(value, list | tuple) and all(type(x) is float for x in value):
        return np.array(value, dtype=np.float64)  # plain floats, the usual input: none refused
    bad = _not_real(value)
    if bad is not None:
        raise InputTypeError(f"{name} must be {expected}, not {bad}")
    if isinstance(value, list | tuple) and _has_bool_or_text(value):
        raise InputTypeError(f"{name} must be {expected}: {_show(value)} holds a bool or a text")
    try:
        arr = np.asarray(value)
    except (TypeError, ValueError, OverflowError):
        raise ValueError(
            f"{name} must be {expected}, not the ragged or unreadable {_show(value)}"
        ) from None
    kind = arr.dtype.kind
    if kind in _REAL_KINDS:
        if arr.dtype.itemsize <= 8:  # fits in a double: no overflow, and no costly np.errstate
            return arr.astype(np.float64)
        with np.errstate(over="ignore"):  # a long double beyond 1.8e308 becomes inf: refused later
            return arr.astype(np.float64)
    if kind == "O":
        return _object_elements(arr, name, expected)
    what = _KIND_NAMES.get(kind, f"values of type {arr.dtype}")
    raise InputTypeError(f"{name} must be {expected}, not {what}: got {_show(value)}")


def real_number(value: object, name: str) -> float:
    """``value`` as one float (not yet checked finite): int, float, numpy scalar, Fraction,
    Decimal or a 0-d array; refuses arrays, text, None, bools and complex numbers."""
    if type(value) is float:
        return value
    if isinstance(value, list | tuple) or (isinstance(value, np.ndarray) and value.ndim):
        raise ValueError(f"{name} must be one number, not the sequence {_show(value)}")
    arr = real_array(value, name, "a real number")
    if arr.shape != ():
        raise ValueError(f"{name} must be one number, not {_show(value)}")
    return float(arr)


def check_number(value: object, name: str) -> float:
    """``value`` as a finite float, else an error naming ``name``."""
    x = real_number(value, name)
    if not math.isfinite(x):
        raise ValueError(f"{name} must be a finite number, got {_show(value)}")
    return x


def check_positive(value: object, name: str) -> float:
    """``value`` as a positive finite float, else an error naming ``name``."""
    x = real_number(value, name)
    if not (math.isfinite(x) and x > 0.0):
        raise ValueError(f"{name} must be positive and finite, got {_show(value)}")
    return x


def check_count(value: object, name: str, minimum: int, maximum: int = MAX_POINTS) -> int:
    """``value`` as an int in ``[minimum, maximum]``: an integer, or a float with an integer
    value (``256.0``); not a bool, not a fraction of a point."""
    if isinstance(value, np.ndarray) and value.shape == ():
        value = value.item()
    if isinstance(value, int | np.integer) and not isinstance(value, _BOOLS):
        n = int(value)
    else:
        x = real_number(value, name)
        if not (math.isfinite(x) and x == math.floor(x)):
            raise ValueError(f"{name} must be a whole number, got {_show(value)}")
        n = int(x)
    if not minimum <= n <= maximum:
        raise ValueError(f"{name} must be between {minimum} and {maximum:,}, got {_show(value)}")
    return n


def grid_size(span: float, step: float, what: str, advice: str) -> int:
    """``ceil(span/step)`` steps of a grid, refused beyond :data:`MAX_SAMPLES` (a step that
    underflowed to 0, or a span of a billion turns, would never end)."""
    n = span / step if step > 0.0 else math.inf
    if not n <= MAX_SAMPLES:
        raise ValueError(f"{what} would take {n:.3g} steps, more than {MAX_SAMPLES:,}: {advice}")
    return math.ceil(n)


def check_flag(value: object, name: str) -> bool:
    """``True`` or ``False`` (or a numpy bool), nothing else."""
    if not isinstance(value, _BOOLS):
        raise InputTypeError(f"{name} must be True or False, not {_show(value)}")
    return bool(value)


def check_sign(value: object, name: str) -> float:
    """+1.0 or -1.0 from ``+1``/``-1`` (int or float)."""
    x = real_number(value, name)
    if x not in (1.0, -1.0):
        raise ValueError(f"{name} must be +1 or -1, got {_show(value)}")
    return x


def check_vector(value: ArrayLike, name: str) -> NDArray[np.float64]:
    """``value`` as a (3,) array of finite floats, else an error naming ``name``."""
    arr = real_array(value, name, "three real numbers")
    if arr.shape != (3,):
        raise ValueError(f"{name} must be three numbers (shape (3,)), got shape {arr.shape}")
    if not all(map(math.isfinite, arr.tolist())):
        raise ValueError(f"{name} must be finite (and within ±1.8e308), got {arr.tolist()}")
    return arr


def check_inertia(value: ArrayLike) -> NDArray[np.float64]:
    """Principal moments as a (3,) array of positive finite floats [kg m², any unit]."""
    inertia = check_vector(value, "the moments of inertia")
    if min(inertia.tolist()) <= 0.0:
        raise ValueError(
            f"the moments of inertia must be positive, got {inertia.tolist()} "
            "(a principal moment is a sum of m·r², never zero or negative)"
        )
    return inertia


def check_moment_span(inertia: NDArray[np.float64]) -> None:
    """Refuse moments more than :data:`MOMENT_SPAN` apart (checked moments, any order)."""
    i_min, i_max = min(inertia.tolist()), max(inertia.tolist())
    if i_max / MOMENT_SPAN > i_min:
        raise ValueError(
            "the moments of inertia span more than 300 decades "
            f"({i_min:g} to {i_max:g}): beyond double precision; express them so that the "
            "smallest is at least 1e-300 of the largest"
        )


#: The identity attitude, one shared instance (a single Rotation cannot be changed in place).
IDENTITY_ATTITUDE = Rotation.identity()


def check_attitude(value: object, name: str = "attitude0") -> Rotation:
    """One scipy Rotation (body -> space) with a finite quaternion; ``None`` is the identity
    (:data:`IDENTITY_ATTITUDE`)."""
    if value is None:
        return IDENTITY_ATTITUDE
    if not isinstance(value, Rotation) or not value.single:
        raise ValueError(f"{name} must be one scipy Rotation (body -> space) or None")
    if not all(map(math.isfinite, value.as_quat().tolist())):
        raise ValueError(
            f"{name} is a Rotation of NaN (made from an infinite or NaN angle or matrix): "
            "build it from finite numbers"
        )
    return value


def check_energy_parameter(D: object, inertia: NDArray[np.float64]) -> float:
    """``D = |L|²/2T`` as a float in ``[min I, max I]`` (same unit as the checked moments)."""
    d = real_number(D, "D")
    if not math.isfinite(d):
        raise ValueError(f"D must be a finite number, got {d}")
    lo, hi = min(inertia.tolist()), max(inertia.tolist())
    if not (lo <= d <= hi):
        raise ValueError(
            "D = |L|²/2T must lie between the smallest and largest moments "
            f"[{lo:g}, {hi:g}], got {d:g}"
        )
    return d


def check_times(t: ArrayLike, name: str = "time") -> float | NDArray[np.float64]:
    """The times as a float if the caller passed one number, else as a (N,) float array."""
    if isinstance(t, float):  # the common scalar (also numpy.float64): no array round trip
        if not math.isfinite(t):
            raise ValueError(f"{name} must be finite (got NaN or infinity)")
        return float(t)
    arr = real_array(t, name, "a number or a 1-D array of numbers")
    if arr.ndim > 1:
        raise ValueError(f"{name} must be a number or a 1-D array, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite (got NaN, infinity or a number beyond 1.8e308)")
    return float(arr) if arr.ndim == 0 else arr


def check_time_array(t: ArrayLike, name: str = "t") -> NDArray[np.float64]:
    """The times as a (N,) float array: a number is one time."""
    times = check_times(t, name)
    return np.atleast_1d(np.asarray(times, dtype=float))
