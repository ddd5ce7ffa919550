"""Command line: ``poinsot [serve] [--host H] [--port P] [--preset NAME]``.

Subcommands are registered in :func:`build_parser`; each sets ``func`` (a callable taking the
parsed arguments and returning the exit code). ``poinsot`` with no subcommand serves.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Sequence

from poinsot.app.presets import PRESETS, preset_by_key


def _add_serve_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--host",
        default="127.0.0.1",
        help="interface to listen on (0.0.0.0 lets students on the room's network connect)",
    )
    parser.add_argument("--port", type=int, default=8080, help="TCP port (0 = any free port)")
    parser.add_argument(
        "--preset",
        default=PRESETS[0].key,
        choices=[p.key for p in PRESETS],
        help="scene each new browser starts with",
    )


def serve(args: argparse.Namespace) -> int:
    """Serve until interrupted (Ctrl-C)."""
    from poinsot.app.live.server import PoinsotApp

    app = PoinsotApp(args.host, args.port, preset=preset_by_key(args.preset))
    print(f"Poinsot is running at {app.url}  (Ctrl-C to stop)", flush=True)
    try:
        while True:
            time.sleep(3600)
    except KeyboardInterrupt:
        pass
    finally:
        app.stop()
    return 0


def report(args: argparse.Namespace) -> int:
    """Write the work-precision report into ``args.out`` (see :mod:`app.report`)."""
    from pathlib import Path

    from poinsot.app.report import run_report

    return run_report(Path(args.out), quick=args.quick)


def screenshot(args: argparse.Namespace) -> int:
    """Write a PNG of a scene through headless Chromium (see :mod:`app.screenshot`)."""
    from poinsot.app.exports.screenshot import screenshot_command

    return screenshot_command(args)


def export_html(args: argparse.Namespace) -> int:
    """Write a standalone animated HTML page (see :mod:`app.export`)."""
    from poinsot.app.exports.export import export_html_command

    return export_html_command(args)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="poinsot", description=__doc__.splitlines()[0])
    _add_serve_arguments(parser)  # `poinsot --host ...` is `poinsot serve --host ...`
    parser.set_defaults(func=serve)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    serve_parser = sub.add_parser("serve", help="serve the interactive scene (the default)")
    _add_serve_arguments(serve_parser)
    serve_parser.set_defaults(func=serve)
    report_parser = sub.add_parser(
        "report", help="work-precision report: the exact solution beside numerical integrators"
    )
    report_parser.add_argument(
        "--quick", action="store_true", help="a reduced case matrix and fewer settings (< 60 s)"
    )
    report_parser.add_argument("--out", default="out/report", help="output directory (created)")
    report_parser.set_defaults(func=report)
    from poinsot.app.exports.export import add_export_html_arguments
    from poinsot.app.exports.screenshot import add_screenshot_arguments

    screenshot_parser = sub.add_parser(
        "screenshot", help="a PNG of a scene, rendered by headless Chromium"
    )
    add_screenshot_arguments(screenshot_parser)
    screenshot_parser.set_defaults(func=screenshot)
    html_parser = sub.add_parser(
        "export-html", help="a standalone animated HTML page that plays from a file"
    )
    add_export_html_arguments(html_parser, [p.key for p in PRESETS])
    html_parser.set_defaults(func=export_html)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    return int(args.func(args))


if __name__ == "__main__":  # python -m poinsot.app.cli behaves as python -m poinsot.app and poinsot
    raise SystemExit(main())
