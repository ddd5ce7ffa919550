"""Each private viser name that :mod:`poinsot.app.viser_private` relies on, pinned.

When viser moves one of them, the test of that name fails and says which viser it found and
which one the adapter was written for (:class:`~poinsot.app.viser_private.ViserChanged`).
"""

from __future__ import annotations

import asyncio
import collections
import dataclasses
import inspect
import threading
import warnings
from typing import Any

import numpy as np
import pytest
import viser
import websockets.asyncio.server
from conftest import session_of, wait_until
from viser import _messages

from poinsot.app import viser_private
from poinsot.app.live.hardening.guard import WireGuard
from poinsot.app.live.hardening.transfers import handle_id

WRITTEN_FOR = f"written for viser {viser_private.VISER_SERIES}.x, found viser {viser.__version__}"


def test_the_installed_viser_is_the_series_the_adapter_was_written_for():
    assert viser.__version__.startswith(viser_private.VISER_SERIES + "."), WRITTEN_FOR
    viser_private.check()


@pytest.mark.parametrize("name", sorted(viser_private.ALLOWED))
def test_each_allowed_message_mirrors_viser_s_own_fields(name):
    theirs = getattr(_messages, name, None)
    assert theirs is not None and dataclasses.is_dataclass(theirs), f"{name}: {WRITTEN_FOR}"
    fields = [f.name for f in dataclasses.fields(theirs) if f.init]
    assert list(viser_private.ALLOWED[name].__struct_fields__) == fields, WRITTEN_FOR


def test_a_moved_name_is_reported_with_the_version(monkeypatch):
    monkeypatch.setattr(_messages, "CommandTriggerMessage", None)
    with pytest.raises(viser_private.ViserChanged, match=rf"viser {viser.__version__} .* 1\.1"):
        viser_private.check()


def test_viser_builds_its_server_through_websockets_serve():
    """The handshake hook rides on the one ``serve`` call of viser's server thread."""
    source = inspect.getsource(viser.infra._infra.WebsockServer._background_worker)
    assert "websockets.asyncio.server.serve(" in source, WRITTEN_FOR
    assert "process_request=" in source, WRITTEN_FOR
    with pytest.raises(viser_private.ViserChanged, match="websockets.asyncio.server.serve"):
        with viser_private.hooked_server(lambda c, r: None, _never):
            pass  # nothing built: the hook is never called
    assert websockets.asyncio.server.serve.__module__ == "websockets.asyncio.server"


def _never(exc: BaseException):
    raise AssertionError(exc)


def test_the_connection_names_hold_on_a_live_server(poinsot_app, probe):
    server = poinsot_app.server
    infra = viser_private.infra(server)
    assert isinstance(infra, viser.infra.WebsockServer), WRITTEN_FOR
    session = session_of(poinsot_app)
    client_id = session.client.client_id
    connection = viser_private.live_connection(server, client_id)
    assert isinstance(connection, websockets.asyncio.server.ServerConnection), WRITTEN_FOR
    assert "recv" in vars(connection), "the guard's recv wrapper is not on the connection"
    assert set(infra._client_state_from_id) == {client_id}, WRITTEN_FOR
    assert client_id in server._connected_clients, WRITTEN_FOR
    assert not viser_private.render_requested(server, client_id)
    assert isinstance(poinsot_app.guard, WireGuard)


def test_the_gui_names_hold_on_a_live_server(poinsot_app, probe):
    session = session_of(poinsot_app)
    handle = session.panel.widgets.speed
    uuid = handle_id(handle)
    found = viser_private.gui_input_handle(poinsot_app.server, session.client.client_id, uuid)
    assert found is handle, WRITTEN_FOR
    assert viser_private.gui_input_handle(poinsot_app.server, 10**6, "nope") is None


def test_a_render_request_is_seen_while_it_waits(poinsot_app, probe):
    """``get_render`` registers a handler on the client's connection until its answer."""
    session = session_of(poinsot_app)
    client = session.client
    answered = []
    # the probe never answers: it times out
    thread = threading.Thread(target=lambda: answered.append(_render_or_timeout(client)))
    thread.start()
    waiting = lambda: viser_private.render_requested(poinsot_app.server, client.client_id)  # noqa: E731
    assert wait_until(waiting, 10), WRITTEN_FOR
    thread.join(10)
    assert answered == ["timed out"]
    assert not waiting()


