"""One client's send queue and socket in viser 1.1.x: part of the one adapter to viser's
private names (:mod:`poinsot.app.viser_private`, whose docstring has the inventory).

- :func:`message_buffer`: ``ClientHandle._websock_connection.get_message_buffer()`` (and
  :func:`gui_message_buffer`: ``GuiApi._websock_interface``'s, the same connection), the
  client's queue, with its ``message_counter`` (next id), ``generator_cursors`` (client id ->
  the last id its sender took), ``message_from_id`` (the messages still queued), ``done``
  (set once the client has left: a message pushed then is never sent, and viser warns) and
  ``sanctioned_dead_writes()`` (pushes within it are dropped without the warning);
- :func:`connection_of`: ``ClientHandle._viser_server._websock_server`` with its
  ``_live_connections`` (client id -> websockets connection) and ``_background_event_loop``;
- :func:`set_on_its_loop_only`: a buffer's ``message_event`` (an ``asyncio.Event``) and
  ``event_loop``, the event made one that only its loop sets (:class:`SetOnItsLoop`: viser
  also sets it from the pushing thread, which races with the sender's wait);
- :func:`held_back`: ``ClientHandle._websock_connection.queue_message`` (the one method
  through which a client's scene API queues), shadowed on the connection within a block so
  that what one thread queues is held back, not sent (the handles keep the values it set);

Both answer None rather than raise when a name has moved (the pacer then never skips, and the
backlog watch sees nothing: the behaviour before either); the test of each pins the names.
"""

from __future__ import annotations

import asyncio
import contextlib
import threading
from collections.abc import Iterator
from contextlib import AbstractContextManager
from typing import Any

import viser

#: What :func:`message_buffer` needs of viser's buffer.
BUFFER_FIELDS = (
    "message_counter",
    "generator_cursors",
    "message_from_id",
    "done",
    "sanctioned_dead_writes",
)


def message_buffer(client: viser.ClientHandle) -> Any:
    """viser 1.1 keeps the queue on the client's connection; None if that ever changes."""
    return _buffer_of(getattr(client, "_websock_connection", None))


def gui_message_buffer(gui: viser.GuiApi) -> Any:
    """The queue of the client whose GUI is ``gui`` (``GuiApi._websock_interface``, the same
    connection), or None."""
    return _buffer_of(getattr(gui, "_websock_interface", None))


def _buffer_of(connection: Any) -> Any:
    getter = getattr(connection, "get_message_buffer", None)
    if getter is None:
        return None
    buffer = getter()
    return buffer if all(hasattr(buffer, name) for name in BUFFER_FIELDS) else None


def connection_of(client: viser.ClientHandle) -> tuple[Any, Any]:
    """The client's websocket connection and the event loop it runs on (viser 1.1 keeps the
    live connections and the loop on its websocket server), or Nones."""
    server = getattr(getattr(client, "_viser_server", None), "_websock_server", None)
    connections = getattr(server, "_live_connections", None)
    connection = connections.get(client.client_id) if isinstance(connections, dict) else None
    return connection, getattr(server, "_background_event_loop", None)


def last_queued(buffer: Any) -> int:
    """The id of the last message put in ``buffer`` (:func:`message_buffer`; -1: none)."""
    return int(buffer.message_counter) - 1


def last_taken(buffer: Any, client_id: int) -> int | None:
    """The id of the last message the client's sender took from ``buffer`` (None: no sender
    yet)."""
    taken = buffer.generator_cursors.get(client_id)
    return None if taken is None else int(taken)


def pending(buffer: Any) -> int:
    """Messages in ``buffer`` now (after viser's coalescing of updates)."""
    return len(buffer.message_from_id)


def closed(buffer: Any) -> bool:
    """True once the client of ``buffer`` has left (nothing pushed then is ever sent)."""
    return bool(buffer.done)


def quiet_if_closed(buffer: Any) -> AbstractContextManager[None]:
    """Pushes to ``buffer`` within this block, if its client has left meanwhile, are dropped
    without viser's warning (a frame begun just before the client left); nothing changes for
    a buffer of None (viser's names moved: :func:`message_buffer`)."""
    return contextlib.nullcontext() if buffer is None else buffer.sanctioned_dead_writes()


class SetOnItsLoop(asyncio.Event):
    """A send queue's message event, set only on the queue's own event loop. viser's buffer sets
    its event where a message is pushed, any thread, and again on its loop
    (``call_soon_threadsafe``, at once or when an atomic block ends), which is what wakes the
    queue's sender. The set from another thread walks the event's waiters while the loop may be
    adding or removing the sender's: "deque mutated during iteration", raised into the thread
    that pushed (a session being built, a frame). Here that set does nothing; the loop's wakes."""

    owner: asyncio.AbstractEventLoop | None = None

    def set(self) -> None:
        # asyncio's own test of the running loop (None on another thread), without the
        # exception of get_running_loop(): this runs for every message pushed.
        running = asyncio._get_running_loop()
        if running is not None and running is self.owner:
            super().set()


def set_on_its_loop_only(buffer: Any) -> bool:
    """Make ``buffer``'s ``message_event`` (an ``asyncio.Event``, woken on ``event_loop``) a
    :class:`SetOnItsLoop`, in place (the sender waiting on it keeps waiting on it). False if
    viser's buffer no longer has them (nothing changed then)."""
    event = getattr(buffer, "message_event", None)
    loop = getattr(buffer, "event_loop", None)
    if not isinstance(event, asyncio.Event) or not isinstance(loop, asyncio.AbstractEventLoop):
        return False
    if not isinstance(event, SetOnItsLoop):
        event.__class__ = SetOnItsLoop
    assert isinstance(event, SetOnItsLoop)
    event.owner = loop
    return True


def senders_woken_on_their_loop(client: viser.ClientHandle) -> bool:
    """The client's send queue's event set on its loop only (:func:`set_on_its_loop_only`)."""
    buffer = message_buffer(client)
    return buffer is not None and set_on_its_loop_only(buffer)


def broadcasts_woken_on_their_loop(server: viser.ViserServer) -> bool:
    """The server's broadcast queue's event set on its loop only (:func:`set_on_its_loop_only`):
    ``ViserServer._websock_server.get_message_buffer()``."""
    getter = getattr(getattr(server, "_websock_server", None), "get_message_buffer", None)
    return getter is not None and set_on_its_loop_only(getter())


@contextlib.contextmanager
def held_back(client: viser.ClientHandle) -> Iterator[list[Any] | None]:
    """Within the block, what this thread queues to ``client`` is held back, not sent: yields
    the list it is gathered in (:func:`queue_held` sends it after all). Its node handles keep
    the values it sets; other threads' messages go as ever. Yields None, and everything goes
    as ever, if viser's names moved or the queue is shadowed already."""
    connection = getattr(client, "_websock_connection", None)
    queue = getattr(connection, "queue_message", None)
    if connection is None or queue is None or "queue_message" in vars(connection):
        yield None
        return
    thread = threading.get_ident()
    held: list[Any] = []

    def queue_message(message: Any) -> None:
        if threading.get_ident() == thread:
            held.append(message)
        else:
            queue(message)

    connection.queue_message = queue_message
    try:
        yield held
    finally:
        del connection.queue_message


def queue_held(client: viser.ClientHandle, messages: list[Any]) -> None:
    """Queue ``messages`` held back by :func:`held_back` to ``client`` after all."""
    for message in messages:
        client._websock_connection.queue_message(message)
