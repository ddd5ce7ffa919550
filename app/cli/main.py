"""Command line: ``poinsot [serve] [--host H] [--port P] [--preset NAME]`` and offline commands.

``poinsot`` serves the live app; ``report``, ``screenshot``, ``export-html``, ``benchmark`` and
``fit`` (the exact free motion fitted to a gyroscope recording) are the offline commands.

:func:`build_parser` makes the one parser of ``poinsot``: the serve, report and benchmark options
are declared here, the other commands' next to their implementation (:mod:`.cli_pictures`:
screenshot and export-html; :mod:`.cli_motion`: video and the strobe; :mod:`.cli_fit`: fit;
:mod:`.check_engine`: check-engine), all with the converters of
:mod:`poinsot.app.cli.converters`. Each subcommand sets
``func``, its implementation, which takes its options as plain typed keyword arguments named
as its parameters (the parser's ``type=`` converters turn the text into values) and returns
the exit code.
``poinsot`` with no subcommand serves.
"""

from __future__ import annotations

import argparse
import inspect
import os
import sys
import time
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from poinsot.app.cli.arguments import (
    OneLineParser,
    output_dir,
    port_number,
    positive_int,
    run_guarded,
)

if TYPE_CHECKING:
    from poinsot.app.lessons.support.spec import SceneSpec

DESCRIPTION = "Poinsot: torque-free rigid-body motion, live in the browser and offline."


class HelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """--help shows every option's default, except where there is none to show (None, a
    switch) or the help already says it."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        if action.default is None or action.nargs == 0 or "(default" in (action.help or ""):
            return action.help
        return super()._get_help_string(action)


class CommandParser(OneLineParser):
    """A command's parser: a bad option is one line on stderr (exit status 2)."""


# -- the commands ---------------------------------------------------------------------------
def serve(
    host: str,
    port: int,
    preset: str,
    start_scene: SceneSpec | None,
    workers: int,
    allow_origin: list[str],
    link: str | None = None,
    redis: str | None = None,
    lecturer_code: str | None = None,
) -> int:
    """Serve until interrupted (Ctrl-C); each browser starts with ``start_scene`` if given,
    else with ``preset``. With ``workers`` > 1 the sessions run in that many processes behind
    a landing port (:mod:`poinsot.app.live.workers`); with ``redis`` the lead is followed on
    every host linked to it (:mod:`poinsot.app.live.broker`). A port that cannot be served is
    one line and exit status 2."""
    from poinsot.app.live.hardening.network import PortError, check_port
    from poinsot.app.model.presets import preset_by_key

    code, url = _classroom_link(redis, lecturer_code)
    try:
        check_port(host, port)
        if workers > 1:
            from poinsot.app.live.workers import serve_classroom

            scene = start_scene.name if start_scene else None
            return serve_classroom(
                host,
                port,
                workers,
                preset,
                scene,
                origins=tuple(allow_origin),
                link=link or "",
                code=code,
                redis=url,
            )
    except PortError as exc:
        print(f"poinsot serve: {exc}", file=sys.stderr)
        return 2
    return _serve_one(
        host, port, preset_by_key(preset), start_scene, allow_origin, link, _hub(code, url)
    )


def _serve_one(
    host: str,
    port: int,
    preset: Any,
    start_scene: SceneSpec | None,
    allow_origin: list[str],
    link: str | None,
    hub: Any,
) -> int:
    """``poinsot serve --workers 1``: one process, until Ctrl-C."""
    from poinsot.app.live.hardening.network import board, port_problem
    from poinsot.app.live.server import PoinsotApp
    from poinsot.app.live.workers import lecturer_line

    app = PoinsotApp(
        host,
        port,
        preset=preset,
        scene=start_scene,
        allow_origins=allow_origin,
        follow=hub,
        serving=True,
    )
    if port and app.port != port:  # viser took the next free port: the board would be wrong
        app.stop()
        print(f"poinsot serve: {port_problem(host, port)}", file=sys.stderr)
        return 2
    print(board(host, app.port, link or ""), flush=True)
    print(lecturer_line(app.follow.code), flush=True)
    try:
        while True:
            time.sleep(3600)
    except KeyboardInterrupt:
        pass
    finally:
        app.stop()
    return 0


