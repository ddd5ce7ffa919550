"""The legend's colours for colour-blind viewers, computed from the palette and each legend's
declared rows (no browser): every two rows of every preset's and every scene's legend, on every
look (dark, light, projector on either), are at least CIEDE2000 15 apart for normal vision and
under simulated deuteranopia, protanopia and tritanopia (Machado et al. at full severity
[MOF09], through colorspacious), or told apart by a declared non-colour cue (the swatch's shape
or line style, drawn so in the scene). Every swatch keeps 3 : 1 against its panel [WCAG21
§1.4.11]. The colour difference is checked first against Sharma et al.'s published test data
[SWD05]."""

from __future__ import annotations

import itertools

import colorspacious
import numpy as np
import pytest

from poinsot.app.construction import palette
from poinsot.app.construction.palette import RGB, Entry, Look
from poinsot.app.lessons import SCENES
from poinsot.app.lessons.support import colors
from poinsot.app.live.lecture.neighbour import ROW as NEIGHBOUR_ROW
from poinsot.app.live.panel.legend import entries, legend_html, merged
from poinsot.app.model.elements import ALL_ELEMENTS
from poinsot.app.model.presets import MENU

#: The least CIEDE2000 difference between two rows told apart by colour alone.
LEAST = 15.0
#: WCAG 2.1's least contrast of a graphical object against its background.
CONTRAST = 3.0
VISIONS = {
    "normal vision": None,
    "deuteranopia": "deuteranomaly",
    "protanopia": "protanomaly",
    "tritanopia": "tritanomaly",
}


def ciede2000(lab1: np.ndarray, lab2: np.ndarray) -> float:
    """The CIEDE2000 difference of two CIELAB colours [SWD05, Eqs. 1-22]."""
    L1, a1, b1 = (float(v) for v in lab1)
    L2, a2, b2 = (float(v) for v in lab2)
    c_mean7 = ((np.hypot(a1, b1) + np.hypot(a2, b2)) / 2.0) ** 7
    g = 0.5 * (1.0 - np.sqrt(c_mean7 / (c_mean7 + 25.0**7)))
    a1p, a2p = (1.0 + g) * a1, (1.0 + g) * a2
    c1, c2 = np.hypot(a1p, b1), np.hypot(a2p, b2)
    h1 = np.degrees(np.arctan2(b1, a1p)) % 360.0 if c1 else 0.0
    h2 = np.degrees(np.arctan2(b2, a2p)) % 360.0 if c2 else 0.0
    dh = 0.0 if c1 * c2 == 0 else (h2 - h1 + 180.0) % 360.0 - 180.0
    if c1 * c2 != 0 and h2 - h1 == -180.0:
        dh = -180.0
    d_big_h = 2.0 * np.sqrt(c1 * c2) * np.sin(np.radians(dh / 2.0))
    l_mean, c_mean = (L1 + L2) / 2.0, (c1 + c2) / 2.0
    if c1 * c2 == 0:
        h_mean = h1 + h2
    elif abs(h1 - h2) <= 180.0:
        h_mean = (h1 + h2) / 2.0
    else:
        h_mean = (h1 + h2 + (360.0 if h1 + h2 < 360.0 else -360.0)) / 2.0
    t = (
        1.0
        - 0.17 * np.cos(np.radians(h_mean - 30.0))
        + 0.24 * np.cos(np.radians(2.0 * h_mean))
        + 0.32 * np.cos(np.radians(3.0 * h_mean + 6.0))
        - 0.20 * np.cos(np.radians(4.0 * h_mean - 63.0))
    )
    s_l = 1.0 + 0.015 * (l_mean - 50.0) ** 2 / np.sqrt(20.0 + (l_mean - 50.0) ** 2)
    s_c, s_h = 1.0 + 0.045 * c_mean, 1.0 + 0.015 * c_mean * t
    r_c = 2.0 * np.sqrt(c_mean**7 / (c_mean**7 + 25.0**7))
    r_t = -np.sin(np.radians(60.0 * np.exp(-(((h_mean - 275.0) / 25.0) ** 2)))) * r_c
    dl, dc, dhh = (L2 - L1) / s_l, (c2 - c1) / s_c, d_big_h / s_h
    return float(np.sqrt(dl**2 + dc**2 + dhh**2 + r_t * dc * dhh))