def _render_or_timeout(client) -> str:
    try:
        client.get_render(8, 8, timeout=1.0)
    except TimeoutError:
        return "timed out"
    return "rendered"


def test_the_share_handlers_are_where_viser_put_them(make_app):
    app = make_app()
    assert not viser_private.share_enabled(app.server)
    plain = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    try:
        assert viser_private.share_enabled(plain), WRITTEN_FOR
        viser_private.disable_share(plain)
        assert not viser_private.share_enabled(plain)
    finally:
        plain.stop()


# -- scene (poinsot.app.viser_private.scene) ---------------------------------------------------
def test_a_node_s_state_and_its_scene_queue_are_where_viser_put_them(make_app):
    server = make_app().server
    frame = server.scene.add_frame("/pinned", show_axes=False)
    node = viser_private.node_state(frame)
    missing = [name for name in viser_private.NODE_FIELDS if not hasattr(node, name)]
    assert not missing, f"{missing}: {WRITTEN_FOR}"
    assert callable(getattr(node.api, "_queue_scene_message", None)), WRITTEN_FOR
    for name, fields in _SCENE_MESSAGES.items():
        theirs = viser_private.wire_class(name)
        assert [f.name for f in dataclasses.fields(theirs)] == fields, f"{name}: {WRITTEN_FOR}"


#: The fields of the messages the fast setters build (name and value; the scene queue stamps
#: ``owner``).
_SCENE_MESSAGES = {
    "SetOrientationMessage": ["name", "wxyz", "owner"],
    "SetPositionMessage": ["name", "position", "owner"],
    "SceneNodeUpdateMessage": ["name", "updates", "owner"],
}


def test_the_property_hints_patch_replaces_viser_s_per_handle_lookup():
    """viser 1.1 looks the hints up in ``AssignablePropsBase._prop_hints``, once per handle."""
    base = viser._assignable_props_api.AssignablePropsBase
    assert base.__dict__.get("_prop_hints") is viser_private.CACHED_HINTS, WRITTEN_FOR
    source = inspect.getsource(viser._assignable_props_api)
    assert "self._prop_hints" in source, WRITTEN_FOR


# -- transport (poinsot.app.viser_private.transport) -------------------------------------------
def test_a_client_s_queue_and_socket_are_where_viser_put_them(poinsot_app, probe):
    session = session_of(poinsot_app)
    client = session.client
    buffer = viser_private.message_buffer(client)
    assert buffer is not None, WRITTEN_FOR
    assert viser_private.last_queued(buffer) >= 0, WRITTEN_FOR  # the scene was sent
    taken = viser_private.last_taken(buffer, client.client_id)
    assert taken is not None and taken <= viser_private.last_queued(buffer), WRITTEN_FOR
    assert viser_private.pending(buffer) >= 0
    assert viser_private.closed(buffer) is False, WRITTEN_FOR  # set once the client leaves
    with viser_private.quiet_if_closed(buffer):  # viser's scope for benign dead writes
        pass
    connection, loop = viser_private.connection_of(client)
    assert isinstance(connection, websockets.asyncio.server.ServerConnection), WRITTEN_FOR
    assert isinstance(loop, asyncio.AbstractEventLoop) and loop.is_running(), WRITTEN_FOR
    assert connection is viser_private.live_connection(poinsot_app.server, client.client_id)


