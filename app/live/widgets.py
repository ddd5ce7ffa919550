"""What a session does to viser's GUI widgets besides creating them: set their values, and
remove them safely.

Removal: the browser applies the GUI updates of one rendered frame after that frame's
removals, so an update sent just before a removal would otherwise reach a widget that no
longer exists and log a console error. A widget that goes is therefore hidden at once (no
update can reach it after that) and deleted :data:`RETIRE_SECONDS` later. The control panel
and the ghost's controls both remove widgets this way, through the session's one
:class:`Retirement`.
"""

from __future__ import annotations

import time
from collections.abc import Iterable
from typing import Any, Protocol, TypeVar

import viser
from viser._messages import GuiSliderMark

#: Delay between hiding a removed widget and deleting it [s].
RETIRE_SECONDS = 1.5

T = TypeVar("T")


class Removable(Protocol):
    """A viser GUI handle, as far as retiring it goes."""

    visible: bool

    def remove(self) -> None: ...


class Retirement:
    """Widgets waiting for their deletion. Driven by one thread (the session's frame thread)."""

    def __init__(self, delay: float = RETIRE_SECONDS) -> None:
        self.delay = float(delay)
        self._due: list[tuple[float, Removable]] = []

    def retire(self, handles: Iterable[Removable]) -> None:
        """Hide ``handles`` now; :meth:`collect` deletes them after the delay."""
        due = time.monotonic() + self.delay
        for handle in handles:
            handle.visible = False
            self._due.append((due, handle))

    def collect(self, now: float | None = None) -> int:
        """Delete the widgets that are due; returns how many are still waiting."""
        if not self._due:
            return 0
        now = time.monotonic() if now is None else now
        waiting = []
        for due, handle in self._due:
            if due <= now:
                handle.remove()
            else:
                waiting.append((due, handle))
        self._due = waiting
        return len(waiting)


def set_value(handle: viser.GuiInputHandle[T], value: T) -> None:
    """``handle.value = value``, sent only if it differs. (viser 1.1 declares the ``value``
    setter apart from its getter, which a type checker reads as a read-only property.)"""
    if handle.value != value:
        handle.value = value  # type: ignore[misc]


def set_marks(slider: viser.GuiSliderHandle[Any], marks: Iterable[tuple[float, str]]) -> None:
    """Move a slider's labelled marks. viser 1.1 takes marks only as an argument of
    ``add_slider``; a handle's ``marks`` attribute is not sent, the ``_marks`` property is."""
    slider._marks = tuple(GuiSliderMark(value=float(v), label=label) for v, label in marks)
