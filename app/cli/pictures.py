"""The commands that write a still picture or a page of the motion: ``poinsot screenshot`` (a
PNG through headless Chromium, with a strobe of the body if asked:
:mod:`poinsot.app.exports.screenshot`) and ``poinsot export-html`` (a standalone animated page:
:mod:`poinsot.app.exports.html`): each one's options and its implementation.
:mod:`poinsot.app.cli.main` lists them among the subcommands.
"""

from __future__ import annotations

import argparse
import pathlib
import sys

from poinsot.app.cli.arguments import bounded_float, non_negative_float, output_file
from poinsot.app.cli.converters import add_preset_or_scene, fixed_view_type, size_type, view_type
from poinsot.app.cli.motion import add_strobe_arguments
from poinsot.app.construction.cameras import CAMERA_NAMES, RIDE_ALONG
from poinsot.app.exports.html import HTML_FPS, HTML_MAX_SECONDS
from poinsot.app.lessons.support.spec import SceneSpec
from poinsot.app.model.presets import Preset


def screenshot(
    out: pathlib.Path,
    scene: Preset | SceneSpec,
    t: float | None,
    size: tuple[int, int],
    view: str,
    background: str,
    fit: bool,
    strobe: int | None,
    t_from: float | None,
    t_to: float | None,
) -> int:
    """Write a PNG of a scene through headless Chromium (see
    :mod:`poinsot.app.exports.screenshot`), with a strobe of the body if asked."""
    from poinsot.app.cli.motion import strobe_of
    from poinsot.app.exports.screenshot import screenshot_command

    try:
        copies = strobe_of(strobe, t_from, t_to, t, view)
    except ValueError as exc:
        print(f"poinsot screenshot: error: {exc}", file=sys.stderr)
        return 2
    return screenshot_command(
        out, scene, t=t, size=size, view=view, background=background, fit=fit, strobe=copies
    )


def export_html(
    out: pathlib.Path,
    preset: Preset | SceneSpec,
    seconds: float,
    fps: float,
    view: str,
    light: bool,
) -> int:
    """Write a standalone animated HTML page (see :mod:`poinsot.app.exports.html`)."""
    from poinsot.app.exports.html import export_html_command

    return export_html_command(out, preset, seconds=seconds, fps=fps, view=view, light=light)


def add_screenshot_arguments(parser: argparse.ArgumentParser) -> None:
    add_preset_or_scene(parser, "scene", "draw")
    parser.add_argument(
        "--time",
        dest="t",
        metavar="TIME",
        type=non_negative_float,
        default=None,
        help="simulation time of the picture (default: one period of omega)",
    )
    parser.add_argument(
        "--size", type=size_type, default="1920x1080", help="WIDTHxHEIGHT in pixels"
    )
    parser.add_argument(
        "--view",
        type=view_type,
        default="default",
        metavar="{" + ",".join(CAMERA_NAMES) + "}",
        help="camera, as the browser's buttons name it: the scene's default view, along L "
        "(from above), the side, or riding on the body",
    )
    parser.add_argument(
        "--background",
        choices=("dark", "light", "transparent"),
        default="dark",
        help="opaque dark or light theme background, or a transparent PNG",
    )
    parser.add_argument(
        "--no-fit",
        dest="fit",
        action="store_false",
        help="keep the view's field of view instead of framing the construction",
    )
    add_strobe_arguments(parser)
    parser.add_argument("--out", type=output_file, required=True, help="output .png file")
    parser.set_defaults(func=screenshot)


def add_export_html_arguments(parser: argparse.ArgumentParser) -> None:
    add_preset_or_scene(parser, "preset", "record")
    parser.add_argument(
        "--seconds",
        type=bounded_float(0.0, HTML_MAX_SECONDS, open_low=True),
        default=20.0,
        help="clip length (wall seconds)",
    )
    parser.add_argument(
        "--fps", type=bounded_float(1.0, 60.0), default=HTML_FPS, help="recorded frames per second"
    )
    parser.add_argument(
        "--view",
        type=fixed_view_type,
        default="default",
        metavar="{" + ",".join(v for v in CAMERA_NAMES if v != RIDE_ALONG) + "}",
        help="initial camera, as the browser's buttons name it (the viewer can still orbit)",
    )
    parser.add_argument("--light", action="store_true", help="light theme (default: dark)")
    parser.add_argument("--out", type=output_file, required=True, help="output .html file")
    parser.set_defaults(func=export_html)
