"""The numbers that look like bugs, and what the report says about them.

- Near and on the separatrix the splitting's errors are exactly 2 (omega reversed) and pi (a
  half-turn) at every step size: it crosses the separatrix and makes flips the exact motion
  does not make (its energy error exceeds the distance to the separatrix).
- Observed orders near zero or negative came from errors that do not decrease with the cost:
  no order is reported for them; nor from errors below the conditioning floor (rounding, which
  differs from one machine to another).
- At 1 - m = 1e-14 no integrator gets below ~0.1: the problem's condition number times the
  unit roundoff is ~0.15.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from poinsot.app.report.findings import crossed, flip_reading, saturated
from poinsot.app.report.measure.cases import CASES
from poinsot.app.report.measure.conditioning import (
    UNIT_ROUNDOFF,
    FlipCounter,
    condition_number,
    separatrix_distance,
)
from poinsot.app.report.measure.runs import IntegratorRun, RunErrors
from poinsot.app.report.verdicts import observed_order, order_fit_runs, verdict
from poinsot.physics import FreeRigidBody

BY_NAME = {c.name: c for c in CASES}


def by_name(results, name):
    return next(r for r in results if r.case.name == name)


def kappa_of(name: str, samples: int = 100):
    case = BY_NAME[name]
    body = FreeRigidBody(case.inertia, case.omega0)
    t = np.linspace(0.0, case.t_end(body.period, quick=True), samples + 1)
    return condition_number(case.inertia, case.omega0, t, body.omega(t))


# --------------------------------------------------------------------------------------------
# Conditioning


def test_the_condition_number_grows_like_one_over_one_minus_m():
    k6 = kappa_of("near-separatrix 1-m=1e-06")
    k8 = kappa_of("near-separatrix 1-m=1e-08")
    assert not k6.lower_bound and not k8.lower_bound
    assert k8.kappa / k6.kappa == pytest.approx(100.0, rel=0.05)
    assert kappa_of("generic").kappa < 1e3


def test_at_one_minus_m_1e_14_rounding_alone_costs_a_tenth():
    c = kappa_of("near-separatrix 1-m=1e-14")
    # Even one ulp moves omega by more than the linear range: kappa is a lower bound.
    assert c.lower_bound
    assert c.floor == c.kappa * UNIT_ROUNDOFF
    assert c.floor > 0.1


def test_separatrix_distance_has_the_sign_of_the_side():
    inertia = (1.0, 2.0, 3.0)
    assert separatrix_distance(inertia, (0.1, 0.2, 1.0)) > 0  # about the major axis (I3)
    assert separatrix_distance(inertia, (1.0, 0.2, 0.1)) < 0  # about the minor axis (I1)
    sep = BY_NAME["separatrix"]
    assert separatrix_distance(sep.inertia, sep.omega0) == 0.0
    # Many rows at once, intermediate moment found in any order of the axes.
    rows = np.array([[1.0, 0.1, 0.2], [0.1, 1.0, 0.2]])  # about I = 3, then about I = 1
    assert np.all(np.sign(separatrix_distance((3.0, 1.0, 2.0), rows)) == [1.0, -1.0])


def test_flip_counter_counts_half_turns_not_wobbles():
    t = np.linspace(0.0, 4.0 * np.pi, 400)
    omega = np.zeros((len(t), 3))
    omega[:, 1] = np.sin(t)  # two periods from 0: up, down, up, down
    counter = FlipCounter.for_motion((1.0, 2.0, 3.0), omega)
    assert counter.axis == 1 and counter.threshold == pytest.approx(0.5, rel=1e-3)
    assert counter.count(omega) == 3  # + to -, - to +, + to -
    wobble = omega.copy()
    wobble[:, 1] = 0.9 + 0.3 * np.sin(7 * t)  # never below -threshold: no flip
    assert counter.count(wobble) == 0


def test_crossing_the_separatrix():
    assert crossed(1e-7, (-1e-5, 1e-7))
    assert not crossed(1e-7, (5e-8, 1e-7))
    assert crossed(-0.2, (-0.2, 1e-9))
    assert crossed(0.0, (-1e-8, 0.0))
    assert not crossed(0.0, (-1e-16, 1e-16))  # rounding


# --------------------------------------------------------------------------------------------
# Saturated errors on the separatrix


def test_the_splitting_on_the_separatrix_makes_a_flip_the_exact_motion_never_makes(small_study):
    r = by_name(small_study, "separatrix")
    assert r.flips_resolved and r.exact_flips == 0
    splitting = [run for run in r.runs if run.method == "splitting"]
    assert splitting and all(run in saturated(r) for run in splitting)
    for run in splitting:
        # omega reversed and a half-turn, to the digits printed: not a bug of the measure.
        assert run.omega_error == pytest.approx(2.0, abs=1e-3)
        assert run.attitude_error == pytest.approx(math.pi, abs=1e-3)
        assert run.flips > r.exact_flips
        assert flip_reading(r, run) == "left the separatrix: extra flips"
    # The midpoint rule keeps the energy and |L|: it stays on the separatrix and unsaturated.
    midpoint = [run for run in r.runs if run.method == "midpoint"]
    assert all(run.omega_error < 1e-2 for run in midpoint)
    assert not any(crossed(0.0, run.separatrix_range) for run in midpoint)


def test_near_the_separatrix_the_splitting_crosses_it(small_study):
    r = by_name(small_study, "near-separatrix 1-m=1e-14")
    d0 = r.conditioning.separatrix_distance
    for run in (run for run in r.runs if run.method == "splitting"):
        assert run.separatrix_range[0] < 0.0 < d0  # it went round the minor axis
        assert run.flips > r.exact_flips
        assert flip_reading(r, run) == "crossed the separatrix: extra flips"


# --------------------------------------------------------------------------------------------
# Observed orders and verdicts


def fake_run(cost: int, error: float) -> IntegratorRun:
    grid = np.array([0.0, 1.0])
    errs = RunErrors(np.array([0.0, error]), np.zeros(2), np.zeros(2))
    return IntegratorRun(
        "case", "RK45", f"n={cost}", 1.0, 1, cost, error, 0.0, 0.0, grid, errs, 0, (0.0, 0.0)
    )


def test_observed_order_of_a_power_law():
    runs = [fake_run(c, 1e-1 * c**-4.0) for c in (10, 100, 1000)]
    assert observed_order(runs) == pytest.approx(4.0)


def test_no_order_where_the_error_does_not_decrease():
    # The separatrix's RK45 runs: 1.6e-4, 4.5e-6, 2.8e-4 (a fit gave -0.16).
    runs = [fake_run(c, e) for c, e in ((400, 1.58e-4), (2000, 4.47e-6), (12000, 2.84e-4))]
    assert math.isnan(observed_order(runs))
    flat = [fake_run(c, 1e-4) for c in (400, 2000)]
    assert math.isnan(observed_order(flat))


def test_errors_below_the_conditioning_floor_are_left_out_of_the_fit():
    # The separatrix's DOP853 runs (kappa u = 2.3e-4): only the first is above the floor; the
    # other two are rounding, and a fit through them gave 2.57 on one machine, 0.63 on another.
    runs = [fake_run(c, e) for c, e in ((300, 5.4e-4), (900, 2.5e-5), (2600, 2.3e-6))]
    assert len(order_fit_runs(runs)) == 3
    assert [r.cost for r in order_fit_runs(runs, floor=2.3e-4)] == [300]
    assert math.isnan(observed_order(order_fit_runs(runs, floor=2.3e-4)))


def test_the_verdict_names_the_conditioning_when_no_setting_gets_below_a_tenth(small_study):
    r = by_name(small_study, "near-separatrix 1-m=1e-14")
    assert re.search(
        r"below an error of 0\.1 \(κ u = 0\.\d+: the problem's conditioning\)", verdict(r).text
    )


# --------------------------------------------------------------------------------------------
# What the quick report says


def section(text: str, title: str) -> str:
    return text.split(f"## {title}", 1)[1].split("\n## ", 1)[0]


def table_rows(block: str) -> dict[str, list[str]]:
    rows = {}
    for line in block.splitlines():
        if line.startswith("| ") and not line.startswith("| case") and "---" not in line:
            cells = [c.strip() for c in line.strip("|").split("|")]
            rows.setdefault(cells[0], cells[1:])
    return rows


@pytest.mark.slow
def test_report_explains_the_conditioning(quick_report: Path):
    text = (quick_report / "report.md").read_text()
    rows = table_rows(section(text, "Conditioning"))
    kappa_u = float(rows["near-separatrix 1-m=1e-14"][3])
    assert kappa_u > 0.1
    assert rows["near-separatrix 1-m=1e-14"][2].startswith("≥")
    assert "**near-separatrix 1-m=1e-14**" in section(text, "Conditioning")


@pytest.mark.slow
def test_report_has_no_order_that_is_not_one(quick_report: Path):
    text = (quick_report / "report.md").read_text()
    for cells in table_rows(section(text, "Observed orders")).values():
        for cell in cells[1:]:
            if cell:
                assert float(cell) > 1.0, cell


@pytest.mark.slow
def test_report_explains_the_saturated_errors(quick_report: Path):
    text = (quick_report / "report.md").read_text()
    block = section(text, "Saturated errors: flips and the separatrix")
    lines = [line for line in block.splitlines() if line.startswith("| separatrix | splitting")]
    assert lines and all("left the separatrix: extra flips" in line for line in lines)
    assert re.search(r"\| 2\.00e\+00 \| 3\.14e\+00 \|", block)


@pytest.mark.slow
def test_long_horizon_runs_settings_that_mean_something(quick_report: Path):
    import csv

    with open(quick_report / "work_precision.csv", newline="") as f:
        rows = [r for r in csv.DictReader(f) if r["case"] == "long horizon"]
    methods = {r["method"] for r in rows} - {"exact"}
    assert len(methods) == 4
    for method in methods:
        best = min(float(r["omega_error"]) for r in rows if r["method"] == method)
        assert best < 0.5, (method, best)  # not the O(1) errors of loose settings