#: Sharma, Wu and Dalal's Table 1 (pairs 1, 7, 9-13, 17-21, 25, 34): L*a*b* pairs and ΔE00.
SHARMA = [
    ((50.0, 2.6772, -79.7751), (50.0, 0.0, -82.7485), 2.0425),
    ((50.0, 0.0, 0.0), (50.0, -1.0, 2.0), 2.3669),
    ((50.0, 2.49, -0.001), (50.0, -2.49, 0.0009), 7.1792),
    ((50.0, 2.49, -0.001), (50.0, -2.49, 0.0011), 7.2195),
    ((50.0, -0.001, 2.49), (50.0, 0.0009, -2.49), 4.8045),
    ((50.0, 2.5, 0.0), (73.0, 25.0, -18.0), 27.1492),
    ((50.0, 2.5, 0.0), (61.0, -5.0, 29.0), 22.8977),
    ((50.0, 2.5, 0.0), (56.0, -27.0, -3.0), 31.9030),
    ((50.0, 2.5, 0.0), (58.0, 24.0, 15.0), 19.4535),
    ((50.0, 2.5, 0.0), (50.0, 3.1736, 0.5854), 1.0000),
    ((60.2574, -34.0099, 36.2677), (60.4626, -34.1751, 39.4387), 1.2644),
    ((22.7233, 20.0904, -46.6940), (23.0331, 14.9730, -42.5619), 2.0373),
]


@pytest.mark.parametrize(("lab1", "lab2", "expected"), SHARMA)
def test_the_colour_difference_reproduces_sharmas_test_data(lab1, lab2, expected):
    assert ciede2000(np.array(lab1), np.array(lab2)) == pytest.approx(expected, abs=1e-4)
    assert ciede2000(np.array(lab2), np.array(lab1)) == pytest.approx(expected, abs=1e-4)


def seen(rgb: RGB, vision: str | None) -> np.ndarray:
    """CIELAB of ``rgb`` as an eye with ``vision`` (None: normal) sees it."""
    x = np.asarray(rgb, dtype=float) / 255.0
    if vision is not None:
        space = {"name": "sRGB1+CVD", "cvd_type": vision, "severity": 100}
        x = np.clip(colorspacious.cspace_convert(x, space, "sRGB1"), 0.0, 1.0)
    return np.asarray(colorspacious.cspace_convert(x, "sRGB1", "CIELab"))


def closest(a: RGB, b: RGB) -> tuple[float, str]:
    """The least difference of two colours over the four visions, and under which."""
    return min((ciede2000(seen(a, v), seen(b, v)), name) for name, v in VISIONS.items())


def contrast(a: RGB, b: RGB) -> float:
    """WCAG 2.1's contrast ratio of two sRGB colours."""

    def luminance(rgb: RGB) -> float:
        c = np.asarray(rgb, dtype=float) / 255.0
        c = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
        return float(c @ (0.2126, 0.7152, 0.0722))

    hi, lo = sorted((luminance(a), luminance(b)), reverse=True)
    return (hi + 0.05) / (lo + 0.05)


def legends() -> list[tuple[str, Look, list[Entry]]]:
    """Every legend a session can show: each preset of the menu (with the neighbour body,
    which any preset may show) and each scene (its elements and its parts), on every look."""
    out = []
    for look_name, look in palette.LOOKS.items():
        for preset in MENU:
            rows = [*entries(preset.elements or ALL_ELEMENTS, look), NEIGHBOUR_ROW]
            out.append((f"{preset.key}, {look_name}", look, merged(rows)))
        for spec in SCENES:
            rows = [*entries(spec.elements, look), *(r for p in spec.parts for r in p.rows())]
            out.append((f"{spec.name}, {look_name}", look, merged(rows)))
    return out


