"""What the server checks on a websocket before viser acts on it: the page it comes from (its
``Origin``), how much it sends (:class:`~poinsot.app.live.budget.MessageBudget`), and that each
message is one the browser could have sent.

viser 1.1 accepts a websocket in its server's ``ws_handler``, runs the infra-level connect
callbacks, and only then starts reading the connection (``_message_consumer``: ``await
websocket.recv()``, then its own decoding and dispatch). :class:`WireGuard` registers one such
callback (``WebsockServer.on_client_connect``): there it reads the handshake's headers and
either closes the connection (an origin not allowed: before any message is read, so no
session is ever built) or wraps that connection's ``recv``, the earliest point at which a
message of this client is seen. A message refused there is never decoded by viser; while a
client is over its budget, its connection is read no faster than the budget refills, so a flood
waits in its own socket (TCP holds the sender back) instead of costing the server CPU.

Origins: a browser sends ``Origin`` with every websocket; a page may only drive the server if
it was served by it (the origin's host:port is the ``Host`` the browser connected to), or if
its origin is listed (``--allow-origin``). Tools that are not browsers (the probe, the load
test, curl) send no ``Origin``: they are let in, as is standard, since no web page can open a
websocket without one.

This reaches into two of viser 1.1's internals, both kept in this module:
``ViserServer._websock_server`` and ``WebsockServer._live_connections``.
"""

from __future__ import annotations

import asyncio
import threading
import time
from collections.abc import Awaitable, Callable, Iterable
from typing import Any
from urllib.parse import urlsplit

import msgspec
import viser

from poinsot.app.live.budget import MessageBudget

#: Messages a second one client may send, sustained, and in one burst (a browser sends a few
#: dozen a second at most: camera moves while orbiting, a dragged slider, upload parts).
MESSAGE_RATE = 200.0
MESSAGE_BURST = 400.0
#: A client over its budget this long (without a second's pause) is disconnected [s].
EXCESS_SECONDS = 3.0
#: Websocket close code for a policy violation (RFC 6455, 7.4.1).
POLICY_VIOLATION = 1008


def normalise_origin(origin: str) -> str:
    """``scheme://host[:port]`` in lower case, without a trailing slash."""
    return origin.strip().rstrip("/").lower()


def origin_allowed(origin: str | None, host: str | None, allowed: Iterable[str] = ()) -> bool:
    """May a websocket with these ``Origin`` and ``Host`` headers connect? Yes without an
    origin (not a browser), for a listed origin, and for the server's own pages (the origin's
    host:port is the ``Host`` header); no for anything else, including ``null`` (a local file
    or a sandboxed frame)."""
    if origin is None:
        return True
    normalised = normalise_origin(origin)
    if normalised in {normalise_origin(a) for a in allowed}:
        return True
    parts = urlsplit(normalised)
    if parts.scheme not in ("http", "https") or not parts.netloc or host is None:
        return False
    return parts.netloc == host.strip().lower()


def _browser_message(raw: Any) -> dict[str, Any] | None:
    """The decoded message if a browser could have sent it: a binary msgpack map with a type,
    and a GUI update carrying only a value (viser would set any attribute of the widget's
    state that a client names, its callbacks included); None otherwise."""
    if not isinstance(raw, bytes):
        return None
    try:
        message = msgspec.msgpack.decode(raw)
    except msgspec.DecodeError:
        return None
    if not isinstance(message, dict) or not isinstance(message.get("type"), str):
        return None
    if message["type"] == "GuiUpdateMessage":
        updates = message.get("updates")
        if not (isinstance(updates, dict) and set(updates) == {"value"}):
            return None
    return message


def _fits(handle: Any, value: Any) -> bool:
    """Can viser convert ``value`` to the type of the widget's value, as it will? (A text
    for a slider, or nothing, would raise inside viser's handler, logged as an error.)"""
    current = getattr(handle, "value", None)
    if current is None:
        return True
    if isinstance(current, tuple):
        return isinstance(value, list | tuple) and len(value) == len(current)
    try:
        type(current)(value)
    except (TypeError, ValueError, OverflowError):
        return False
    return True


