"""Reading gyroscope recordings, finding the flights in them, and the ``fit`` command's report.

Every file is written into ``tmp_path`` from synthetic data: phyphox exports (folder and zip,
with and without ``meta/``, in phyphox's CSV flavours), plain CSV files, and a recording of
three throws separated by stretches in the hand.
"""

from __future__ import annotations

import io
import json
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from poinsot.app.model import recordings
from poinsot.app.model.fitting import fit_segments, format_table, run_fit, to_json
from poinsot.app.model.recordings import find_flights, read_recording, select_segments
from poinsot.physics import FreeRigidBody

HEADER = ["Time (s)", "Gyroscope x (rad/s)", "Gyroscope y (rad/s)", "Gyroscope z (rad/s)"]
I_TRUE = np.array([1.0, 1.9, 2.7])


# -- writers ------------------------------------------------------------------------------------
def phyphox_csv(t, omega, sep=",", comma=False) -> str:
    """The data table as phyphox writes it: quoted header, 16 significant digits, |ω| last."""
    cols = [*HEADER, "Absolute (rad/s)"]
    lines = [sep.join(f'"{c}"' for c in cols)]
    table = np.column_stack([t, omega, np.linalg.norm(omega, axis=1)])
    for row in table:
        fields = [f"{v:.15E}" for v in row]
        lines.append(sep.join(f.replace(".", ",") if comma else f for f in fields))
    return "\n".join(lines) + "\n"


def time_csv(events, sep=",", comma=False) -> str:
    lines = [sep.join(['"event"', '"experiment time"', '"system time"', '"system time text"'])]
    for k, (event, when) in enumerate(events):
        fields = [f'"{event}"', f"{when:.15E}", f"{1.7e9 + 10 * k:.15E}", '"2024-05-01 10:00:00"']
        if comma:
            fields = [f.replace(".", ",") for f in fields]
        lines.append(sep.join(fields))
    return "\n".join(lines) + "\n"


def write_folder(root: Path, t, omega, events=None, **flavour) -> Path:
    folder = root / "Gyroscope rotation rate 2024-05-01 10-00-00"
    folder.mkdir()
    (folder / "Raw Data.csv").write_text(phyphox_csv(t, omega, **flavour))
    if events is not None:
        (folder / "meta").mkdir()
        (folder / "meta" / "time.csv").write_text(time_csv(events, **flavour))
        (folder / "meta" / "device.csv").write_text('"property","value"\n"deviceModel","X"\n')
    return folder


def write_zip(path: Path, t, omega, events=None, prefix="", **flavour) -> Path:
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr(prefix + "Raw Data.csv", phyphox_csv(t, omega, **flavour))
        if events is not None:
            archive.writestr(prefix + "meta/time.csv", time_csv(events, **flavour))
    return path


def toss(duration=1.0, omega0=(12.0, 1.0, 1.0), start=0.0, seed=0):
    """A free flight sampled at 100 Hz with 0.02 rad/s of noise."""
    rng = np.random.default_rng(seed)
    t = start + np.arange(int(duration * 100) + 1) / 100.0
    w = FreeRigidBody(I_TRUE, omega0).omega(t - start)
    return t, w + 0.02 * rng.standard_normal(w.shape)


def three_throws(seed=0):
    """A recording: hand, throw, flight, catch, three times, then the hand again.

    In the hand: |ω| below ~0.5 rad/s with noise and sudden knocks (3 rad/s bumps lasting
    ~30 ms: torque spikes). The throw spins the body up in 0.12 s, the catch stops it in 0.08 s.
    Returns (t, omega, the true flights as (start, end) pairs).
    """
    rng = np.random.default_rng(seed)
    tosses = [((12.0, 1.0, 1.0), 0.9), ((1.0, 2.0, 8.0), 1.1), ((3.06, 10.0, 2.0), 1.0)]
    parts, flights, now = [], [], 0.0

    def add(duration, fn):
        nonlocal now
        n = int(round(duration * 100))
        tau = (np.arange(n) + 0.3 * (rng.random(n) - 0.5)) / 100.0
        parts.append((now + tau, fn(tau)))
        now += n / 100.0

    def hand(tau):
        w = 0.3 * np.sin(np.outer(tau, [1.3, 0.7, 2.1]) + rng.random(3) * 6)
        for c in rng.uniform(0.2, 1.2, 2):  # knocks
            w += 3.0 * np.exp(-(((tau - c) / 0.015) ** 2))[:, None] * rng.normal(size=3) / 1.7
        return w + 0.05 * rng.standard_normal(w.shape)

    for omega0, duration in tosses:
        body = FreeRigidBody(I_TRUE, omega0)
        add(1.5, hand)
        add(0.12, lambda tau, b=body: _ramp(tau / 0.12)[:, None] * b.omega(0.0))
        start = now
        add(duration, lambda tau, b=body: b.omega(tau))
        flights.append((start, now))
        end_w = body.omega(duration)
        add(0.08, lambda tau, w=end_w: (1.0 - _ramp(tau / 0.08))[:, None] * w)
    add(1.0, hand)
    t = np.concatenate([p[0] for p in parts])
    w = np.concatenate([p[1] for p in parts])
    return t, w + 0.02 * rng.standard_normal(w.shape), flights


