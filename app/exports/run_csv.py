"""The run as a CSV table: t, ω in the body frame and the attitude quaternion.

Every number comes from :mod:`poinsot.physics` (``FreeRigidBody.state``); this module only
samples and formats. Values are written with the shortest text that reads back as the same
doubles (Python's float repr), so that :func:`read_run_csv` gives exactly what physics gave;
the header names the quaternion convention (:data:`QUATERNION_CONVENTION`) and the body.
"""

from __future__ import annotations

import dataclasses
import io
import math

import numpy as np
from numpy.typing import ArrayLike

from poinsot.app.construction.sampled.frames import wxyz
from poinsot.physics import FreeRigidBody

#: Written into the CSV header; the one convention of every quaternion this module exports.
QUATERNION_CONVENTION = (
    "q = (qw, qx, qy, qz): unit quaternion, scalar first (Hamilton product), the attitude "
    "body -> space (v_space = q v_body q^-1; columns of its matrix = body axes in space), "
    "space frame with L along +z; sign continuous in time, qw >= 0 at the first row"
)
CSV_COLUMNS = ("t", "omega1", "omega2", "omega3", "qw", "qx", "qy", "qz")
#: Samples per period of omega (and time step where omega has no period).
SAMPLES_PER_PERIOD = 200
APERIODIC_STEP = 0.02
#: Rows at most (a 20 000-row file is about 3 MB).
MAX_ROWS = 20_001
#: A run shorter than this is exported over one period of omega instead (a freshly loaded
#: scene still gives a useful file) [time units].
MIN_RUN = 1e-9
#: The span of a fresh run where omega has no period [time units].
DEFAULT_SPAN = 20.0


@dataclasses.dataclass(frozen=True)
class Run:
    """Samples of one run: ``t`` (N,), ``omega`` (N, 3) body frame, ``quaternion`` (N, 4) in
    :data:`QUATERNION_CONVENTION`, and the header's ``key: value`` pairs."""

    t: np.ndarray
    omega: np.ndarray
    quaternion: np.ndarray
    meta: dict[str, str]


def period_or(body: FreeRigidBody, default: float) -> float:
    """The period of omega, or ``default`` where omega does not return."""
    period = float(body.period)
    return period if math.isfinite(period) and period > 0 else default


def run_span(body: FreeRigidBody, t_now: float) -> float:
    """The time span an export covers: the run so far, or one period of omega (20 time units
    where omega has none) if the run has not started yet."""
    if math.isfinite(t_now) and t_now > MIN_RUN:
        return float(t_now)
    return period_or(body, DEFAULT_SPAN)


def sample_times(body: FreeRigidBody, t_end: float) -> np.ndarray:
    """0 .. t_end with SAMPLES_PER_PERIOD samples per period of omega, at most MAX_ROWS."""
    period = float(body.period)
    step = period / SAMPLES_PER_PERIOD if math.isfinite(period) and period > 0 else APERIODIC_STEP
    rows = min(MAX_ROWS, max(2, math.ceil(t_end / step) + 1))
    return np.linspace(0.0, float(t_end), rows)


def continuous_quaternions(q: np.ndarray) -> np.ndarray:
    """Flip signs so that consecutive quaternions lie in the same hemisphere (q and -q are
    the same attitude; a continuous series is what students plot)."""
    q = np.array(q, dtype=np.float64, copy=True)
    if len(q) > 1:
        flips = np.einsum("ij,ij->i", q[1:], q[:-1]) < 0.0
        sign = np.concatenate([[1.0], np.where(np.cumsum(flips) % 2 == 1, -1.0, 1.0)])
        q *= sign[:, None]
    return q


def sample_run(body: FreeRigidBody, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """omega (N, 3) and the attitude quaternions (N, 4) at times ``t``, from physics."""
    omega, rotation = body.state(np.asarray(t, dtype=np.float64))
    return np.asarray(omega), continuous_quaternions(wxyz(rotation))


def _fmt(values: ArrayLike) -> str:
    """Shortest text that reads back as the same doubles (Python's float repr)."""
    return ", ".join(repr(float(v)) for v in np.ravel(values))


def _header(body: FreeRigidBody, t: np.ndarray, name: str, source: str) -> dict[str, str]:
    return {
        "poinsot run": "torque-free rigid body, exact closed-form solution "
        "(poinsot.physics.FreeRigidBody)",
        "scene": name,
        "source": source,
        "inertia I1, I2, I3": _fmt(body.inertia),
        "omega0 (body frame)": _fmt(body.omega0),
        "angular momentum L (space frame)": _fmt(body.angular_momentum),
        "energy T": _fmt([body.energy]),
        "D = |L|^2/2T": _fmt([body.D]),
        "regime": body.regime.name,
        "period of omega": _fmt([body.period]),
        "omega": "angular velocity in the body frame, principal axes 1, 2, 3 as the inertia",
        "quaternion": QUATERNION_CONVENTION,
        "rows": f"{len(t)}, t from 0 to {_fmt([t[-1]])}",
    }


def run_csv(body: FreeRigidBody, t_end: float, *, name: str = "", source: str = "") -> str:
    """The run 0 <= t <= t_end as CSV text (header comments start with ``#``)."""
    t = sample_times(body, t_end)
    omega, q = sample_run(body, t)
    out = io.StringIO()
    for key, value in _header(body, t, name, source).items():
        if value:
            out.write(f"# {key}: {value}\n")
    out.write(",".join(CSV_COLUMNS) + "\n")
    data = np.column_stack([t, omega, q])
    out.write("\n".join(",".join(map(repr, row)) for row in data.tolist()))
    out.write("\n")
    return out.getvalue()


def read_run_csv(text: str) -> Run:
    """Parse :func:`run_csv` output (or any file with the same columns)."""
    meta: dict[str, str] = {}
    lines = text.splitlines()
    body_start = 0
    for i, line in enumerate(lines):
        if line.startswith("#"):
            key, _, value = line[1:].partition(":")
            meta[key.strip()] = value.strip()
            continue
        if tuple(c.strip() for c in line.split(",")) != CSV_COLUMNS:
            raise ValueError(f"expected the column header {','.join(CSV_COLUMNS)!r}, got {line!r}")
        body_start = i + 1
        break
    else:
        raise ValueError("no column header found")
    data = np.loadtxt(io.StringIO("\n".join(lines[body_start:])), delimiter=",", ndmin=2)
    if data.shape[1] != len(CSV_COLUMNS):
        raise ValueError(f"expected {len(CSV_COLUMNS)} columns, got {data.shape[1]}")
    return Run(data[:, 0], data[:, 1:4], data[:, 4:8], meta)
