"""What a session does to viser's GUI widgets besides creating them: set their values, and
put them away safely.

The browser applies all the GUI updates it has queued *after* the removals queued with them
(viser's client drains its message queue once per rendered frame). So an update sent before
a removal reaches a widget that no longer exists, and the browser logs "Tried to update
non-existent component", whenever both wait in the same drain: that is, whenever the
browser's main thread stalls for longer than the time between them (a software-WebGL browser
compiling the shaders of a new scene, a long render for a screenshot). No delay is safe
against every stall, so:

- :class:`Shelf`: widgets that come back (the control panel's groups, when a preset declares
  them again) are hidden and kept, never removed, and shown again when wanted;
- :class:`Retirement`: widgets made per use (the ghost's readout and plot, a scene's
  controls) are hidden at once and deleted :data:`RETIRE_SECONDS` later, longer than any
  stall of a browser that still animates.
"""

from __future__ import annotations

import asyncio
import contextlib
import dataclasses
import math
import time
from collections.abc import Callable, Hashable, Iterable
from typing import Any, Protocol, TypeVar

import viser

from poinsot.app import viser_private
from poinsot.app.model.elements import Control, Plot

#: Delay between hiding a removed widget and deleting it [s]: a browser whose main thread
#: stalls longer than this (1.5 s was seen to be too short for software WebGL switching
#: between the sphere and a custom body) could still log an update to a deleted widget.
RETIRE_SECONDS = 30.0
#: Clients whose changes are refused (a follower's: :mod:`.lead`), by ``id()`` of their
#: handle, each with what to call when one is refused. Set and cleared by :func:`hold_input`.
_HELD: dict[int, Callable[[bool], None]] = {}


def hold_input(client: Any, refused: Callable[[bool], None] | None) -> None:
    """Refuse ``client``'s changes to every widget but the free ones (:func:`on_user`), each
    put back to its last value and ``refused(True)`` called (on viser's loop: it must only
    post), and its pointer on the scene (:func:`refuse_held`); None accepts them again."""
    if refused is None:
        _HELD.pop(id(client), None)
    else:
        _HELD[id(client)] = refused


def refuse_held(client: Any) -> bool:
    """A pointer on the scene (a click or a drag, not a widget): True, and ``refused(False)``
    called (nothing to put back), if ``client`` is held (:func:`hold_input`)."""
    held = None if client is None else _HELD.get(id(client))
    if held is None:
        return False
    held(False)
    return True


def _refused(event: viser.GuiEvent[Any], handle: Any, last: Sent) -> bool:
    """A held client's change: the widget shows its last value again (the lead's)."""
    held = None if event.client is None else _HELD.get(id(event.client))
    if held is None:
        return False
    if hasattr(handle, "value"):
        handle.value = last.value
    held(True)
    return True


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


class Shelf:
    """Groups of widgets put away instead of removed: hidden, kept under a key, and shown again
    by :meth:`take` (no widget is ever deleted, so no update can ever reach a deleted one).
    Driven by one thread (the session's frame thread)."""

    def __init__(self) -> None:
        self._kept: dict[Hashable, list[Removable]] = {}

    def stow(self, key: Hashable, handles: Iterable[Removable]) -> None:
        """Hide ``handles`` and keep them for :meth:`take`."""
        kept = list(handles)
        for handle in kept:
            handle.visible = False
        self._kept[key] = kept

    def take(self, key: Hashable) -> list[Removable] | None:
        """The widgets stowed under ``key``, shown again; None if there are none."""
        kept = self._kept.pop(key, None)
        for handle in kept or ():
            handle.visible = True
        return kept

    def __contains__(self, key: Hashable) -> bool:
        return key in self._kept


def set_value(handle: viser.GuiInputHandle[T], value: T) -> None:
    """``handle.value = value``, sent only if it differs. (viser 1.1 declares the ``value``
    setter apart from its getter, which a type checker reads as a read-only property.)"""
    if handle.value != value:
        handle.value = value  # type: ignore[misc]


def set_marks(slider: viser.GuiSliderHandle[Any], marks: Iterable[tuple[float, str]]) -> None:
    """Move a slider's labelled marks (viser 1.1 has no public way: the adapter's)."""
    viser_private.set_slider_marks(slider, marks)