def _ramp(x):
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


# -- phyphox exports ----------------------------------------------------------------------------
def test_phyphox_folder_with_meta_splits_runs_at_pauses(tmp_path):
    t, w = toss(2.0)
    folder = write_folder(tmp_path, t, w, events=[("START", 0.0), ("PAUSE", 0.8), ("START", 0.8)])
    rec = read_recording(folder)
    np.testing.assert_allclose(rec.t, t, rtol=1e-15)
    np.testing.assert_allclose(rec.omega, w, rtol=1e-14)
    assert rec.runs == ((0, 81), (81, t.size))
    assert rec.source.endswith("Raw Data.csv")


def test_phyphox_folder_without_meta_is_one_run(tmp_path):
    t, w = toss()
    rec = read_recording(write_folder(tmp_path, t, w))
    assert rec.runs == ((0, t.size),)


@pytest.mark.parametrize("prefix", ["", "Gyroscope rotation rate/"])
def test_phyphox_zip_with_meta(tmp_path, prefix):
    t, w = toss(2.0)
    events = [("START", 0.0), ("PAUSE", 0.5), ("START", 0.5), ("PAUSE", 1.5), ("START", 1.5)]
    rec = read_recording(write_zip(tmp_path / "export.zip", t, w, events, prefix=prefix))
    np.testing.assert_allclose(rec.omega, w, rtol=1e-14)
    assert rec.runs == ((0, 51), (51, 151), (151, t.size))


def test_phyphox_zip_without_meta(tmp_path):
    t, w = toss()
    rec = read_recording(write_zip(tmp_path / "export.zip", t, w))
    assert rec.runs == ((0, t.size),) and rec.t.size == t.size


@pytest.mark.parametrize("sep, comma", [(";", True), ("\t", True), (";", False), ("\t", False)])
def test_phyphox_csv_flavours(tmp_path, sep, comma):
    t, w = toss()
    events = [("START", 0.0), ("PAUSE", 0.3), ("START", 0.3)]
    rec = read_recording(write_folder(tmp_path, t, w, events, sep=sep, comma=comma))
    np.testing.assert_allclose(rec.omega, w, rtol=1e-14)
    assert len(rec.runs) == 2


# -- plain CSV ----------------------------------------------------------------------------------
def _plain(path, t, w, header=None, scale=1.0):
    lines = [header] if header else []
    lines += [f"{a:.9f},{b:.9f},{c:.9f},{d:.9f}" for a, (b, c, d) in zip(t, w * scale, strict=True)]
    path.write_text("\n".join(lines) + "\n")
    return path


def test_plain_csv_with_and_without_header(tmp_path):
    t, w = toss()
    bare = read_recording(_plain(tmp_path / "a.csv", t, w))
    named = read_recording(_plain(tmp_path / "b.csv", t, w, header="t,wx,wy,wz"))
    for rec in (bare, named):
        np.testing.assert_allclose(rec.omega, w, atol=1e-9)
        assert rec.runs == ((0, t.size),)


def test_plain_csv_in_degrees(tmp_path):
    t, w = toss()
    path = _plain(tmp_path / "deg.csv", t, w, scale=180.0 / np.pi)
    np.testing.assert_allclose(read_recording(path, degrees=True).omega, w, atol=1e-9)
    labelled = _plain(
        tmp_path / "l.csv", t, w, "t (s),wx (deg/s),wy (deg/s),wz (deg/s)", 180 / np.pi
    )
    np.testing.assert_allclose(read_recording(labelled).omega, w, atol=1e-9)


def test_header_unit_contradicting_the_flag(tmp_path):
    t, w = toss()
    folder = write_folder(tmp_path, t, w)
    with pytest.raises(ValueError, match="header says rad/s, but deg/s was asked"):
        read_recording(folder, degrees=True)


