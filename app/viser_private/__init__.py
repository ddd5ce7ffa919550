"""Every use of viser's private names, in one place: the adapter between Poinsot and viser 1.1.x.

viser's public API does not reach the wire: it offers no hook before a message is decoded, none
at the HTTP handshake, and no switch for the share tunnel's message handlers. What Poinsot needs
there is done here, on names that viser may move in any release. Each is pinned by a test
(``tests/app/test_viser_private.py``) that fails naming the viser version when it moves, and
:func:`check` runs the same checks at start.

Written for viser **1.1.x** (:data:`VISER_SERIES`), websockets 13 or later (its public
``serve(process_request=..., create_connection=...)``). It imports no other Poinsot folder
(an import-linter contract), so that ``app.scene``, ``app.live``, ``app.load`` and
``app.exports`` may all import it; ``tests/test_layout.py`` refuses a private viser name
anywhere else in ``app/``.

Inventory (section, private name, what it is used for):

*Handshake*
  - ``viser.infra._infra`` calls ``websockets.asyncio.server.serve`` (looked up on the module at
    call time, inside ``WebsockServer.start``, before ``ViserServer()`` returns) with its own
    ``process_request`` (the page server): :func:`hooked_server` wraps it for the duration of
    one construction, adding a request check of ours before viser's and a connection class
    that reads an HTTP/1.0 request line as HTTP/1.1.

*Connections*
  - ``ViserServer._websock_server`` (the infra ``WebsockServer``): its public
    ``on_client_connect``/``on_client_disconnect``/``unregister_handler``.
  - ``WebsockServer._live_connections`` (client id -> websockets ``ServerConnection``): the
    connection whose ``recv`` viser's consumer awaits (an instance attribute can wrap it).
  - ``WebsockServer._client_state_from_id``: the connections viser holds state for (the load
    test counts leaked ones).
  - ``ViserServer._connected_clients`` (client id -> ``ClientHandle``) and
    ``ClientHandle._websock_connection._incoming_handlers`` (a render response is expected
    only while a ``get_render`` handler is registered).

*GUI*
  - ``GuiApi._gui_input_handle_from_uuid`` (uuid -> handle): the widget a value is meant for
    (:func:`gui_input_handle`, :func:`gui_widget`).
  - ``handle._impl.uuid``: a widget's wire id (:func:`handle_id`).
  - ``GuiApi._current_file_upload_states`` (transfer id -> state dict): the uploads in
    progress, which the upload cap drops early (:func:`upload_states`).
  - ``GuiApi._event_loop``: the loop a client's GUI runs its callbacks on, for a caller that
    holds the GUI and not the server (:func:`gui_event_loop`; it is the loop of the public
    :meth:`viser.ViserServer.get_event_loop`).
  - ``GuiSliderHandle._marks`` (the ``GuiSliderProps._marks`` prop, tuples of
    ``viser._messages.GuiSliderMark``): viser 1.1 takes marks only in ``add_slider``; setting
    the private prop sends them (:func:`set_slider_marks`).
  - ``ClientHandle._websock_connection``'s ``register_handler``/``queue_message`` with a class
    of ``viser._messages``: a handler of a client's messages after viser's own, and a message
    to that client (:func:`on_client_message`, :func:`send_to_client`).

*Scene* (:mod:`poinsot.app.viser_private.scene`)
  - ``SceneNodeHandle._impl`` (``name``, ``wxyz``, ``position``, ``props``, ``removed``,
    ``api``) and ``SceneApi._queue_scene_message`` with ``SetOrientationMessage``,
    ``SetPositionMessage`` and ``SceneNodeUpdateMessage``: the frame path's setters without
    viser's comparison.
  - ``viser._assignable_props_api.AssignablePropsBase._prop_hints``: replaced, class-wide, by a
    property cached per properties class
    (:func:`~poinsot.app.viser_private.scene.cache_property_hints`).

*Transport* (:mod:`poinsot.app.viser_private.transport`)
  - ``ClientHandle._websock_connection.get_message_buffer()`` with its ``message_counter``,
    ``generator_cursors`` and ``message_from_id``: how far a client's send queue was taken (the
    pacer).
  - ``ClientHandle._viser_server._websock_server`` with ``_live_connections`` and
    ``_background_event_loop``: a client's socket and its loop (the pacer's unacknowledged
    bytes, the backlog watch).

*Messages*
  - ``viser._messages``: the client-to-server message classes whose fields
    :data:`ALLOWED` mirrors (names and order checked by :func:`check`), and ``ShareUrlRequest``
    / ``ShareUrlDisconnect``, whose server handlers :func:`disable_share` removes.
  - ``viser._messages.<name>`` built by hand, and ``Message.as_serializable_dict`` encoded as
    viser's client encodes it (:func:`wire_message`, :func:`wire_class`, :func:`encode`): what
    the headless probe and the load test send as a browser would.

*Page* (a page's own address, and the clipboard)
  - ``ViserServer._websock_server._live_connections[client_id].request``: the websocket
    handshake of a client (:func:`handshake_origin`). viser keeps the connection to itself; its
    ``ClientHandle`` exposes no header. Used to tell a web page (it always sends ``Origin``) from
    a tool (the probe, the load test), which runs no JavaScript.
  - ``ClientHandle._websock_connection``: ``queue_message``, ``register_handler`` and
    ``unregister_handler`` of one client's connection, with the message classes
    ``viser._messages.RunJavascriptMessage``, ``LocalStorageGetItemRequestMessage`` and
    ``LocalStorageGetItemResponseMessage`` (:func:`page_address`, :func:`copy_to_clipboard`).
    viser's client connects its websocket to the page's address *without* the query
    (``getDefaultServerFromUrl`` drops everything after ``?``) and sends nothing of the page's
    address on connect, so a link's query never reaches the server by a public way. A line of
    JavaScript run in the page writes ``window.location.href`` to the page's ``localStorage``
    under a key of this connection alone, and viser's own localStorage request reads it back;
    :meth:`viser.LocalStorageHandle.get_item` does the same read but blocks a thread, where this
    awaits on the event loop (a page that never answers holds no thread).
  - ``"viser-user:"``: the prefix viser's client puts before the keys of its localStorage API
    (``LOCAL_STORAGE_PREFIX`` in the client's ``MessageHandler.tsx``).
  - The bottom sheet of a narrow page (the client's ``ControlPanel/BottomPanel.tsx``): a
    ``position: fixed; bottom: 0`` Mantine ``Paper`` whose bar (``cursor: pointer``,
    ``height: 3.5em``) toggles it; it is open when it mounts (its state is the page's own,
    ``useDisclosure(true)``: no message and no GUI handle folds it). :func:`fold_bottom_sheet`
    taps that bar once, from the page, as a finger would.
"""

