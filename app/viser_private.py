"""Every use of viser's private names, in one place: the adapter between Poinsot and viser 1.1.x.

viser's public API does not reach the wire: it offers no hook before a message is decoded, none
at the HTTP handshake, and no switch for the share tunnel's message handlers. What Poinsot needs
there is done here, on names that viser may move in any release. Each is pinned by a test
(``tests/app/test_viser_private.py``) that fails naming the viser version when it moves, and
:func:`check` runs the same checks at start.

Written for viser **1.1.x** (:data:`VISER_SERIES`), websockets 13 or later (its public
``serve(process_request=..., create_connection=...)``).

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
  - ``GuiApi._gui_input_handle_from_uuid`` (uuid -> handle): the widget a value is meant for.

*Messages*
  - ``viser._messages``: the client-to-server message classes whose fields
    :data:`ALLOWED` mirrors (names and order checked by :func:`check`), and ``ShareUrlRequest``
    / ``ShareUrlDisconnect``, whose server handlers :func:`disable_share` removes.
"""

from __future__ import annotations

import contextlib
import dataclasses
import threading
from collections.abc import Awaitable, Callable, Iterator
from typing import Annotated, Any, Union

import msgspec
import viser
import websockets.asyncio.server
from viser import _messages
from websockets.asyncio.server import ServerConnection
from websockets.http11 import Request, Response

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
        handle = gui._gui_input_handle_from_uuid.get(uuid) if gui is not None else None
        if handle is not None:
            return handle
    return None


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


# -- messages ----------------------------------------------------------------------------------
# The messages viser 1.1's own client sends, as msgspec structs with the fields of viser's
# dataclasses (same names, same order), typed strictly and bounded: a text no longer than a
# browser's would be, a number finite and of a sane size, no nesting a browser never sends.
_NUM = 1e9
Num = Annotated[float, msgspec.Meta(ge=-_NUM, le=_NUM)]
Count = Annotated[int, msgspec.Meta(ge=0, le=1 << 40)]
Id = Annotated[str, msgspec.Meta(max_length=256)]
Text = Annotated[str, msgspec.Meta(max_length=65_536)]
Scalar = bool | int | float | Text | None
#: A widget value: a scalar, or a flat list (vectors, colours, multi-sliders).
Value = Scalar | Annotated[list[Scalar], msgspec.Meta(max_length=64)]
#: One part of an upload [bytes] (viser's client sends far smaller ones).
MAX_PART_BYTES = 4_000_000
#: A rendered picture (viser's own message limit).
MAX_RENDER_BYTES = 50 * 1024 * 1024
V3 = tuple[Num, Num, Num]
V2 = tuple[Num, Num]


def _message(name: str) -> dict[str, Any]:
    return {"tag_field": "type", "tag": name, "forbid_unknown_fields": True, "frozen": True}


class ViewerCamera(msgspec.Struct, **_message("ViewerCameraMessage")):
    wxyz: tuple[Num, Num, Num, Num]
    position: V3
    fov: Num
    near: Num
    far: Num
    image_height: Num  # a canvas's size (not always a whole number)
    image_width: Num
    look_at: V3
    up_direction: V3


class GuiUpdate(msgspec.Struct, **_message("GuiUpdateMessage")):
    uuid: Id
    updates: Annotated[dict[Id, Value], msgspec.Meta(max_length=16)]


class GuiButtonHold(msgspec.Struct, **_message("GuiButtonHoldMessage")):
    uuid: Id
    frequency: Num


class GuiFormSubmit(msgspec.Struct, **_message("GuiFormSubmitMessage")):
    uuid: Id


class GuiFormDirty(msgspec.Struct, **_message("GuiFormDirtyMessage")):
    uuid: Id


class CommandTrigger(msgspec.Struct, **_message("CommandTriggerMessage")):
    uuid: Id


class FileTransferStartUpload(msgspec.Struct, **_message("FileTransferStartUpload")):
    source_component_uuid: Id
    transfer_uuid: Id
    filename: Text
    mime_type: Id
    part_count: Count
    size_bytes: Count


class FileTransferPart(msgspec.Struct, **_message("FileTransferPart")):
    source_component_uuid: Id | None
    transfer_uuid: Id
    part_index: Count
    content: Annotated[bytes, msgspec.Meta(max_length=MAX_PART_BYTES)]