# -- bad files ----------------------------------------------------------------------------------
def test_missing_path(tmp_path):
    with pytest.raises(ValueError, match="no such file or folder"):
        read_recording(tmp_path / "nothing.csv")


def test_empty_file(tmp_path):
    (tmp_path / "e.csv").write_text("\n\n")
    with pytest.raises(ValueError, match="is empty"):
        read_recording(tmp_path / "e.csv")


def test_unparsable_line_is_named(tmp_path):
    t, w = toss()
    path = _plain(tmp_path / "x.csv", t, w, header="t,wx,wy,wz")
    lines = path.read_text().splitlines()
    lines[6] = "0.05,oops,1,2"
    path.write_text("\n".join(lines))
    with pytest.raises(ValueError, match=r"line 7: expected four numbers .*'0.05,oops,1,2'"):
        read_recording(path)


def test_too_few_columns(tmp_path):
    (tmp_path / "x.csv").write_text("0,1,2\n0.01,1,2\n")
    with pytest.raises(ValueError, match="line 1: expected four numbers"):
        read_recording(tmp_path / "x.csv")


def test_nan_line_is_named(tmp_path):
    t, w = toss()
    w = w.copy()
    w[3, 2] = np.nan
    folder = write_folder(tmp_path, t, w)
    with pytest.raises(ValueError, match="line 5: a value is not a number"):
        read_recording(folder)


def test_times_going_back(tmp_path):
    t, w = toss()
    t = t.copy()
    t[10] = t[8]
    with pytest.raises(ValueError, match=r"line 11: the time 0.08 s does not come after 0.09 s"):
        read_recording(_plain(tmp_path / "x.csv", t, w))


def test_another_sensor_is_refused(tmp_path):
    (tmp_path / "acc.csv").write_text(
        '"Time (s)","Acceleration x (m/s^2)","Acceleration y (m/s^2)","Acceleration z (m/s^2)"\n'
        "0,0.1,0.2,9.8\n"
    )
    with pytest.raises(ValueError, match="not a gyroscope recording"):
        read_recording(tmp_path / "acc.csv")


def test_zip_without_csv(tmp_path):
    path = tmp_path / "x.zip"
    with zipfile.ZipFile(path, "w") as archive:
        archive.writestr("meta/time.csv", time_csv([("START", 0.0)]))
    with pytest.raises(ValueError, match="no CSV file"):
        read_recording(path)


def test_size_cap(tmp_path, monkeypatch):
    t, w = toss()
    path = _plain(tmp_path / "big.csv", t, w)
    monkeypatch.setattr(recordings, "MAX_BYTES", 1000)
    with pytest.raises(ValueError, match=r"MB, more than the 0 MB this command reads"):
        read_recording(path)
    zipped = write_zip(tmp_path / "big.zip", t, w)  # small archive, large file inside
    monkeypatch.setattr(recordings, "MAX_BYTES", zipped.stat().st_size + 10)
    with pytest.raises(ValueError, match="Raw Data.csv is"):
        read_recording(zipped)


def test_row_cap(tmp_path, monkeypatch):
    t, w = toss()
    monkeypatch.setattr(recordings, "MAX_ROWS", 50)
    with pytest.raises(ValueError, match="101 rows, more than the 50"):
        read_recording(_plain(tmp_path / "x.csv", t, w))


# -- segments -----------------------------------------------------------------------------------
def _recording(t, w, runs=None):
    return recordings.Recording(t, w, runs or ((0, t.size),), "synthetic")


@pytest.mark.parametrize("seed", range(3))
def test_finds_the_three_flights_between_the_hand_stretches(seed):
    t, w, truth = three_throws(seed)
    flights = find_flights(_recording(t, w))
    assert len(flights) == 3
    for segment, (start, end) in zip(flights, truth, strict=True):
        assert start - 0.02 <= segment.start and segment.end <= end + 0.02
        assert segment.end - segment.start >= 0.8 * (end - start)
        assert segment.t[0] == segment.start and segment.t[-1] == segment.end


def test_the_flights_fit_as_free_motions():
    t, w, _ = three_throws(1)
    results = fit_segments(find_flights(_recording(t, w)))
    for r in results:
        assert r.fit is not None and r.fit.explained, r.fit and r.fit.message
        np.testing.assert_allclose(r.fit.inertia, I_TRUE / 2.7, atol=0.03)


