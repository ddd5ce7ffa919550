"""What the server checks on a websocket before viser acts on it: the handshake (its ``Host`` and
``Origin``), how much a client sends (:class:`~poinsot.app.live.hardening.budget.MessageBudget`),
and that each message is one viser's own client sends, with fields of the right types and sizes.

Handshakes (:class:`HandshakeGate`) are checked at the HTTP upgrade, before viser sees the
connection: a refused one gets ``403`` and leaves nothing behind (no client id, no state in
viser). ``Host`` must be one value naming an address this server listens on (any port: a proxy
in front forwards the page's own ``Host``), ``localhost``, or the host of an ``--allow-origin``
entry: a page on a hostile site whose name was re-pointed at this machine (DNS rebinding)
sends its own name and is refused. ``Origin``: a page may drive the server only if it was
served by it (the origin's host:port is the ``Host``), or if its origin is listed. Tools that are
not browsers (the probe, the load test, curl) send no ``Origin``: they are let in, as is
standard, since no web page can open a websocket without one.

Messages (:class:`WireGuard`): each connection's ``recv`` is wrapped, the earliest point at
which a message of this client is seen. Beyond the client's budget, messages are read no faster
than it refills (a flood waits in its own socket, costing the server nothing), then the client is
disconnected. A message that is not one of :data:`~poinsot.app.viser_private.ALLOWED` (an unknown
type, a share request, wrong field types, deep nesting, invalid UTF-8, a render nobody asked
for) closes that client's connection with one log line; a GUI value that does not fit its
widget is only dropped (the widget keeps its value). Log lines are rate-limited
(:class:`QuietLog`), never tracebacks. viser's private names live in
:mod:`poinsot.app.viser_private`.
"""

from __future__ import annotations

import asyncio
import errno
import http
import ipaddress
import logging
import socket
import threading
import time
from collections.abc import Awaitable, Callable, Iterable
from typing import Any
from urllib.parse import urlsplit

import viser
from websockets.asyncio.server import ServerConnection
from websockets.datastructures import Headers
from websockets.http11 import Request, Response

from poinsot.app import viser_private
from poinsot.app.live.hardening.budget import MessageBudget

#: Messages a second one client may send, sustained, and in one burst (a browser sends a few
#: dozen a second at most: camera moves while orbiting, a dragged slider, upload parts).
MESSAGE_RATE = 200.0
MESSAGE_BURST = 400.0
#: A client over its budget this long (without a second's pause) is disconnected [s].
EXCESS_SECONDS = 3.0
#: Websocket close code for a policy violation (RFC 6455, 7.4.1).
POLICY_VIOLATION = 1008
#: How long a client closed for a policy violation has to answer the close before its
#: connection is dropped [s]. websockets waits 10 s by default; a flooding client's answer
#: waits behind its flood, and its session would stay that long.
POLICY_CLOSE_SECONDS = 1.0


async def _close_for_policy(websocket: Any, reason: str) -> None:
    """Close ``websocket`` for a policy violation, waiting at most
    :data:`POLICY_CLOSE_SECONDS` for the client's answer (a websockets connection)."""
    websocket.close_timeout = POLICY_CLOSE_SECONDS
    await websocket.close(POLICY_VIOLATION, reason)


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


ANY_HOST = ("0.0.0.0", "::", "")
log = logging.getLogger(__name__)


class QuietLog:
    """One warning line per event, at most one a ``interval`` seconds; the lines held back are
    counted in the next one ("+N more"). Thread-safe."""

    def __init__(self, interval: float = 1.0, logger: logging.Logger = log) -> None:
        self.interval = interval
        self._logger = logger
        self._lock = threading.Lock()
        self._last = -float("inf")
        self._held = 0
        #: Every event, written or held back.
        self.events = 0

    def __call__(self, line: str) -> None:
        now = time.monotonic()
        with self._lock:
            self.events += 1
            if now - self._last < self.interval:
                self._held += 1
                return
            held, self._held, self._last = self._held, 0, now
        more = f" (+{held} more since the last line)" if held else ""
        self._logger.warning("poinsot: %s%s", line, more)


def _host_part(host: str) -> str:
    """The name or address of a ``Host`` value, without its port (``[::1]:80`` -> ``::1``)."""
    host = host.strip().lower()
    if host.startswith("["):
        return host[1 : host.find("]")] if "]" in host else host
    return host.rsplit(":", 1)[0] if host.count(":") == 1 else host


