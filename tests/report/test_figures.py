"""The report's figures: legends that hide no data (the exact solution's star included), a unit
on every axis label, a caption and a takeaway per figure in report.md, and a console message
when matplotlib is missing.

The drawing tests use ``small_study`` (conftest.py): Toutatis and 1 - m = 1e-14 are the panels
whose legends used to sit on the star.
"""

from __future__ import annotations

import builtins
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from poinsot.app.report.figures import (
    FIGURE_NAMES,
    MISSING,
    caption,
    draw_error_vs_time,
    draw_work_precision,
    growth_exponent,
    takeaway,
    write_figures,
)
from poinsot.app.report.measure.study import CaseResult

pytest.importorskip("matplotlib")

UNIT = re.compile(r"\[[^\]]+\]")


def drawings(results: list[CaseResult]) -> dict[str, Any]:
    figures = (
        draw_work_precision(results, "omega"),
        draw_work_precision(results, "attitude"),
        draw_error_vs_time(results),
    )
    return dict(zip(FIGURE_NAMES, figures, strict=True))


@pytest.fixture(scope="module")
def figures(small_study):
    import matplotlib.pyplot as plt

    drawn = drawings(small_study)
    for fig in drawn.values():
        fig.canvas.draw()
    yield drawn
    for fig in drawn.values():
        plt.close(fig)


def visible_points(ax: Any) -> list[tuple[np.ndarray, bool]]:
    """(display coordinates of each drawn point inside the panel, whether it is a star)."""
    box = ax.get_window_extent()
    points = []
    for line in ax.get_lines():
        xy = line.get_transform().transform(np.asarray(line.get_xydata(), dtype=float))
        for p in xy:
            if box.contains(*p):
                points.append((p, line.get_marker() == "*"))
    return points


@pytest.mark.parametrize("name", FIGURE_NAMES)
def test_legends_hide_no_data_and_no_star(figures, small_study, name):
    fig = figures[name]
    renderer = fig.canvas.get_renderer()
    axes = [ax for ax in fig.axes if ax.get_visible()]
    legends = list(fig.legends) + [ax.get_legend() for ax in axes if ax.get_legend()]
    assert legends
    boxes = [legend.get_window_extent(renderer) for legend in legends]
    stars = 0
    for ax in axes:
        for point, is_star in visible_points(ax):
            stars += is_star
            for box in boxes:
                assert not box.contains(*point), (name, ax.get_title(), point)
    # Every panel shows the exact solution's star (the cases are verified against mpmath).
    assert stars >= len(small_study)


@pytest.mark.parametrize("name", FIGURE_NAMES)
def test_every_axis_label_has_a_unit(figures, name):
    for ax in figures[name].axes:
        if ax.get_visible():
            assert UNIT.search(ax.get_xlabel()), (name, ax.get_xlabel())
            assert UNIT.search(ax.get_ylabel()), (name, ax.get_ylabel())


def test_simulated_time_is_in_the_case_unit(figures):
    labels = {ax.get_title(): ax.get_xlabel() for ax in figures["error_vs_time.png"].axes}
    assert labels["Toutatis"] == "simulated time [d]"  # omega0 in rad/day
    assert labels["separatrix"] == "simulated time [s]"


def test_the_conditioning_floor_is_drawn_where_it_explains_the_errors(figures, small_study):
    # At 1 - m = 1e-14, kappa u ~ 0.15: the dashed floor sits among the integrators' errors.
    ns14 = next(r for r in small_study if r.case.name == "near-separatrix 1-m=1e-14")
    assert ns14.conditioning.floor > 0.1
    ax = next(ax for ax in figures["work_precision.png"].axes if ax.get_title() == ns14.case.name)
    dashed = [line for line in ax.get_lines() if line.get_linestyle() == "--"]
    assert len(dashed) == 1
    assert dashed[0].get_ydata()[0] == pytest.approx(ns14.conditioning.floor)


def test_each_figure_has_a_caption_and_a_takeaway(small_study):
    for name in FIGURE_NAMES:
        assert len(caption(name)) > 80
        line = takeaway(name, small_study)
        assert line.endswith(".") and "\n" not in line
    assert "★" in takeaway("work_precision.png", small_study)
    assert "t^" in takeaway("error_vs_time.png", small_study)


def test_growth_exponent_of_a_linear_phase_drift(small_study):
    run = small_study[0].runs[0]
    linear = type(run.errors)(1e-9 * run.times, run.errors.attitude, run.errors.energy)
    drifting = type(run)(**{**run.__dict__, "errors": linear})
    assert growth_exponent(drifting) == pytest.approx(1.0)


def test_missing_matplotlib_is_said_on_the_console(small_study, tmp_path, monkeypatch, capsys):
    real_import = builtins.__import__

    def no_matplotlib(name: str, *args: Any, **kwargs: Any) -> Any:
        if name == "matplotlib" or name.startswith("matplotlib."):
            raise ImportError(f"No module named {name!r}")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_matplotlib)
    written, note = write_figures(tmp_path, small_study)
    assert written == [] and note == MISSING
    assert "matplotlib is not installed" in capsys.readouterr().err
    assert not list(tmp_path.iterdir())


@pytest.mark.slow
def test_report_gives_each_figure_a_caption_and_a_takeaway(quick_report: Path):
    text = (quick_report / "report.md").read_text()
    figures = text.split("## Figures", 1)[1]
    for number, name in enumerate(FIGURE_NAMES, start=1):
        after = figures.split(f"![{name}]({name})", 1)[1]
        block = after.split("![", 1)[0]
        assert f"*Figure {number} ({name}).*" in block
        assert "**Takeaway:**" in block