def test_what_a_thread_queues_to_a_client_can_be_held_back_and_sent_after_all(poinsot_app, probe):
    """A client's scene queues through its connection's ``queue_message``: within
    :func:`held_back` what this thread queues is held (its browser is not sent it, the node's
    handle keeps the value), another thread's goes as ever, and the queue is viser's own
    again after the block; :func:`queue_held` sends what was held. A client's messages
    arrive in the order queued, so the other thread's, queued after, arriving first shows the
    first held."""
    client = session_of(poinsot_app).client
    node = client.scene.add_frame("/held", show_axes=False)
    assert probe.wait_for(lambda p: "/held" in p.snapshot()[0], 30)

    def shown() -> Any:
        return probe.snapshot()[0]["/held"]

    with viser_private.held_back(client) as held:
        assert held is not None, WRITTEN_FOR
        node.position = (1.0, 2.0, 3.0)
        other = threading.Thread(target=lambda: setattr(node, "wxyz", (0.0, 1.0, 0.0, 0.0)))
        other.start()
        other.join()
    assert [type(m).__name__ for m in held] == ["SetPositionMessage"], WRITTEN_FOR
    assert tuple(node.position) == (1.0, 2.0, 3.0)
    assert "queue_message" not in vars(client._websock_connection)
    assert probe.wait_for(lambda p: shown().wxyz == (0.0, 1.0, 0.0, 0.0), 30)
    assert shown().position == (0.0, 0.0, 0.0)
    viser_private.queue_held(client, held)
    assert probe.wait_for(lambda p: shown().position == (1.0, 2.0, 3.0), 30)
    with viser_private.held_back(client) as outer, viser_private.held_back(client) as inner:
        assert outer is not None and inner is None  # one holder at a time: the inner sends


def test_a_departed_client_s_widgets_are_written_quietly_within_the_gui_s_scope(poinsot_app, probe):
    """Within :func:`gui_quiet_if_closed` a write to the widget of a client that has left is
    dropped without viser's warning: the scope is the one viser's queue of that client
    consults (its count of sanctioned writes)."""
    client = session_of(poinsot_app).client
    slider = client.gui.add_slider("pinned", 0.0, 1.0, 0.1, 0.5)
    buffer = viser_private.message_buffer(client)
    probe.close()
    assert wait_until(lambda: viser_private.closed(buffer) and not poinsot_app.sessions(), 30)
    # The departed session's own last writes, in the same scope, may still be under way.
    assert wait_until(lambda: buffer._sanctioned_dead_writes == 0, 30), WRITTEN_FOR
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with viser_private.gui_quiet_if_closed(client.gui):
            assert buffer._sanctioned_dead_writes >= 1, WRITTEN_FOR
            slider.value = 0.25
        assert [w for w in caught if "closed connection" in str(w.message)] == [], WRITTEN_FOR
    assert wait_until(lambda: buffer._sanctioned_dead_writes == 0, 30), WRITTEN_FOR


class _Walked(collections.deque):
    """An event's waiters that record each walk through them (from which thread)."""

    def __init__(self) -> None:
        super().__init__()
        self.walked_from: list[int] = []

    def __iter__(self):
        self.walked_from.append(threading.get_ident())
        return super().__iter__()


def test_a_send_queue_is_woken_on_its_loop_only(poinsot_app, probe):
    """viser sets a send queue's event from the thread that pushes a message, walking the
    sender's waiters while its loop may change them ("deque mutated during iteration" in a
    session being built); here only the loop sets it. Every client's queue and the broadcast
    queue have the event; set from another thread it is untouched, on its loop it wakes."""
    session = session_of(poinsot_app)
    buffers = [
        viser_private.message_buffer(session.client),
        viser_private.infra(poinsot_app.server).get_message_buffer(),
    ]
    for buffer in buffers:
        event, loop = buffer.message_event, buffer.event_loop
        assert isinstance(event, asyncio.Event), WRITTEN_FOR
        assert isinstance(loop, asyncio.AbstractEventLoop) and loop.is_running(), WRITTEN_FOR
        assert isinstance(event, viser_private.SetOnItsLoop) and event.owner is loop
    # The behaviour, on an event of its own: a plain asyncio.Event set from another thread
    # walks its waiters there; the queue's does not, and its own loop's set wakes the waiter.
    loop = asyncio.new_event_loop()
    thread = threading.Thread(target=loop.run_forever, daemon=True)
    thread.start()
    try:
        for kind in (asyncio.Event, viser_private.SetOnItsLoop):
            event = kind()
            if isinstance(event, viser_private.SetOnItsLoop):
                event.owner = loop
            event._waiters = waiters = _Walked()
            waiting = asyncio.run_coroutine_threadsafe(event.wait(), loop)
            assert wait_until(lambda w=waiters: len(w) == 1, 10)
            event.set()  # from this thread, as viser's push does
            foreign = [t for t in waiters.walked_from if t != thread.ident]
            if kind is asyncio.Event:  # what the race comes from
                assert foreign
                loop.call_soon_threadsafe(lambda: None)  # its waiter's wake-up, left unheard
                assert waiting.result(10) is True
                continue
            assert not foreign and not event.is_set() and not waiting.done()
            loop.call_soon_threadsafe(event.set)  # viser's wake-up on the loop
            assert waiting.result(10) is True and event.is_set()
    finally:
        loop.call_soon_threadsafe(loop.stop)
        thread.join(10)
        loop.close()