def _local_address(address: str) -> bool:
    """Is ``address`` (an IP) one of this machine's? (A bind to it succeeds only then.)"""
    ip = ipaddress.ip_address(address)
    if ip.is_loopback:
        return True
    family = socket.AF_INET6 if ip.version == 6 else socket.AF_INET
    with socket.socket(family, socket.SOCK_STREAM) as sock:
        try:
            sock.bind((address, 0))
        except OSError as exc:
            return exc.errno != errno.EADDRNOTAVAIL
    return True


def host_allowed(host: str | None, listen: str, allowed_origins: Iterable[str] = ()) -> bool:
    """May a handshake with this ``Host`` reach the server listening on ``listen``? Only if
    it names an address the server listens on (every address of this machine for 0.0.0.0),
    ``localhost`` (when loopback is served), ``listen`` itself, or the host of an allowed
    origin. A name of someone else's (DNS rebinding) is refused."""
    if host is None or not host.strip():
        return False
    name = _host_part(host)
    listen = listen.strip().lower()
    if name in {urlsplit(normalise_origin(o)).hostname for o in allowed_origins} or name == listen:
        return True
    serves_loopback = listen in ANY_HOST or listen == "localhost" or _is_loopback(listen)
    if name == "localhost":
        return serves_loopback
    try:
        ip = ipaddress.ip_address(name)
    except ValueError:
        return False
    if listen in ANY_HOST:
        return _local_address(str(ip))
    return ip.is_loopback and serves_loopback


def _is_loopback(address: str) -> bool:
    try:
        return ipaddress.ip_address(address).is_loopback
    except ValueError:
        return False


class HandshakeGate:
    """The check of every HTTP request at the server's port, before viser: a websocket upgrade
    with a bad ``Host`` or ``Origin`` (one of each, no more) is answered ``403`` and never
    becomes a connection; a request viser's page server cannot take is answered ``400``."""

    def __init__(self, listen: str, allowed_origins: Iterable[str] = ()) -> None:
        self.listen = listen
        self.allowed_origins = tuple(normalise_origin(o) for o in allowed_origins)
        self.say = QuietLog()
        self._lock = threading.Lock()
        #: Websocket handshakes refused; requests that viser's page server failed on.
        self.refused = 0
        self.failed = 0

    def why_refused(self, request: Request) -> str | None:
        """The reason to refuse this upgrade request, or None to let it through."""
        hosts = request.headers.get_all("Host")
        origins = request.headers.get_all("Origin")
        if len(hosts) != 1:
            return f"{len(hosts)} Host headers"
        if len(origins) > 1:
            return f"{len(origins)} Origin headers"
        if not host_allowed(hosts[0], self.listen, self.allowed_origins):
            return (
                f"Host {hosts[0][:60]!r} is not an address of this server "
                "(behind a proxy or another name: --allow-origin http://THAT-HOST:PORT)"
            )
        origin = origins[0] if origins else None
        if origin is not None and not origin_allowed(origin, hosts[0], self.allowed_origins):
            return f"Origin {origin[:60]!r} is not this server's page nor --allow-origin"
        return None

    def check(self, connection: ServerConnection, request: Request) -> Response | None:
        if "websocket" not in {v.lower() for v in request.headers.get_all("Upgrade")}:
            return None  # a page request: viser's page server answers it
        why = self.why_refused(request)
        if why is None:
            return None
        with self._lock:
            self.refused += 1
        self.say(f"refused a websocket from {_peer(connection)}: {why}")
        return connection.respond(http.HTTPStatus.FORBIDDEN, f"Refused: {why}.\n")

    def error(self, exc: BaseException) -> Response:
        """The answer to a request viser's page server raised on (one log line)."""
        with self._lock:
            self.failed += 1
        self.say(f"answered 400 to a request the page server could not take ({exc!r:.80})")
        text = b"Bad request.\n"
        headers = Headers(
            [("Content-Type", "text/plain; charset=utf-8"), ("Content-Length", str(len(text)))]
        )
        return Response(400, "Bad Request", headers, text)


def _peer(connection: Any) -> str:
    """``host:port`` of the other end of a websockets connection, or "?"."""
    try:
        address = connection.remote_address
        return f"{address[0]}:{address[1]}"
    except (AttributeError, IndexError, TypeError, OSError):
        return "?"


#: Pages of our own served before viser's page server: a request's path -> a response, or None.
Pages = Callable[[str], Response | None]


