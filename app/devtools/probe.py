"""A headless viser client over a websocket, for the benchmark and the server-side tests.

It speaks viser's wire protocol like the browser does (subprotocol ``viser-v<version>``, a
camera message to be registered, msgpack messages out; zstd-compressed msgpack plus raw
binary buffers in), counts the bytes it receives, decodes every message and keeps a model of
the scene and the GUI *as sent*: what the browser would draw. Tests check the geometry on this
model; the benchmark measures traffic and latency with it.
"""

from __future__ import annotations

import contextlib
import dataclasses
import socket
import threading
import time
from collections.abc import Callable
from typing import Any

import msgspec
import numpy as np
import viser
import websockets.sync.client
import zstandard

from poinsot.app.viser_private import encode, wire_message


@dataclasses.dataclass
class Node:
    """A scene node as the browser knows it."""

    type: str
    props: dict[str, Any]
    wxyz: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)
    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    visible: bool = True
    owner: str = ""  # the scope viser stamped on it (a client's id for a client's node)


@dataclasses.dataclass
class Widget:
    type: str
    props: dict[str, Any]
    value: Any = None
    container: str = ""


@dataclasses.dataclass
class Batch:
    """One websocket message (a window of viser messages)."""

    received: float  # time.perf_counter() on arrival
    nbytes: int
    types: list[str]
    names: list[str]


def decode_frame(frame: bytes) -> list[dict[str, Any]]:
    """The messages of one websocket frame, as viser's client decodes them."""
    inner_len = int.from_bytes(frame[0:8], "little")
    compressed_len = int.from_bytes(frame[8:16], "little")
    inner = zstandard.ZstdDecompressor().decompress(
        frame[16 : 16 + compressed_len], max_output_size=inner_len
    )
    payload = msgspec.msgpack.decode(inner)
    buffers: list[memoryview] = []
    offset = 16 + compressed_len
    for length in payload["binaryBufferLengths"]:
        offset += (8 - offset % 8) % 8
        buffers.append(memoryview(frame)[offset : offset + length])
        offset += length

    def resolve(value: Any) -> Any:
        if isinstance(value, dict):
            if "__binary_index" in value and "dtype" in value:
                return np.frombuffer(buffers[value["__binary_index"]], dtype=value["dtype"])
            return {k: resolve(v) for k, v in value.items()}
        if isinstance(value, list):
            return [resolve(v) for v in value]
        return value

    return [resolve(m) for m in payload["messages"]]


