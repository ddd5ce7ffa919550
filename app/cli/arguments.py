"""What the command lines share: a parser whose errors are one line, the converters that check a
value before any work starts, and the boundary that turns an unexpected failure into one line.

A converter raises :class:`argparse.ArgumentTypeError` with a message that says what to give
instead; argparse then prints ``<prog>: error: argument --x: <message>`` and exits 2.
"""

from __future__ import annotations

import argparse
import errno
import math
import os
import pathlib
import sys
import tempfile
import traceback
from collections.abc import Callable
from typing import NoReturn

#: Exit status of a failure after the arguments were accepted (a bad argument is 2).
EXIT_FAILED = 1
#: Exit status after Ctrl-C (the shell's convention, 128 + SIGINT).
EXIT_INTERRUPTED = 130


def one_line(text: str) -> str:
    """``text`` with its line breaks folded, so that a message is one line on the terminal."""
    return " ".join(text.split())


class OneLineParser(argparse.ArgumentParser):
    """A parser whose errors are one line on stderr, ``<prog>: error: ...`` (exit status 2),
    without the usage block (``--help`` prints it)."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {one_line(message)} (see {self.prog} --help)\n")


# -- numbers ----------------------------------------------------------------------------------
def _number(text: str, kind: type[int] | type[float]) -> float:
    try:
        value = kind(text)
    except ValueError:
        noun = "a whole number" if kind is int else "a number"
        raise argparse.ArgumentTypeError(f"{text!r} is not {noun}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text!r} is not a finite number")
    return value


def in_bounds(
    text: str,
    kind: type[int] | type[float],
    low: float,
    high: float = math.inf,
    *,
    open_low: bool = False,
    wanted: str,
) -> float:
    """``text`` as a finite ``kind`` in [low, high] (or (low, high] with ``open_low``); else
    :class:`argparse.ArgumentTypeError` ``'<text>': <wanted>``. Every numeric converter is one
    call of this."""
    value = _number(text, kind)
    if value > high or value < low or (open_low and value == low):
        raise argparse.ArgumentTypeError(f"{text!r}: {wanted}")
    return value


def positive_int(text: str) -> int:
    """A whole number >= 1."""
    return int(in_bounds(text, int, 1, wanted="give a whole number >= 1"))


def port_number(text: str) -> int:
    """A TCP port: a whole number from 0 (any free port) to 65535."""
    return int(in_bounds(text, int, 0, 65535, wanted="a port is a whole number from 0 to 65535"))


def non_negative_int(text: str) -> int:
    """A whole number >= 0."""
    return int(in_bounds(text, int, 0, wanted="give a whole number >= 0"))


def positive_float(text: str) -> float:
    """A finite number > 0."""
    return float(in_bounds(text, float, 0, open_low=True, wanted="give a finite number > 0"))


def non_negative_float(text: str) -> float:
    """A finite number >= 0."""
    return float(in_bounds(text, float, 0, wanted="give a finite number >= 0"))


def fraction(text: str) -> float:
    """A number between 0 and 1 (a share, a tolerance)."""
    return float(in_bounds(text, float, 0, 1, wanted="give a number between 0 and 1"))


def seconds_type(text: str) -> float:
    """A time in seconds: a finite number."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a time in seconds") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text!r} is not a time in seconds")
    return value


def bounded_float(low: float, high: float, *, open_low: bool = False) -> Callable[[str], float]:
    """A converter for a finite number in [low, high] (or (low, high] with ``open_low``)."""
    shown = f"{'(' if open_low else '['}{low:g}, {high:g}]"

    def convert(text: str) -> float:
        wanted = f"give a number in {shown}"
        return float(in_bounds(text, float, low, high, open_low=open_low, wanted=wanted))

    convert.__name__ = f"number in {shown}"  # argparse names the type in some messages
    return convert


# -- paths ------------------------------------------------------------------------------------
def _nearest_existing(path: pathlib.Path) -> pathlib.Path:
    for candidate in (path, *path.parents):
        if candidate.exists():
            return candidate
    return pathlib.Path(".")


def _writable_folder(folder: pathlib.Path, shown: str) -> None:
    """Raise unless a file can be created in ``folder`` (tried: permissions alone say nothing
    to root, nor on /proc or a read-only mount). The trial file is removed at once."""
    if not folder.is_dir():
        raise argparse.ArgumentTypeError(f"{shown}: {folder} is not a folder")
    try:
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as exc:
        reason = os.strerror(exc.errno) if exc.errno else str(exc)
        raise argparse.ArgumentTypeError(f"{shown}: cannot write in {folder} ({reason})") from None


def output_file(text: str) -> pathlib.Path:
    """A file to write: not a folder, and its folder (or the nearest existing one, where the
    command creates the rest) takes new files."""
    path = pathlib.Path(text)
    if not text or path.is_dir():
        raise argparse.ArgumentTypeError(f"{text!r} is a folder; give a file name")
    _writable_folder(_nearest_existing(path.parent), text)
    return path


def output_dir(text: str) -> pathlib.Path:
    """A folder to write into (created with its parents if missing)."""
    path = pathlib.Path(text)
    if not text:
        raise argparse.ArgumentTypeError("give a folder")
    _writable_folder(_nearest_existing(path), text)
    return path


def input_path(text: str) -> pathlib.Path:
    """A file or folder that exists and can be read."""
    path = pathlib.Path(text)
    if not path.exists():
        raise argparse.ArgumentTypeError(f"{text}: no such file or folder")
    if not os.access(path, os.R_OK):
        raise argparse.ArgumentTypeError(f"{text}: {os.strerror(errno.EACCES)}")
    return path


# -- the boundary -----------------------------------------------------------------------------
def run_guarded(prog: str, call: Callable[[], int], *, debug: bool) -> int:
    """Run a command: its exit status, or, for an exception it did not handle, one line on
    stderr and :data:`EXIT_FAILED` (the traceback too with ``debug``)."""
    try:
        return int(call())
    except KeyboardInterrupt:
        print(f"{prog}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except Exception as exc:
        if debug:
            traceback.print_exc()
        reason = one_line(str(exc)) or "no message"
        hint = "" if debug else " (--debug shows the traceback)"
        print(f"{prog}: error: {type(exc).__name__}: {reason}{hint}", file=sys.stderr)
        return EXIT_FAILED
