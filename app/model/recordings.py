"""Gyroscope recordings: phyphox exports and plain CSV files, and the free flights in them.

Formats read by :func:`read_recording`:

- a phyphox export (experiment "Gyroscope (rotation rate)"), as the folder or its ``.zip``:
  a data CSV with the header ``"Time (s)","Gyroscope x (rad/s)","Gyroscope y (rad/s)",
  "Gyroscope z (rad/s)","Absolute (rad/s)"`` and, if present, ``meta/time.csv`` listing the
  ``START`` and ``PAUSE`` events with their experiment times. phyphox's experiment time stands
  still while paused, so a pause leaves no gap in the time column: the recording is split into
  runs at the pauses, and nothing ever spans one. Any of phyphox's CSV flavours is read
  (comma, tab or semicolon separated; decimal point or decimal comma).
- a plain CSV of ``t, ωx, ωy, ωz`` with or without a header line, in rad/s, or in deg/s with
  ``degrees=True`` (a header naming its unit, ``(rad/s)`` or ``(deg/s)``, is checked against
  the flag).

:func:`find_flights` then finds the free flights: the stretches where |ω| stays high between
the throw and the catch, trimmed where the hand's torque shows. In free flight Euler's
equations bound the angular acceleration of any real body, ``|dω/dt| <= |ω|²/√3`` [LL76 §36,
Eq. 36.5] (each ``|Ij - Ik| <= Ii`` by the triangle inequality, and ``Σ ωj²ωk² <= |ω|⁴/3``);
a hand that throws or catches exceeds it.
"""

from __future__ import annotations

import io
import re
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from scipy.ndimage import median_filter

from poinsot.physics.fit import smooth

#: Largest file read (bytes): a phone records a gyroscope at ~100-500 Hz, 20 MB is over an
#: hour of it.
MAX_BYTES = 20 * 1024 * 1024
#: Most rows read.
MAX_ROWS = 1_000_000
#: A flight spins at least this fast [rad/s] ...
MIN_FLIGHT_RATE = 2.0
#: ... and at least this fraction of the recording's fastest spin (99th percentile of |ω|).
FLIGHT_FRACTION = 0.3
#: Shortest flight kept [s].
MIN_FLIGHT = 0.25
#: Samples dropped at each end of a flight (the last touch of the hand).
GUARD = 2
# |dω/dt| may exceed the free-flight bound |ω|²/√3 by this fraction of it before it counts as
# a torque (smoothing errors), plus the derivative's noise.
_TORQUE_SLACK = 0.25
_DEG = np.pi / 180.0
_UNIT = re.compile(r"\((?:rad|deg|°)\s*/\s*s\)|rad/s|deg/s|°/s", re.IGNORECASE)


@dataclass(frozen=True)
class Recording:
    """A gyroscope recording.

    Attributes:
        t: (N,) strictly increasing times [s] (phyphox's experiment time).
        omega: (N, 3) angular velocity [rad/s] in the phone's axes.
        runs: ``(start, stop)`` row ranges of the runs between pauses (one if never paused).
        source: where the data came from, for messages.
    """

    t: NDArray[np.float64]
    omega: NDArray[np.float64]
    runs: tuple[tuple[int, int], ...]
    source: str


@dataclass(frozen=True)
class Segment:
    """A stretch of a recording to fit: ``t`` (n,) [s] and ``omega`` (n, 3) [rad/s]."""

    start: float
    end: float
    t: NDArray[np.float64]
    omega: NDArray[np.float64]
    run: int


def read_recording(path: str | Path, *, degrees: bool = False) -> Recording:
    """Read a phyphox export (folder or zip) or a plain CSV file of ``t, ωx, ωy, ωz``.

    Args:
        path: the file or folder.
        degrees: the plain CSV's angular velocities are in deg/s (default rad/s).

    Raises:
        ValueError: a file that is too large (over :data:`MAX_BYTES` or :data:`MAX_ROWS`),
            not a gyroscope recording, unparsable (the line is named), with NaN values, or
            with times that go backwards.
        OSError: the path cannot be read.
    """
    path = Path(path)
    if not path.exists():
        raise ValueError(f"{path}: no such file or folder")
    if path.is_dir():
        data_name, text, meta = _from_folder(path)
    elif zipfile.is_zipfile(path):
        _check_size(path.stat().st_size, str(path))
        try:
            data_name, text, meta = _from_zip(path)
        except (zipfile.BadZipFile, zipfile.LargeZipFile, NotImplementedError) as exc:
            raise ValueError(f"{path}: a damaged or unsupported zip archive ({exc})") from None
    else:
        _check_size(path.stat().st_size, str(path))
        data_name, text, meta = str(path), _decode(path.read_bytes(), str(path)), None
    t, omega = parse_table(text, data_name, degrees=degrees)
    pauses = parse_pauses(meta, f"{path}/meta/time.csv") if meta is not None else []
    return Recording(t, omega, _runs(t, pauses), data_name)