# -- GUI -----------------------------------------------------------------------------------------
def test_a_widget_s_id_loop_and_uploads_are_where_viser_put_them(poinsot_app, probe):
    session = session_of(poinsot_app)
    gui = session.client.gui
    speed = session.panel.widgets.speed
    assert viser_private.gui_widget(gui, viser_private.handle_id(speed)) is speed, WRITTEN_FOR
    assert viser_private.gui_event_loop(gui) is poinsot_app.server.get_event_loop(), WRITTEN_FOR
    assert isinstance(viser_private.upload_states(gui), dict), WRITTEN_FOR
    connection = session.client._websock_connection
    for name in ("register_handler", "unregister_handler", "queue_message"):
        assert callable(getattr(connection, name, None)), f"{name}: {WRITTEN_FOR}"


def test_a_button_group_reaches_its_page_through_its_gui(poinsot_app, probe):
    """:func:`show_pressed` sends a line of JavaScript through the group's own GUI
    (``handle._impl.gui_api._websock_interface``): a client's group, to that client's page."""
    session = session_of(poinsot_app)
    group = session.panel.widgets.side
    connection = session.client._websock_connection
    assert group._impl.gui_api._websock_interface is connection, WRITTEN_FOR
    sent: list = []
    original = connection.queue_message
    connection.queue_message = lambda message: (sent.append(message), original(message))
    try:
        viser_private.show_pressed(group, "major axis")
    finally:
        del connection.queue_message
    # (the session's frame thread may queue its frames on the same connection meanwhile)
    scripts = [m for m in sent if isinstance(m, _messages.RunJavascriptMessage)]
    assert len(scripts) == 1, WRITTEN_FOR
    assert viser_private.handle_id(group) in sent[0].source and "major axis" in sent[0].source


def test_slider_marks_are_a_sent_property_of_the_handle(make_app):
    """viser 1.1 sends a slider's ``_marks`` prop (``GuiSliderProps._marks``) when it is set."""
    server = make_app().server
    slider = server.gui.add_slider("pinned", 0.0, 1.0, 0.1, 0.5)
    viser_private.set_slider_marks(slider, [(0.25, "a"), (0.75, "b")])
    props = [f.name for f in dataclasses.fields(_messages.GuiSliderProps)]
    assert "_marks" in props, WRITTEN_FOR
    assert [(m.value, m.label) for m in slider._marks] == [(0.25, "a"), (0.75, "b")], WRITTEN_FOR


# -- messages ------------------------------------------------------------------------------------
def test_a_hand_built_message_is_what_the_wire_check_reads():
    """The probe's and the load test's messages decode under the allow-list, field for field."""
    sent = viser_private.wire_message("GuiUpdateMessage", "abc", {"value": 1.5})
    decoded = viser_private.client_message(viser_private.encode(sent))
    assert decoded == viser_private.GuiUpdate(uuid="abc", updates={"value": 1.5}), WRITTEN_FOR
    for name in _HAND_BUILT:
        assert dataclasses.is_dataclass(viser_private.wire_class(name)), f"{name}: {WRITTEN_FOR}"
    with pytest.raises(viser_private.ViserChanged, match=rf"viser {viser.__version__} .* 1\.1"):
        viser_private.wire_class("NoSuchMessage")


_HAND_BUILT = (
    "ViewerCameraMessage",
    "GuiUpdateMessage",
    "SceneNodeDragMessage",
    "LocalStorageGetItemResponseMessage",
    "FileTransferStartUpload",
    "FileTransferPart",
    "FileTransferPartAck",
    "GuiSliderMark",
)