class Sent:
    """The value a browser last sent for one widget, recorded on viser's event loop as its
    message arrives. A callback runs later on a worker thread; by then the server may have
    written the widget again (a preset shown, a slider snapped), and ``handle.value`` would
    hand it the server's stale value instead of the user's choice. ``Sent`` never does.
    ``count`` is the number of values the browser has sent (see :meth:`newer_than`)."""

    __slots__ = ("count", "value")

    def __init__(self, value: Any) -> None:
        self.value = value
        self.count = 0

    def newer_than(self, count: int | None) -> bool:
        """True if the browser has sent a value since ``count`` was read: a server write meant
        for the state of then would overwrite a newer choice, still on its way to the frame
        thread (and viser, comparing the browser's next message with that stale value, could
        drop it as "unchanged")."""
        return count is not None and self.count != count


def write_unless_newer(
    handle: Any, value: Any, sent: Sent, count: int | None, loop: asyncio.AbstractEventLoop
) -> None:
    """Write ``value`` into a widget the browser writes too (from any thread), unless the
    browser has chosen again: since ``count`` was read (``sent.count``, when the change being
    shown was asked for), or so lately that its callbacks have not yet recorded it. viser
    stores a browser's value in the handle on its event loop, then runs the callbacks; a write
    from another thread landing in between would replace the user's value, and viser, finding
    the user's next message "unchanged", could drop it. So the check and the write run on the
    event loop, where nothing lands between them."""

    def write() -> None:
        if sent.newer_than(count) or handle.value != sent.value:
            return  # the newer choice is on its way to the frame thread; it is shown then
        set_value(handle, value)
        sent.value = value

    on_loop(loop, write)


def on_loop(loop: asyncio.AbstractEventLoop, callback: Callable[..., None], *args: Any) -> bool:
    """Run ``callback(*args)`` on viser's event loop ``loop`` (from any thread); False, and
    nothing run, if the loop is closed: the server stopped while a session's frame thread was
    still at work (what the writes would send goes to nobody)."""
    try:
        loop.call_soon_threadsafe(callback, *args)
    except RuntimeError:
        if not loop.is_closed():
            raise
        return False
    return True


class Refused(ValueError):
    """A value no browser widget could have sent (not a number, not an option...)."""


#: The longest text a text box may send [characters].
MAX_TEXT = 10_000


def _clamped(handle: Any, value: float) -> float:
    """``value`` within the handle's ``min`` and ``max`` (a slider's or a number box's)."""
    low, high = getattr(handle, "min", None), getattr(handle, "max", None)
    if isinstance(low, int | float) and value < low:
        value = low
    if isinstance(high, int | float) and value > high:
        value = high
    return value


def checked(handle: Any, value: Any) -> Any:
    """``value`` as the browser's widget would have let the user give it: a number clamped into
    the widget's range; raises :class:`Refused` for what no widget sends (NaN or an infinity,
    an option that is not offered, a text longer than :data:`MAX_TEXT`)."""
    if isinstance(handle, viser.GuiButtonHandle):
        return value
    options = getattr(handle, "options", None)
    if options is not None:
        if value not in tuple(options):
            raise Refused(f"{value!r} is not one of the options")
        return value
    if isinstance(value, bool):
        return value
    if isinstance(value, int):  # no NaN; beyond the double range it is clamped like any other
        return type(value)(_clamped(handle, value))
    if isinstance(value, float):
        if not math.isfinite(value):
            raise Refused(f"{value!r} is not a finite number")
        return float(_clamped(handle, value))
    if isinstance(value, str) and len(value) > MAX_TEXT:
        raise Refused(f"a text of {len(value)} characters (at most {MAX_TEXT})")
    if isinstance(value, tuple) and not all(
        math.isfinite(v) for v in value if isinstance(v, float)
    ):
        raise Refused(f"{value!r} has a value that is not a finite number")
    return value


def _accepted(handle: Any, sent: Sent, last: Sent) -> bool:
    """On the event loop, as a browser's value arrives (viser has stored it in the handle):
    keep it if a widget could have sent it, clamped; else put the widget back to ``last``,
    the last valid value, in the handle and in the browser. True if the value is accepted."""
    value = handle.value
    try:
        value = checked(handle, value)
    except (Refused, OverflowError, TypeError):
        handle.value = last.value  # sent back to the browser too
        return False
    if value != handle.value:
        handle.value = value  # the browser shows the clamped value
    sent.value = last.value = value
    sent.count += 1
    return True