from __future__ import annotations

import asyncio
import contextlib
import dataclasses
import json
import threading
import uuid
from collections.abc import Awaitable, Callable, Iterable, Iterator
from typing import Any

import msgspec
import viser
import websockets.asyncio.server
from viser import _messages
from websockets.asyncio.server import ServerConnection
from websockets.http11 import Request, Response

from poinsot.app.viser_private.messages import (
    ALLOWED,
    GetRenderResponse,
    GuiUpdate,
    Refused,
    client_message,
    message_type,
)

__all__ = ["ALLOWED", "GetRenderResponse", "GuiUpdate", "Refused", "client_message", "message_type"]

#: The viser release series this module was written for.
VISER_SERIES = "1.1"


class ViserChanged(RuntimeError):
    """A private name or shape this module relies on is not what viser 1.1.x had."""

    def __init__(self, what: str) -> None:
        super().__init__(
            f"viser {viser.__version__} is not the viser {VISER_SERIES}.x that "
            f"poinsot.app.viser_private was written for: {what}"
        )


# -- handshake ---------------------------------------------------------------------------------
RequestCheck = Callable[[ServerConnection, Request], Response | None]
_SERVE_LOCK = threading.Lock()
#: The longest request line read before it is handed on as it is [bytes].
_REQUEST_LINE_MAX = 8192


