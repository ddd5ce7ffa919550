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

*Handshake* (:mod:`poinsot.app.viser_private.handshake`)
  - ``websockets.asyncio.server.serve`` as viser's infra calls it: a request check of ours
    before viser's page server, and HTTP/1.0 read as 1.1 (:func:`hooked_server`).

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
  - ``GuiApi._websock_interface``'s queue: writes to a departed client's widgets dropped
    without viser's warning (:func:`gui_quiet_if_closed`: the sliders a session mirrored,
    written on viser's loop after its browser left).
  - ``GuiApi._event_loop``: the loop a client's GUI runs its callbacks on, for a caller that
    holds the GUI and not the server (:func:`gui_event_loop`; it is the loop of the public
    :meth:`viser.ViserServer.get_event_loop`).
  - ``GuiSliderHandle._marks`` (the ``GuiSliderProps._marks`` prop, tuples of
    ``viser._messages.GuiSliderMark``): viser 1.1 takes marks only in ``add_slider``; setting
    the private prop sends them (:func:`set_slider_marks`).
  - ``ClientHandle._websock_connection``'s ``register_handler``/``queue_message`` with a class
    of ``viser._messages``: a handler of a client's messages after viser's own, and a message
    to that client (:func:`on_client_message`, :func:`send_to_client`).
  - ``handle._impl.gui_api._websock_interface`` with ``viser._messages.GuiUpdateMessage``: a
    dropdown's options sent to the browser in groups (Mantine's ``Select`` takes
    ``{group, items: [{value, label}]}``; viser 1.1 types its options as plain strings), the
    handle keeping its flat options for the server's checks (:func:`set_dropdown_groups`).

*Scene* (:mod:`poinsot.app.viser_private.scene`)
  - ``SceneNodeHandle._impl`` (``name``, ``wxyz``, ``position``, ``props``, ``removed``,
    ``api``) and ``SceneApi._queue_scene_message`` with ``SetOrientationMessage``,
    ``SetPositionMessage`` and ``SceneNodeUpdateMessage``: the frame path's setters without
    viser's comparison.
  - ``viser._assignable_props_api.AssignablePropsBase._prop_hints`` and
    ``_cast_value_recursive`` (with ``colors_to_uint8``): replaced, class-wide, by a property
    cached per properties class and by the same cast with its array hints made once
    (:func:`~poinsot.app.viser_private.scene.cache_property_hints`).

*Transport* (:mod:`poinsot.app.viser_private.transport`)
  - ``ClientHandle._websock_connection.get_message_buffer()`` with its ``message_counter``,
    ``generator_cursors``, ``message_from_id``, ``done`` and ``sanctioned_dead_writes()``: how
    far a client's send queue was taken (the pacer), whether its client has left, and viser's
    scope for benign writes to a departed client's queue (a frame begun just before it left);
    its ``message_event`` and ``event_loop``, and the broadcast queue's
    (``ViserServer._websock_server.get_message_buffer()``): the event is made one that only
    its loop sets (viser also sets it from the pushing thread, a race with the sender's wait).
  - ``ClientHandle._viser_server._websock_server`` with ``_live_connections`` and
    ``_background_event_loop``: a client's socket and its loop (the pacer's unacknowledged
    bytes, the backlog watch).
  - ``ClientHandle._websock_connection.queue_message`` (through which a client's scene API
    queues), shadowed on the connection within a block: what one thread queues is held back
    (:func:`held_back`, :func:`queue_held`: a follower's new body, sent through the
    followers' shared windows instead).

*Window* (:mod:`poinsot.app.viser_private.window`)
  - ``viser.infra._infra._message_producer``'s wire format (its ``_append_aligned_buffers``,
    ``Message.as_serializable_dict``, zstd level 1): a window of messages encoded once and
    written to many clients' connections (the followers' shared frames), each client's copy
    with the owner id viser stamps on its own scene's messages (``SceneApi._owner_id``, the
    ``owner`` field its client routes a node's updates by; a small copy stored in its zstd
    frame, raw blocks, rather than compressed), in one call on their
    loop, each as websockets' ``ServerConnection.send`` writes a message, without its task: the
    connection's Sans-I/O ``protocol.send_binary`` and its ``send_data``, ``paused`` (flow
    control), ``drain`` and ``send_in_progress`` (:func:`encode_window`, :class:`OwnedWindow`,
    :class:`WindowSocket`, :func:`send_each`).

*Messages*
  - ``viser._messages``: the client-to-server message classes whose fields
    :data:`ALLOWED` mirrors (names and order checked by :func:`check`), and ``ShareUrlRequest``
    / ``ShareUrlDisconnect``, whose server handlers :func:`disable_share` removes.
  - ``viser._messages.<name>`` built by hand, and ``Message.as_serializable_dict`` encoded as
    viser's client encodes it (:func:`wire_message`, :func:`wire_class`, :func:`encode`): what
    the headless probe and the load test send as a browser would.

*Page* (:mod:`poinsot.app.viser_private.page`)
  - A client's websocket handshake (its ``Origin``), JavaScript run in its page, and its
    localStorage: a page's own address, the clipboard, a narrow page's bottom sheet; the
    page's accessibility (names, keyboard, contrast, pressed buttons) inside viser's client.