def test_a_flight_never_spans_a_pause():
    t, w, truth = three_throws(2)
    middle = 0.5 * (truth[1][0] + truth[1][1])
    cut = int(np.searchsorted(t, middle))
    flights = find_flights(_recording(t, w, ((0, cut), (cut, t.size))))
    for f in flights:
        assert f.end < middle or f.start > middle
    assert len(flights) == 4  # the second flight, cut in two


def test_segment_chosen_by_hand():
    t, w, truth = three_throws(0)
    rec = _recording(t, w)
    (segment,) = select_segments(rec, truth[1][0] + 0.1, truth[1][1] - 0.1)
    assert segment.start >= truth[1][0] + 0.1 and segment.end <= truth[1][1] - 0.1
    (whole,) = select_segments(rec, start=truth[2][0])
    assert whole.end == t[-1]
    with pytest.raises(ValueError, match="must come before the end"):
        select_segments(rec, 3.0, 2.0)
    with pytest.raises(ValueError, match="no samples between"):
        select_segments(rec, 100.0, 101.0)
    paused = _recording(t, w, ((0, 500), (500, t.size)))
    with pytest.raises(ValueError, match="spans a pause of the recording"):
        select_segments(paused, t[400], t[600])


# -- the command --------------------------------------------------------------------------------
def test_run_fit_on_a_phyphox_zip_prints_writes_json_and_plot(tmp_path):
    t, w, truth = three_throws(0)
    path = write_zip(tmp_path / "throws.zip", t, w, [("START", 0.0)])
    out, err = io.StringIO(), io.StringIO()
    status = run_fit(
        path, json_out=tmp_path / "fit.json", plot_out=tmp_path / "fit.png", out=out, err=err
    )
    assert status == 0, err.getvalue()
    table = out.getvalue().splitlines()
    assert "3 tosses" in table[0] and table[1].startswith("#")
    assert [line.split()[0] for line in table[2:5]] == ["1", "2", "3"]
    data = json.loads((tmp_path / "fit.json").read_text())
    assert len(data["segments"]) == 3
    keys = {"start", "end", "inertia", "inertia_sigma", "omega0", "rms", "period"}
    keys |= {"flip_period", "measured_flip_period", "family"}
    for entry, (start, _) in zip(data["segments"], truth, strict=True):
        assert keys <= set(entry)
        assert entry["start"] == pytest.approx(start, abs=0.05)
        assert max(entry["inertia"]) == 1.0
    assert (tmp_path / "fit.png").stat().st_size > 10_000


def test_run_fit_by_hand_with_degrees(tmp_path):
    t, w = toss(1.0, omega0=(3.06, 10.0, 2.0), start=5.0)
    path = _plain(tmp_path / "deg.csv", t, w, scale=180.0 / np.pi)
    out = io.StringIO()
    assert run_fit(path, start=5.2, end=5.9, degrees=True, fit_bias=True, out=out) == 0
    assert "1 toss;" in out.getvalue() and "5.20 s" in out.getvalue()


def test_run_fit_reports_bad_input_on_stderr(tmp_path):
    err = io.StringIO()
    assert run_fit(tmp_path / "none.csv", out=io.StringIO(), err=err) == 1
    assert "no such file or folder" in err.getvalue()
    still = tmp_path / "still.csv"
    still.write_text("\n".join(f"{k / 100},0.01,0.0,0.02" for k in range(300)))
    err = io.StringIO()
    assert run_fit(still, out=io.StringIO(), err=err) == 1
    assert "no free flight found" in err.getvalue() and "--start and --end" in err.getvalue()


def test_run_fit_without_matplotlib_says_so(tmp_path, monkeypatch):
    t, w = toss()
    path = _plain(tmp_path / "x.csv", t, w)
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    out, err = io.StringIO(), io.StringIO()
    assert run_fit(path, start=0.0, plot_out=tmp_path / "p.png", out=out, err=err) == 1
    assert "needs matplotlib" in err.getvalue()
    assert "1 toss" in out.getvalue()
    assert not (tmp_path / "p.png").exists()


def test_table_and_json_of_a_segment_that_could_not_be_fitted():
    t, w = toss()
    seg = recordings.Segment(float(t[0]), float(t[9]), t[:10], w[:10], 0)
    results = fit_segments([seg])
    assert results[0].fit is None and "too few samples" in results[0].error
    assert "toss 1: not fitted: too few samples" in format_table(results, "x")
    assert to_json(results, "x")["segments"][0]["error"].startswith("too few samples")
    json.dumps(to_json(results, "x"), allow_nan=False)