def confusions(rows: list[Entry]) -> list[str]:
    """The pairs of rows (and of colours within a row) told apart by colour alone and closer
    than LEAST for some vision."""
    found = []
    for a, b in itertools.combinations(rows, 2):
        if a.cue != b.cue:
            continue
        d, vision = min(closest(x, y) for x in a.colors for y in b.colors)
        if d < LEAST:
            found.append(f"{a.name!r} / {b.name!r}: {d:.1f} ({vision})")
    for row in rows:
        if row.style != "labelled":
            for x, y in itertools.combinations(row.colors, 2):
                d, vision = closest(x, y)
                if d < LEAST:
                    found.append(f"{row.name!r}'s {x} / {y}: {d:.1f} ({vision})")
    return found


def test_every_two_legend_rows_are_told_apart_under_every_colour_vision():
    failures = {name: bad for name, _, rows in legends() if (bad := confusions(rows))}
    assert failures == {}


def test_rows_of_like_colour_are_told_apart_by_a_cue_the_swatch_draws():
    """A cue is declared only where it is drawn: the swatch of a thin, thick or dashed line
    differs from a solid one's (its height or its paint)."""
    look = palette.DARK
    solid, *others = (
        legend_html([Entry("x", (look.polhode,), "line", style)])
        for style in ("solid", "thin", "thick", "dashed")
    )
    assert len({solid, *others}) == 4
    full = next(e for e in entries(ALL_ELEMENTS, look) if e.name == "whole polhode")
    assert full.style == "thin" and palette.FULL_POLHODE_WIDTH_PX < palette.TRACE_WIDTH_PX


def test_every_swatch_stands_out_of_its_panel_on_either_theme():
    low = {
        f"{name}: {row.name!r} {color} {ratio:.2f}"
        for name, look, rows in legends()
        for row in rows
        for color in row.colors
        if (ratio := contrast(color, palette.background(look))) < CONTRAST
    }
    assert low == set()


def test_the_twin_and_the_neighbour_are_not_the_herpolhodes_colour():
    for look in palette.LOOKS.values():
        for twin in (colors.TWIN, *NEIGHBOUR_ROW.colors):
            assert closest(twin, look.herpolhode)[0] >= LEAST


def test_every_colour_a_scene_part_draws_has_its_legend_row():
    for spec in SCENES:
        for part in spec.parts:
            listed = {c for row in part.rows() for c in row.colors}
            drawn = {*part.colors, *([part.surface] if part.surface else [])}
            assert drawn <= listed, (spec.name, part.key, drawn - listed)
    dzhanibekov = next(s for s in SCENES if s.name == "dzhanibekov")
    twin = next(p for p in dzhanibekov.parts if "twin" in p.key)
    assert twin.rows()[0].colors == (colors.TWIN,)


def test_the_palette_is_okabe_and_itos():
    """The published values [OI08], which the looks take their hues from."""
    assert palette.OKABE_ITO == {
        "black": (0, 0, 0),
        "orange": (230, 159, 0),
        "sky blue": (86, 180, 233),
        "bluish green": (0, 158, 115),
        "yellow": (240, 228, 66),
        "blue": (0, 114, 178),
        "vermillion": (213, 94, 0),
        "reddish purple": (204, 121, 167),
    }
    assert palette.DARK.polhode == palette.OKABE_ITO["reddish purple"]
    assert palette.DARK.omega == palette.OKABE_ITO["yellow"]


#: The longest row name the legend's two columns show whole in the 300 px left column at its
#: 0.78 rem text ("T-handle (its mesh)", 19 characters, was the longest seen whole; "polhodes
#: round the major axis" was cut).
NAME_CHARACTERS = 19


def test_every_legend_row_name_fits_its_column():
    long = {row.name for _, _, rows in legends() for row in rows if len(row.name) > NAME_CHARACTERS}
    assert long == set()
