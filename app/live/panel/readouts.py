"""Live text: the motion in one plain sentence (:func:`headline`), then the conserved quantities
and constants of the motion at 4 significant figures, each defined in words (on hover, and in a
folded list a tap opens). One notation throughout: D = |L|²/2T, h = 2T/|L|.

Formatting only; every number comes from the :class:`poinsot.physics.FreeRigidBody` (the CSV
export keeps every digit).
"""

from __future__ import annotations

import html
import math
import re
from collections.abc import Callable, Mapping, Sequence

import numpy as np

from poinsot.app.model import docs_site
from poinsot.physics import FreeRigidBody, Regime
from poinsot.physics.models.axis_angles import axis_angles
from poinsot.physics.models.geometric_phase import montgomery_phase

REGIME_TEXT: dict[Regime, str] = {
    Regime.MAJOR_AXIS: "polhode around the major axis",
    Regime.MINOR_AXIS: "polhode around the minor axis",
    Regime.SEPARATRIX: "on the separatrix (unstable)",
    Regime.SYMMETRIC: "symmetric top: regular precession",
    Regime.SPHERE: "sphere: ω constant",
    Regime.PERMANENT_ROTATION: "permanent rotation",
    Regime.REST: "at rest",
}
#: L within this angle of ±e₂ over a period: the motion is read as a flip about the middle
#: axis (the headline and the regime say so), not as a wobble round the stable axis.
NEAR_MIDDLE = math.radians(30.0)
SURVEY = 256

#: What each quantity is, in a sentence a second-year student reads (on hover, and in the
#: folded list under the table, which a tap opens).
DEFINITIONS: dict[str, str] = {
    "regime": "Which kind of motion this is: which principal axis the polhode (the path of ω "
    "on the body) goes round.",
    "k²": "The parameter of the Jacobi elliptic functions that give ω(t): 0 for a circle, "
    "near 1 close to the separatrix.",
    "period of ω": "The time after which ω, seen in the body, comes back to its start.",
    "precession / period": "How far the body turns about L while ω goes once round its polhode.",
    "… dynamic 2TP/|L|": "The part of that turn given by the energy: 2T × period / |L| "
    "(Montgomery 1991).",
    "… geometric −Ω": "The other part: minus the solid angle that L sweeps out in the body "
    "over one period (Montgomery 1991).",
    "D = |L|²/2T": "The constant that picks the polhode: between the smallest and the largest "
    "moment; equal to the middle one on the separatrix.",
    "h = 2T/|L|": "The distance of the invariable plane from the centre, on which the energy "
    "ellipsoid rolls.",
    "energy T": "The kinetic energy of rotation, ½ ω·Iω: constant in free motion.",
    "|L|": "The size of the angular momentum L = Iω: constant in free motion, and L keeps its "
    "direction in space.",
}


def _num(x: float, digits: int = 4) -> str:
    if math.isinf(x):
        return "∞"
    if math.isnan(x):
        return "—"
    return f"{x + 0.0:.{digits}g}"


def near_middle(body: FreeRigidBody) -> bool:
    """Whether L comes within NEAR_MIDDLE of the middle axis ±e₂ over a period (a triaxial
    body on either side of the separatrix)."""
    if body.regime not in (Regime.MAJOR_AXIS, Regime.MINOR_AXIS):
        return False
    if not math.isfinite(body.period):
        return True
    angles = axis_angles(body.inertia, body.omega(np.linspace(0.0, body.period, SURVEY)))[:, 1]
    return float(np.min(np.minimum(angles, math.pi - angles))) < NEAR_MIDDLE


def headline(body: FreeRigidBody) -> str:
    """The motion in plain words, with its one number (times in the app's time unit, s)."""
    regime, period = body.regime, body.period
    if regime in (Regime.MAJOR_AXIS, Regime.MINOR_AXIS):
        if near_middle(body):
            return f"Near the middle axis: it flips over every {_num(period / 2.0, 3)} s."
        side = "largest" if regime is Regime.MAJOR_AXIS else "smallest"
        return (
            f"Stable spin about the axis of {side} moment: ω wobbles round it once every "
            f"{_num(period, 3)} s."
        )
    if regime is Regime.SEPARATRIX:
        return "On the separatrix: ω creeps towards the middle axis and never comes back."
    if regime is Regime.SYMMETRIC:
        return f"A symmetric body: ω goes round the symmetry axis every {_num(period, 3)} s."
    if regime is Regime.SPHERE:
        return "All three moments equal: ω stays fixed, along L."
    if regime is Regime.PERMANENT_ROTATION:
        return "Spinning exactly about a principal axis: nothing changes."
    return "At rest."


def regime_text(body: FreeRigidBody) -> str:
    """The regime's row: a polhode round a stable axis that sweeps past the middle one says
    so (the T-handle's flip is not a wobble round the major axis)."""
    text = REGIME_TEXT.get(body.regime, str(body.regime))
    if near_middle(body):
        return "flipping about the middle axis (near the separatrix)"
    return text


def rows(body: FreeRigidBody, digits: int = 4) -> list[tuple[str, str]]:
    """(label, value) pairs shown in the readout table, at ``digits`` significant figures."""
    n = lambda x: _num(x, digits)  # noqa: E731
    precession = body.precession_per_period
    if math.isfinite(body.period):
        precession_text = f"{n(precession)} rad ({math.degrees(precession):.1f}°)"
    else:
        precession_text = "— (no period)"
    # A sphere has no elliptic motion, so no parameter k² to show (it would read "0").
    k2 = [] if body.regime is Regime.SPHERE else [("k²", n(body.parameter))]
    return [
        ("regime", regime_text(body)),
        *k2,
        ("period of ω", n(body.period)),
        ("precession / period", precession_text),
        *_montgomery(body, n),
        ("D = |L|²/2T", n(body.D)),
        ("h = 2T/|L|", n(body.plane_distance)),
        ("energy T", n(body.energy)),
        ("|L|", n(math.hypot(*body.angular_momentum))),
    ]


