"""Readouts a second-year student understands: a headline in words, 4 significant figures on
screen (every digit on hover, in the CSV and in the readout table), a definition of each
quantity, one notation (D = |L|²/2T), sources as authors and year linked to the list, a row
whose theory does not hold saying so, plot labels in plain Unicode short enough to be drawn
whole."""

from __future__ import annotations

import pathlib
import re

import pytest

from poinsot.app.lessons import SCENES
from poinsot.app.lessons.support.spec import (
    Readout,
    Slider,
    on_screen,
    screen_cells,
    screen_table,
)
from poinsot.app.live.panel import plots, readouts
from poinsot.app.model.parameters import Parameters
from poinsot.app.model.presets import PRESETS, preset_by_key

REFERENCES = (pathlib.Path(__file__).resolve().parents[2] / "docs" / "REFERENCES.md").read_text()


def body(key: str):
    return Parameters.from_preset(preset_by_key(key)).build()


def significant(text: str) -> list[int]:
    """The significant figures of each decimal number in ``text``."""
    out = []
    for number in re.findall(r"\d+\.\d+|\d+", text.replace("−", "-")):
        digits = number.replace(".", "").lstrip("0")
        out.append(len(digits))
    return out


@pytest.mark.parametrize("key", ["t_handle", "near_separatrix"])
def test_a_body_near_the_middle_axis_is_headlined_as_a_flip(key):
    b = body(key)
    text = readouts.headline(b)
    assert text == f"Near the middle axis: it flips over every {b.period / 2:.3g} s."
    regime = readouts.regime_text(b)
    assert regime == "flipping about the middle axis (near the separatrix)"


def test_a_stable_spin_is_headlined_round_its_axis_and_every_preset_has_a_headline():
    assert readouts.headline(body("major")).startswith("Stable spin about the axis of largest")
    assert readouts.headline(body("minor")).startswith("Stable spin about the axis of smallest")
    assert readouts.regime_text(body("major")) == "polhode around the major axis"
    for preset in PRESETS:
        b = Parameters.from_preset(preset).build()
        assert readouts.headline(b).endswith("."), preset.key
        assert readouts.markdown(b).startswith(f"**{readouts.headline(b)}**")


def test_the_live_readouts_show_4_significant_figures_and_define_every_quantity():
    for preset in PRESETS:
        b = Parameters.from_preset(preset).build()
        for label, value in readouts.rows(b):
            assert label in readouts.DEFINITIONS, label
            figures = significant(value.split("(")[0])
            assert all(n <= 4 for n in figures), (preset.key, label, value)
        text = readouts.markdown(b)
        assert text.count("<span title=") == len(readouts.rows(b))
        assert "<details" in text and "What these mean" in text  # a tap opens them


def test_the_screen_rounds_a_scene_row_and_keeps_every_digit_on_hover():
    row = Readout.compare("period", 13.712345678, 13.7200001, 1e-2)
    theory, measured = screen_cells(row)
    assert (theory, measured) == ("13.71", "13.72 (+0.056 %)")
    tiny = Readout.compare("D", 1.6, 1.6 * (1.0 - 1.1e-16), 1e-12)
    assert screen_cells(tiny) == ("1.6", "1.6 (agrees)")  # not "(-1.1e-16)"
    table = screen_table((row,))
    assert f'<span title="{row.measured}">13.72 (+0.056 %)</span>' in table
    assert on_screen("t₁ = 12.3456789, −3.14159265, e₂, 1e-12") == "t₁ = 12.35, −3.142, e₂, 1e-12"


def test_a_row_whose_theory_does_not_hold_says_so():
    """The polhode family's wobble far from the axis: the small-oscillation theory gives 0.96
    where the motion wobbles at 0.538, and the row says the theory is not valid there."""
    spec = next(s for s in SCENES if s.name == "polhode-family")
    rows = spec.build(spec.defaults()).readouts(spec.picture_time)
    wobble = next(r for r in rows if r.quantity.startswith("wobble"))
    assert not wobble.applies
    theory, _ = screen_cells(wobble)
    assert theory.endswith("(not valid here)")
    assert "holds near the axis only" in wobble.note


def test_one_notation_for_d_everywhere_on_screen():
    texts = [label for b in (body(p.key) for p in PRESETS) for label, _ in readouts.rows(b)]
    for spec in SCENES:
        texts += [c.label for c in spec.controls if isinstance(c, Slider)]
        for row in spec.build(spec.defaults()).readouts(spec.picture_time):
            texts += [row.quantity, row.note]
    assert not [t for t in texts if "G²" in t or "G^2" in t]
    assert any(t == "D = |L|²/2T" for t in texts)


def test_sources_read_as_authors_and_year_linked_to_the_list():
    dzhanibekov = next(s for s in SCENES if s.name == "dzhanibekov")
    text = readouts.readable(dzhanibekov.source)
    assert text.startswith(
        '<a href="/docs/REFERENCES/" target="_blank" rel="noopener">'
        "[Ashbaugh, Chicone & Cushman 1991; Landau & Lifshitz 1976, §37; "
        "Fasano & Marmi 2006, Theorem 7.3; NIST DLMF 2024, 19.12.1]</a>"
    )
    for spec in SCENES:
        shown = readouts.readable(spec.source)
        assert re.match(r'<a href="/docs/REFERENCES/" [^>]*>\[[^\]]*\]</a>', shown), spec.name
        assert not re.search(r"\[[A-Z][A-Za-z]*\d\d", shown), shown  # no key left


def test_each_citation_names_the_authors_and_year_of_its_reference():
    """Against docs/REFERENCES.md itself: the year and every surname cited are in the key's
    row, and every key of the list has its citation."""
    listed = dict(re.findall(r"^\| \*\*([A-Za-z0-9]+)\*\* \| ([^|]*)\|", REFERENCES, re.M))
    for key, reference in listed.items():
        if key not in readouts.CITATIONS:
            continue
        cited = readouts.CITATIONS[key]
        year = cited.rsplit(" ", 1)[1]
        assert f"({year})" in reference or f" {year} " in reference, (key, year)
        for name in re.split(r", | & ", cited.rsplit(" ", 1)[0]):
            if name not in ("NIST DLMF", "W3C WCAG 2.1"):
                assert name in reference, (key, name)
    cited_keys = {
        item.strip().split(" ")[0]
        for spec in SCENES
        for group in re.findall(r"\[([^\]]*)\]", spec.source)
        for item in group.split(";")
    }
    assert cited_keys <= set(readouts.CITATIONS), cited_keys - set(readouts.CITATIONS)


#: The most characters a plot's y title has before it is cut: a plot of the left column
#: (300 px wide, aspect 1.6) draws about 180 px of height, about 20 characters of its font.
Y_TITLE_CHARACTERS = 20


def test_plot_titles_and_legends_are_plain_unicode_and_fit():
    texts: list[str] = []
    y_titles = [q.y_label for q in plots.QUANTITIES]
    for spec in SCENES:
        for plot in spec.plots:
            texts += [plot.title, plot.x_label, plot.y_label, *(s for s, _ in plot.series)]
            y_titles.append(plot.y_label)
    assert not [t for t in texts if re.search(r"[\^_\\{}]", t)]
    assert not [t for t in y_titles if len(t) > Y_TITLE_CHARACTERS]
    dzhanibekov = next(s for s in SCENES if s.name == "dzhanibekov").plots[0]
    assert dzhanibekov.y_label == "log₁₀ sin ∠(ω, e₂)"
    assert "theory ε·exp(σt)" in [s for s, _ in dzhanibekov.series]
