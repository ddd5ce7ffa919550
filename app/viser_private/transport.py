"""One client's send queue and socket in viser 1.1.x: part of the one adapter to viser's
private names (:mod:`poinsot.app.viser_private`, whose docstring has the inventory).

- :func:`message_buffer`: ``ClientHandle._websock_connection.get_message_buffer()``, the
  client's queue, with its ``message_counter`` (next id), ``generator_cursors`` (client id ->
  the last id its sender took), ``message_from_id`` (the messages still queued), ``done``
  (set once the client has left: a message pushed then is never sent, and viser warns) and
  ``sanctioned_dead_writes()`` (pushes within it are dropped without the warning);
- :func:`connection_of`: ``ClientHandle._viser_server._websock_server`` with its
  ``_live_connections`` (client id -> websockets connection) and ``_background_event_loop``.

Both answer None rather than raise when a name has moved (the pacer then never skips, and the
backlog watch sees nothing: the behaviour before either); the test of each pins the names.
"""

from __future__ import annotations

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
    connection = getattr(client, "_websock_connection", None)
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
    without viser's warning (a frame begun just before the client left)."""
    return buffer.sanctioned_dead_writes()
