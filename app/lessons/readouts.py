"""The readout table of the scenes: for each scene, every readout's theory against the value
measured from its motion, as one Markdown table.

    python -m poinsot.app.lessons.readouts [--scene NAME]

Every number comes from the scenes' own models (``spec.build(settings).readouts(t)``): the
settings of each scene's ``table_settings`` over its defaults, at its ``picture_time``. A row
that compares two numbers shows its gap (measured/theory − 1, or as its note says) and the
tolerance the scene states for it; the exit status is 1 if any gap is beyond its tolerance.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import sys
from collections.abc import Iterable, Sequence

from poinsot.app.lessons import SCENES, scene_by_name
from poinsot.app.lessons.support.spec import Readout, SceneSpec, Value

HEADER = (
    "| scene | settings | quantity | theory | measured | gap | tolerance | ok |",
    "|:--|:--|:--|--:|--:|--:|--:|:-:|",
)


@dataclasses.dataclass(frozen=True)
class Tabulated:
    """The readouts of one scene at one set of settings and one time."""

    spec: SceneSpec
    settings: dict[str, Value]
    t: float
    rows: tuple[Readout, ...]

    @property
    def label(self) -> str:
        """The settings the table shows (over the defaults), with the time."""
        changed = {k: v for k, v in self.settings.items() if self.spec.defaults().get(k) != v}
        shown = ", ".join(f"{k} = {_value(v)}" for k, v in changed.items()) or "defaults"
        return f"{shown}, t = {self.t:g}"


def _value(value: Value) -> str:
    return f"{value:.12g}" if isinstance(value, float) else value


def tabulate(spec: SceneSpec) -> list[Tabulated]:
    """The scene's readouts at each of its ``table_settings``, at its ``picture_time``."""
    out = []
    for extra in spec.table_settings:
        settings = {**spec.defaults(), **extra}
        rows = spec.build(settings).readouts(spec.picture_time)
        out.append(Tabulated(spec, settings, spec.picture_time, rows))
    return out


def _cell(text: str) -> str:
    return text.replace("|", "\\|")


def _gap(row: Readout) -> tuple[str, str, str]:
    if row.gap is None or row.tolerance is None:
        return "", "", ""
    gap = "—" if math.isnan(row.gap) else f"{row.gap:+.1e}"
    return gap, f"{row.tolerance:.1e}", "✓" if row.within else "✗"


def markdown(tables: Iterable[Tabulated]) -> str:
    """The rows of ``tables`` as one Markdown table."""
    lines = list(HEADER)
    for tab in tables:
        for row in tab.rows:
            cells = (
                f"`{tab.spec.name}`",
                tab.label,
                row.quantity,
                row.theory,
                row.measured,
                *_gap(row),
            )
            lines.append("| " + " | ".join(_cell(c) for c in cells) + " |")
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m poinsot.app.lessons.readouts", description=__doc__.split("\n\n")[0]
    )
    parser.add_argument("--scene", action="append", help="only this scene (repeatable)")
    args = parser.parse_args(argv)
    try:
        specs = [scene_by_name(n) for n in args.scene] if args.scene else list(SCENES)
    except KeyError as exc:
        parser.error(str(exc.args[0]))
    tables = [tab for spec in specs for tab in tabulate(spec)]
    print(markdown(tables))
    beyond = [row for tab in tables for row in tab.rows if row.within is False]
    return 1 if beyond else 0


if __name__ == "__main__":
    sys.exit(main())
