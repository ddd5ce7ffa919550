"""One fuzz case: build the call, run it with warnings as errors, sort its outcome.

A call ends *cleanly* in one of three ways:

* ``ValueError``: a ValueError raised by a ``raise`` statement of :mod:`poinsot.physics`
  (not by numpy, scipy or Python underneath), with a message of a sentence;
* ``TypeError``: the same for a TypeError (a wrong kind of argument);
* ``finite``: a result whose checks pass (finite numbers, and the invariants of the motion to
  :data:`~poinsot.physics.tools.fuzz.checks.TOL`).

Anything else is *unclean*: another exception, an error raised inside a library or with an
internal message, an escaped warning, a non-finite number, a broken invariant.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

import poinsot.physics
from poinsot.physics.tools.fuzz.checks import InvariantError
from poinsot.physics.tools.fuzz.values import Source

__all__ = ["CLEAN", "Call", "Outcome", "Target", "run_case"]

#: The clean outcomes, in the order they are reported.
CLEAN = ("ValueError", "TypeError", "finite")
#: A refusal shorter than this cannot say what is wrong and what to change.
_SHORTEST_MESSAGE = 20

#: The fuzz's own modules (physics/tools/fuzz/): an error raised there is no refusal, nor one
#: raised outside the physics package's folder (whichever room of it the fuzz sits in).
_FUZZ = __file__.replace("\\", "/").rsplit("/", 1)[0] + "/"
_PHYSICS = poinsot.physics.__file__.replace("\\", "/").rsplit("/", 1)[0] + "/"
_LINES: dict[str, list[str]] = {}


@dataclass(frozen=True)
class Call:
    """One call of the public API: what it is, how to make it, how to check its result."""

    text: str
    run: Callable[[], Any]
    check: Callable[[Any], object]


#: A target builds one call from a source of choices.
Target = Callable[[Source], Call]


@dataclass(frozen=True)
class Outcome:
    """How one call ended: ``kind`` is one of :data:`CLEAN` or ``"UNCLEAN"``."""

    target: str
    kind: str
    detail: str
    call: str
    seconds: float

    @property
    def clean(self) -> bool:
        return self.kind in CLEAN


def _source_line(path: str, line: int) -> str:
    if path not in _LINES:
        try:
            with open(path, encoding="utf-8") as f:
                _LINES[path] = f.read().splitlines()
        except OSError:
            _LINES[path] = []
    lines = _LINES[path]
    return lines[line - 1].strip() if 0 < line <= len(lines) else ""


def raised_by_physics(exc: BaseException) -> str | None:
    """Why ``exc`` is not a refusal of :mod:`poinsot.physics` itself, or None if it is."""
    tb = exc.__traceback__
    if tb is None:
        return "no traceback"
    while tb.tb_next is not None:
        tb = tb.tb_next
    path = tb.tb_frame.f_code.co_filename.replace("\\", "/")
    where = f"{path.rsplit('/', 1)[-1]}:{tb.tb_lineno}"
    if not path.startswith(_PHYSICS) or path.startswith(_FUZZ):
        return f"raised outside poinsot.physics ({where})"
    if not _source_line(path, tb.tb_lineno).startswith("raise "):
        return f"raised by an operation, not by a raise statement ({where})"
    if len(str(exc)) < _SHORTEST_MESSAGE:
        return f"message too short to say what to change ({where})"
    return None


def _exception_outcome(exc: Exception) -> tuple[str, str]:
    name = type(exc).__name__
    text = f"{name}: {exc}"
    if isinstance(exc, Warning):
        return "UNCLEAN", f"warning escaped: {text}"
    if isinstance(exc, ValueError | TypeError):
        why = raised_by_physics(exc)
        if why is None:
            return ("TypeError" if isinstance(exc, TypeError) else "ValueError"), text
        return "UNCLEAN", f"{text} [{why}]"
    why = raised_by_physics(exc) or "in poinsot.physics"
    return "UNCLEAN", f"{text} [{why.removeprefix('raised ')}]"


def build(target: Target, src: Source) -> Call:
    """The call a target makes from ``src`` (building the arguments warns about nothing)."""
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        return target(src)


def run_case(name: str, call: Call) -> Outcome:
    """Run one call with every warning turned into an error, and sort how it ended."""
    start = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            result = call.run()
        except Exception as exc:  # the point of the fuzz: every way a call can end
            kind, detail = _exception_outcome(exc)
        else:
            try:
                call.check(result)
                kind, detail = "finite", ""
            except InvariantError as exc:
                kind, detail = "UNCLEAN", f"check failed: {exc}"
            except Exception as exc:  # a check that cannot even read the result
                kind, detail = "UNCLEAN", f"result unreadable: {type(exc).__name__}: {exc}"
    return Outcome(name, kind, detail, call.text, time.perf_counter() - start)