# -- window (poinsot.app.viser_private.window) -------------------------------------------------
def _viser_s_own_window(messages: list) -> bytes:
    """The bytes viser's send task writes for ``messages`` queued at once (its producer run on
    a loop of its own, against a socket that records what it is sent)."""
    from viser.infra import _infra
    from viser.infra._async_message_buffer import AsyncMessageBuffer

    sent: list[bytes] = []

    async def produce() -> None:
        buffer = AsyncMessageBuffer(asyncio.get_running_loop(), persistent_messages=False)
        buffer.atomic_start()
        for message in messages:
            buffer.push(message)
        buffer.atomic_end()

        class Socket:
            async def send(self, data: bytes) -> None:
                sent.append(data)
                buffer.set_done()

        buffer.flush()
        await _infra._message_producer(Socket(), buffer, client_id=0)  # type: ignore[arg-type]

    # On a thread of its own: this one may hold the event loop of a real-browser test that ran
    # before, in this worker.
    thread = threading.Thread(target=asyncio.run, args=(produce(),))
    thread.start()
    thread.join(30)
    assert not thread.is_alive() and len(sent) == 1, WRITTEN_FOR
    return sent[0]


def _header(frame: bytes) -> tuple[int, int]:
    """A window's msgpack size and compressed size."""
    return int.from_bytes(frame[:8], "little"), int.from_bytes(frame[8:16], "little")


def _inner(frame: bytes) -> dict:
    """A window's decompressed msgpack, viser's timestamp aside."""
    import msgspec
    import zstandard

    size, compressed = _header(frame)
    payload = zstandard.ZstdDecompressor().decompress(
        frame[16 : 16 + compressed], max_output_size=size
    )
    decoded = msgspec.msgpack.decode(payload)
    decoded.pop("timestampSec")
    return decoded


def test_a_window_encoded_once_is_the_window_viser_sends():
    import numpy as np

    from poinsot.app.devtools.probe import decode_frame

    points = np.arange(18, dtype=np.float32).reshape(3, 2, 3)
    messages = [
        viser_private.orientation_message("/space/body", (1.0, 0.0, 0.0, 0.0)),
        viser_private.position_message("/space/tip", (0.1, 0.2, 0.3)),
        viser_private.props_message("/space/omega", {"points": points}),
    ]
    ours, theirs = viser_private.encode_window(messages), _viser_s_own_window(messages)

    # The same msgpack size (the compressed size may differ by a byte: the timestamps differ).
    assert _header(ours)[0] == _header(theirs)[0], WRITTEN_FOR
    # The same messages, the same binary layout (only viser's timestamp differs).
    assert _inner(ours) == _inner(theirs), WRITTEN_FOR
    decoded = decode_frame(ours)
    assert [m["type"] for m in decoded] == [
        "SetOrientationMessage",
        "SetPositionMessage",
        "SceneNodeUpdateMessage",
    ]
    np.testing.assert_array_equal(decoded[2]["updates"]["points"], points.ravel())
    assert ours[-points.nbytes :] == theirs[-points.nbytes :] == points.tobytes()


def test_a_window_for_many_clients_is_each_one_s_window_of_its_own_nodes():
    """Each client's copy of an owned window is the window viser sends that client had its own
    scene queued the messages: stamped with its id (its browser applies a scene message to the
    node of the scope that queued it only), the rest the same for all."""
    import numpy as np

    from poinsot.app.devtools.probe import decode_frame

    points = np.arange(18, dtype=np.float32).reshape(3, 2, 3)

    def messages(owner: str | None) -> list:
        made = [
            viser_private.orientation_message("/space/body", (0.5, 0.5, 0.5, 0.5)),
            viser_private.position_message("/space/tip", (0.1, 0.2, 0.3)),
            viser_private.props_message("/space/omega", {"points": points}),
        ]
        for message in made if owner is not None else ():
            message.owner = owner  # as a client's SceneApi stamps its messages
        return made

    window = viser_private.OwnedWindow(messages(None))
    for owner in ("7", "1234", "18446744073709551615"):
        ours, theirs = window.bytes_for(owner), _viser_s_own_window(messages(owner))
        assert _inner(ours) == _inner(theirs), WRITTEN_FOR
        decoded = decode_frame(ours)
        assert {m["owner"] for m in decoded} == {owner}
        np.testing.assert_array_equal(decoded[2]["updates"]["points"], points.ravel())
        assert ours[-points.nbytes :] == points.tobytes()