def _check_size(size: int, name: str) -> None:
    if size > MAX_BYTES:
        raise ValueError(
            f"{name} is {size / 2**20:.1f} MB, more than the {MAX_BYTES / 2**20:.0f} MB this "
            "command reads: cut the recording to the throws (phyphox can export a time range)"
        )


def _decode(raw: bytes, name: str) -> str:
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise ValueError(f"{name} is not a text (CSV) file") from None


def _is_data_csv(name: str) -> bool:
    parts = name.replace("\\", "/").split("/")
    return parts[-1].lower().endswith(".csv") and "meta" not in parts[:-1]


def _pick(names: list[str], headers: dict[str, str], where: str) -> str:
    """The gyroscope table among the data CSVs of an export."""
    if not names:
        raise ValueError(f"{where}: no CSV file (expected phyphox's 'Raw Data.csv')")
    gyro = [n for n in names if "gyro" in headers[n].lower()]
    named = [n for n in names if n.replace("\\", "/").split("/")[-1] == "Raw Data.csv"]
    for choice in (gyro, named, names if len(names) == 1 else []):
        if choice:
            return sorted(choice)[0]
    raise ValueError(f"{where}: several CSV files and none is a gyroscope table: {names}")


def _from_folder(folder: Path) -> tuple[str, str, str | None]:
    names = sorted(str(p) for p in folder.iterdir() if _is_data_csv(p.name))
    for n in names:
        _check_size(Path(n).stat().st_size, n)
    headers = {}
    for n in names:
        with open(n, "rb") as handle:
            headers[n] = _first_line(handle.read(4096))
    chosen = _pick(names, headers, str(folder))
    meta_path = folder / "meta" / "time.csv"
    meta = None
    if meta_path.is_file():
        _check_size(meta_path.stat().st_size, str(meta_path))
        meta = _decode(meta_path.read_bytes(), str(meta_path))
    return chosen, _decode(Path(chosen).read_bytes(), chosen), meta


def _from_zip(path: Path) -> tuple[str, str, str | None]:
    with zipfile.ZipFile(path) as archive:
        infos = {i.filename: i for i in archive.infolist() if not i.is_dir()}
        names = sorted(n for n in infos if _is_data_csv(n))
        for n in names:  # the uncompressed size: a small zip can hold a huge file
            _check_size(infos[n].file_size, f"{path}:{n}")
        headers = {}
        for n in names:
            with archive.open(n) as handle:
                headers[n] = _first_line(handle.read(4096))
        chosen = _pick(names, headers, str(path))
        prefix = chosen.rsplit("/", 1)[0] + "/" if "/" in chosen else ""
        meta_name = prefix + "meta/time.csv"
        meta = None
        if meta_name in infos:
            _check_size(infos[meta_name].file_size, f"{path}:{meta_name}")
            meta = _decode(archive.read(meta_name), f"{path}:{meta_name}")
        return f"{path}:{chosen}", _decode(archive.read(chosen), f"{path}:{chosen}"), meta


def _first_line(raw: bytes) -> str:
    lines = raw.decode("utf-8-sig", errors="replace").splitlines()
    return lines[0] if lines else ""


def _separator(line: str) -> str:
    """phyphox writes comma-, tab- or semicolon-separated values."""
    for sep in ("\t", ";"):
        if sep in line:
            return sep
    return ","


def _fields(line: str, sep: str) -> list[str]:
    return [f.strip().strip('"').strip() for f in line.split(sep)]


def _floats(fields: list[str], comma: bool) -> list[float] | None:
    try:
        return [float(f.replace(",", ".") if comma else f) for f in fields]
    except ValueError:
        return None


