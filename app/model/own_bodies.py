"""A body of one's own: an uploaded gyroscope recording or mesh becomes a preset the session plays.

Two ways in, both from the bytes of an upload (never from a path a browser names):

- a recording (phyphox export ``.zip`` or a ``.csv`` of ``t, ωx, ωy, ωz``):
  :func:`fit_recording` reads it (:mod:`poinsot.app.model.recordings`), finds the free
  flights, fits each (:func:`poinsot.app.model.fitting.fit_segments`) and keeps the best;
  :func:`toss_preset` makes the fitted body a preset under the label of
  :data:`~poinsot.app.model.presets.FITTED_TOSS`, and :func:`toss_markdown` is its readout;
- a mesh (STL, OBJ, PLY, GLB, or one of the bundled bodies):
  :mod:`poinsot.app.model.bodies` measures it, :func:`mesh_preset` makes it a preset whose
  solid is the mesh itself.

Sizes are checked before anything is parsed. Every failure is a ValueError whose message is
for the student. Formatting and bookkeeping only: the fit and the moments come from
:mod:`poinsot.physics` and trimesh.
"""

from __future__ import annotations

import dataclasses
import math
import os
import pathlib
import re
import tempfile

import numpy as np
from numpy.typing import NDArray

from poinsot.app.model import bodies, recordings
from poinsot.app.model.bodies import MeshBody
from poinsot.app.model.elements import MeshShape, Plot, Solid
from poinsot.app.model.fitting import SegmentFit, fit_segments
from poinsot.app.model.parameters import SPEED_RANGE, Parameters
from poinsot.app.model.presets import FITTED_TOSS, MESH_BODY, Preset
from poinsot.physics.fit import AngularVelocityFit

#: Largest recording accepted [bytes] (the reader's own cap) and largest mesh.
MAX_RECORDING_BYTES = recordings.MAX_BYTES
MAX_MESH_BYTES = bodies.MAX_MESH_BYTES
#: File types taken as a recording.
RECORDING_SUFFIXES = (".zip", ".csv", ".txt")
#: At most this many flights of one recording are fitted (the longest ones).
MAX_TOSSES = 6
#: Measured samples kept for the plot (evenly thinned beyond this).
MEASURED_POINTS = 300
#: A fitted toss plays at the speed that turns it at about this rate on screen [rad/s].
SCREEN_RATE = 2.0
#: D of a body from a mesh: this fraction of the way from I2 towards I3, so that it shows the
#: intermediate-axis flip (the tennis-racquet theorem) right after loading.
MESH_D_FRACTION = 0.01

_AXES = ("x", "y", "z")
_SUBSCRIPTS = "₁₂₃"


@dataclasses.dataclass(frozen=True)
class FittedToss:
    """The toss of a recording that is shown, with the data for the plot.

    Attributes:
        name: the uploaded file's name.
        index, count: which toss of how many found (1-based).
        result: its segment and fit (``result.fit`` is not None).
        tau: (n,) times of the kept samples since the segment's first [s].
        measured: (n, 3) the measured ω at ``tau`` [rad/s], sensor axes.
        exact: (n, 3) the fitted exact solution at ``tau`` [rad/s].
        bound: no component of ω, measured or exact, exceeds it [rad/s]: the energy
            ellipsoid's largest semi-axis (I_k ω_k² <= 2T), or a noisy sample beyond it.
    """

    name: str
    index: int
    count: int
    result: SegmentFit
    tau: NDArray[np.float64]
    measured: NDArray[np.float64]
    exact: NDArray[np.float64]
    bound: float

    @property
    def fit(self) -> AngularVelocityFit:
        assert self.result.fit is not None
        return self.result.fit


def display_name(name: str) -> str:
    """The file name alone (no folders), with anything but plain characters replaced."""
    base = pathlib.PurePath(name.replace("\\", "/")).name or "upload"
    return re.sub(r"[^\w.\- ()]", "_", base)[:80]


#: What to do with a file that is too large, by kind.
ADVICE = {
    "toss": "cut the recording to the throws (phyphox exports a chosen time range)",
    "mesh": "simplify the mesh (fewer faces) and upload it again",
}


def too_large(size: int, limit: int, name: str, kind: str) -> str:
    """What to tell about a file of ``size`` bytes over ``limit``; ``kind`` ("toss" or "mesh")
    picks the advice."""
    return (
        f"{name} is {size / 2**20:.3g} MB; files up to {limit / 2**20:.3g} MB are accepted: "
        + ADVICE[kind]
    )