def _montgomery(body: FreeRigidBody, n: Callable[[float], str]) -> list[tuple[str, str]]:
    """The precession per period split [Mon91]: its dynamic part 2TP/|L| and its geometric part
    −Ω (the solid angle L sweeps in the body), on a triaxial body's polhode; nothing else."""
    if body.regime not in (Regime.MAJOR_AXIS, Regime.MINOR_AXIS):
        return []
    try:
        phase = montgomery_phase(body)
    except ValueError:  # a period beyond the double range: the row above says so
        return []
    return [
        ("… dynamic 2TP/|L|", f"{n(phase.dynamic)} rad"),
        ("… geometric −Ω", f"{n(phase.geometric)} rad"),
    ]


def defined(label: str, definitions: Mapping[str, str] = DEFINITIONS) -> str:
    """``label`` with its definition shown on hover (HTML ``title``), if it has one."""
    meaning = definitions.get(label)
    if not meaning:
        return label
    return f'<span title="{html.escape(meaning)}">{html.escape(label, quote=False)}</span>'


def glossary(labels: Sequence[str], definitions: Mapping[str, str] = DEFINITIONS) -> str:
    """The definitions of ``labels`` folded under the table (a tap or a click opens them)."""
    items = [
        f"<li><b>{html.escape(label)}</b>: {html.escape(definitions[label])}</li>"
        for label in labels
        if label in definitions
    ]
    if not items:
        return ""
    return (
        '<details class="poinsot-glossary"><summary>What these mean</summary><ul>'
        + "".join(items)
        + "</ul></details>"
    )


def markdown(body: FreeRigidBody) -> str:
    """The headline, then the readouts as a markdown table (a "|" inside a cell is escaped;
    each quantity defined on hover and in the folded list below)."""
    escape = lambda text: text.replace("|", "\\|")  # noqa: E731
    shown = rows(body)
    lines = [f"**{headline(body)}**", "", "| quantity | value |", "|:--|--:|"]
    lines += [f"| {escape(defined(label))} | {escape(value)} |" for label, value in shown]
    return "\n".join([*lines, "", glossary([label for label, _ in shown])])


#: Where the sources are listed in full: the guide's page of docs/REFERENCES.md, served at
#: /docs/ by the server (opened beside the scene, so that the session stays).
REFERENCES_URL = docs_site.PREFIX + "REFERENCES/"
#: The keys of docs/REFERENCES.md as a reader cites them: authors and year.
CITATIONS: dict[str, str] = {
    "LL76": "Landau & Lifshitz 1976",
    "FM06": "Fasano & Marmi 2006",
    "Pars65": "Pars 1965",
    "GPS02": "Goldstein, Poole & Safko 2002",
    "CFSZ08": "Celledoni, Fassò, Säfström & Zanna 2008",
    "vZS07": "van Zon & Schofield 2007",
    "DLM97": "Dullweber, Leimkuhler & McLachlan 1997",
    "ACC91": "Ashbaugh, Chicone & Cushman 1991",
    "Mon91": "Montgomery 1991",
    "VMS17": "Van Damme, Mardešić & Sugny 2017",
    "VMS20": "Mardešić, Gutierrez Guillen, Van Damme & Sugny 2020",
    "BG58": "Bracewell & Garriott 1958",
    "HO95": "Hudson & Ostro 1995",
    "DLMF": "NIST DLMF 2024",
    "Bul65": "Bulirsch 1965",
    "Car95": "Carlson 1995",
    "DP80": "Dormand & Prince 1980",
    "HNW93": "Hairer, Nørsett & Wanner 1993",
    "HLW06": "Hairer, Lubich & Wanner 2006",
    "JZ05": "Jorba & Zou 2005",
    "Dek71": "Dekker 1971",
    "CW80": "Cody & Waite 1980",
    "OI08": "Okabe & Ito 2008",
    "MOF09": "Machado, Oliveira & Fernandes 2009",
    "SWD05": "Sharma, Wu & Dalal 2005",
    "WCAG21": "W3C WCAG 2.1 2018",
}
_CITED = re.compile(r"\[([A-Za-z]+[0-9]*\b[^\]]*)\]")


def readable(source: str) -> str:
    """``source`` with its bracketed keys of docs/REFERENCES.md as authors and year, linked
    to that list in the guide: "[LL76 §37; FM06]" reads "[Landau & Lifshitz 1976, §37; Fasano &
    Marmi 2006]", a link to :data:`REFERENCES_URL` opened in a new tab. A bracket that cites no
    known key is left as it is."""

    def cite(match: re.Match[str]) -> str:
        items = [item.strip() for item in match.group(1).split(";")]
        out = []
        for item in items:
            key, _, rest = item.partition(" ")
            if key not in CITATIONS:
                return match.group(0)
            out.append(CITATIONS[key] + (f", {rest}" if rest else ""))
        return f'<a href="{REFERENCES_URL}" target="_blank" rel="noopener">[{"; ".join(out)}]</a>'

    return _CITED.sub(cite, source)


def time_markdown(t: float, paused: bool) -> str:
    state = "paused" if paused else "running"
    return f"**t = {t:8.2f}** &nbsp; _{state}_"
