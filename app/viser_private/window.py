"""One window of viser messages, encoded once and handed to many clients' sockets (viser 1.1.x):
part of the one adapter to viser's private names (:mod:`poinsot.app.viser_private`, whose
docstring has the inventory).

viser encodes and compresses a window once per client (``viser.infra._infra._message_producer``
on each client's send task). Where many clients are sent the same messages, :func:`encode_window`
makes the bytes that task would make, once, and :func:`send_each` hands them to each client's
websocket connection on its event loop, without waiting for any of them:

- the wire format of ``_message_producer``: ``[8 bytes] msgpack size, [8 bytes] compressed size,
  zstd-compressed msgpack of {"messages", "timestampSec", "binaryBufferLengths"}, then the
  binary buffers, each 8-byte aligned`` (``_infra._append_aligned_buffers``), each message
  serialised by ``Message.as_serializable_dict`` (its numpy arrays put in the binary buffers);
- the client's connection and loop (:func:`~.transport.connection_of`), on which one call
  writes the window to every socket of the loop as ``ServerConnection.send(bytes)`` (websockets'
  coroutine) writes a message: its Sans-I/O protocol frames it (``protocol.send_binary``) and
  ``send_data`` hands the frame to the transport, which never blocks. A task a socket, as
  ``send`` is run, kept the loop of a process of 150 followers behind the cast's frames (see
  ``docs/measurements/classroom.md``). What ``send`` awaits after writing is websockets' flow
  control (``drain``: the transport's buffer past its high-water mark): a socket whose
  transport paused writing stays busy, in a task of its own that drains it, and
  :class:`WindowSocket` hands it nothing more until it has drained, so that a client whose
  socket does not drain holds only that task and one window.

A scene message names its node *and its scope*: viser 1.1 keeps a node's variants per owner (the
broadcast scope's ``""``, a client's id), stamps every scene message with the owner of the API
that queued it (``SceneApi._queue_scene_message``), and its client drops an update addressed to
a variant it does not show (``routeShadowedUpdate``). A client's own nodes are its id's, so a
window for several clients differs in that id alone: :class:`OwnedWindow` serialises the
messages once, with a marker for the owner, and makes each client's copy by splicing its id
into that msgpack. A copy of up to :data:`STORED_LIMIT` bytes is then *stored* in its zstd frame
rather than compressed (:func:`stored_zstd`: a frame of raw blocks, which every zstd decoder,
the client's included, reads as any other): zstd's compressor lets go of the interpreter for
each call, and a thread that lets go of it while the process's other threads are busy waits a
switch interval (5 ms) or more to have it back. The cast's thread, making 75 copies a frame
while a lead's move rebuilds every follower of the process, then made its frames late and
dropped a quarter of them (a follower's pose window is 440 bytes stored, 344 compressed).

``tests/app/test_viser_private.py`` checks that a window encoded here decodes to what viser's own
producer sends for the same messages, each client's copy with its own id.
"""

from __future__ import annotations

import asyncio
import secrets
import threading
import time
from collections.abc import Sequence
from typing import Any

import msgspec.msgpack
import viser
import zstandard
from viser.infra import _infra

from poinsot.app.viser_private.transport import connection_of

#: viser's compression level for a window (``_message_producer``).
ZSTD_LEVEL = 1
#: A client's copy of an owned window whose msgpack is at most this long [bytes] is stored in
#: its zstd frame, not compressed (see the module's docstring).
STORED_LIMIT = 4096
#: zstd's frame magic number, and the largest block it allows [bytes] (more than
#: :data:`STORED_LIMIT`: a stored copy is one block).
ZSTD_MAGIC = b"\x28\xb5\x2f\xfd"
ZSTD_BLOCK = 128 * 1024

_local = threading.local()


def _compressor() -> zstandard.ZstdCompressor:
    """A compressor per thread (a ``ZstdCompressor`` is not safe across threads)."""
    zstd = getattr(_local, "zstd", None)
    if zstd is None:
        zstd = _local.zstd = zstandard.ZstdCompressor(level=ZSTD_LEVEL)
    return zstd


def _inner(messages: Sequence[Any]) -> tuple[bytes, list[memoryview]]:
    """A window's msgpack (the part viser compresses) and its binary buffers."""
    binary_buffers: list[memoryview] = []
    serialized = tuple(message.as_serializable_dict(binary_buffers) for message in messages)
    inner = msgspec.msgpack.encode(
        {
            "messages": serialized,
            "timestampSec": time.perf_counter(),
            "binaryBufferLengths": tuple(b.nbytes for b in binary_buffers),
        }
    )
    return inner, binary_buffers


def stored_zstd(data: bytes) -> bytes:
    """``data`` (at most :data:`ZSTD_BLOCK` bytes) in a zstd frame of one raw (stored) block,
    made without the compressor (RFC 8878: a single-segment frame header with the content
    size, no checksum)."""
    n = len(data)
    if n > ZSTD_BLOCK:
        raise ValueError(f"{n} bytes do not fit one zstd block ({ZSTD_BLOCK})")
    if n < 256:
        header = bytes((0x20, n))  # single segment, a 1-byte content size
    elif n < 256 + 65536:
        header = b"\x60" + (n - 256).to_bytes(2, "little")  # a 2-byte size, less 256
    else:
        header = b"\xa0" + n.to_bytes(4, "little")
    block = (n << 3 | 1).to_bytes(3, "little")  # raw (type 0), the last
    return b"".join((ZSTD_MAGIC, header, block, data))