class Http10Connection(ServerConnection):
    """A websockets server connection that reads an ``HTTP/1.0`` request line as ``HTTP/1.1``
    (websockets parses only 1.1 and would drop the request unanswered), so that an HTTP/1.0
    GET gets viser's page (a 1.1 response with its length, which HTTP/1.0 clients read)."""

    _head: bytes | None = b""

    def data_received(self, data: bytes) -> None:
        if self._head is not None:
            self._head += data
            if b"\n" not in self._head and len(self._head) < _REQUEST_LINE_MAX:
                return
            data, self._head = _as_http11(self._head), None
        super().data_received(data)


def _as_http11(head: bytes) -> bytes:
    line, newline, rest = head.partition(b"\n")
    crlf = line.endswith(b"\r")
    bare = line[:-1] if crlf else line
    if bare.endswith(b" HTTP/1.0"):
        line = bare[: -len(b"1.0")] + b"1.1" + (b"\r" if crlf else b"")
    return line + newline + rest


@contextlib.contextmanager
def hooked_server(
    check: RequestCheck, on_error: Callable[[BaseException], Response]
) -> Iterator[None]:
    """Within this block, the one ``viser.ViserServer(...)`` built runs ``check`` on every HTTP
    request before viser's page server (a response refuses it, None lets it through) and
    answers with ``on_error(exc)`` when viser's page server raises. Raises :class:`ViserChanged`
    if the server was built without going through ``websockets.asyncio.server.serve``."""
    original = websockets.asyncio.server.serve
    calls: list[int] = []

    def serve(handler: Any, *args: Any, **kwargs: Any) -> Any:
        page = kwargs.get("process_request")

        def process_request(connection: ServerConnection, request: Request) -> Response | None:
            refusal = check(connection, request)
            if refusal is not None or page is None:
                return refusal
            try:
                response: Response | None = page(connection, request)
            except Exception as exc:  # a request viser's page server cannot take
                return on_error(exc)
            return response

        kwargs["process_request"] = process_request
        kwargs["create_connection"] = Http10Connection
        calls.append(1)
        return original(handler, *args, **kwargs)

    with _SERVE_LOCK:
        websockets.asyncio.server.serve = serve  # type: ignore[misc,assignment]
        try:
            yield
        finally:
            websockets.asyncio.server.serve = original  # type: ignore[misc]
    if not calls:
        raise ViserChanged("ViserServer() no longer calls websockets.asyncio.server.serve")


# -- connections -------------------------------------------------------------------------------
def infra(server: viser.ViserServer) -> Any:
    """viser's infra-level websocket server of ``server``."""
    return server._websock_server


def live_connection(server: viser.ViserServer, client_id: int) -> ServerConnection | None:
    """The websockets connection viser reads ``client_id``'s messages from."""
    found: ServerConnection | None = infra(server)._live_connections.get(client_id)
    return found


def connection_count(server: viser.ViserServer) -> int:
    """The websocket connections viser holds state for (live ones, or leaked ones)."""
    return len(infra(server)._client_state_from_id)


def wrap_recv(
    connection: ServerConnection,
    wrapper: Callable[[Callable[[], Awaitable[Any]]], Callable[[], Awaitable[Any]]],
) -> None:
    """Make viser's consumer read ``connection`` through ``wrapper(connection.recv)``."""
    connection.recv = wrapper(connection.recv)  # type: ignore[method-assign,assignment]


def render_requested(server: viser.ViserServer, client_id: int) -> bool:
    """Is a ``get_render`` of this client waiting for its answer?"""
    client = server._connected_clients.get(client_id)
    if client is None:
        return False
    handlers = client._websock_connection._incoming_handlers
    return bool(handlers.get(_messages.GetRenderResponseMessage))


# -- GUI ---------------------------------------------------------------------------------------
def gui_input_handle(server: viser.ViserServer, client_id: int, uuid: str) -> Any:
    """The input widget ``uuid`` of the client's own GUI or the shared one, or None."""
    client = server._connected_clients.get(client_id)
    for gui in (client.gui if client is not None else None, server.gui):
        handle = gui_widget(gui, uuid) if gui is not None else None
        if handle is not None:
            return handle
    return None


def gui_widget(gui: viser.GuiApi, uuid: str) -> Any:
    """The input widget ``uuid`` of ``gui`` (a client's own, or the shared one), or None."""
    return gui._gui_input_handle_from_uuid.get(uuid)