def check_size(size: int, limit: int, name: str, kind: str) -> None:
    """ValueError if ``size`` bytes is over ``limit`` (checked before anything is parsed)."""
    if size > limit:
        raise ValueError(too_large(size, limit, name, kind))


# -- a recording ----------------------------------------------------------------------------
def fit_recording(data: bytes, name: str) -> FittedToss:
    """Read, find the free flights, fit them, keep the best (explained first, then longest).

    Raises:
        ValueError: too large, not a recording, no free flight, or no flight could be fitted.
    """
    name = display_name(name)
    check_size(len(data), MAX_RECORDING_BYTES, name, "toss")
    suffix = pathlib.PurePath(name).suffix.lower()
    if suffix not in RECORDING_SUFFIXES:
        raise ValueError(
            f"{name} is not a recording Poinsot reads: upload phyphox's export (.zip) or a CSV "
            "of t, ωx, ωy, ωz (.csv)"
        )
    if not data:
        raise ValueError(f"{name} is empty")
    with tempfile.TemporaryDirectory(prefix="poinsot-upload-") as folder:
        path = pathlib.Path(folder) / name
        path.write_bytes(data)
        try:
            segments = recordings.select_segments(recordings.read_recording(path))
        except (ValueError, OSError) as exc:  # the messages name the file: not our folder
            raise ValueError(str(exc).replace(folder + os.sep, "")) from None
    if not segments:
        raise ValueError(
            f"no free flight found in {name}: no stretch of at least {recordings.MIN_FLIGHT} s "
            f"spinning faster than {recordings.MIN_FLIGHT_RATE:g} rad/s without the hand's "
            "torque (throw it spinning, and record the flight)"
        )
    longest = sorted(segments, key=lambda s: s.t.size, reverse=True)[:MAX_TOSSES]
    chosen = sorted(longest, key=lambda s: s.start)
    results = fit_segments(chosen)
    fitted = [r for r in results if r.fit is not None]
    if not fitted:
        raise ValueError(f"{name}: no toss could be fitted: {results[0].error}")
    best = max(fitted, key=lambda r: (r.fit is not None and r.fit.explained, r.segment.t.size))
    index = next(k for k, s in enumerate(segments, 1) if s is best.segment)
    return _toss(name, index, len(segments), best)


def _toss(name: str, index: int, count: int, result: SegmentFit) -> FittedToss:
    """The toss with its samples thinned for the plot and the fit evaluated at them."""
    fit = result.fit
    assert fit is not None
    segment = result.segment
    stride = max(1, math.ceil(segment.t.size / MEASURED_POINTS))
    t = segment.t[::stride]
    exact = np.asarray(fit.predict(t), dtype=np.float64)
    measured = np.asarray(segment.omega[::stride], dtype=np.float64)
    tau = np.asarray(t - fit.t0, dtype=np.float64)
    bound = max(float(np.max(fit.body.semi_axes)), float(np.max(np.abs(measured))))
    if not (np.all(np.isfinite(exact)) and np.all(np.isfinite(measured))) or not (
        math.isfinite(bound) and bound > 0.0
    ):
        raise ValueError(f"{name}: the fitted motion is not finite; nothing is shown")
    return FittedToss(name, index, count, result, tau, measured, exact, bound)


def toss_preset(toss: FittedToss) -> Preset:
    """The fitted body as a preset: its moments (largest 1, the phone's axes), its exact ω0,
    played slowly enough to follow; the plot shows the measured ω over the exact one.

    Raises:
        ValueError: the fitted values make no body the scene can show.
    """
    fit = toss.fit
    inertia = _triple(fit.inertia)
    omega0 = _triple(fit.omega0)
    norm = float(np.linalg.norm(fit.omega0))
    speed = min(1.0, max(SPEED_RANGE[0], SCREEN_RATE / norm)) if norm > 0 else 1.0
    segment = toss.result.segment
    preset = dataclasses.replace(
        FITTED_TOSS,
        source=f"{toss.name}: toss {toss.index} of {toss.count} ({segment.start:.2f} s to "
        f"{segment.end:.2f} s, {segment.t.size} samples), fitted by the exact free motion; "
        "moments up to scale (largest = 1) in the phone's axes x, y, z; time in seconds",
        inertia=inertia,
        D=float(fit.body.D),
        omega_norm=norm,
        omega0=omega0,
        speed=speed,
        plots=frozenset({Plot.MEASURED}),
    )
    Parameters.from_preset(preset).build()  # raises ValueError with the reason
    return preset


