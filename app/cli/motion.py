"""The options of the commands that show motion: ``poinsot video`` (an MP4 or GIF of a preset
or a scene: its options and its implementation; :mod:`poinsot.app.cli.main` lists it among the
subcommands) and ``poinsot screenshot --strobe`` (copies of the body over an interval, see
:mod:`poinsot.app.exports.strobe`).

The frames are rendered by headless Chromium and encoded by the ffmpeg that the imageio-ffmpeg
wheel ships (:mod:`poinsot.app.exports.video`). A progress bar (rich) shows on a terminal; when
the output is not a terminal, a few plain lines.
"""

from __future__ import annotations

import argparse
import pathlib
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager

from poinsot.app.cli.arguments import bounded_float, non_negative_float, positive_int
from poinsot.app.cli.converters import add_preset_or_scene, video_file, video_size, view_type
from poinsot.app.construction.cameras import CAMERA_NAMES, RIDE_ALONG, space_view
from poinsot.app.construction.view import View
from poinsot.app.exports.chromium import (
    EXIT_NO_BROWSER,
    BrowserMissing,
    find_chromium,
    sigterm_exits,
)
from poinsot.app.exports.screenshot import THEME_BACKGROUND, open_stage
from poinsot.app.exports.strobe import MAX_COPIES, Strobe
from poinsot.app.exports.video import (
    DEFAULT_FPS,
    FPS_RANGE,
    MAX_SECONDS,
    Clip,
    Progress,
    check_clip,
    film,
)
from poinsot.app.lessons.support.spec import SceneSpec
from poinsot.app.model.presets import Preset

PROG = "poinsot video"
#: Plain progress lines (not a terminal): one at each of these fractions of the frames.
PLAIN_STEPS = (0.25, 0.5, 0.75, 1.0)


def add_video_arguments(parser: argparse.ArgumentParser) -> None:
    """The options of ``poinsot video``."""
    add_preset_or_scene(parser, "scene", "film")
    parser.add_argument(
        "--seconds",
        type=bounded_float(0.0, MAX_SECONDS, open_low=True),
        default=10.0,
        help="clip length (wall seconds; the scene's own speed)",
    )
    parser.add_argument(
        "--fps", type=bounded_float(*FPS_RANGE), default=DEFAULT_FPS, help="frames per second"
    )
    parser.add_argument(
        "--size",
        type=video_size,
        default="1280x720",
        help="WIDTHxHEIGHT in pixels, up to 3840x2160 (even sides for MP4)",
    )
    parser.add_argument(
        "--view",
        type=view_type,
        default="default",
        metavar="{" + ",".join(CAMERA_NAMES) + "}",
        help="camera, as the browser's buttons name it (ride-along follows the body)",
    )
    parser.add_argument(
        "--from",
        dest="t0",
        type=non_negative_float,
        default=0.0,
        metavar="T0",
        help="simulation time of the first frame",
    )
    parser.add_argument("--light", action="store_true", help="light theme (default: dark)")
    parser.add_argument(
        "--out",
        type=video_file,
        nargs="+",
        required=True,
        help="output file: .mp4 (H.264, plays in PowerPoint and browsers) or .gif (loops); "
        "several (clip.mp4 clip.gif): the frames are rendered once and encoded into each",
    )
    parser.set_defaults(func=video)


def add_strobe_arguments(parser: argparse.ArgumentParser) -> None:
    """``poinsot screenshot``'s strobe options."""
    parser.add_argument(
        "--strobe",
        type=positive_int,
        default=None,
        metavar="N",
        help=f"draw N copies of the body (2 to {MAX_COPIES}) at equal times over an interval, "
        "the earliest faintest (default interval: one flip, else one period of omega)",
    )
    parser.add_argument(
        "--from",
        dest="t_from",
        type=non_negative_float,
        default=None,
        metavar="T0",
        help="the strobe's first time",
    )
    parser.add_argument(
        "--to",
        dest="t_to",
        type=non_negative_float,
        default=None,
        metavar="T1",
        help="the strobe's last time (the picture's time)",
    )


def strobe_of(
    copies: int | None, t_from: float | None, t_to: float | None, t: float | None, view: str
) -> Strobe | None:
    """The strobe the options ask for (None: no strobe); ValueError for a combination that
    makes no sense."""
    if copies is None:
        if t_from is not None or t_to is not None:
            raise ValueError("--from and --to set the interval of a --strobe")
        return None
    if t is not None:
        raise ValueError("a strobe picture is taken at its last time (--to), not at --time")
    if view == RIDE_ALONG:
        raise ValueError("a strobe needs a camera that stands still, not ride-along")
    return Strobe(copies, t_from, t_to)


@contextmanager
def progress_bar(total: int, label: str) -> Iterator[Progress]:
    """``progress(done, total)``: a rich bar on a terminal (stderr), else a few plain lines."""
    if sys.stderr.isatty():
        from rich.console import Console
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TimeRemainingColumn

        with Progress(
            "[progress.description]{task.description}",
            BarColumn(),
            MofNCompleteColumn(),
            TimeRemainingColumn(),
            console=Console(stderr=True),
            transient=True,
        ) as bar:
            task = bar.add_task(label, total=total)
            yield lambda done, _total: bar.update(task, completed=done)
        return
    marks = sorted({max(1, round(f * total)) for f in PLAIN_STEPS})

    def plain(done: int, _total: int) -> None:
        if done in marks:
            print(f"{label}: {done}/{total} frames", file=sys.stderr, flush=True)

    yield plain


def camera_of(scene: Preset | SceneSpec, view: str) -> View | None:
    """The fixed camera of ``view`` (a scene's own framing for "default"), None to ride along."""
    if view == RIDE_ALONG:
        return None
    if isinstance(scene, SceneSpec) and view == "default":
        return scene.view
    return space_view(view)


def video(
    out: list[pathlib.Path],
    scene: Preset | SceneSpec,
    seconds: float,
    fps: float,
    size: tuple[int, int],
    view: str,
    t0: float,
    light: bool,
) -> int:
    """Film a clip; 0 on success, 2 for a clip that cannot be made, EXIT_NO_BROWSER without
    Chromium, 1 on failure."""
    speed = scene.initial_speed() if isinstance(scene, SceneSpec) else scene.speed
    clip = Clip(seconds, fps, size, t0=t0, speed=speed)
    try:
        for path in out:
            check_clip(clip, path.suffix.lower())
        chromium = find_chromium()
    except ValueError as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 2
    except BrowserMissing as exc:
        print(f"{PROG}: {exc}", file=sys.stderr)
        return EXIT_NO_BROWSER
    for path in out:
        path.parent.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    label = f"{scene.key} {' '.join(path.name for path in out)}"
    with sigterm_exits(), progress_bar(clip.frames, label) as progress:
        made = film(
            lambda client_of: open_stage(scene, dark_mode=not light, client_of=client_of),
            clip,
            camera_of(scene, view),
            out,
            chromium=chromium,
            background=THEME_BACKGROUND[not light],
            progress=progress,
        )
    elapsed = time.perf_counter() - start
    for path in made.paths:
        print(
            f"wrote {path} ({made.width}x{made.height}, {made.frames} frames at {fps:g} fps, "
            f"{path.stat().st_size / 1e6:.2f} MB, scene {scene.key}, from t = {t0:g}, view "
            f"{view}) in {elapsed:.1f} s ({made.seconds_per_frame:.2f} s per frame)"
        )
    return 0
