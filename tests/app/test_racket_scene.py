"""The tennis-racket scene's bodies and readouts: Brody's measured racquet beside the mesh, the
distance between their moments said in words, and the twist closing on the separatrix formula as
the toss nears the middle axis."""

from __future__ import annotations

import pytest

from poinsot.app.lessons.tennis_racket import BRODY_OPTION, SPEC, mesh_against_brody, racquet
from poinsot.app.model.bodies import MEASURED


def test_brody_is_a_body_beside_the_mesh() -> None:
    brody = MEASURED["brody"]
    assert brody.inertia == (0.00121, 0.01638, 0.01748)
    assert tuple(round(r, 3) for r in brody.ratios) == (0.069, 0.937, 1.0)
    assert tuple(round(r, 3) for r in racquet().ratios) == (0.077, 0.925, 1.0)


def test_the_readout_says_how_far_the_mesh_is_from_brody() -> None:
    row = mesh_against_brody()
    assert "0.0692 : 0.937 : 1" in row.theory and "0.0771 : 0.925 : 1" in row.measured
    assert "I₁/I₃ +11.3%" in row.note and "I₂/I₃ -1.3%" in row.note


@pytest.mark.parametrize("moments", [BRODY_OPTION, "ideal racket 0.01 : 0.99 : 1"])
def test_the_twist_closes_on_the_formula_as_epsilon_shrinks(moments: str) -> None:
    gaps = []
    for epsilon in (1e-1, 1e-2, 1e-3, 1e-5):
        model = SPEC.build({**SPEC.defaults(), "moments": moments, "epsilon": epsilon})
        gaps.append(abs(model.measured.twist - float(model.theory.twist)))
        assert all(row.within is not False for row in model.rows), model.rows
    assert all(a > b for a, b in zip(gaps, gaps[1:], strict=False))
    assert gaps[-1] < 1e-8