def _triple(values: NDArray[np.float64] | tuple[float, ...]) -> tuple[float, float, float]:
    a, b, c = (float(v) for v in values)
    return a, b, c


def plus_minus(value: float, sigma: float) -> str:
    """``value ± sigma`` with the sigma to two significant digits."""
    if not math.isfinite(sigma) or sigma <= 0.0:
        return f"{value:.4g}"
    decimals = max(0, min(8, 1 - math.floor(math.log10(sigma))))
    return f"{value:.{decimals}f} ± {sigma:.{decimals}f}"


def _period(value: float | None, sigma: float | None = None) -> str:
    if value is None:
        return "— (fewer than two flips seen)"
    if not math.isfinite(value):
        return "never (no repeated flip)"
    return plus_minus(value, math.nan if sigma is None else sigma) + " s"


def toss_markdown(toss: FittedToss) -> str:
    """The readout of a fitted toss: moments ± σ, the residual and its verdict, the flip
    periods predicted and seen."""
    fit = toss.fit
    verdict = "explained" if fit.explained else "**not explained**"
    lines = [
        f"**{toss.name}**, toss {toss.index} of {toss.count}: {fit.family}",
        "",
        "| fitted | value |",
        "|:--|--:|",
    ]
    for k in range(3):
        moment = plus_minus(float(fit.inertia[k]), float(fit.inertia_sigma[k]))
        lines.append(f"| I{_SUBSCRIPTS[k]} ({_AXES[k]}), largest = 1 | {moment} |")
    lines += [
        f"| rms residual | {fit.rms:.3g} rad/s ({100 * fit.relative_rms:.2g} % of \\|ω\\|) |",
        f"| by a free motion | {verdict} |",
        f"| flip period, predicted | {_period(fit.flip_period, fit.flip_period_sigma)} |",
        f"| flip period, measured | {_period(fit.measured_flip_period)} |",
        "",
        f"<small>{fit.message[:1].upper()}{fit.message[1:]}.</small>",
    ]
    return "\n".join(lines)


# -- a mesh ---------------------------------------------------------------------------------
def load_mesh(data: bytes, name: str) -> MeshBody:
    """A mesh upload measured (:func:`poinsot.app.model.bodies.load_mesh_body`), size checked first.

    Raises:
        ValueError: too large, not a mesh, or not a closed surface (a MeshError's message).
    """
    name = display_name(name)
    check_size(len(data), MAX_MESH_BYTES, name, "mesh")
    return bodies.load_mesh_body(data, name)


def mesh_preset(body: MeshBody) -> Preset:
    """The measured mesh as a preset: moments at uniform density (largest 1, ascending along
    the mesh's principal axes x, y, z), the mesh drawn as the solid, D just past the
    separatrix so that the flip shows."""
    i1, i2, i3 = body.ratios
    shape = MeshShape.of(body.mesh.vertices, body.mesh.faces, body.name)
    repaired = "; trimesh repaired it (closed holes, fixed normals)" if body.repaired else ""
    return dataclasses.replace(
        MESH_BODY,
        source=f"{body.name}: principal moments of the closed mesh at uniform density "
        f"(trimesh), largest = 1{repaired}",
        inertia=(i1, i2, i3),
        D=i2 + MESH_D_FRACTION * (i3 - i2),
        solid=Solid("mesh", (), mesh=shape),
    )


def mesh_markdown(body: MeshBody) -> str:
    """What was measured: the name, size and moments."""
    moments = ", ".join(f"I{_SUBSCRIPTS[k]} = {body.ratios[k]:.4g}" for k in range(3))
    return (
        f"**{body.name}**: {len(body.mesh.vertices):,} vertices, {len(body.mesh.faces):,} "
        f"faces; moments at uniform density (largest = 1): {moments}"
    )


def repair_note(body: MeshBody) -> str:
    """The status after a mesh was measured: says so if trimesh had to repair it."""
    if not body.repaired:
        return ""
    return (
        f"Repaired: {body.name} was not closed; trimesh closed its holes and fixed its "
        "normals, and the moments are those of the repaired solid."
    )
