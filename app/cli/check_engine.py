"""``poinsot check-engine LOG.csv``: does a physics engine's log move as a free rigid body?

Reads the log (:mod:`poinsot.app.model.engine_logs`: ``t, wx, wy, wz`` and optionally
``qw, qx, qy, qz``), needs the body's principal moments in the log's axes (``--inertia
I1,I2,I3``, or a ``# inertia: I1, I2, I3`` comment line in the log; the option wins), and
answers in words and numbers: does it stay on one polhode (energy, |L|, and L in space when the
attitude is given), does it flip when the exact motion from its first sample does, and which
game engine's step it looks like. Exit status 0: it moves as a free rigid body should; 1: it
does not; 2: the log (or the moments) cannot be read, in one line.
"""

from __future__ import annotations

import argparse
import json
import pathlib
import sys

from poinsot.app.cli.arguments import input_path, output_file
from poinsot.app.model.engine_logs import LogError, judge, parse_inertia, read_engine_log

__all__ = ["add_check_engine_arguments", "check_engine"]

EXIT_FREE, EXIT_NOT_FREE, EXIT_UNREADABLE = 0, 1, 2


def add_check_engine_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "log",
        type=input_path,
        metavar="LOG.csv",
        help="CSV with a header: t, wx, wy, wz [s, rad/s, body frame], optionally qw, qx, qy, qz",
    )
    parser.add_argument(
        "--inertia",
        metavar="I1,I2,I3",
        help="principal moments in the log's body axes (else the log's '# inertia:' line)",
    )
    parser.add_argument(
        "--json", dest="json_out", type=output_file, metavar="OUT", help="write the figures as JSON"
    )
    parser.set_defaults(func=check_engine)


def check_engine(
    log: pathlib.Path, inertia: str | None = None, json_out: pathlib.Path | None = None
) -> int:
    """Check the log, print the answers; the exit status (0 free, 1 not, 2 unreadable)."""
    try:
        data = read_engine_log(log)
        if inertia is not None:
            moments = parse_inertia(inertia)
        elif data.inertia is not None:
            moments = data.inertia
        else:
            raise LogError(
                f"{log.name}: no moments: give --inertia I1,I2,I3 or a '# inertia:' comment line"
            )
        verdict = judge(data, moments)
    except LogError as exc:
        print(f"poinsot check-engine: {exc}", file=sys.stderr)
        return EXIT_UNREADABLE
    print("\n".join(verdict.lines))
    if json_out is not None:
        json_out.parent.mkdir(parents=True, exist_ok=True)
        json_out.write_text(json.dumps(verdict.figures, indent=2) + "\n")
    return EXIT_FREE if verdict.free else EXIT_NOT_FREE