def guarded_viser(
    host: str,
    port: int,
    *,
    verbose: bool = False,
    allow_origins: Iterable[str] = (),
    pages: Pages | None = None,
) -> tuple[viser.ViserServer, HandshakeGate]:
    """A viser server whose handshakes pass :class:`HandshakeGate` and whose share tunnel is
    off (its handlers removed; the wire refuses the messages too). Its broadcast queue is woken
    on viser's loop only, as each client's is once connected (the server's connect handler):
    :func:`poinsot.app.viser_private.transport.set_on_its_loop_only`. ``pages`` answers the
    page requests it knows (the guide at ``/docs/``) before viser's page server."""
    gate = HandshakeGate(host, allow_origins)

    def check(connection: ServerConnection, request: Request) -> Response | None:
        refusal = gate.check(connection, request)
        if refusal is not None or pages is None:
            return refusal
        if "websocket" in {v.lower() for v in request.headers.get_all("Upgrade")}:
            return None
        return pages(request.path)

    with viser_private.hooked_server(check, gate.error):
        server = viser.ViserServer(host=host, port=port, verbose=verbose)
    viser_private.disable_share(server)
    viser_private.broadcasts_woken_on_their_loop(server)
    return server, gate


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
    """Message budget and allow-list on every websocket of ``server`` (see the module)."""

    def __init__(
        self,
        server: viser.ViserServer,
        gate: HandshakeGate,
        *,
        rate: float = MESSAGE_RATE,
        burst: float = MESSAGE_BURST,
        excess_seconds: float = EXCESS_SECONDS,
    ) -> None:
        self.gate = gate
        self._limits = (rate, burst, excess_seconds)
        self._server = server
        self._lock = threading.Lock()
        self._budgets: dict[int, MessageBudget] = {}
        #: Clients closed: for flooding; for a message viser's client never sends.
        self.disconnected = 0
        self.closed_for_message = 0
        #: Messages dropped: beyond a budget; GUI values that do not fit their widget.
        self.dropped = 0
        self.malformed = 0
        self._agents: dict[int, str] = {}  # each connected browser's User-Agent header
        infra = viser_private.infra(server)
        infra.on_client_connect(self._accept)
        infra.on_client_disconnect(self._forget)

    @property
    def refused(self) -> int:
        """Websocket handshakes refused (:class:`HandshakeGate`)."""
        return self.gate.refused

    def user_agent(self, client_id: int) -> str:
        """The ``User-Agent`` a connected browser gave in its handshake ("" if none)."""
        with self._lock:
            return self._agents.get(client_id, "")

    def budget(self, client_id: int) -> MessageBudget | None:
        """The budget of a connected client (tests)."""
        with self._lock:
            return self._budgets.get(client_id)

    async def _accept(self, connection: Any) -> None:
        websocket = viser_private.live_connection(self._server, connection.client_id)
        if websocket is None:
            return
        budget = MessageBudget(*self._limits)
        with self._lock:
            self._budgets[connection.client_id] = budget
            request = websocket.request
            self._agents[connection.client_id] = (
                str(request.headers.get("User-Agent") or "") if request is not None else ""
            )
        viser_private.wrap_recv(
            websocket, lambda receive: self._budgeted(connection.client_id, websocket, budget)
        )

    def _forget(self, connection: Any) -> None:
        with self._lock:
            self._budgets.pop(connection.client_id, None)
            self._agents.pop(connection.client_id, None)

    def _verdict(self, client_id: int, raw: Any) -> str | None:
        """None to pass the message on, "drop" to drop it, else why the client is closed."""
        try:
            message = viser_private.client_message(raw)
        except viser_private.Refused as refused:
            return f"a {refused.kind!r} message ({refused})"
        if isinstance(message, viser_private.GetRenderResponse):
            if not viser_private.render_requested(self._server, client_id):
                return "a render nobody asked for"
        if isinstance(message, viser_private.GuiUpdate):
            # A browser sends only values; viser would set any attribute named (callbacks).
            if set(message.updates) != {"value"}:
                return "drop"
            handle = viser_private.gui_input_handle(self._server, client_id, message.uuid)
            if handle is not None and not _fits(handle, message.updates["value"]):
                return "drop"
        return None

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
                        close = _close_for_policy(websocket, "message budget exceeded")
                        closing.append(asyncio.create_task(close))
                    # Read no faster than the budget refills: the rest waits in the client's
                    # socket (its sends block), costing this process nothing.
                    await asyncio.sleep(1.0 / budget.rate)
                    continue
                verdict = self._verdict(client_id, raw)
                if verdict is None:
                    return raw
                if verdict == "drop":
                    with self._lock:
                        self.malformed += 1
                    continue
                with self._lock:
                    self.closed_for_message += 1
                self.gate.say(f"closed {_peer(websocket)}: it sent {verdict}")
                # The next read raises ConnectionClosed, which ends viser's handler cleanly.
                await _close_for_policy(websocket, "message not allowed")

        return recv