@pytest.mark.parametrize("size", [0, 1, 255, 256, 65791, 65792, 128 * 1024])
def test_a_stored_zstd_frame_is_read_by_zstd_s_own_decoder(size):
    """A frame of one raw block made without the compressor (the followers' small copies) is a
    zstd frame like any other: zstd's decoder reads it back, at every size of its header's
    content size up to a whole block, and reports the content size it declares; more than a
    block is refused."""
    import zstandard

    data = bytes(np.random.default_rng(size).integers(0, 256, size, dtype=np.uint8))
    frame = viser_private.window.stored_zstd(data)
    assert zstandard.ZstdDecompressor().decompress(frame) == data
    assert zstandard.frame_content_size(frame) == size
    assert len(frame) - size <= 4 + 5 + 3  # magic, frame header, block header: nothing else
    with pytest.raises(ValueError, match="one zstd block"):
        viser_private.window.stored_zstd(bytes(128 * 1024 + 1))


def test_a_follower_s_small_copy_is_stored_and_a_large_one_compressed():
    """A client's copy of a small owned window (a pose: the cast's frames) is stored, not
    compressed (no call that lets go of the interpreter); a large one is compressed as viser
    compresses it; both decode to the same messages for that client."""
    from poinsot.app.devtools.probe import decode_frame

    def window(n: int) -> viser_private.OwnedWindow:
        points = np.zeros((n, 2, 3), dtype=np.float32)
        return viser_private.OwnedWindow(
            [
                viser_private.orientation_message("/space/body", (0.5, 0.5, 0.5, 0.5)),
                viser_private.props_message("/space/omega", {"colors": points.tolist()}),
            ]
        )

    small, large = window(1).bytes_for("42"), window(400).bytes_for("42")
    for frame, stored in ((small, True), (large, False)):
        size, compressed = _header(frame)
        body = frame[16 : 16 + compressed]
        assert (size <= viser_private.window.STORED_LIMIT) is stored
        # A stored frame's first block is raw (type 0) and holds the whole msgpack.
        first_block = int.from_bytes(body[6 if size < 256 else 7 :][:3], "little")
        assert ((first_block >> 1) & 3 == 0 and compressed > size) is stored
        assert {m["owner"] for m in decode_frame(frame)} == {"42"}
        assert _inner(frame)["messages"][0]["name"] == "/space/body"


def test_the_cast_of_a_property_is_viser_s_own_for_every_hint_of_its_nodes_and_widgets():
    """The patched cast (its array hints made once) gives what viser's own gives, for each
    property hint of viser's scene nodes and widgets and values of every kind a caller sets."""
    import typing

    import numpy as np

    from poinsot.app.viser_private import scene

    base = viser._assignable_props_api.AssignablePropsBase
    assert base.__dict__.get("_cast_value_recursive") is scene.cast_value, WRITTEN_FOR
    props_classes = [
        c
        for c in vars(viser._messages).values()
        if isinstance(c, type) and c.__name__.endswith("Props")
    ]
    hints = {(name, hint) for c in props_classes for name, hint in typing.get_type_hints(c).items()}
    assert len(props_classes) > 20 and len(hints) > 100, WRITTEN_FOR
    values = [
        (0.5, 1.0, 2.0),
        (1, 2, 3),
        (255, 128, 0),
        [0.1, 0.2],
        np.arange(6, dtype=np.float64).reshape(2, 3),
        np.arange(6, dtype=np.float32),
        ((0.0, 1.0, 2.0), (3.0, 4.0, 5.0)),
        (np.zeros(3), np.ones(3)),
        "label",
        3,
        None,
        True,
    ]
    handle = object.__new__(base)
    for name, hint in sorted(hints, key=repr):
        for value in values:
            try:
                theirs = scene.VISER_CAST(handle, hint, value, name)
            except Exception as exc:  # noqa: BLE001 - the same error is asked of ours
                with pytest.raises(type(exc)):
                    scene.cast_value(handle, hint, value, name)
                continue
            ours = scene.cast_value(handle, hint, value, name)
            assert type(ours) is type(theirs), (name, hint, value)
            if isinstance(theirs, np.ndarray):
                assert ours.dtype == theirs.dtype and np.array_equal(ours, theirs, equal_nan=True)
            elif isinstance(theirs, tuple):
                assert repr(ours) == repr(theirs), (name, hint, value)
            else:
                assert ours is theirs or ours == theirs, (name, hint, value)