def on_user(
    handle: Any,
    callback: Callable[[Sent], None],
    report: Callable[[Exception], None],
    sent: Sent | None = None,
    *,
    inline: bool = False,
    free: bool = False,
) -> Any:
    """Run ``callback(sent)`` for changes made in a browser only (a value set by the server
    fires the same viser callbacks, with no client). The callback runs on a worker thread,
    never raises into viser (``report`` gets the exception) and reads, as ``sent.value``, the
    value the browser sent last: two quick changes may run out of order, both read the later.
    With ``inline``, for a callback that only posts to a session's queue (it never blocks),
    it runs on viser's event loop as the value arrives: in order, and without waiting for a
    worker thread (under load, the hop to the thread pool was the slowest step of a slider
    move before the rebuild).

    Nothing a client sends is trusted: a value is first :func:`checked` against the widget, as
    the browser would (a number clamped into the slider's range, an option among the options);
    a value no widget could send (NaN, an option not offered) never reaches the callback, and
    the widget shows its last valid value again (so does a held one: :func:`hold_input`,
    unless ``free``). ``sent``: the browser's values (one is made if not given)."""
    sent = Sent(getattr(handle, "value", None)) if sent is None else sent
    last = Sent(sent.value)  # the last valid value, the server's or the browser's

    def run() -> None:
        try:
            callback(sent)
        except Exception as exc:
            report(exc)

    def dispatch() -> None:
        if inline:
            run()
        else:
            asyncio.get_running_loop().run_in_executor(None, run)  # never waits on the callback

    async def received(event: viser.GuiEvent[Any]) -> None:
        if not free and _refused(event, handle, last):  # a follower's (:func:`hold_input`)
            return
        if not hasattr(handle, "value"):  # a button
            if event.client is not None:
                dispatch()
            return
        if event.client is None:  # set by the server: remember it if valid (it runs later)
            with contextlib.suppress(Refused, OverflowError, TypeError):
                last.value = checked(handle, handle.value)
            return
        if _accepted(handle, sent, last):
            dispatch()

    if isinstance(handle, viser.GuiButtonHandle | viser.GuiButtonGroupHandle):
        handle.on_click(received)
    else:
        handle.on_update(received)
    return handle


class Pressed:
    """The option shown pressed in each button group (``aria-pressed`` and the pressed style in
    the page: :func:`~poinsot.app.viser_private.show_pressed`), sent only when it changes."""

    def __init__(self) -> None:
        self._shown: dict[str, str] = {}

    def show(self, group: viser.GuiButtonGroupHandle, option: str) -> None:
        key = viser_private.handle_id(group)
        if self._shown.get(key) != option:
            self._shown[key] = option
            viser_private.show_pressed(group, option)


# -- the widgets a session's state is mirrored into ---------------------------------------------
@dataclasses.dataclass
class Widgets:
    """The declared widgets the session's state is mirrored into (empty: not declared)."""

    inertia: tuple[viser.GuiSliderHandle[float], ...] = ()
    energy: viser.GuiSliderHandle[float] | None = None
    omega_norm: viser.GuiSliderHandle[float] | None = None
    speed: viser.GuiSliderHandle[float] | None = None
    trail: viser.GuiSliderHandle[int] | None = None
    pause: viser.GuiButtonHandle | None = None
    side: viser.GuiButtonGroupHandle | None = None

    def forget(self, group: Control | Plot) -> None:
        """The widgets of ``group`` are gone."""
        for field in dataclasses.fields(self):
            if field.name == _MIRRORED.get(group):
                setattr(self, field.name, field.default)  # () or None

    def remember(self, group: Control | Plot, handles: list[Removable]) -> None:
        """The widgets of ``group`` (as its builder returned them) are back."""
        name = _MIRRORED.get(group)
        if name is not None:
            setattr(self, name, tuple(handles) if name == "inertia" else handles[0])


#: The :class:`Widgets` field each group fills.
_MIRRORED: dict[Control | Plot, str] = {
    Control.INERTIA: "inertia",
    Control.ENERGY: "energy",
    Control.OMEGA_NORM: "omega_norm",
    Control.SPEED: "speed",
    Control.TRAIL: "trail",
    Control.PLAYBACK: "pause",
    Control.SIDE: "side",
}
