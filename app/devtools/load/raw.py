"""A websocket client on a bare socket, for what a well-behaved client library will not do.

It speaks just enough of RFC 6455 to misbehave on purpose: stop halfway through the HTTP
upgrade, drop the TCP connection without a closing handshake (a FIN, or a RST), or write
thousands of pre-built messages a second. A reader thread drains what the server sends (so
the client is never a stalled one by accident), counts it without decoding it, and answers the
server's pings. The socket is non-blocking; every wait has a deadline.
"""

from __future__ import annotations

import base64
import math
import os
import select
import socket
import struct
import threading
import time

import viser

from poinsot.app.viser_private import encode, wire_message

_OP_CLOSE, _OP_PING, _OP_PONG, _OP_BINARY = 0x8, 0x9, 0xA, 0x2


def upgrade_request(port: int, host: str = "127.0.0.1") -> bytes:
    """The HTTP request that opens a viser websocket."""
    key = base64.b64encode(os.urandom(16)).decode()
    return (
        f"GET / HTTP/1.1\r\nHost: {host}:{port}\r\nUpgrade: websocket\r\n"
        f"Connection: Upgrade\r\nSec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\n"
        f"Sec-WebSocket-Protocol: viser-v{viser.__version__}\r\n\r\n"
    ).encode()


def client_frame(payload: bytes, opcode: int = _OP_BINARY) -> bytes:
    """One masked, final client frame."""
    n = len(payload)
    if n < 126:
        header = struct.pack("!BB", 0x80 | opcode, 0x80 | n)
    elif n < 1 << 16:
        header = struct.pack("!BBH", 0x80 | opcode, 0x80 | 126, n)
    else:
        header = struct.pack("!BBQ", 0x80 | opcode, 0x80 | 127, n)
    mask = os.urandom(4)
    key = (mask * (n // 4 + 1))[:n]
    masked = (int.from_bytes(payload, "big") ^ int.from_bytes(key, "big")).to_bytes(n, "big")
    return header + mask + masked


def camera_message(step: int = 0) -> bytes:
    """A viewer-camera message as the browser sends it while the user orbits (msgpack)."""
    angle = 0.01 * step
    message = wire_message(
        "ViewerCameraMessage",
        wxyz=(1.0, 0.0, 0.0, 0.0),
        position=(3.0 * math.cos(angle), -3.0 + 3.0 * math.sin(angle), 2.0),
        fov=0.8,
        near=0.01,
        far=100.0,
        image_height=720,
        image_width=1280,
        look_at=(0.0, 0.0, 0.0),
        up_direction=(0.0, 0.0, 1.0),
    )
    return encode(message)


class RawClient:
    """A TCP connection to the server on ``port``; nothing is sent until asked."""

    def __init__(self, port: int, host: str = "127.0.0.1", timeout: float = 10.0):
        self.port, self.host, self.timeout = port, host, timeout
        self.sock = socket.create_connection((host, port), timeout=timeout)
        self.bytes_received = 0
        self.messages_received = 0
        self.closed_by_server = False
        self._buffer = bytearray()
        self._send_lock = threading.Lock()
        self._stop = threading.Event()
        self._reader: threading.Thread | None = None

    # -- the opening handshake ---------------------------------------------------------------
    def send_half_upgrade(self) -> None:
        """The first half of the upgrade request, and nothing more."""
        request = upgrade_request(self.port, self.host)
        self.sock.sendall(request[: len(request) // 2])

    def open(self) -> None:
        """Complete the upgrade (101 Switching Protocols), then read in a thread."""
        self.sock.sendall(upgrade_request(self.port, self.host))
        response = bytearray()
        while b"\r\n\r\n" not in response:
            chunk = self.sock.recv(4096)
            if not chunk:
                raise ConnectionError("the server closed the connection during the upgrade")
            response += chunk
        head, _, rest = bytes(response).partition(b"\r\n\r\n")
        if not head.startswith(b"HTTP/1.1 101"):
            raise ConnectionError(f"upgrade refused: {head.splitlines()[0]!r}")
        self._buffer += rest
        self.sock.setblocking(False)
        self._reader = threading.Thread(target=self._read, name="load-raw-reader", daemon=True)
        self._reader.start()

    # -- sending -------------------------------------------------------------------------------
    def send(self, data: bytes, deadline: float) -> int:
        """Write ``data`` (whole frames) before ``deadline`` (monotonic); the bytes written.
        Fewer than ``len(data)`` only when the server stopped reading until the deadline, or
        closed the connection (``closed_by_server``); the connection is then unusable (a frame
        was cut) and the caller stops sending."""
        view = memoryview(data)
        sent = 0
        with self._send_lock:
            while sent < len(view):
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    break
                _, writable, _ = select.select([], [self.sock], [], remaining)
                if not writable:
                    break
                try:
                    sent += self.sock.send(view[sent:])
                except BlockingIOError:
                    continue
                except (ConnectionResetError, BrokenPipeError):  # the server cut us off
                    self.closed_by_server = True
                    break
        return sent

    # -- receiving -----------------------------------------------------------------------------
    def _read(self) -> None:
        try:
            while not self._stop.is_set():
                readable, _, _ = select.select([self.sock], [], [], 0.1)
                if not readable:
                    continue
                try:
                    chunk = self.sock.recv(1 << 16)
                except BlockingIOError:
                    continue
                if not chunk:
                    self.closed_by_server = True
                    return
                self.bytes_received += len(chunk)
                self._buffer += chunk
                if self._parse():
                    self.closed_by_server = True
                    return
        except OSError:
            self.closed_by_server = not self._stop.is_set()

    def _parse(self) -> bool:
        """Consume whole frames from the buffer; True once the server sent a close frame."""
        buf = self._buffer
        while len(buf) >= 2:
            opcode, length, offset = buf[0] & 0x0F, buf[1] & 0x7F, 2
            if length == 126:
                if len(buf) < 4:
                    return False
                length, offset = struct.unpack_from("!H", buf, 2)[0], 4
            elif length == 127:
                if len(buf) < 10:
                    return False
                length, offset = struct.unpack_from("!Q", buf, 2)[0], 10
            if len(buf) < offset + length:
                return False
            payload = bytes(buf[offset : offset + length])
            del buf[: offset + length]
            if opcode == _OP_CLOSE:
                return True
            if opcode == _OP_PING:
                self.send(client_frame(payload, _OP_PONG), time.monotonic() + self.timeout)
            elif opcode != _OP_PONG:
                self.messages_received += 1
        return False

    # -- ending --------------------------------------------------------------------------------
    def drop(self, reset: bool = False) -> None:
        """Close the TCP connection without a websocket close: a FIN, or a RST if ``reset``
        (a browser killed, a laptop lid shut, a cable pulled)."""
        self._stop.set()
        if self._reader is not None:
            self._reader.join(self.timeout)
        if reset:
            self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
        self.sock.close()
