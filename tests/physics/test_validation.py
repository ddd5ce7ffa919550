"""Bad input raises ``ValueError`` with a readable message; valid input never gives a NaN.

Valid includes the awkward corners: components 300 decades apart (a spin a hair off a principal
axis, where ``1 - m`` or an amplitude underflows), subnormal components, and the body at rest.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from poinsot.physics import FreeRigidBody, attitude_with_L_along_z, omega_from_energy

GOOD_I = (1.0, 2.0, 3.0)
GOOD_W = (0.3, 0.2, 1.0)

MOMENTS = r"(?i)inertia|moment"
OMEGA = r"(?i)omega|angular velocity"
TIME = r"(?i)\bt\b|time"


@pytest.mark.parametrize(
    "inertia",
    [
        (0.0, 1.0, 2.0),
        (-1.0, 1.0, 2.0),
        (1.0, -1e-300, 2.0),
        (np.nan, 1.0, 2.0),
        (np.inf, 1.0, 2.0),
        (1.0, 2.0, -np.inf),
        (1.0, 2.0),
        (1.0, 2.0, 3.0, 4.0),
        ((1.0, 2.0, 3.0),),
        [[1.0], [2.0], [3.0]],
        "abc",
        None,
    ],
)
def test_bad_inertia(inertia) -> None:
    with pytest.raises(ValueError, match=MOMENTS):
        FreeRigidBody(inertia=inertia, omega0=GOOD_W)


@pytest.mark.parametrize(
    "omega0",
    [
        (np.nan, 0.0, 0.0),
        (0.0, np.inf, 0.0),
        (0.0, 0.0, -np.inf),
        (1.0, 2.0, 3.0, 4.0),
        (1.0, 2.0),
        [[1.0, 2.0, 3.0]],
        "xyz",
        None,
    ],
)
def test_bad_omega0(omega0) -> None:
    with pytest.raises(ValueError, match=OMEGA):
        FreeRigidBody(inertia=GOOD_I, omega0=omega0)


def test_bad_attitude0() -> None:
    stack = Rotation.from_rotvec([[0.1, 0.0, 0.0], [0.0, 0.2, 0.0]])
    for bad in (stack, np.eye(3), "identity"):
        with pytest.raises(ValueError, match=r"(?i)attitude"):
            FreeRigidBody(inertia=GOOD_I, omega0=GOOD_W, attitude0=bad)


@pytest.mark.parametrize(
    "t",
    [
        np.nan,
        np.inf,
        -np.inf,
        np.array([0.0, np.nan]),
        np.array([1.0, np.inf]),
        np.zeros((4, 2)),
        np.zeros((2, 3, 1)),
        "soon",
    ],
)
@pytest.mark.parametrize("method", ["omega", "attitude", "contact_point"])
def test_bad_times(t, method: str) -> None:
    body = FreeRigidBody(inertia=GOOD_I, omega0=GOOD_W)
    with pytest.raises(ValueError, match=TIME):
        getattr(body, method)(t)


def test_bad_polhode_size() -> None:
    body = FreeRigidBody(inertia=GOOD_I, omega0=GOOD_W)
    for n in (0, 1, -5):
        with pytest.raises(ValueError):
            body.polhode(n)


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        ({"inertia": GOOD_I, "D": 0.5}, r"D"),  # below min I
        ({"inertia": GOOD_I, "D": 3.5}, r"D"),  # above max I
        ({"inertia": GOOD_I, "D": np.nan}, r"D"),
        ({"inertia": GOOD_I, "D": 2.0, "omega_norm": 0.0}, r"(?i)omega"),
        ({"inertia": GOOD_I, "D": 2.0, "omega_norm": -1.0}, r"(?i)omega"),
        ({"inertia": GOOD_I, "D": 2.0, "omega_norm": np.inf}, r"(?i)omega"),
        ({"inertia": (1.0, 0.0, 3.0), "D": 2.0}, MOMENTS),
        ({"inertia": (1.0, 2.0), "D": 2.0}, MOMENTS),
    ],
)
def test_bad_omega_from_energy(kwargs, pattern) -> None:
    with pytest.raises(ValueError, match=pattern):
        omega_from_energy(**kwargs)


def test_bad_attitude_with_L_along_z() -> None:  # noqa: N802
    with pytest.raises(ValueError, match=MOMENTS):
        attitude_with_L_along_z((1.0, -2.0, 3.0), GOOD_W)
    with pytest.raises(ValueError, match=OMEGA):
        attitude_with_L_along_z(GOOD_I, (np.nan, 0.0, 1.0))


def test_messages_are_readable() -> None:
    """One sentence that names the argument and shows the offending value."""
    with pytest.raises(ValueError) as info:
        FreeRigidBody(inertia=(1.0, -2.0, 3.0), omega0=GOOD_W)
    msg = str(info.value)
    assert re.search(MOMENTS, msg) and "-2" in msg and len(msg) < 300
    with pytest.raises(ValueError) as info:
        FreeRigidBody(inertia=(1.0, 2.0), omega0=GOOD_W)
    assert re.search(r"3|shape", str(info.value))


# ---- never a NaN ------------------------------------------------------------------------------

CORNERS = [
    ((1.0, np.sqrt(10.0), 10.0), (1.0, 1e-300, 0.0)),  # a hair off the minor axis
    ((1.0, np.sqrt(10.0), 10.0), (1e-300, 1.0, 0.0)),  # a hair off the intermediate axis
    ((1.0, np.sqrt(10.0), 10.0), (0.0, 1.0, 1e-300)),
    ((1.0, np.sqrt(10.0), 10.0), (5e-324, 1.0, 0.0)),  # subnormal perturbation
    ((1.0, np.sqrt(10.0), 10.0), (1e-300, 1e-300, 1.0)),  # a hair off the major axis
    ((1.0, 2.0, 3.0), (1e-160, 1.0, 1e-160)),
    ((1.0, 2.0, 3.0), (1e-200, 1e-200, 1e-300)),
    ((1.0, 1.0, 1.0), (0.0, 0.0, 1.1e-186)),
    ((1.0, 1.0 + 2**-52, 1.0 + 2**-51), (0.3, 0.4, 0.5)),  # three moments one ulp apart
    ((1.0, 2.0, 3.0), (0.0, 0.0, 0.0)),
]


def test_moment_span_of_300_decades_stays_finite() -> None:
    """The widest span allowed. ω1 swings by ~1e150 within 1e-150 time units here, so only
    finiteness is asserted (the phase at t = 0.5 is beyond any double-precision conditioning)."""
    body = FreeRigidBody(inertia=(1e-150, 1.0, 1e150), omega0=(1.0, 1.0, 1.0))
    _assert_no_nan(body, np.array([0.0, 0.5, 10.0, 1e4, 1e9]))


def test_moment_span_beyond_double_precision_is_refused_clearly() -> None:
    """Moments 600 decades apart cannot share one floating-point scale: a clear ValueError."""
    with pytest.raises(ValueError, match=MOMENTS) as info:
        FreeRigidBody(inertia=(1e-300, 1.0, 1e300), omega0=(1.0, 1.0, 1.0))
    assert "decades" in str(info.value)


BEYOND_DOUBLE = "beyond the largest double-precision number"
SCALARS = (
    "energy",
    "D",
    "plane_distance",
    "parameter",
    "complementary_parameter",
    "frequency",
    "period",
    "precession_per_period",
    "second_period",
)


def _scalar_or_refusal(body: FreeRigidBody, name: str) -> float:
    """The property's value, or 0.0 where it lies beyond the double range and the body says so
    (a spin of 1e-309 has a period of ~1e309: a clear ValueError, never inf or NaN)."""
    try:
        return float(getattr(body, name))
    except ValueError as error:
        assert BEYOND_DOUBLE in str(error), (name, str(error))
        return 0.0


def _assert_no_nan(body: FreeRigidBody, times: np.ndarray) -> None:
    scalars = {name: _scalar_or_refusal(body, name) for name in SCALARS}
    nan = [k for k, v in scalars.items() if np.isnan(v)]
    assert not nan, f"NaN in {nan}"
    for name in ("angular_momentum", "plane_normal", "semi_axes"):
        assert np.all(np.isfinite(getattr(body, name))), name
    assert np.all(np.isfinite(body.polhode(16))), "polhode"
    assert np.all(np.isfinite(body.omega(times))), "omega"
    assert np.all(np.isfinite(body.attitude(times).as_quat())), "attitude"
    assert np.all(np.isfinite(body.contact_point(times))), "contact_point"


@pytest.mark.parametrize(("inertia", "omega0"), CORNERS)
def test_no_nan_in_corners(inertia, omega0) -> None:
    body = FreeRigidBody(inertia=inertia, omega0=omega0, attitude0=Rotation.from_rotvec([1, 0, 0]))
    _assert_no_nan(body, np.array([0.0, 0.5, 10.0, 1e4, 1e9]))
    # near a permanent rotation the state is that rotation to all printed digits for a while
    w = body.omega(np.array([0.0, 0.5]))
    assert np.allclose(w, np.asarray(omega0), rtol=1e-12, atol=1e-15 * np.max(np.abs(omega0)))


@settings(max_examples=200, deadline=None, derandomize=True)
@given(
    st.lists(st.floats(-3.0, 3.0), min_size=3, max_size=3),
    st.lists(st.one_of(st.just(None), st.floats(-320.0, 0.0)), min_size=3, max_size=3),
    st.lists(st.sampled_from([-1.0, 1.0]), min_size=3, max_size=3),
    st.floats(-3.0, 3.0),
)
def test_no_nan_for_any_valid_input(logs, mags, signs, taus) -> None:
    """Components up to 320 decades apart, some exactly zero: finite everywhere."""
    inertia = 10.0 ** np.array(logs)
    omega0 = np.array([0.0 if m is None else s * 10.0**m for m, s in zip(mags, signs, strict=True)])
    body = FreeRigidBody(inertia=inertia, omega0=omega0)
    _assert_no_nan(body, np.array([0.0, 10.0**taus, 1e3 * 10.0**taus]))