def _framed(inner: bytes, binary_buffers: Sequence[memoryview], stored: bool = False) -> bytes:
    """The bytes of a window: its msgpack's sizes, the msgpack compressed (``stored``: in a
    frame of raw blocks, :func:`stored_zstd`), its buffers."""
    compressed = stored_zstd(inner) if stored else _compressor().compress(inner)
    parts: list[bytes | memoryview] = [
        len(inner).to_bytes(8, "little"),
        len(compressed).to_bytes(8, "little"),
        compressed,
    ]
    _infra._append_aligned_buffers(parts, list(binary_buffers), 16 + len(compressed))
    return b"".join(parts)


def encode_window(messages: Sequence[Any]) -> bytes:
    """The bytes viser's send task would write for the window ``messages`` (viser messages)."""
    return _framed(*_inner(messages))


def client_owner(client: viser.ClientHandle) -> str:
    """The owner id viser stamps on the scene messages of ``client``'s own nodes."""
    return str(client.client_id)


class OwnedWindow:
    """A window of scene messages for many clients, each sent it for its own nodes: serialised
    once (``messages`` are stamped with a marker owner here), then :meth:`bytes_for` each
    client's owner id (:func:`client_owner`), the bytes viser's send task would write for that
    client had its own scene queued the messages."""

    def __init__(self, messages: Sequence[Any]) -> None:
        marker = f"~{secrets.token_hex(8)}~"  # 18 characters a msgpack fixstr; never an id
        for message in messages:
            message.owner = marker
        self._messages = messages
        inner, self._buffers = _inner(messages)
        self._pieces = inner.split(msgspec.msgpack.encode(marker))
        # Each message holds the marker once; else (not seen) each copy is encoded whole.
        self._spliced = len(self._pieces) == len(messages) + 1

    def bytes_for(self, owner: str) -> bytes:
        if not self._spliced:
            for message in self._messages:
                message.owner = owner
            return encode_window(self._messages)
        inner = msgspec.msgpack.encode(owner).join(self._pieces)
        return _framed(inner, self._buffers, stored=len(inner) <= STORED_LIMIT)


class WindowSocket:
    """One client's websocket, for windows encoded once. ``busy`` from a window's handing to
    its writing, and while its transport has paused writing; ``sent`` and ``failed`` count the
    windows."""

    def __init__(self, client: viser.ClientHandle) -> None:
        self.connection, self.loop = connection_of(client)
        self.busy = False
        self.sent = 0
        self.failed = 0
        self.handed = 0  # windows handed to it (:func:`send_each`), written or not
        self._written = threading.Condition()

    @property
    def usable(self) -> bool:
        """False if viser's names moved, or the client left before it was reached."""
        return self.connection is not None and isinstance(self.loop, asyncio.AbstractEventLoop)

    def wait_written(self, timeout: float) -> bool:
        """Wait (a thread other than its loop's) until every window handed to it has been
        written or has failed, at most ``timeout`` seconds: False if some were not."""
        with self._written:
            return self._written.wait_for(lambda: self.sent + self.failed >= self.handed, timeout)

    def _done(self, written: bool) -> None:
        """A window handed to it was written (or failed): counted, its waiters told."""
        with self._written:
            if written:
                self.sent += 1
            else:
                self.failed += 1
            self._written.notify_all()

    def write(self, data: bytes) -> None:
        """On its loop: ``data`` written as ``ServerConnection.send`` writes a message, then
        busy until its transport drains, if it paused writing (see the module)."""
        connection = self.connection
        written = connection.send_in_progress is None  # else a message sent in fragments
        if written:  # (viser sends none; ``send`` would wait for it, this frame is skipped)
            try:
                connection.protocol.send_binary(data)  # raises unless the connection is open
                connection.send_data()
            except Exception:  # the client left meanwhile
                written = False
        self._done(written)
        if not written:
            self.busy = False
            return
        if connection.paused:
            self.loop.create_task(connection.drain()).add_done_callback(self._drained)
        else:
            self.busy = False

    def _drained(self, task: asyncio.Task[None]) -> None:
        self.busy = False
        if not task.cancelled():
            task.exception()  # the client left while it drained: retrieved, nothing to do


def send_each(sends: Sequence[tuple[WindowSocket, bytes]]) -> int:
    """Hand each socket its window's bytes, one call on each loop for its sockets (any thread;
    never waits). Returns how many were handed theirs (a closed loop takes none)."""
    by_loop: dict[Any, list[tuple[WindowSocket, bytes]]] = {}
    for socket, data in sends:
        socket.busy = True
        socket.handed += 1
        by_loop.setdefault(socket.loop, []).append((socket, data))
    handed = 0
    for loop, group in by_loop.items():
        try:
            loop.call_soon_threadsafe(_start, group)
            handed += len(group)
        except RuntimeError:  # the server stopped: its loop is closed
            for socket, _ in group:
                socket.busy = False
                socket._done(False)
    return handed


def _start(group: list[tuple[WindowSocket, bytes]]) -> None:
    """On the sockets' loop: each written."""
    for socket, data in group:
        socket.write(data)