def handle_id(handle: Any) -> str:
    """The wire id of a GUI handle (viser 1.1 keeps it in ``handle._impl.uuid``)."""
    return str(handle._impl.uuid)


def upload_states(gui: viser.GuiApi) -> dict[str, Any]:
    """The GUI's transfers in progress (transfer id -> viser's state of it, a dict with
    ``client_id``, ``total_bytes``, ``transferred_bytes`` and ``parts``)."""
    states: dict[str, Any] = gui._current_file_upload_states
    return states


def gui_event_loop(gui: viser.GuiApi) -> asyncio.AbstractEventLoop:
    """The event loop viser runs ``gui``'s callbacks on (the server's
    :meth:`viser.ViserServer.get_event_loop`, for a GUI whose server is out of reach)."""
    loop: asyncio.AbstractEventLoop = gui._event_loop
    return loop


def set_slider_marks(
    slider: viser.GuiSliderHandle[Any], marks: Iterable[tuple[float, str]]
) -> None:
    """Move a slider's labelled marks. viser 1.1 takes marks only as an argument of
    ``add_slider``; a handle's ``marks`` attribute is not sent, the ``_marks`` property is."""
    slider._marks = tuple(
        _messages.GuiSliderMark(value=float(v), label=label) for v, label in marks
    )


# -- messages ----------------------------------------------------------------------------------
def wire_class(name: str) -> type:
    """viser's message class ``name`` (``viser._messages.<name>``)."""
    found = getattr(_messages, name, None)
    if not isinstance(found, type):
        raise ViserChanged(f"no message class {name} in viser._messages")
    return found


def wire_message(name: str, /, *args: Any, **fields: Any) -> Any:
    """A message of viser's class ``name``, as viser's client or server would build it."""
    return wire_class(name)(*args, **fields)


def encode(message: Any) -> bytes:
    """``message`` (:func:`wire_message`) as a websocket frame's payload, as the browser sends
    it (msgpack of viser's serializable dict)."""
    return msgspec.msgpack.encode(message.as_serializable_dict())


def on_client_message(client: viser.ClientHandle, name: str, handler: Callable[..., None]) -> None:
    """Run ``handler(client_id, message)`` on viser's event loop for each message ``name`` from
    ``client``, after viser's own handlers (``ClientHandle._websock_connection``)."""
    client._websock_connection.register_handler(wire_class(name), handler)


def send_to_client(client: viser.ClientHandle, name: str, /, **fields: Any) -> None:
    """Queue viser's message ``name`` for ``client``."""
    client._websock_connection.queue_message(wire_message(name, **fields))


# -- share -------------------------------------------------------------------------------------
SHARE_MESSAGES = (_messages.ShareUrlRequest, _messages.ShareUrlDisconnect)


def disable_share(server: viser.ViserServer) -> None:
    """Remove viser's handlers that open and close the public share tunnel: a message asking
    for it then does nothing, even if it got past the wire."""
    for message in SHARE_MESSAGES:
        with contextlib.suppress(AssertionError, KeyError):
            infra(server).unregister_handler(message)


def share_enabled(server: viser.ViserServer) -> bool:
    """Would a share request reach a handler?"""
    handlers = infra(server)._incoming_handlers
    return any(handlers.get(message) for message in SHARE_MESSAGES)


# -- page ------------------------------------------------------------------------------------
#: The client's prefix of the keys its localStorage API reads and writes.
LOCAL_STORAGE_PREFIX = "viser-user:"


def handshake_origin(server: viser.ViserServer, client_id: int) -> str | None:
    """The ``Origin`` header of the client's websocket handshake (None: not a web page, or
    the connection is gone)."""
    connection: Any = server._websock_server._live_connections.get(client_id)
    request = getattr(connection, "request", None)
    if request is None:
        return None
    origin = request.headers.get("Origin")
    return str(origin) if origin is not None else None


def _run_javascript(client: viser.ClientHandle, source: str) -> None:
    client._websock_connection.queue_message(_messages.RunJavascriptMessage(source=source))


