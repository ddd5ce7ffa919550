"""The live readouts split the precession per period into Montgomery's dynamic and geometric
parts [Mon91] on every triaxial preset, and show no such rows elsewhere."""

from __future__ import annotations

import math

import pytest

from poinsot.app.live.panel.readouts import rows
from poinsot.app.model.parameters import Parameters
from poinsot.app.model.presets import PRESETS, Preset
from poinsot.physics import Regime
from poinsot.physics.models.geometric_phase import wrap_angle


def _number(text: str) -> float:
    return float(text.split()[0])


@pytest.mark.parametrize("preset", PRESETS, ids=lambda p: p.key)
def test_triaxial_presets_show_the_split(preset: Preset) -> None:
    body = Parameters.from_preset(preset).build()
    table = dict(rows(body))
    if body.regime in (Regime.MAJOR_AXIS, Regime.MINOR_AXIS):
        dynamic = _number(table["… dynamic 2TP/|L|"])
        geometric = _number(table["… geometric −Ω"])
        # The split adds up to the precession per period (mod 2π), to the 4 digits shown.
        total = float(wrap_angle(dynamic + geometric - body.precession_per_period))
        assert abs(total) < 2e-3 * max(1.0, abs(dynamic))
        assert 2 * math.pi > abs(geometric) > 0.0
    else:
        assert "… geometric −Ω" not in table
