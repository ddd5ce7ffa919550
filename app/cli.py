"""Command line: ``poinsot [serve] [--host H] [--port P]``."""

from __future__ import annotations

import argparse


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="poinsot", description=__doc__)
    sub = parser.add_subparsers(dest="command")
    serve = sub.add_parser("serve", help="serve the interactive scene (default)")
    for p in (parser, serve):
        p.add_argument("--host", default="127.0.0.1", help="interface to listen on")
        p.add_argument("--port", type=int, default=8080, help="TCP port (0 = any free port)")
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    print(f"poinsot: the scene is not built yet ({args.host}:{args.port})")
    return 0