async def page_address(client: viser.ClientHandle, timeout: float) -> str | None:
    """The address of the page of ``client`` (``window.location.href``, its query included),
    or None if the page does not answer within ``timeout`` seconds or has no localStorage. Run
    on viser's event loop, outside its connect handler (the answer arrives only once viser
    reads the connection, after the handler)."""
    key = f"poinsot-page-{uuid.uuid4().hex}"
    request_uuid = uuid.uuid4().hex
    answer: asyncio.Future[str | None] = asyncio.get_running_loop().create_future()

    def got(client_id: int, message: _messages.LocalStorageGetItemResponseMessage) -> None:
        del client_id
        if message.request_uuid == request_uuid and not answer.done():
            answer.set_result(message.value if message.error is None else None)

    connection = client._websock_connection
    connection.register_handler(_messages.LocalStorageGetItemResponseMessage, got)
    try:
        name = json.dumps(LOCAL_STORAGE_PREFIX + key)
        _run_javascript(
            client, f"try {{ localStorage.setItem({name}, window.location.href); }} catch (e) {{}}"
        )
        connection.queue_message(
            _messages.LocalStorageGetItemRequestMessage(key=key, request_uuid=request_uuid)
        )
        client.flush()
        return await asyncio.wait_for(answer, timeout)
    except TimeoutError:
        return None
    finally:
        connection.unregister_handler(_messages.LocalStorageGetItemResponseMessage, got)
        client.local_storage.remove_item(key)


_COPY_JS = """
const text = %s;
const fallback = () => {
  const area = document.createElement("textarea");
  area.value = text;
  area.style.position = "fixed";
  area.style.opacity = "0";
  document.body.appendChild(area);
  area.select();
  try { document.execCommand("copy"); } catch (e) {}
  area.remove();
};
if (navigator.clipboard && window.isSecureContext) {
  navigator.clipboard.writeText(text).catch(fallback);
} else {
  fallback();
}
"""


_FOLD_SHEET_JS = """
(() => {
  if (window.poinsotSheetFolded) return;
  const until = Date.now() + %d;
  const fold = () => {
    const sheet = [...document.querySelectorAll(".mantine-Paper-root")].find(
      (e) => e.style.position === "fixed" && e.style.bottom === "0px");
    const bar = sheet && [...sheet.querySelectorAll("div")].find(
      (e) => e.style.cursor === "pointer" && e.style.height === "3.5em");
    if (bar && sheet.getBoundingClientRect().height > 1.5 * bar.getBoundingClientRect().height) {
      window.poinsotSheetFolded = true;
      bar.click();
    } else if (Date.now() < until) {
      setTimeout(fold, 100);
    }
  };
  fold();
})();
"""


def fold_bottom_sheet(client: viser.ClientHandle, wait_ms: int = 10000) -> None:
    """Fold the page's bottom sheet (a narrow page's) once, as one tap on its bar does, as soon
    as it is there and open (looked for during ``wait_ms``; a wide page has none). Its bar then
    opens and closes it with one tap each, as ever."""
    _run_javascript(client, _FOLD_SHEET_JS % int(wait_ms))
    client.flush()


def copy_to_clipboard(client: viser.ClientHandle, text: str) -> None:
    """Ask the page of ``client`` to put ``text`` on the clipboard (the browser may refuse:
    the caller also shows the text)."""
    _run_javascript(client, _COPY_JS % json.dumps(text))
    client.flush()


# -- checks --------------------------------------------------------------------------------------
def check() -> None:
    """Raise :class:`ViserChanged` if a private name or message shape used here has moved."""
    if not viser.__version__.startswith(VISER_SERIES + "."):
        raise ViserChanged(f"version {viser.__version__}")
    for name, struct in ALLOWED.items():
        original = getattr(_messages, name, None)
        if original is None or not dataclasses.is_dataclass(original):
            raise ViserChanged(f"no message class {name} in viser._messages")
        theirs = [f.name for f in dataclasses.fields(original) if f.init]
        if list(struct.__struct_fields__) != theirs:
            raise ViserChanged(f"{name} has fields {theirs}, not {struct.__struct_fields__}")
    for message in SHARE_MESSAGES:
        if message.__name__ in ALLOWED:
            raise ViserChanged(f"{message.__name__} is allowed")
