"""``poinsot fit``: the exact free motion fitted to each toss of a gyroscope recording (a phyphox
export or a CSV; :mod:`poinsot.app.model.fitting`): its options and its implementation.
:mod:`poinsot.app.cli.main` lists it among the subcommands.
"""

from __future__ import annotations

import argparse
import pathlib
import sys

from poinsot.app.cli.arguments import input_path, output_file, seconds_type


def fit(
    path: pathlib.Path,
    start: float | None,
    end: float | None,
    json_out: pathlib.Path | None,
    plot_out: pathlib.Path | None,
    degrees: bool,
    fit_rotation: bool,
    fit_bias: bool,
) -> int:
    """Fit the exact free motion to each toss of a recording (see
    :mod:`poinsot.app.model.fitting`)."""
    from poinsot.app.model.fitting import run_fit

    if start is not None and end is not None and not start < end:
        print(
            f"poinsot fit: error: the start ({start:g} s) must come before the end ({end:g} s)",
            file=sys.stderr,
        )
        return 2
    return run_fit(
        path,
        start=start,
        end=end,
        json_out=json_out,
        plot_out=plot_out,
        degrees=degrees,
        fit_rotation=fit_rotation,
        fit_bias=fit_bias,
    )


def add_fit_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "path",
        type=input_path,
        metavar="PATH",
        help="a phyphox export (folder or .zip) or a CSV of t, ωx, ωy, ωz",
    )
    parser.add_argument(
        "--start", type=seconds_type, metavar="S", help="fit only from this time [s] (one stretch)"
    )
    parser.add_argument(
        "--end", type=seconds_type, metavar="E", help="fit only up to this time [s] (one stretch)"
    )
    parser.add_argument(
        "--json", dest="json_out", type=output_file, metavar="OUT", help="write the fits as JSON"
    )
    parser.add_argument(
        "--plot",
        dest="plot_out",
        type=output_file,
        metavar="OUT.png",
        help="plot the measured ω against the fits (needs matplotlib)",
    )
    parser.add_argument(
        "--deg", dest="degrees", action="store_true", help="the plain CSV is in deg/s"
    )
    parser.add_argument(
        "--rotation",
        dest="fit_rotation",
        action="store_true",
        help="also fit a small rotation between the sensor's and the principal axes",
    )
    parser.add_argument(
        "--bias", dest="fit_bias", action="store_true", help="also fit a constant gyroscope bias"
    )
    parser.set_defaults(func=fit)