class WireGuard:
    """Origin check and message budget on every websocket of ``server``."""

    def __init__(
        self,
        server: viser.ViserServer,
        allowed_origins: Iterable[str] = (),
        *,
        rate: float = MESSAGE_RATE,
        burst: float = MESSAGE_BURST,
        excess_seconds: float = EXCESS_SECONDS,
    ) -> None:
        self.allowed_origins = tuple(normalise_origin(o) for o in allowed_origins)
        self._limits = (rate, burst, excess_seconds)
        self._server = server
        self._infra = server._websock_server
        self._lock = threading.Lock()
        self._budgets: dict[int, MessageBudget] = {}
        #: Connections refused for their origin; clients closed for flooding.
        self.refused = 0
        self.disconnected = 0
        #: Messages dropped: beyond a budget, or not one a browser sends.
        self.dropped = 0
        self.malformed = 0
        self._agents: dict[int, str] = {}  # each connected browser's User-Agent header
        self._infra.on_client_connect(self._accept)
        self._infra.on_client_disconnect(self._forget)

    def user_agent(self, client_id: int) -> str:
        """The ``User-Agent`` a connected browser gave in its handshake ("" if none)."""
        with self._lock:
            return self._agents.get(client_id, "")

    def budget(self, client_id: int) -> MessageBudget | None:
        """The budget of a connected client (tests)."""
        with self._lock:
            return self._budgets.get(client_id)

    async def _accept(self, connection: Any) -> None:
        # the connection viser reads from (its consumer calls ``recv`` on the instance)
        websocket: Any = self._infra._live_connections.get(connection.client_id)
        if websocket is None:
            return
        headers = websocket.request.headers if websocket.request is not None else {}
        if not origin_allowed(headers.get("Origin"), headers.get("Host"), self.allowed_origins):
            with self._lock:
                self.refused += 1
            websocket.recv = _discarding(websocket.recv)
            await websocket.close(POLICY_VIOLATION, "origin not allowed")
            return
        budget = MessageBudget(*self._limits)
        with self._lock:
            self._budgets[connection.client_id] = budget
            self._agents[connection.client_id] = str(headers.get("User-Agent") or "")
        websocket.recv = self._budgeted(connection.client_id, websocket, budget)

    def _forget(self, connection: Any) -> None:
        with self._lock:
            self._budgets.pop(connection.client_id, None)
            self._agents.pop(connection.client_id, None)

    def _acceptable(self, client_id: int, raw: Any) -> bool:
        """A message a browser could send, whose value (for a GUI update) fits its widget."""
        message = _browser_message(raw)
        if message is None:
            return False
        if message["type"] != "GuiUpdateMessage":
            return True
        client = self._server._connected_clients.get(client_id)
        uuid = str(message.get("uuid"))
        for gui in (client.gui if client is not None else None, self._server.gui):
            handle = gui._gui_input_handle_from_uuid.get(uuid) if gui else None
            if handle is not None:
                return _fits(handle, message["updates"]["value"])
        return True  # no such widget: viser ignores it

    def _budgeted(
        self, client_id: int, websocket: Any, budget: MessageBudget
    ) -> Callable[[], Awaitable[Any]]:
        receive = websocket.recv
        closing: list[asyncio.Task[None]] = []

        async def recv() -> Any:
            while True:
                raw = await receive()
                now = time.monotonic()
                if not budget.admit(now):
                    with self._lock:
                        self.dropped += 1
                    if budget.sustained(now) and not closing:
                        with self._lock:
                            self.disconnected += 1
                        close = websocket.close(POLICY_VIOLATION, "message budget exceeded")
                        closing.append(asyncio.create_task(close))
                    # Read no faster than the budget refills: the rest waits in the client's
                    # socket (its sends block), costing this process nothing.
                    await asyncio.sleep(1.0 / budget.rate)
                    continue
                if not self._acceptable(client_id, raw):
                    with self._lock:
                        self.malformed += 1
                    continue
                return raw

        return recv


def _discarding(receive: Callable[[], Awaitable[Any]]) -> Callable[[], Awaitable[Any]]:
    """A ``recv`` that reads and drops everything until the connection is closed (it raises
    ``ConnectionClosed`` then, which ends viser's handler for it)."""

    async def recv() -> Any:
        while True:
            await receive()

    return recv
