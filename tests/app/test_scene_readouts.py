"""The readout table of the scenes (``python -m poinsot.app.lessons.readouts``): it runs, covers
every scene, and each row's gap between theory and measurement is within the tolerance its
scene states; the gap it carries is the one the readout shows."""

from __future__ import annotations

import math
import pathlib
import re

import pytest

from poinsot.app.lessons import SCENES, readouts
from poinsot.app.lessons.support.spec import Readout

NAMES = [spec.name for spec in SCENES]


@pytest.fixture(scope="module")
def tables() -> list[readouts.Tabulated]:
    return [tab for spec in SCENES for tab in readouts.tabulate(spec)]


@pytest.mark.slow
def test_the_command_prints_one_markdown_table_of_every_scene(capsys) -> None:
    assert readouts.main([]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert tuple(lines[:2]) == readouts.HEADER
    assert all(line.startswith("| `") and line.endswith(" |") for line in lines[2:])
    assert {re.match(r"\| `([a-z0-9-]+)`", line).group(1) for line in lines[2:]} == set(NAMES)
    assert not any("✗" in line for line in lines)
    rows = sum(len(spec.readouts) * len(spec.table_settings) for spec in SCENES)
    assert len(lines) == 2 + rows


def test_the_command_takes_one_scene_and_refuses_an_unknown_one(capsys) -> None:
    assert readouts.main(["--scene", "long-cylinder"]) == 0
    body = capsys.readouterr().out.splitlines()[2:]
    assert body and all(line.startswith("| `long-cylinder` |") for line in body)
    with pytest.raises(SystemExit) as exit_:
        readouts.main(["--scene", "no-such-scene"])
    assert exit_.value.code == 2


@pytest.mark.parametrize("name", NAMES)
def test_each_row_is_within_its_scenes_tolerance(tables, name) -> None:
    mine = [tab for tab in tables if tab.spec.name == name]
    compared = [row for tab in mine for row in tab.rows if row.gap is not None]
    assert compared, f"{name} compares no theory with a measurement"
    for tab in mine:
        assert tuple(r.quantity for r in tab.rows) == tab.spec.readouts
        for row in tab.rows:
            if row.gap is not None:
                assert row.tolerance is not None and row.tolerance > 0, row
                assert math.isfinite(row.gap) and row.within, (name, tab.label, row)


def test_the_gap_is_the_one_the_readout_shows(tables) -> None:
    shown = 0
    for tab in tables:
        for row in tab.rows:
            match = re.search(r"\(([-+]\d\.\de[-+]\d+)\)$", row.measured)
            if match and row.gap is not None:  # two digits shown; rounding at 1e-16 aside
                cell = float(match.group(1))
                assert abs(row.gap - cell) <= 0.06 * abs(cell) + 1e-15, row
                shown += 1
    assert shown >= len(SCENES)


def test_a_gap_beyond_the_tolerance_is_flagged() -> None:
    row = Readout.compare("x", 2.0, 2.2, 1e-3)
    assert row.gap == pytest.approx(0.1) and row.within is False
    assert row.measured == "2.2 (+1.0e-01)"
    assert Readout("x", "1", "—").within is None
    spec = SCENES[0]
    line = readouts.markdown([readouts.Tabulated(spec, spec.defaults(), 0.0, (row,))])
    assert line.splitlines()[-1].endswith("| +1.0e-01 | 1.0e-03 | ✗ |")


def test_the_guide_shows_the_table_of_every_row(tables) -> None:
    page = pathlib.Path(__file__).resolve().parents[2] / "docs" / "measurements" / "readouts.md"
    readme = page.read_text()
    assert "python -m poinsot.app.lessons.readouts" in readme
    start = readme.index(readouts.HEADER[0])
    shown = readme[start:].split("\n\n", 1)[0].splitlines()[2:]
    printed = readouts.markdown(tables).splitlines()[2:]
    key = lambda line: line.split(" | ")[:3]  # noqa: E731  scene, settings, quantity
    assert [key(line) for line in shown] == [key(line) for line in printed]
