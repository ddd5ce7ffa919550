"""Regressions of the fuzz, by root cause: arguments that are no real number.

Before, numpy converted them silently or failed with its own message: a complex ω was cut to
its real part (a ComplexWarning), text was parsed, True read as 1.0, a Python int beyond the
double range raised ``OverflowError: int too large to convert to float``, ``polhode(inf)`` an
``OverflowError``, ``polhode(None)`` a TypeError about ``int()``. Now each is refused by the
package's own check, as an :class:`~poinsot.physics.core.validation.InputTypeError` (a TypeError
that is also a ValueError, so that ``except ValueError`` still catches every refusal) or a
ValueError, with a message that names the argument.
"""

from __future__ import annotations

import math
import re
from decimal import Decimal
from fractions import Fraction

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from poinsot.physics import (
    FreeRigidBody,
    attitude_with_L_along_z,
    box_dimensions,
    omega_from_energy,
)
from poinsot.physics.core.validation import InputTypeError, real_array
from poinsot.physics.integrators import Propagation, integrate

pytestmark = pytest.mark.filterwarnings("error")

GOOD_I, W = (1.0, 2.0, 3.0), (0.3, 0.2, 1.0)
NOT_NUMBERS = [
    (1.0 + 1.0j, 2.0, 3.0),
    np.array([1.0, 2.0, 3.0], dtype=complex),  # zero imaginary parts: refused all the same
    ("1", 2.0, 3.0),
    "1 2 3",
    (True, 2.0, 3.0),
    np.array([True, False, True]),
    (None, 2.0, 3.0),
    None,
    (object(), 2.0, 3.0),
    np.array(["2020-01-01"] * 3, dtype="datetime64[D]"),
]


def value_id(value: object) -> str:
    """The value's repr without a memory address: every pytest-xdist worker collects the same
    test ids (an ``<object object at 0x...>`` differs from one process to the next)."""
    return re.sub(r" at 0x[0-9a-fA-F]+", "", repr(value))


@pytest.mark.parametrize("value", NOT_NUMBERS, ids=value_id)
def test_moments_and_omega_that_are_no_real_numbers_are_refused(value) -> None:
    for args, name in (((value, W), "moments of inertia"), ((GOOD_I, value), "omega0")):
        with pytest.raises(InputTypeError, match=name) as info:
            FreeRigidBody(*args)
        assert isinstance(info.value, TypeError) and isinstance(info.value, ValueError)


def test_real_numbers_of_every_kind_are_accepted() -> None:
    reference = FreeRigidBody(GOOD_I, W).omega(0.7)
    for inertia in (
        (1, 2, 3),
        np.array([1, 2, 3], dtype=np.int8),
        np.array(GOOD_I, dtype=np.float32),
        (Fraction(1), Decimal(2), np.float16(3.0)),
        [np.float64(1.0), np.int64(2), 3.0],
    ):
        np.testing.assert_array_equal(FreeRigidBody(inertia, W).omega(0.7), reference)


@pytest.mark.parametrize(
    "value", [(10**400, 2.0, 3.0), np.array([np.longdouble("1e400"), 1.0, 1.0])], ids=repr
)
def test_numbers_beyond_the_double_range_are_refused(value) -> None:
    with pytest.raises(ValueError, match=r"1\.8e308") as info:
        FreeRigidBody(value, W)
    assert not isinstance(info.value, TypeError)


@pytest.mark.parametrize(
    "t", [1j, True, "1.0", None, [1.0, "2"], [True, 1.0], 10**400, np.longdouble("1e400")]
)
def test_times_that_are_no_real_numbers_are_refused(t) -> None:
    body = FreeRigidBody(GOOD_I, W)
    for method in (body.omega, body.attitude, body.state, body.sample, body.contact_point):
        with pytest.raises(ValueError, match="time"):
            method(t)


@pytest.mark.parametrize(
    ("n", "kind"),
    [
        (math.inf, ValueError),
        (math.nan, ValueError),
        (2.5, ValueError),
        (10**9, ValueError),
        (1e9, ValueError),
        (0, ValueError),
        (-1, ValueError),
        (True, TypeError),
        (None, TypeError),
        ("16", TypeError),
        (16 + 0j, TypeError),
        (np.array([16]), ValueError),
    ],
    ids=repr,
)
def test_polhode_needs_a_whole_number_of_points(n, kind) -> None:
    with pytest.raises(kind, match="number of polhode points"):
        FreeRigidBody(GOOD_I, W).polhode(n)


@pytest.mark.parametrize("n", [16, np.int64(16), 16.0, np.array(16), np.uint8(16)], ids=repr)
def test_polhode_takes_any_integer(n) -> None:
    assert FreeRigidBody(GOOD_I, W).polhode(n).shape == (16, 3)


@pytest.mark.parametrize("sign", [0, 2.5, math.nan, "a", None, 1j])
def test_pole_sign_is_plus_or_minus_one(sign) -> None:
    with pytest.raises(ValueError, match="pole_sign"):
        FreeRigidBody.from_energy(GOOD_I, 2.5, pole_sign=sign)
    with pytest.raises(ValueError, match="pole_sign"):
        omega_from_energy(GOOD_I, 2.5, 1.0, sign)


def test_an_attitude_of_nan_is_refused() -> None:
    nan_rotation = Rotation.from_rotvec([1e300, 0.0, 0.0])  # scipy makes it NaN
    with pytest.raises(ValueError, match="attitude0 is a Rotation of NaN"):
        FreeRigidBody(GOOD_I, W, nan_rotation)


def test_every_module_refuses_the_same_way() -> None:
    """The helpers share the checks: the same kind of error with the same words."""
    with pytest.raises(InputTypeError, match="moments of inertia"):
        attitude_with_L_along_z((1j, 2.0, 3.0), W)
    with pytest.raises(InputTypeError, match="the mass"):
        box_dimensions(GOOD_I, "1 kg")
    with pytest.raises(InputTypeError, match="method must be a name"):
        integrate(["RK45"], GOOD_I, W, None, [0.0, 1.0])
    with pytest.raises(InputTypeError, match="setting"):
        Propagation("splitting", GOOD_I, W, None, 1j)


@pytest.mark.parametrize("value", [[1.0, [2.0, 3.0]], [1.0], (), np.array([2.0])], ids=repr)
def test_one_number_is_not_a_sequence(value) -> None:
    """np.shape of a ragged list raised numpy's own ValueError before the check could."""
    with pytest.raises(ValueError, match="D must be one number, not the sequence"):
        FreeRigidBody.from_energy(GOOD_I, value)


def test_real_array_keeps_float64_arrays_as_they_are() -> None:
    """The common case costs nothing: a float64 array is returned itself."""
    arr = np.array([1.0, 2.0, 3.0])
    assert real_array(arr, "x") is arr