class FileTransferPartAck(msgspec.Struct, **_message("FileTransferPartAck")):
    source_component_uuid: Id | None
    transfer_uuid: Id
    transferred_bytes: Count
    total_bytes: Count


class ScenePointer(msgspec.Struct, **_message("ScenePointerMessage")):
    event_type: Id
    ray_origin: V3 | None
    ray_direction: V3 | None
    screen_pos: Annotated[list[V2], msgspec.Meta(max_length=16)]
    modifier: Id | None


class SceneNodeClick(msgspec.Struct, **_message("SceneNodeClickMessage")):
    name: Text
    instance_index: Count | None
    ray_origin: V3
    ray_direction: V3
    screen_pos: V2
    modifier: Id | None
    owner: Id = ""


class SceneNodeDrag(msgspec.Struct, **_message("SceneNodeDragMessage")):
    phase: Id
    name: Text
    instance_index: Count | None
    start_position: V3
    start_screen_pos: V2
    end_position: V3
    end_screen_pos: V2
    button: Id
    modifier: Id | None
    owner: Id = ""


class TransformControlsUpdate(msgspec.Struct, **_message("TransformControlsUpdateMessage")):
    name: Text
    wxyz: tuple[Num, Num, Num, Num]
    position: V3
    owner: Id = ""


class TransformControlsDragStart(msgspec.Struct, **_message("TransformControlsDragStartMessage")):
    name: Text
    owner: Id = ""


class TransformControlsDragEnd(msgspec.Struct, **_message("TransformControlsDragEndMessage")):
    name: Text
    owner: Id = ""


class GetRenderResponse(msgspec.Struct, **_message("GetRenderResponseMessage")):
    payload: Annotated[bytes, msgspec.Meta(max_length=MAX_RENDER_BYTES)]
    render_uuid: Id


#: What a client may send: viser's message class name -> its struct. ``ShareUrlRequest`` and
#: ``ShareUrlDisconnect`` are left out on purpose (no student opens a public tunnel).
ALLOWED: dict[str, type[msgspec.Struct]] = {
    struct.__struct_config__.tag: struct  # type: ignore[misc]
    for struct in (
        ViewerCamera,
        GuiUpdate,
        GuiButtonHold,
        GuiFormSubmit,
        GuiFormDirty,
        CommandTrigger,
        FileTransferStartUpload,
        FileTransferPart,
        FileTransferPartAck,
        ScenePointer,
        SceneNodeClick,
        SceneNodeDrag,
        TransformControlsUpdate,
        TransformControlsDragStart,
        TransformControlsDragEnd,
        GetRenderResponse,
    )
}
_DECODER: msgspec.msgpack.Decoder[Any] = msgspec.msgpack.Decoder(
    Union[tuple(ALLOWED.values())]  # noqa: UP007 (a union built from a tuple at run time)
)


class _Envelope(msgspec.Struct):
    type: str


class Refused(ValueError):
    """A message that is not one viser's client sends; ``kind`` names its type as sent."""

    def __init__(self, kind: str, why: str) -> None:
        super().__init__(why)
        self.kind = kind


def client_message(raw: object) -> msgspec.Struct:
    """``raw`` decoded as one of the :data:`ALLOWED` messages, or :class:`Refused` (with the
    type it claimed, and why). Never deeper than the message's own fields: a value nested
    where a number belongs fails at its first level."""
    if not isinstance(raw, bytes):
        raise Refused("text frame", "not a binary frame")
    try:
        message: msgspec.Struct = _DECODER.decode(raw)
    except (msgspec.DecodeError, msgspec.ValidationError, ValueError, RecursionError) as exc:
        raise Refused(message_type(raw), str(exc)[:120]) from None
    return message


def message_type(raw: bytes) -> str:
    """The type a message claims (at most 40 characters), else what it is."""
    try:
        kind = msgspec.msgpack.decode(raw, type=_Envelope).type
    except (msgspec.DecodeError, msgspec.ValidationError, ValueError, RecursionError):
        return "not a message"
    return kind[:40] if kind.isprintable() else repr(kind)[:40]


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
