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

``tests/app/test_viser_private.py`` checks that a window encoded here decodes to what viser's own
producer sends for the same messages.
"""

from __future__ import annotations

import asyncio
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

_local = threading.local()


def _compressor() -> zstandard.ZstdCompressor:
    """A compressor per thread (a ``ZstdCompressor`` is not safe across threads)."""
    zstd = getattr(_local, "zstd", None)
    if zstd is None:
        zstd = _local.zstd = zstandard.ZstdCompressor(level=ZSTD_LEVEL)
    return zstd


def encode_window(messages: Sequence[Any]) -> bytes:
    """The bytes viser's send task would write for the window ``messages`` (viser messages)."""
    binary_buffers: list[memoryview] = []
    serialized = tuple(message.as_serializable_dict(binary_buffers) for message in messages)
    inner = msgspec.msgpack.encode(
        {
            "messages": serialized,
            "timestampSec": time.perf_counter(),
            "binaryBufferLengths": tuple(b.nbytes for b in binary_buffers),
        }
    )
    compressed = _compressor().compress(inner)
    parts: list[bytes | memoryview] = [
        len(inner).to_bytes(8, "little"),
        len(compressed).to_bytes(8, "little"),
        compressed,
    ]
    _infra._append_aligned_buffers(parts, binary_buffers, 16 + len(compressed))
    return b"".join(parts)


class WindowSocket:
    """One client's websocket, for windows encoded once. ``busy`` from a window's handing to
    its writing, and while its transport has paused writing; ``sent`` and ``failed`` count the
    windows."""

    def __init__(self, client: viser.ClientHandle) -> None:
        self.connection, self.loop = connection_of(client)
        self.busy = False
        self.sent = 0
        self.failed = 0

    @property
    def usable(self) -> bool:
        """False if viser's names moved, or the client left before it was reached."""
        return self.connection is not None and isinstance(self.loop, asyncio.AbstractEventLoop)

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
        if not written:
            self.busy = False
            self.failed += 1
            return
        self.sent += 1
        if connection.paused:
            self.loop.create_task(connection.drain()).add_done_callback(self._drained)
        else:
            self.busy = False

    def _drained(self, task: asyncio.Task[None]) -> None:
        self.busy = False
        if not task.cancelled():
            task.exception()  # the client left while it drained: retrieved, nothing to do


def send_each(sockets: Sequence[WindowSocket], data: bytes) -> int:
    """Hand ``data`` to every socket, one call on each loop for its sockets (any thread; never
    waits). Returns how many were handed it (a closed loop takes none)."""
    by_loop: dict[Any, list[WindowSocket]] = {}
    for socket in sockets:
        socket.busy = True
        by_loop.setdefault(socket.loop, []).append(socket)
    handed = 0
    for loop, group in by_loop.items():
        try:
            loop.call_soon_threadsafe(_start, group, data)
            handed += len(group)
        except RuntimeError:  # the server stopped: its loop is closed
            for socket in group:
                socket.busy = False
    return handed


def _start(group: list[WindowSocket], data: bytes) -> None:
    """On the sockets' loop: each written."""
    for socket in group:
        socket.write(data)