def _classroom_link(redis: str | None, lecturer_code: str | None) -> tuple[str, str]:
    """The lecturer code ("": a new one) and the Redis URL to link to ("": none), with
    ``--redis`` the code shared there and one line said (:mod:`poinsot.app.live.broker`)."""
    lecturer_code = lecturer_code.strip().lower() if lecturer_code else None  # as it is typed
    if not redis:
        return lecturer_code or "", ""
    from poinsot.app.live.broker import shared_code
    from poinsot.app.live.classroom.follow import new_code

    code, line, reachable = shared_code(redis, lecturer_code, new_code())
    print(line, file=sys.stdout if reachable else sys.stderr, flush=True)
    return code, redis if reachable else ""


def _hub(code: str, url: str) -> Any:
    """One process's follow hub, linked to the Redis at ``url`` if given."""
    from poinsot.app.live.classroom.follow import FollowHub

    hub = FollowHub(code or None)
    if url:
        from poinsot.app.live.broker import link_hub

        link_hub(hub, url)
    return hub


def report(args: argparse.Namespace) -> int:
    """Write the work-precision report into ``args.out`` (see :mod:`app.report`)."""
    from pathlib import Path

    from poinsot.app.report import run_report

    return run_report(Path(args.out), quick=args.quick)


# -- the parser -----------------------------------------------------------------------------
def _add_serve_arguments(parser: argparse.ArgumentParser) -> None:
    from poinsot.app.cli.converters import link_type, scene_only_type
    from poinsot.app.lessons import scene_names
    from poinsot.app.model.presets import PRESETS

    parser.add_argument(
        "--host",
        default="127.0.0.1",
        help="interface to listen on (0.0.0.0 lets students on the room's network connect)",
    )
    parser.add_argument(
        "--port",
        type=port_number,
        default=8080,
        help="TCP port; if it is busy the server says so and stops (0 = any free port)",
    )
    parser.add_argument(
        "--workers",
        type=positive_int,
        default=os.cpu_count() or 1,
        metavar="N",
        help="processes serving the sessions (default: the number of cores, here %(default)s);"
        " with N > 1 the port redirects each new browser to the least-loaded one, on the "
        "ports that follow it; 1 = one process",
    )
    parser.add_argument(
        "--allow-origin",
        action="append",
        default=[],
        metavar="ORIGIN",
        help="also accept browsers from this page's origin (http://host:port), and its host "
        "name (a name students type, a proxy's address); repeatable",
    )
    parser.add_argument(
        "--link",
        type=link_type,
        default=None,
        metavar="QUERY",
        help="also print the link to this state and its QR code, as 'preset=t_handle&t=12"
        "&view=side' (the guide's page Link parameters lists them)",
    )
    _add_redis_arguments(parser)
    which = parser.add_mutually_exclusive_group()
    which.add_argument(
        "--preset",
        default=PRESETS[0].key,
        choices=[p.key for p in PRESETS],
        help="preset each new browser starts with",
    )
    which.add_argument(
        "--scene",
        dest="start_scene",
        type=scene_only_type,
        default=None,
        metavar="{" + ",".join(scene_names()) + "}",
        help="or the scene each new browser starts with",
    )
    parser.set_defaults(func=serve)


def _add_redis_arguments(parser: argparse.ArgumentParser) -> None:
    """Following across hosts (:mod:`poinsot.app.live.broker`)."""
    parser.add_argument(
        "--redis",
        default=None,
        metavar="URL",
        help="follow the lecturer across hosts through this Redis, as redis://HOST:6379/0 "
        "(redis://:PASSWORD@HOST:6379/0 with requirepass; needs pip install 'poinsot[redis]')",
    )
    parser.add_argument(
        "--lecturer-code",
        default=None,
        metavar="CODE",
        help="the lecturer code (default: a new one, or with --redis the one the classroom's "
        "first host set there)",
    )


def _add_report_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--quick", action="store_true", help="a reduced case matrix and fewer settings (< 60 s)"
    )
    parser.add_argument(
        "--out", type=output_dir, default="out/report", help="output directory (created)"
    )
    parser.set_defaults(func=report)


# The commands declared in their own modules, imported only when their options are declared:
# `poinsot fit ...` imports neither the scenes nor the exports (see build_parser).
def _add_benchmark(parser: argparse.ArgumentParser) -> None:
    from poinsot.app.devtools.benchmark import add_arguments

    add_arguments(parser)


