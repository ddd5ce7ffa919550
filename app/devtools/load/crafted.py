"""What a hostile student's script sends, and what it gets back: the inputs of the hostile phase.

Each function sends one kind of crafted input to a server on loopback and returns the outcome
as a short word (``"closed 1008"``, ``"403"``, ``"200"``, ...), which the phase counts. Messages
go over a real websocket (the ``websockets`` client); handshakes and HTTP/1.0 requests over a
bare socket, since no client library sends two ``Host`` headers.
"""

from __future__ import annotations

import math
import socket
import time
from collections import Counter
from collections.abc import Callable

import msgspec
import viser
import websockets
import websockets.sync.client

from poinsot.app.devtools.load.raw import camera_message, upgrade_request

_pack = msgspec.msgpack.encode


def _camera(**fields: object) -> bytes:
    message = msgspec.msgpack.decode(camera_message())
    message.update(fields)
    return _pack(message)


#: Messages viser's client never sends; each must close its sender's connection (1008).
MESSAGES: dict[str, bytes | str] = {
    "share request": _pack({"type": "ShareUrlRequest"}),
    "share disconnect": _pack({"type": "ShareUrlDisconnect"}),
    "unknown type": _pack({"type": "NoSuchMessage", "x": 1}),
    "no type": _pack({"uuid": "x", "updates": {"value": 1}}),
    "a server's message type": _pack({"type": "RunJavascriptMessage", "source": "alert(1)"}),
    "text where the camera wants numbers": _camera(wxyz="abcd"),
    "NaN in the camera": _camera(position=[math.nan, 0.0, 0.0]),
    "an unknown camera field": _camera(evil=True),
    "an unsolicited render": _pack(
        {"type": "GetRenderResponseMessage", "payload": b"\0" * 64, "render_uuid": "r"}
    ),
    "100k-deep nesting": b"\x91" * 100_000 + b"\xc0",
    "100k-deep nesting in a value": b"\x83"
    + b"".join(_pack(s) for s in ("type", "GuiUpdateMessage", "uuid", "u", "updates"))
    + b"\x81"
    + _pack("value")
    + b"\x91" * 100_000
    + b"\xc0",
    "invalid UTF-8 (a1 ff)": b"\xa1\xff",
    "invalid UTF-8 in the type": b"\x81\xa4type\xa1\xff",
    "not msgpack (c1)": b"\xc1",
    "truncated msgpack": camera_message()[:-5],
    "a text frame": '{"type": "ViewerCameraMessage"}',
    "a 1 MB string as a GUI value": _pack(
        {"type": "GuiUpdateMessage", "uuid": "u", "updates": {"value": "x" * 1_000_000}}
    ),
    "an upload part of 5 MB": _pack(
        {
            "type": "FileTransferPart",
            "source_component_uuid": "u",
            "transfer_uuid": "t",
            "part_index": 0,
            "content": b"\0" * 5_000_000,
        }
    ),
}


def send_message(port: int, payload: bytes | str, timeout: float = 10.0) -> str:
    """Open a websocket, send ``payload``, and wait for the server to close it: the outcome."""
    try:
        with websockets.sync.client.connect(
            f"ws://127.0.0.1:{port}",
            subprotocols=[websockets.Subprotocol(f"viser-v{viser.__version__}")],
            max_size=None,
            compression=None,
            open_timeout=timeout,
            ping_interval=None,
        ) as ws:
            ws.send(payload)
            deadline = time.monotonic() + timeout
            while time.monotonic() < deadline:
                try:
                    ws.recv(timeout=max(0.0, deadline - time.monotonic()))
                except TimeoutError:
                    break
                except websockets.ConnectionClosed:
                    code = ws.close_code
                    return f"closed {code}" if code is not None else "closed"
            return "still open"
    except (OSError, websockets.InvalidHandshake) as exc:
        return f"failed: {type(exc).__name__}"


def _host_twice(port: int) -> bytes:
    return upgrade_request(port).replace(
        b"\r\n\r\n", f"\r\nHost: 127.0.0.1:{port}\r\n\r\n".encode()
    )


def _no_host(port: int) -> bytes:
    return upgrade_request(port).replace(f"Host: 127.0.0.1:{port}\r\n".encode(), b"")


def _rebinding(port: int) -> bytes:
    evil = f"evil.example:{port}"
    return upgrade_request(port).replace(
        f"Host: 127.0.0.1:{port}".encode(), f"Host: {evil}\r\nOrigin: http://{evil}".encode()
    )


def _with_origin(origin: str) -> Callable[[int], bytes]:
    def request(port: int) -> bytes:
        return upgrade_request(port).replace(b"\r\n\r\n", f"\r\nOrigin: {origin}\r\n\r\n".encode())

    return request


#: Websocket upgrade requests that must be refused (403) and leave nothing behind.
HANDSHAKES: dict[str, Callable[[int], bytes]] = {
    "two Host headers": _host_twice,
    "no Host header": _no_host,
    "DNS rebinding (Host and Origin evil.example)": _rebinding,
    "another site's page": _with_origin("http://evil.example"),
    "a local file (Origin null)": _with_origin("null"),
    "two Origin headers": lambda port: _with_origin(f"http://127.0.0.1:{port}")(port).replace(
        b"Origin:", b"Origin: http://evil.example\r\nOrigin:", 1
    ),
}


def exchange(port: int, request: bytes, timeout: float = 10.0) -> str:
    """Send a raw HTTP request; the response's status code, "no answer", or "failed: ..."."""
    try:
        with socket.create_connection(("127.0.0.1", port), timeout=timeout) as sock:
            sock.sendall(request)
            head = b""
            while b"\r\n" not in head:
                chunk = sock.recv(4096)
                if not chunk:
                    break
                head += chunk
    except OSError as exc:
        return f"failed: {type(exc).__name__}"
    parts = head.split(b" ", 2)
    return parts[1].decode(errors="replace") if head.startswith(b"HTTP/") else "no answer"


#: HTTP/1.0 requests (a proxy left at 1.0, curl -0 following the landing's redirect).
HTTP10: dict[str, bytes] = {
    "HTTP/1.0 GET /": b"GET / HTTP/1.0\r\n\r\n",
    "HTTP/1.0 GET / with a Host": b"GET / HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n",
}


def bad_handshakes(port: int, count: int, seconds: float = 0.0) -> Counter[str]:
    """``count`` refused handshakes, the kinds in turn, spread evenly over ``seconds`` (0: as
    fast as they go); their outcomes."""
    kinds = list(HANDSHAKES.values())
    outcomes: Counter[str] = Counter()
    start = time.monotonic()
    for k in range(count):
        wait = start + k * seconds / count - time.monotonic()
        if wait > 0:
            time.sleep(wait)
        outcomes[exchange(port, kinds[k % len(kinds)](port))] += 1
    return outcomes
