"""A physics engine's log of one free body: read it, write one, and say in words whether it
moves as a free rigid body should (:func:`poinsot.physics.integrators.engine_check.check_log`
measures).

The log is a CSV with a header line: ``t, wx, wy, wz`` (seconds; body-frame angular velocity,
rad/s) and optionally ``qw, qx, qy, qz`` (the attitude, body -> space, as engines report a
body's rotation). Columns are found by name, in any order, case and spaces ignored, a unit in
brackets dropped (``wx (rad/s)``); ``time`` and ``omega_x`` are read too. The separator is a
comma, a semicolon or a tab. Lines starting with ``#`` are comments; one of them may give the
principal moments in the log's body axes: ``# inertia: I1, I2, I3`` (a log carries ω only, and
the moments are what the check needs; the command line's ``--inertia`` overrides it).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from poinsot.physics.integrators.engine_check import LogCheck, check_log

__all__ = [
    "DRIFT_LIMIT",
    "EngineLog",
    "LogError",
    "judge",
    "parse_engine_log",
    "read_engine_log",
    "write_engine_log",
]

#: Largest file read (bytes), and most rows.
MAX_BYTES = 20 * 1024 * 1024
MAX_ROWS = 1_000_000
#: Largest relative drift of the energy or of |L| per simulated minute of a free body.
DRIFT_LIMIT = 1e-3
#: Largest |L(t) - L(0)| / |L| in space, per minute (at least this much over any log).
SPACE_LIMIT = 1e-3

_ALIASES = {
    "t": ("t", "time"),
    "wx": ("wx", "omegax", "ωx"),
    "wy": ("wy", "omegay", "ωy"),
    "wz": ("wz", "omegaz", "ωz"),
    "qw": ("qw",),
    "qx": ("qx",),
    "qy": ("qy",),
    "qz": ("qz",),
}
_INERTIA = re.compile(r"^#\s*inertia\s*[:=]\s*(.+)$", re.IGNORECASE)


class LogError(ValueError):
    """A log that cannot be read: the message is one line."""


@dataclass(frozen=True)
class EngineLog:
    t: NDArray[np.float64]
    """(N,) [s], increasing."""
    omega: NDArray[np.float64]
    """(N, 3) body-frame angular velocity [rad/s]."""
    quaternion: NDArray[np.float64] | None
    """(N, 4) scalar-last (x, y, z, w), body -> space, or None."""
    inertia: tuple[float, float, float] | None
    """From the ``# inertia:`` comment, or None."""


def read_engine_log(path: Path) -> EngineLog:
    try:
        size = path.stat().st_size
        if size > MAX_BYTES:
            raise LogError(f"{path.name}: {size:,} bytes, more than {MAX_BYTES:,}")
        raw = path.read_bytes()
    except OSError as exc:
        raise LogError(f"{path}: {exc.strerror or exc}") from None
    return parse_engine_log(raw, path.name)


def parse_engine_log(raw: bytes, name: str) -> EngineLog:
    """Read the log's bytes; :class:`LogError` with one line if they are not a log."""
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise LogError(f"{name}: not a text file (UTF-8)") from None
    lines = [line.strip() for line in text.splitlines()]
    inertia = None
    for line in lines:
        match = _INERTIA.match(line)
        if match:
            inertia = parse_inertia(match.group(1), f"{name}: the '# inertia' comment")
    data = [line for line in lines if line and not line.startswith("#")]
    if not data:
        raise LogError(f"{name}: no header line (t, wx, wy, wz)")
    sep = next((s for s in (",", ";", "\t") if s in data[0]), ",")
    columns = _columns(data[0].split(sep), name)
    if len(data) - 1 > MAX_ROWS:
        raise LogError(f"{name}: more than {MAX_ROWS:,} rows")
    rows = []
    for k, line in enumerate(data[1:], start=2):
        fields = line.split(sep)
        try:
            rows.append([float(fields[columns[c]]) for c in columns])
        except (ValueError, IndexError):
            raise LogError(
                f"{name}: row {k} is not numbers in every column: {line[:60]!r}"
            ) from None
    return _log(np.array(rows, dtype=float).reshape(-1, len(columns)), list(columns), inertia, name)


def _columns(header: list[str], name: str) -> dict[str, int]:
    keys = [re.sub(r"\(.*?\)|\[.*?\]|[\s_\"']", "", h).lower() for h in header]
    found: dict[str, int] = {}
    for column, aliases in _ALIASES.items():
        where = [i for i, k in enumerate(keys) if k in aliases]
        if where:
            found[column] = where[0]
    missing = [c for c in ("t", "wx", "wy", "wz") if c not in found]
    if missing:
        raise LogError(f"{name}: no column {', '.join(missing)} in the header {header!r}")
    quaternion = [c for c in ("qw", "qx", "qy", "qz") if c in found]
    if 0 < len(quaternion) < 4:
        raise LogError(f"{name}: the attitude needs all of qw, qx, qy, qz")
    return found


