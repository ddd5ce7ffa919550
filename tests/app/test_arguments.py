"""The one bounds check that every numeric argument converter is a call of."""

from __future__ import annotations

import argparse
import math

import pytest

from poinsot.app.cli.arguments import in_bounds


@pytest.mark.parametrize("text", ["0", "0.5", "1"])
def test_a_closed_range_takes_its_ends(text):
    assert in_bounds(text, float, 0, 1, wanted="w") == float(text)


@pytest.mark.parametrize(
    ("text", "kind", "low", "high", "open_low"),
    [
        ("-1", float, 0, 1, False),
        ("1.0001", float, 0, 1, False),
        ("0", float, 0, 1, True),  # an open low end refuses the end itself
        ("-0.0", float, 0, 1, True),
        ("-1", int, 0, math.inf, False),
    ],
)
def test_out_of_bounds_is_the_wanted_message(text, kind, low, high, open_low):
    with pytest.raises(argparse.ArgumentTypeError) as info:
        in_bounds(text, kind, low, high, open_low=open_low, wanted="give what fits")
    assert str(info.value) == f"{text!r}: give what fits"


def test_the_high_end_is_unbounded_unless_given():
    assert in_bounds("1e300", float, 0, wanted="w") == 1e300
    assert in_bounds("0.0001", float, 0, open_low=True, wanted="w") == 0.0001


@pytest.mark.parametrize(
    ("text", "kind", "message"),
    [
        ("1.5", int, "'1.5' is not a whole number"),
        ("two", float, "'two' is not a number"),
        ("nan", float, "'nan' is not a finite number"),
        ("inf", float, "'inf' is not a finite number"),  # before the bounds, which inf would pass
    ],
)
def test_what_is_not_a_finite_number_is_refused_before_the_bounds(text, kind, message):
    with pytest.raises(argparse.ArgumentTypeError) as info:
        in_bounds(text, kind, -math.inf, math.inf, wanted="never this")
    assert str(info.value) == message


def test_a_whole_number_stays_whole():
    value = in_bounds("65535", int, 0, 65535, wanted="w")
    assert value == 65535 and isinstance(value, int)
