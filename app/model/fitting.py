"""``poinsot fit``: fit the exact free motion to each toss of a gyroscope recording.

Recording -> segments (the free flights, or one stretch chosen by hand) -> one fit each
(:func:`poinsot.physics.fit.fit_angular_velocity`) -> a table, and on request a JSON file and a
plot of the measured ω against the fitted solution. :func:`run_fit` is the command's entry.
"""

from __future__ import annotations

import json
import math
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TextIO

import numpy as np

from poinsot.app.model.recordings import Recording, Segment, read_recording, select_segments
from poinsot.physics.fit import AngularVelocityFit, fit_angular_velocity

_AXES = ("x", "y", "z")


@dataclass(frozen=True)
class SegmentFit:
    """One toss: its segment, and its fit or the reason it could not be fitted."""

    segment: Segment
    fit: AngularVelocityFit | None
    error: str | None = None


def run_fit(
    path: str | Path,
    *,
    start: float | None = None,
    end: float | None = None,
    json_out: str | Path | None = None,
    plot_out: str | Path | None = None,
    degrees: bool = False,
    fit_rotation: bool = False,
    fit_bias: bool = False,
    out: TextIO | None = None,
    err: TextIO | None = None,
) -> int:
    """Fit every toss of the recording at ``path`` and report; returns the exit code.

    Args:
        path: a phyphox export (folder or zip) or a CSV of ``t, ωx, ωy, ωz``.
        start, end: fit the one stretch between these times [s] instead of the flights found
            automatically (either may be left out: the recording's start or end).
        json_out: write the results there as JSON (``{"segments": [...]}``).
        plot_out: draw the measured ω against the fits into this PNG (needs matplotlib).
        degrees: the plain CSV is in deg/s.
        fit_rotation, fit_bias: also fit a small sensor-to-principal rotation, a gyro bias.
        out, err: where the table and the messages go (stdout and stderr by default).

    Returns:
        0 if at least one toss was fitted and every requested file written, else 1 (the
        reason is printed on ``err``).
    """
    out = sys.stdout if out is None else out
    err = sys.stderr if err is None else err
    try:
        recording = read_recording(path, degrees=degrees)
        segments = select_segments(recording, start, end)
    except (ValueError, OSError) as exc:
        print(f"poinsot fit: {exc}", file=err)
        return 1
    if not segments:
        print(
            f"poinsot fit: no free flight found in {recording.source} (no stretch of at least "
            "0.25 s spinning faster than 2 rad/s without the hand's torque): choose one with "
            "--start and --end",
            file=err,
        )
        return 1
    results = fit_segments(segments, fit_rotation=fit_rotation, fit_bias=fit_bias)
    print(format_table(results, recording.source), file=out)
    written = _write_files(recording, results, json_out, plot_out, err)
    return 0 if written and any(r.fit is not None for r in results) else 1


def _write_files(
    recording: Recording,
    results: list[SegmentFit],
    json_out: str | Path | None,
    plot_out: str | Path | None,
    err: TextIO,
) -> bool:
    """Write the JSON and the plot asked for; False (after saying why on ``err``) if one
    could not be written."""
    ok = True
    if json_out is not None:
        try:
            text = json.dumps(to_json(results, recording.source), indent=2, allow_nan=False)
            Path(json_out).write_text(text)
        except OSError as exc:
            print(f"poinsot fit: cannot write {json_out}: {exc}", file=err)
            ok = False
    if plot_out is not None:
        try:
            plot_fits(recording, results, plot_out)
        except ImportError:
            print(
                "poinsot fit: --plot needs matplotlib, which is not installed "
                "(pip install 'poinsot[report]'); the table above was printed without the plot",
                file=err,
            )
            ok = False
        except OSError as exc:
            print(f"poinsot fit: cannot write {plot_out}: {exc}", file=err)
            ok = False
    return ok


def fit_segments(
    segments: list[Segment], *, fit_rotation: bool = False, fit_bias: bool = False
) -> list[SegmentFit]:
    """One :class:`SegmentFit` per segment (a segment the fit refuses keeps the reason)."""
    results = []
    for segment in segments:
        try:
            fit = fit_angular_velocity(
                segment.t, segment.omega, fit_rotation=fit_rotation, fit_bias=fit_bias
            )
        except ValueError as exc:
            results.append(SegmentFit(segment, None, str(exc)))
        else:
            results.append(SegmentFit(segment, fit))
    return results


def _pm(value: float, sigma: float) -> str:
    """``value ± sigma`` with the sigma to two significant digits."""
    if not math.isfinite(sigma) or sigma <= 0.0:
        return f"{value:.4g}"
    decimals = max(0, min(8, 1 - math.floor(math.log10(sigma))))
    return f"{value:.{decimals}f} ± {sigma:.{decimals}f}"


def _seconds(value: float | None, sigma: float | None = None) -> str:
    if value is None:
        return "-"
    if not math.isfinite(value):
        return "never"
    return _pm(value, sigma if sigma is not None else math.nan) + " s"


