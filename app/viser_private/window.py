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
- the client's connection and loop (:func:`~.transport.connection_of`), on which
  ``ServerConnection.send(bytes)`` (websockets' public coroutine) runs as a task of its own, so
  that a client whose socket does not drain holds only its own task (:class:`WindowSocket` sends it
  nothing more until that task ends).

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
    """One client's websocket, for windows encoded once. ``busy`` while a window handed to it
    is not yet written (its send task not ended); ``sent`` and ``failed`` count the windows."""

    def __init__(self, client: viser.ClientHandle) -> None:
        self.connection, self.loop = connection_of(client)
        self.busy = False
        self.sent = 0
        self.failed = 0

    @property
    def usable(self) -> bool:
        """False if viser's names moved, or the client left before it was reached."""
        return self.connection is not None and isinstance(self.loop, asyncio.AbstractEventLoop)

    def _ended(self, task: asyncio.Task[None]) -> None:
        self.busy = False
        if task.cancelled() or task.exception() is not None:  # the client left meanwhile
            self.failed += 1
        else:
            self.sent += 1


def send_each(sockets: Sequence[WindowSocket], data: bytes) -> int:
    """Hand ``data`` to every socket, each as a task on its loop (any thread; never waits).
    Returns how many were handed it (a closed loop takes none)."""
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
    """On the sockets' loop: one send task each."""
    for socket in group:
        task = socket.loop.create_task(socket.connection.send(data))
        task.add_done_callback(socket._ended)
