"""The command line's converters: text to a preset, a scene, a time, a view or a size, with a
readable one-line error for argparse. Every command's parser (:mod:`poinsot.app.cli.main` and the
commands that declare their options in their own module) takes its types from here."""

from __future__ import annotations

import argparse
import pathlib

from poinsot.app.cli.arguments import output_file
from poinsot.app.construction.cameras import RIDE_ALONG, canonical
from poinsot.app.exports.screenshot import parse_size, resolve_scene
from poinsot.app.exports.video import FORMATS as VIDEO_FORMATS
from poinsot.app.exports.video import MAX_SIZE as VIDEO_MAX_SIZE
from poinsot.app.lessons import scene_by_name, scene_names
from poinsot.app.lessons.support.spec import SceneSpec
from poinsot.app.live.classroom.links import LinkError, parse
from poinsot.app.model.presets import PRESETS, Preset, preset_by_key


def preset_type(key: str) -> Preset:
    try:
        return preset_by_key(key)
    except KeyError as exc:
        raise argparse.ArgumentTypeError(exc.args[0]) from exc


def scene_type(name: str) -> Preset | SceneSpec:
    try:
        return resolve_scene(name)
    except KeyError as exc:
        raise argparse.ArgumentTypeError(exc.args[0]) from exc


def add_preset_or_scene(parser: argparse.ArgumentParser, dest: str, verb: str) -> None:
    """``--preset KEY`` or ``--scene NAME`` (a scene, or a preset by key or label), one of the
    two, into ``dest`` (the first preset if neither): what an offline command ``verb``s."""
    which = parser.add_mutually_exclusive_group()
    which.add_argument(
        "--preset",
        dest=dest,
        type=preset_type,
        default=PRESETS[0].key,
        metavar="{" + ",".join(p.key for p in PRESETS) + "}",
        help=f"preset to {verb}",
    )
    which.add_argument(
        "--scene",
        dest=dest,
        type=scene_type,
        metavar="NAME",
        help=f"or a scene to {verb} by name ("
        + ", ".join(scene_names())
        + "), or a preset by key or label, e.g. 'Sphere (a cube)'",
    )


def scene_only_type(name: str) -> SceneSpec:
    try:
        return scene_by_name(name)
    except KeyError as exc:
        raise argparse.ArgumentTypeError(exc.args[0]) from exc


def view_type(text: str) -> str:
    """A camera view's name (:data:`~poinsot.app.construction.cameras.CAMERA_NAMES`, the words of
    the browser's buttons; the older "top" and "body" are still understood)."""
    try:
        return canonical(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from exc


def fixed_view_type(text: str) -> str:
    """A camera view that stands still (an HTML page's initial camera)."""
    view = view_type(text)
    if view == RIDE_ALONG:
        raise argparse.ArgumentTypeError("a page starts from a fixed view, not ride-along")
    return view


def size_type(text: str) -> tuple[int, int]:
    try:
        return parse_size(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from exc


def link_type(text: str) -> str:
    """A link to a state (:mod:`poinsot.app.live.classroom.links`): its query, or a whole URL; the
    query is returned, checked."""
    query = text.partition("?")[2] if "?" in text else text
    try:
        parse(query)
    except LinkError as exc:
        raise argparse.ArgumentTypeError(f"this link cannot be opened: {exc}") from None
    if not query.strip():
        raise argparse.ArgumentTypeError("a link needs a state, as 'preset=t_handle&t=12'")
    return query.strip()


def video_file(text: str) -> pathlib.Path:
    """A video to write: a file name ending in .mp4 or .gif, in a folder that takes files."""
    path = output_file(text)
    if path.suffix.lower() not in VIDEO_FORMATS:
        raise argparse.ArgumentTypeError(f"{text!r}: a video file ends in .mp4 or .gif")
    return path


def video_size(text: str) -> tuple[int, int]:
    """WIDTHxHEIGHT of a video: at most 4K (3840x2160)."""
    width, height = size_type(text)
    if width > VIDEO_MAX_SIZE[0] or height > VIDEO_MAX_SIZE[1]:
        raise argparse.ArgumentTypeError(
            f"a video is at most {VIDEO_MAX_SIZE[0]}x{VIDEO_MAX_SIZE[1]} pixels, got {text!r}"
        )
    return width, height