class Probe:
    """Connect to a viser server on ``port``; use as a context manager."""

    def __init__(
        self,
        port: int,
        host: str = "127.0.0.1",
        *,
        keep_batches: bool = True,
        origin: str | None = None,
        size: tuple[int, int] = (1280, 720),
        source: str | None = None,
        receive_buffer: int | None = None,
    ):
        """``origin``: the ``Origin`` header a browser would send (a page's
        ``scheme://host:port``); None sends none, as tools that are not browsers do. ``size``:
        the picture's width and height it reports [px] (a phone's is narrow). ``source``: the
        local address it connects from (a loopback address, so that a balancer hashing the
        client's address sees distinct browsers). ``receive_buffer``: its socket's receive
        buffer [bytes], set before it connects (a small one: a stalled client's socket fills
        sooner)."""
        self.uri = f"ws://{host}:{port}"
        self.size = size
        self.nodes: dict[str, Node] = {}
        self.widgets: dict[str, Widget] = {}
        self.batches: list[Batch] = []
        self.keep_batches = keep_batches
        self.bytes_received = 0
        self.messages_received = 0
        #: Scene messages for a variant of a node the page does not show, dropped as viser's
        #: client drops them (:meth:`_apply_node`).
        self.dropped = 0
        self._cond = threading.Condition()
        self._listeners: list[Callable[[dict[str, Any], float], None]] = []
        self._raw_listeners: list[Callable[[bytes], None]] = []
        self._ws = websockets.sync.client.connect(
            self.uri,
            subprotocols=[websockets.Subprotocol(f"viser-v{viser.__version__}")],
            max_size=None,
            compression=None,
            open_timeout=10,
            # No keepalive pings of its own: a probe told to stop reading (a stalled client)
            # would miss the pong and print a traceback; the server's pings watch the line.
            ping_interval=None,
            origin=None if origin is None else websockets.Origin(origin),
            sock=self._socket(host, port, source, receive_buffer),
        )
        self._closed = False
        self._reading = threading.Event()
        self._reading.set()
        self._thread = threading.Thread(target=self._receive, daemon=True, name="viser-probe")
        self._thread.start()
        self._send_first_camera()

    @staticmethod
    def _socket(
        host: str, port: int, source: str | None, receive_buffer: int | None
    ) -> socket.socket | None:
        """The connection's socket when it needs more than websockets makes (None: its own):
        bound to ``source``, its receive buffer set before it connects. A buffer shrunk on an
        open connection shrinks the window under the data in flight: the kernel drops what no
        longer fits and the sender retransmits it with back-off, seconds at a time (a close
        then waits for its timeout)."""
        if source is None and receive_buffer is None:
            return None
        family, kind, proto, _, address = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)[0]
        sock = socket.socket(family, kind, proto)
        try:
            if receive_buffer is not None:
                sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, receive_buffer)
            if source is not None:
                sock.bind((source, 0))
            sock.settimeout(10.0)
            sock.connect(address)
            sock.settimeout(None)
        except OSError:
            sock.close()
            raise
        return sock

    def _send_first_camera(self) -> None:
        """The camera message that makes viser call a client connected. A server that refuses
        the connection may have closed it already: :attr:`close_code` then says why."""
        with contextlib.suppress(websockets.ConnectionClosed):
            self._send_camera()

    @property
    def close_code(self) -> int | None:
        """The code of the server's close frame (1008: refused by policy), None while open."""
        return self._ws.close_code

    @property
    def closed(self) -> bool:
        """True once the connection is closed (by either side)."""
        with self._cond:
            return self._closed

    def _send_camera(self) -> None:
        self.send(
            wire_message(
                "ViewerCameraMessage",
                wxyz=(1.0, 0.0, 0.0, 0.0),
                position=(3.0, -3.0, 2.0),
                fov=0.8,
                near=0.01,
                far=100.0,
                image_height=self.size[1],
                image_width=self.size[0],
                look_at=(0.0, 0.0, 0.0),
                up_direction=(0.0, 0.0, 1.0),
            )
        )

    def __enter__(self) -> Probe:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Close the connection. The receiving thread keeps draining until the close
        handshake completes (stopping it first would leave the server's close frame unread
        behind a backlog, and the handshake would wait for its timeout)."""
        if self._thread.is_alive():
            self._reading.set()
            self._ws.close()
            self._thread.join(5.0)
        self._closed = True

    def stall(self, stalled: bool = True) -> None:
        """Stop (or resume) reading from the socket: a frozen or very slow browser."""
        if stalled:
            self._reading.clear()
        else:
            self._reading.set()

    # -- sending -------------------------------------------------------------------------
    def send(self, message: Any) -> None:
        """One of viser's messages (:func:`~poinsot.app.viser_private.wire_message`)."""
        self._ws.send(encode(message))

    def send_raw(self, frame: bytes | str) -> None:
        """Any frame at all (binary for bytes, text for str): what a hostile script sends."""
        self._ws.send(frame)

    def set_value(self, uuid: str, value: Any) -> None:
        """What the browser sends when the user moves a slider, ticks a box, picks an option,
        or clicks a button (``value=True``)."""
        self.send(wire_message("GuiUpdateMessage", uuid, {"value": value}))

    def drag(self, name: str, phase: str, end: tuple[float, float, float]) -> None:
        """What the browser sends while the left button drags the node ``name`` (a drag on a
        node with a drag binding), the pointer at the world point ``end``."""
        node = self.nodes.get(name)
        self.send(
            wire_message(
                "SceneNodeDragMessage",
                phase=phase,
                name=name,
                instance_index=None,
                start_position=end,
                start_screen_pos=(0.5, 0.5),
                end_position=end,
                end_screen_pos=(0.5, 0.5),
                button="left",
                modifier=None,
                owner="" if node is None else node.owner,
            )
        )

    # -- receiving -----------------------------------------------------------------------
    def wait_frames(self, count: int, timeout: float = 60.0) -> bool:
        """Wait until ``count`` more frames (poses of the body) have arrived."""
        seen = threading.Semaphore(0)
        self.add_listener(
            lambda m, _t: (
                seen.release()
                if m["type"] == "SetOrientationMessage" and m.get("name") == "/space/body"
                else None
            )
        )
        return all(seen.acquire(timeout=timeout) for _ in range(count))

    def add_listener(self, listener: Callable[[dict[str, Any], float], None]) -> None:
        """``listener(message, arrival_time)`` for every decoded message the page applies (not
        those it drops: :meth:`_apply_node`) (receiver thread)."""
        self._listeners.append(listener)

    def add_raw_listener(self, listener: Callable[[bytes], None]) -> None:
        """``listener(frame)`` for every websocket frame as it came, before it is decoded
        (receiver thread)."""
        self._raw_listeners.append(listener)

    def _receive(self) -> None:
        try:
            while True:
                self._reading.wait()
                frame = self._ws.recv()
                now = time.perf_counter()
                assert isinstance(frame, bytes)
                for raw in self._raw_listeners:
                    raw(frame)
                messages = decode_frame(frame)
                with self._cond:
                    self.bytes_received += len(frame)
                    self.messages_received += len(messages)
                    applied = [message for message in messages if self._apply(message)]
                    self.dropped += len(messages) - len(applied)
                    if self.keep_batches:
                        self.batches.append(
                            Batch(
                                now,
                                len(frame),
                                [m["type"] for m in messages],
                                [m.get("name", m.get("uuid", "")) for m in messages],
                            )
                        )
                    self._cond.notify_all()
                for message in applied:
                    self._answer(message)
                    for listener in self._listeners:
                        listener(message, now)
        except websockets.ConnectionClosed:
            pass
        finally:
            with self._cond:
                self._closed = True
                self._cond.notify_all()

    def _answer(self, m: dict[str, Any]) -> None:
        """Answer what the server asks of a page as a page that runs no JavaScript would: its
        localStorage holds nothing (the server then opens its default scene at once)."""
        if m["type"] == "LocalStorageGetItemRequestMessage":
            self.send(
                wire_message(
                    "LocalStorageGetItemResponseMessage",
                    value=None,
                    error=None,
                    request_uuid=str(m["request_uuid"]),
                )
            )

    def _apply(self, m: dict[str, Any]) -> bool:
        """Apply ``m`` to the model; False if the page drops it (:meth:`_apply_node`)."""
        kind: str = m["type"]
        name = m.get("name")
        if isinstance(name, str):
            return self._apply_node(kind, name, m)
        self._apply_widget(kind, m)
        return True

    def _apply_node(self, kind: str, name: str, m: dict[str, Any]) -> bool:
        """As viser's client routes a scene message by its owner (the scope that queued it:
        ``""`` the broadcast one, a client's id its own): a client's own node is shown over the
        broadcast one of its name, and an update or a removal addressed to the variant not
        shown is dropped (False), as a pose sent for another scope's node is."""
        node = self.nodes.get(name)
        owner = str(m.get("owner") or "")
        if node is not None and name and owner != node.owner:
            created = isinstance(m.get("props"), dict)
            if not (created and owner):  # a client's own node replaces the broadcast one
                return False
        if kind == "RemoveSceneNodeMessage":
            self.nodes.pop(name, None)
        elif kind == "SetOrientationMessage" and node is not None:
            w, x, y, z = (float(c) for c in m["wxyz"])
            node.wxyz = (w, x, y, z)
        elif kind == "SetPositionMessage" and node is not None:
            x, y, z = (float(c) for c in m["position"])
            node.position = (x, y, z)
        elif kind == "SetSceneNodeVisibilityMessage" and node is not None:
            node.visible = bool(m["visible"])
        elif kind == "SceneNodeUpdateMessage" and node is not None:
            node.props.update(m["updates"])
        elif isinstance(m.get("props"), dict):
            self.nodes[name] = Node(kind, dict(m["props"]), owner=owner)
        return True

    def _apply_widget(self, kind: str, m: dict[str, Any]) -> None:
        if kind == "GuiRemoveMessage":
            self.widgets.pop(m["uuid"], None)
        elif kind == "GuiUpdateMessage" and m["uuid"] in self.widgets:
            widget = self.widgets[m["uuid"]]
            for key, value in m["updates"].items():
                if key == "value":
                    widget.value = value
                else:
                    widget.props[key] = value
        elif kind.startswith("Gui") and "uuid" in m and isinstance(m.get("props"), dict):
            self.widgets[m["uuid"]] = Widget(
                kind, dict(m["props"]), m.get("value"), m.get("container_uuid", "")
            )

    # -- queries -------------------------------------------------------------------------
    def wait_for(self, predicate: Callable[[Probe], bool], timeout: float = 10.0) -> bool:
        """Wait until ``predicate(self)`` holds (evaluated under the model lock)."""
        deadline = time.monotonic() + timeout
        with self._cond:
            while not predicate(self):
                remaining = deadline - time.monotonic()
                if remaining <= 0 or self._closed:
                    return predicate(self)
                self._cond.wait(remaining)
            return True

    def snapshot(self) -> tuple[dict[str, Node], dict[str, Widget]]:
        """A consistent copy of the model."""
        with self._cond:
            nodes = {k: dataclasses.replace(v, props=dict(v.props)) for k, v in self.nodes.items()}
            widgets = {
                k: dataclasses.replace(v, props=dict(v.props)) for k, v in self.widgets.items()
            }
        return nodes, widgets

    def widget(self, label: str) -> tuple[str, Widget]:
        """The (uuid, widget) whose label is ``label``."""
        with self._cond:
            for uuid, widget in self.widgets.items():
                if widget.props.get("label") == label:
                    return uuid, widget
        raise KeyError(f"no widget labelled {label!r}; have {self.labels()}")

    def labels(self) -> list[str]:
        with self._cond:
            return [str(w.props["label"]) for w in self.widgets.values() if w.props.get("label")]

    def has_widget(self, label: str) -> bool:
        return label in self.labels()