"""

from __future__ import annotations

import asyncio
import contextlib
import dataclasses
from collections.abc import Awaitable, Callable, Iterable
from typing import Any

import msgspec
import viser
from viser import _messages
from websockets.asyncio.server import ServerConnection

from poinsot.app.viser_private.handshake import Http10Connection, RequestCheck, hooked_server
from poinsot.app.viser_private.messages import (
    ALLOWED,
    GetRenderResponse,
    GuiUpdate,
    Refused,
    client_message,
    message_type,
)
from poinsot.app.viser_private.page import (
    LOCAL_STORAGE_PREFIX,
    RAIL_TITLE,
    copy_to_clipboard,
    fold_bottom_sheet,
    handshake_origin,
    make_accessible,
    page_address,
    scroll_to_button,
    show_pressed,
)
from poinsot.app.viser_private.scene import (
    CACHED_HINTS,
    NODE_FIELDS,
    cache_property_hints,
    node_state,
    orientation_message,
    position_message,
    props_message,
    queue_orientation,
    queue_position,
    queue_props,
)
from poinsot.app.viser_private.transport import (
    BUFFER_FIELDS,
    SetOnItsLoop,
    broadcasts_woken_on_their_loop,
    closed,
    connection_of,
    gui_message_buffer,
    held_back,
    last_queued,
    last_taken,
    message_buffer,
    pending,
    queue_held,
    quiet_if_closed,
    senders_woken_on_their_loop,
    set_on_its_loop_only,
)
from poinsot.app.viser_private.version import VISER_SERIES, ViserChanged
from poinsot.app.viser_private.window import (
    OwnedWindow,
    WindowSocket,
    client_owner,
    encode_window,
    send_each,
)

__all__ = [
    "ALLOWED",
    "BUFFER_FIELDS",
    "CACHED_HINTS",
    "NODE_FIELDS",
    "SetOnItsLoop",
    "broadcasts_woken_on_their_loop",
    "cache_property_hints",
    "closed",
    "connection_of",
    "last_queued",
    "last_taken",
    "message_buffer",
    "node_state",
    "pending",
    "queue_orientation",
    "queue_position",
    "queue_props",
    "quiet_if_closed",
    "senders_woken_on_their_loop",
    "set_on_its_loop_only",
    "held_back",
    "queue_held",
    "connection_count",
    "infra",
    "live_connection_ids",
    "store_value",
    "stored_value",
    "upload_states",
    "wire_message",
    "LOCAL_STORAGE_PREFIX",
    "VISER_SERIES",
    "GetRenderResponse",
    "GuiUpdate",
    "Http10Connection",
    "Refused",
    "RequestCheck",
    "ViserChanged",
    "client_message",
    "copy_to_clipboard",
    "fold_bottom_sheet",
    "scroll_to_button",
    "make_accessible",
    "RAIL_TITLE",
    "show_pressed",
    "handshake_origin",
    "hooked_server",
    "message_type",
    "page_address",
    "OwnedWindow",
    "WindowSocket",
    "client_owner",
    "encode_window",
    "send_each",
    "orientation_message",
    "position_message",
    "props_message",
]


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


def live_connection_ids(server: viser.ViserServer) -> list[int]:
    """The client ids viser holds a live websocket connection for."""
    return list(infra(server)._live_connections)


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


def stored_value(handle: Any) -> Any:
    """The value viser holds for a GUI widget (what the browser sent last, before or without
    the widget's callbacks: ``handle.value`` may be a callback's view of it)."""
    return handle._impl.value


def store_value(handle: Any, value: Any) -> None:
    """Store ``value`` as viser does when a browser's update arrives, before the callbacks run
    (nothing is sent, no callback runs)."""
    handle._impl.value = value


def upload_states(gui: viser.GuiApi) -> dict[str, Any]:
    """The GUI's transfers in progress (transfer id -> viser's state of it, a dict with
    ``client_id``, ``total_bytes``, ``transferred_bytes`` and ``parts``)."""
    states: dict[str, Any] = gui._current_file_upload_states
    return states


def gui_quiet_if_closed(gui: viser.GuiApi) -> contextlib.AbstractContextManager[None]:
    """Writes to the GUI's widgets within this block, if its client has left meanwhile, are
    dropped without viser's warning (:func:`quiet_if_closed` on its client's queue)."""
    return quiet_if_closed(gui_message_buffer(gui))


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


def set_dropdown_groups(
    dropdown: viser.GuiDropdownHandle[str],
    groups: Iterable[tuple[str, Iterable[tuple[str, str]]]],
) -> None:
    """Show ``dropdown``'s options in the browser as labelled groups: ``(group label, [(value,
    shown label), ...])``. The browser's Select renders a heading per group and sends the
    value; the handle keeps its flat ``options`` (the values, checked on arrival), which must
    hold every value given here."""
    data: list[dict[str, Any]] = [
        {"group": name, "items": [{"value": v, "label": label} for v, label in items]}
        for name, items in groups
    ]
    values = {item["value"] for group in data for item in group["items"]}
    if not values <= set(dropdown.options):
        raise ValueError(
            f"values not among the dropdown's options: {values - set(dropdown.options)}"
        )
    impl = dropdown._impl
    impl.gui_api._websock_interface.queue_message(
        _messages.GuiUpdateMessage(impl.uuid, {"options": data})
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