def parse_table(text: str, name: str, *, degrees: bool = False) -> tuple[NDArray, NDArray]:
    """``(t (N,) [s], omega (N, 3) [rad/s])`` from the text of a CSV table.

    The first four columns are read as ``t, ωx, ωy, ωz`` (phyphox's fifth, |ω|, is ignored).
    A header line is optional; if it names units, the angular velocities must be in rad/s or
    deg/s (``degrees`` must then agree), which also rejects another sensor's table.
    """
    lines = [(k + 1, line) for k, line in enumerate(text.splitlines()) if line.strip()]
    if not lines:
        raise ValueError(f"{name} is empty")
    sep = _separator(lines[0][1])
    header = _fields(lines[0][1], sep)
    has_header = _floats([f for f in header if f], sep != ",") is None
    data = lines[1:] if has_header else lines
    if not data:
        raise ValueError(f"{name} has a header but no data")
    if len(data) > MAX_ROWS:
        raise ValueError(
            f"{name} has {len(data)} rows, more than the {MAX_ROWS} this command reads: cut the "
            "recording to the throws (phyphox can export a time range)"
        )
    comma = sep != "," and "," in data[0][1]
    if has_header:
        degrees = _header_unit(header, name, degrees)
    values = _rows(data, sep, comma, name)
    bad = ~np.isfinite(values).all(axis=1)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"{name}, line {data[k][0]}: a value is not a number ({data[k][1].strip()!r}): "
            "delete the line or export again"
        )
    t = values[:, 0]
    back = np.flatnonzero(np.diff(t) <= 0.0)
    if back.size:
        k = int(back[0])
        raise ValueError(
            f"{name}, line {data[k + 1][0]}: the time {t[k + 1]:g} s does not come after "
            f"{t[k]:g} s (line {data[k][0]}): the times must increase"
        )
    omega = values[:, 1:4] * (_DEG if degrees else 1.0)
    return t, omega


def _header_unit(header: list[str], name: str, degrees: bool) -> bool:
    """Whether the header's angular velocities are in deg/s (checked against the flag)."""
    if len(header) < 4:
        raise ValueError(
            f"{name}: {len(header)} columns, expected time and three angular velocities "
            "(t, ωx, ωy, ωz)"
        )
    units = [_UNIT.search(h) for h in header[1:4]]
    if not any(units):
        if any(re.search(r"\(.+\)", h) for h in header[1:4]):
            raise ValueError(
                f"{name} is not a gyroscope recording: its columns are {header[1:4]} (phyphox's "
                "'Gyroscope' experiment exports 'Gyroscope x (rad/s)', ...)"
            )
        return degrees
    in_degrees = any(u is not None and "rad" not in u.group(0).lower() for u in units)
    if degrees and not in_degrees:
        raise ValueError(f"{name}: the header says rad/s, but deg/s was asked for (--deg)")
    return in_degrees


def _rows(data: list[tuple[int, str]], sep: str, comma: bool, name: str) -> NDArray:
    """(N, 4) the first four numbers of each data line; a line that does not parse is named."""
    body = "\n".join(line for _, line in data)
    if comma:
        body = body.replace(",", ".")
    try:
        return np.loadtxt(
            io.StringIO(body), delimiter=sep, usecols=(0, 1, 2, 3), ndmin=2, quotechar='"'
        )
    except ValueError:
        pass
    for number, line in data:  # find the culprit for the message
        row = _floats(_fields(line, sep), comma)
        if row is None or len(row) < 4:
            raise ValueError(
                f"{name}, line {number}: expected four numbers t, ωx, ωy, ωz separated by "
                f"{sep!r}, found {line.strip()!r}"
            ) from None
    raise ValueError(f"{name}: the table could not be read")


def parse_pauses(text: str, name: str) -> list[float]:
    """Experiment times [s] of the ``PAUSE`` events of phyphox's ``meta/time.csv``."""
    lines = [(k + 1, line) for k, line in enumerate(text.splitlines()) if line.strip()]
    pauses = []
    for number, line in lines:
        sep = _separator(line)
        fields = _fields(line, sep)
        if fields[0].lower() == "event" or len(fields) < 2:
            continue
        value = _floats([fields[1]], sep != ",")
        if value is None:
            raise ValueError(f"{name}, line {number}: no experiment time in {line.strip()!r}")
        if fields[0].upper() == "PAUSE":
            pauses.append(value[0])
    return pauses


def _runs(t: NDArray, pauses: list[float]) -> tuple[tuple[int, int], ...]:
    """Row ranges between the pauses (a row at a pause's time ends the run before it)."""
    cuts = sorted(int(np.searchsorted(t, p, side="right")) for p in pauses)
    bounds = [0, *cuts, t.size]
    return tuple((a, b) for a, b in zip(bounds[:-1], bounds[1:], strict=True) if b > a)