def _family(fit: AngularVelocityFit) -> str:
    sigmas = abs(fit.separatrix_distance) / fit.separatrix_sigma if fit.separatrix_sigma else 0
    name = fit.family.replace(" family", "")
    if not math.isfinite(sigmas):
        return name
    return f"{name} ({sigmas:.0f}σ)" if sigmas >= 10 else f"{name} ({sigmas:.1f}σ)"


def format_table(results: list[SegmentFit], source: str) -> str:
    """The table of the fits, one row per toss, with notes below it."""
    header = ["#", "start", "end"] + [f"I{a}" for a in _AXES]
    header += ["rms", "flip (fit)", "flip (seen)", "family (from separatrix)"]
    rows, notes = [], []
    for k, r in enumerate(results, 1):
        row = [str(k), f"{r.segment.start:.2f} s", f"{r.segment.end:.2f} s"]
        if r.fit is None:
            rows.append(row + ["-"] * 7)
            notes.append(f"toss {k}: not fitted: {r.error}")
            continue
        f = r.fit
        row += [_pm(float(i), float(s)) for i, s in zip(f.inertia, f.inertia_sigma, strict=True)]
        row += [f"{f.rms:.3g} rad/s", _seconds(f.flip_period, f.flip_period_sigma)]
        row += [_seconds(f.measured_flip_period), _family(f)]
        rows.append(row)
        if not f.explained or not f.family_confirmed:
            notes.append(f"toss {k}: {f.message}")
    widths = [max(len(x) for x in col) for col in zip(header, *rows, strict=True)]
    lines = [
        f"{source}: {len(results)} toss{'es' if len(results) != 1 else ''}; moments up to scale "
        "(largest = 1) in the sensor's axes, ± 1σ",
        "  ".join(h.ljust(w) for h, w in zip(header, widths, strict=True)).rstrip(),
    ]
    lines += [
        "  ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)).rstrip() for row in rows
    ]
    return "\n".join([*lines, *notes])


def _finite(value: float | None) -> float | None:
    """JSON has no inf: a period that never comes is written as null."""
    return None if value is None or not math.isfinite(value) else float(value)


def _vector(values: np.ndarray | None) -> list[float] | None:
    return None if values is None else [float(v) for v in values]


def to_json(results: list[SegmentFit], source: str) -> dict[str, Any]:
    """``{"source", "units", "segments": [...]}``, one entry per toss (null: none, never)."""
    segments = []
    for r in results:
        entry: dict[str, Any] = {"start": r.segment.start, "end": r.segment.end}
        f = r.fit
        if f is None:
            entry["error"] = r.error
            segments.append(entry)
            continue
        entry.update(
            n_samples=f.n_samples,
            inertia=_vector(f.inertia),
            inertia_sigma=_vector(f.inertia_sigma),
            omega0=_vector(f.omega0),
            omega0_sigma=_vector(f.omega0_sigma),
            rms=f.rms,
            relative_rms=f.relative_rms,
            noise=f.noise,
            period=_finite(f.period),
            flip_period=_finite(f.flip_period),
            flip_period_sigma=_finite(f.flip_period_sigma),
            measured_flip_period=_finite(f.measured_flip_period),
            family=f.family,
            regime=f.regime.label,
            separatrix_distance=f.separatrix_distance,
            separatrix_sigma=_finite(f.separatrix_sigma),
            family_confirmed=f.family_confirmed,
            intermediate_axis=_AXES[f.intermediate_axis],
            bias=_vector(f.bias),
            bias_sigma=_vector(f.bias_sigma),
            rotation=None if f.rotation is None else _vector(f.rotation.as_rotvec()),
            rotation_sigma=_vector(f.rotation_sigma),
            explained=f.explained,
            message=f.message,
        )
        segments.append(entry)
    units = {"time": "s", "omega": "rad/s", "rotation": "rad (rotation vector)", "inertia": "1"}
    return {"source": source, "units": units, "segments": segments}


def plot_fits(recording: Recording, results: list[SegmentFit], path: str | Path) -> None:
    """Measured ω and the fitted solutions, one panel per component, into a PNG.

    Raises:
        ImportError: matplotlib is not installed.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(10, 7), constrained_layout=True)
    lo = min(r.segment.start for r in results)
    hi = max(r.segment.end for r in results)
    margin = 0.1 * (hi - lo) + 0.2
    shown = (recording.t >= lo - margin) & (recording.t <= hi + margin)
    for k, ax in enumerate(axes):
        ax.plot(recording.t[shown], recording.omega[shown, k], ".", ms=2, color="0.6")
        for n, r in enumerate(results, 1):
            if r.fit is None:
                continue
            fine = np.linspace(r.segment.start, r.segment.end, 20 * r.segment.t.size)
            ax.plot(fine, r.fit.predict(fine)[:, k], lw=1.2, label=f"toss {n}" if k == 0 else None)
        ax.set_ylabel(f"ω{_AXES[k]} (rad/s)")
        ax.grid(alpha=0.3)
    axes[0].set_title(f"{recording.source}: measured (dots) and fitted free motion (lines)")
    if any(r.fit is not None for r in results):
        axes[0].legend(loc="upper right", fontsize="small")
    axes[-1].set_xlabel("time (s)")
    fig.savefig(path, dpi=120)
    plt.close(fig)
