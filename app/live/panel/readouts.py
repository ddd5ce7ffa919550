"""Live text: the conserved quantities and constants of the motion, formatted for a projector.

Formatting only; every number comes from the :class:`poinsot.physics.FreeRigidBody`.
"""

from __future__ import annotations

import math

from poinsot.physics import FreeRigidBody, Regime
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


def _num(x: float, digits: int = 4) -> str:
    if math.isinf(x):
        return "∞"
    if math.isnan(x):
        return "—"
    return f"{x:.{digits}g}"


def rows(body: FreeRigidBody) -> list[tuple[str, str]]:
    """(label, value) pairs shown in the readout table."""
    precession = body.precession_per_period
    if math.isfinite(body.period):
        precession_text = f"{_num(precession)} rad ({math.degrees(precession):.1f}°)"
    else:
        precession_text = "— (no period)"
    # A sphere has no elliptic motion, so no parameter k² to show (it would read "0").
    k2 = [] if body.regime is Regime.SPHERE else [("k²", _num(body.parameter, 6))]
    return [
        ("regime", REGIME_TEXT.get(body.regime, str(body.regime))),
        *k2,
        ("period of ω", _num(body.period)),
        ("precession / period", precession_text),
        *_montgomery(body),
        ("D = |L|²/2T", _num(body.D, 6)),
        ("h = 2T/|L|", _num(body.plane_distance)),
        ("energy T", _num(body.energy)),
        ("|L|", _num(math.hypot(*body.angular_momentum))),
    ]


def _montgomery(body: FreeRigidBody) -> list[tuple[str, str]]:
    """The precession per period split [Mon91]: its dynamic part 2TP/|L| and its geometric part
    −Ω (the solid angle L sweeps in the body), on a triaxial body's polhode; nothing else."""
    if body.regime not in (Regime.MAJOR_AXIS, Regime.MINOR_AXIS):
        return []
    try:
        phase = montgomery_phase(body)
    except ValueError:  # a period beyond the double range: the row above says so
        return []
    return [
        ("… dynamic 2TP/|L|", f"{_num(phase.dynamic)} rad"),
        ("… geometric −Ω", f"{_num(phase.geometric)} rad"),
    ]


def markdown(body: FreeRigidBody) -> str:
    """The readouts as a markdown table (a "|" inside a cell is escaped)."""
    lines = ["| quantity | value |", "|:--|--:|"]
    lines += [
        f"| {label.replace('|', chr(92) + '|')} | {value.replace('|', chr(92) + '|')} |"
        for label, value in rows(body)
    ]
    return "\n".join(lines)


def time_markdown(t: float, paused: bool) -> str:
    state = "paused" if paused else "running"
    return f"**t = {t:8.2f}** &nbsp; _{state}_"