def select_segments(
    recording: Recording, start: float | None = None, end: float | None = None
) -> list[Segment]:
    """The stretches to fit: the free flights (:func:`find_flights`) if neither ``start`` nor
    ``end`` [s] is given, else the one stretch between them (the recording's ends by default).

    Raises:
        ValueError: ``start >= end``, a stretch with no samples, or one across a pause.
    """
    if start is None and end is None:
        return find_flights(recording)
    t = recording.t
    lo = float(t[0]) if start is None else float(start)
    hi = float(t[-1]) if end is None else float(end)
    if not lo < hi:
        raise ValueError(f"the start ({lo:g} s) must come before the end ({hi:g} s)")
    a, b = int(np.searchsorted(t, lo, side="left")), int(np.searchsorted(t, hi, side="right"))
    if b <= a:
        raise ValueError(
            f"no samples between {lo:g} s and {hi:g} s (the recording runs from {t[0]:g} s "
            f"to {t[-1]:g} s)"
        )
    runs = [k for k, (r0, r1) in enumerate(recording.runs) if r0 < b and a < r1]
    if len(runs) > 1:
        pause = float(t[recording.runs[runs[0]][1] - 1])
        raise ValueError(
            f"{lo:g} s to {hi:g} s spans a pause of the recording (at {pause:g} s): the motion "
            "before and after it is not one flight; choose a stretch on one side"
        )
    return [Segment(float(t[a]), float(t[b - 1]), t[a:b], recording.omega[a:b], runs[0])]


def find_flights(
    recording: Recording, *, min_duration: float = MIN_FLIGHT, min_rate: float = MIN_FLIGHT_RATE
) -> list[Segment]:
    """The free flights of a recording, in time order.

    A flight is a stretch of one run where |ω| (median-filtered over 5 samples) stays above
    ``max(min_rate, FLIGHT_FRACTION × 99th percentile of |ω|)``, cut down to its longest part
    in which the smoothed angular acceleration keeps within the free-flight bound
    ``|dω/dt| <= |ω|²/√3`` (gaps of one or two samples closed), less :data:`GUARD` samples at
    each end; kept if it lasts at least ``min_duration`` [s].
    """
    speed = np.linalg.norm(recording.omega, axis=1)
    level = max(min_rate, FLIGHT_FRACTION * float(np.quantile(speed, 0.99)))
    flights = []
    for k, (a, b) in enumerate(recording.runs):
        t, w = recording.t[a:b], recording.omega[a:b]
        if t.size < 5:
            continue
        high = median_filter(np.linalg.norm(w, axis=1), size=5, mode="nearest") > level
        for i, j in _true_runs(high):
            piece = _free_part(t[i:j], w[i:j])
            if piece is None:
                continue
            p, q = i + piece[0] + GUARD, i + piece[1] - GUARD
            if q - p >= 2 and t[q - 1] - t[p] >= min_duration:
                flights.append(Segment(float(t[p]), float(t[q - 1]), t[p:q], w[p:q], k))
    return flights


def _true_runs(mask: NDArray[np.bool_]) -> list[tuple[int, int]]:
    """``(start, stop)`` of the stretches where ``mask`` is true."""
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return list(
        zip(np.flatnonzero(edges == 1).tolist(), np.flatnonzero(edges == -1).tolist(), strict=True)
    )


def _free_part(t: NDArray, w: NDArray) -> tuple[int, int] | None:
    """The longest stretch of ``(t, w)`` that keeps the free-flight bound on dω/dt."""
    if t.size < 7:
        return None
    step = float(np.median(np.diff(t)))
    half = max(2, int(round(0.02 / step)))
    smoothed = smooth(t, w, half)
    rate = np.linalg.norm(smoothed.derivative, axis=1)
    bound = np.sum(smoothed.value**2, axis=1) / np.sqrt(3.0)
    noise = 5.0 * np.sqrt(3.0) * smoothed.noise / (half * step)
    free = rate <= (1.0 + _TORQUE_SLACK) * bound + noise
    gaps = _true_runs(~free)
    for i, j in gaps:  # close gaps of one or two samples inside the stretch
        if j - i <= 2 and i > 0 and j < free.size:
            free[i:j] = True
    runs = _true_runs(free)
    return max(runs, key=lambda r: r[1] - r[0]) if runs else None