def _add_screenshot(parser: argparse.ArgumentParser) -> None:
    from poinsot.app.cli.pictures import add_screenshot_arguments

    add_screenshot_arguments(parser)


def _add_export_html(parser: argparse.ArgumentParser) -> None:
    from poinsot.app.cli.pictures import add_export_html_arguments

    add_export_html_arguments(parser)


def _add_video(parser: argparse.ArgumentParser) -> None:
    from poinsot.app.cli.motion import add_video_arguments

    add_video_arguments(parser)


def _add_fit(parser: argparse.ArgumentParser) -> None:
    from poinsot.app.cli.fit import add_fit_arguments

    add_fit_arguments(parser)


def _add_check_engine(parser: argparse.ArgumentParser) -> None:
    from poinsot.app.cli.check_engine import add_check_engine_arguments

    add_check_engine_arguments(parser)


#: Subcommand -> (help, how its options are declared).
_SUBCOMMANDS: dict[str, tuple[str, Callable[[argparse.ArgumentParser], None]]] = {
    "serve": ("serve the interactive scene (the default)", _add_serve_arguments),
    "report": (
        "work-precision report: the exact solution beside numerical integrators",
        _add_report_arguments,
    ),
    "screenshot": ("a PNG of a scene, rendered by headless Chromium", _add_screenshot),
    "export-html": (
        "a standalone animated HTML page that plays from a file",
        _add_export_html,
    ),
    "video": ("an MP4 or GIF of a scene, rendered by headless Chromium", _add_video),
    "benchmark": (
        "server time per client-frame, bytes per frame and slider-to-redraw time",
        _add_benchmark,
    ),
    "fit": (
        "fit the exact free motion to the tosses of a gyroscope recording (phyphox or CSV)",
        _add_fit,
    ),
    "check-engine": (
        "does a physics engine's log (t, wx, wy, wz[, qw, qx, qy, qz]) move as a free body?",
        _add_check_engine,
    ),
}


def _add_debug_argument(parser: argparse.ArgumentParser, default: object) -> None:
    parser.add_argument(
        "--debug",
        action="store_true",
        default=default,
        help="show the traceback of an unexpected failure (else one line)",
    )


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The parser of ``poinsot``; given a ``command`` (not serve), only that command's options
    are declared (the others are listed, empty, and the top level has no serve options), so
    that running it imports only what it needs."""
    parser = CommandParser(prog="poinsot", description=DESCRIPTION, formatter_class=HelpFormatter)
    _add_debug_argument(parser, False)
    if command is None:
        _add_serve_arguments(parser)  # `poinsot --host ...` is `poinsot serve --host ...`
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=CommandParser)
    for name, (help_text, add_arguments) in _SUBCOMMANDS.items():
        subparser = sub.add_parser(
            name, help=help_text, description=help_text, formatter_class=HelpFormatter
        )
        # `poinsot --debug fit ...` and `poinsot fit --debug ...` both work.
        _add_debug_argument(subparser, argparse.SUPPRESS)
        if command in (None, name):
            add_arguments(subparser)
    return parser


def _command(argv: Sequence[str]) -> str | None:
    """The command that ``argv`` names first (after ``--debug`` only), if not serve: its options
    alone need declaring. None for anything else (serve, ``--help``, top-level options)."""
    words = [word for word in argv if word != "--debug"]
    if words and words[0] in _SUBCOMMANDS and words[0] != "serve":
        return words[0]
    return None


def _run(args: argparse.Namespace) -> int:
    if args.func is report:  # the report's own entry point takes the parsed options as they are
        return int(report(args))
    # A command takes the options named by its parameters (the top-level parser's serve
    # options are in every namespace).
    options = vars(args)
    names = inspect.signature(args.func).parameters
    return int(args.func(**{name: options[name] for name in names}))


def main(argv: Sequence[str] | None = None) -> int:
    """Parse, run the command; a bad argument is one line and exit status 2, an unexpected
    failure one line and exit status 1 (with its traceback under ``--debug``)."""
    argv = sys.argv[1:] if argv is None else list(argv)
    args = build_parser(_command(argv)).parse_args(argv)
    prog = f"poinsot {args.command or 'serve'}"
    return run_guarded(prog, lambda: _run(args), debug=args.debug)