def _log(
    table: NDArray, names: list[str], inertia: tuple[float, float, float] | None, name: str
) -> EngineLog:
    col = {c: table[:, i] for i, c in enumerate(names)}
    if table.shape[0] < 3:
        raise LogError(f"{name}: {table.shape[0]} rows; a log needs at least 3")
    if not np.all(np.isfinite(table)):
        raise LogError(f"{name}: a value is not finite (nan or inf)")
    t = col["t"]
    if np.any(np.diff(t) <= 0.0):
        raise LogError(f"{name}: the times must increase from row to row")
    omega = np.column_stack((col["wx"], col["wy"], col["wz"]))
    if not np.any(omega[0]):
        raise LogError(f"{name}: the body is at rest in the first sample")
    quaternion = None
    if "qw" in col:
        quaternion = np.column_stack((col["qx"], col["qy"], col["qz"], col["qw"]))
        if np.any(np.linalg.norm(quaternion, axis=1) < 0.5):
            raise LogError(f"{name}: a quaternion (qw, qx, qy, qz) is far from unit length")
    return EngineLog(t, omega, quaternion, inertia)


def parse_inertia(text: str, what: str = "--inertia") -> tuple[float, float, float]:
    """``"I1,I2,I3"`` -> three positive finite moments; :class:`LogError` otherwise."""
    try:  # three numbers need no more than 200 characters
        values = [float(v) for v in text.replace(";", ",").split(",")] if len(text) <= 200 else []
    except ValueError:
        values = []
    if len(values) != 3 or not all(math.isfinite(v) and v > 0.0 for v in values):
        got = text.strip()[:40] + ("…" if len(text.strip()) > 40 else "")
        raise LogError(f"{what} must be three positive moments I1,I2,I3; got {got!r}")
    return values[0], values[1], values[2]


def write_engine_log(
    path: Path,
    t: NDArray,
    omega: NDArray,
    inertia: tuple[float, float, float],
    quaternion: NDArray | None = None,
) -> None:
    """Write a log as :func:`read_engine_log` reads it (quaternion scalar-last in memory)."""
    header = "t,wx,wy,wz" + (",qw,qx,qy,qz" if quaternion is not None else "")
    table = np.column_stack((t, omega))
    if quaternion is not None:
        table = np.column_stack((table, quaternion[:, 3], quaternion[:, :3]))
    moments = ", ".join(repr(float(v)) for v in inertia)
    body = "\n".join(",".join(repr(float(v)) for v in row) for row in table)
    path.write_text(f"# inertia: {moments}\n{header}\n{body}\n")


@dataclass(frozen=True)
class Judgement:
    free: bool
    """Behaves as a free rigid body should."""
    lines: list[str]
    figures: dict[str, Any]


def judge(log: EngineLog, inertia: tuple[float, float, float]) -> Judgement:
    """Check the log and say in words and numbers what it shows."""
    try:
        c = check_log(log.t, log.omega, np.array(inertia), log.quaternion)
    except ValueError as exc:  # moments or a first sample that make no free body
        raise LogError(f"no free body from these moments and the first sample: {exc}") from None
    minutes = max(1.0, c.duration / 60.0)
    kept = abs(c.energy_drift) <= DRIFT_LIMIT and abs(c.momentum_drift) <= DRIFT_LIMIT
    space_kept = c.space_drift is None or c.space_drift <= SPACE_LIMIT * minutes
    free = kept and space_kept and c.flips_agree
    lines = [
        f"{c.duration:.3g} s of log, step {c.step:.3g} s; "
        f"moments {', '.join(f'{v:g}' for v in inertia)}.",
        ("Stays on one polhode: " if kept else "Leaves its polhode: ")
        + f"energy drifts {c.energy_drift:+.2e} and |L| {c.momentum_drift:+.2e} per minute "
        f"(a free body: 0; allowed {DRIFT_LIMIT:g}).",
    ]
    if c.space_drift is not None:
        lines.append(
            ("L stays fixed in space" if space_kept else "L moves in space")
            + f": |L(t) - L(0)| up to {c.space_drift:.2e} of |L|."
        )
    lines.append(_flip_line(c))
    lines.append(
        f"Looks most like: {c.looks_like} (RMS ω difference "
        + ", ".join(f"{k} {v:.2g}" for k, v in sorted(c.likeness.items(), key=lambda kv: kv[1]))
        + ", relative to |ω0|)."
    )
    lines.append(
        "Verdict: moves as a free rigid body should."
        if free
        else "Verdict: does NOT move as a free rigid body should."
    )
    return Judgement(free, lines, _figures(c, inertia, free))


def _flip_line(c: LogCheck) -> str:
    def times(x: NDArray) -> str:
        shown = ", ".join(f"{v:.3f}" for v in x[:4])
        return (shown + (", ..." if x.size > 4 else "")) or "none"

    head = (
        "Flips when the exact motion does"
        if c.flips_agree
        else "Does NOT flip as the exact motion does"
    )
    return (
        f"{head}: predicted {c.predicted_flips.size} flips at {times(c.predicted_flips)} s, "
        f"measured {c.measured_flips.size}"
        + (f" at {times(c.measured_flips)} s " if c.measured_flips.size else " ")
        + f"(allowed ±{c.flip_tolerance:.2g} s)."
    )


def _figures(c: LogCheck, inertia: tuple[float, float, float], free: bool) -> dict[str, Any]:
    return {
        "free_rigid_body": free,
        "inertia": list(inertia),
        "duration_s": c.duration,
        "step_s": c.step,
        "energy_drift_per_min": c.energy_drift,
        "momentum_drift_per_min": c.momentum_drift,
        "space_drift": c.space_drift,
        "predicted_flips_s": c.predicted_flips.tolist(),
        "measured_flips_s": c.measured_flips.tolist(),
        "flip_tolerance_s": c.flip_tolerance,
        "flips_agree": c.flips_agree,
        "looks_like": c.looks_like,
        "likeness_rms": {k: (v if math.isfinite(v) else None) for k, v in c.likeness.items()},
    }
