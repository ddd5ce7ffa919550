"""The HTTP handshake of viser's server: a request check of ours before viser's page server, and
an HTTP/1.0 request line read as HTTP/1.1.

Private names:
  - ``viser.infra._infra`` calls ``websockets.asyncio.server.serve`` (looked up on the module at
    call time, inside ``WebsockServer.start``, before ``ViserServer()`` returns) with its own
    ``process_request`` (the page server): :func:`hooked_server` wraps it for the duration of
    one construction, adding a request check of ours before viser's and a connection class
    that reads an HTTP/1.0 request line as HTTP/1.1.
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Callable, Iterator
from typing import Any

import websockets.asyncio.server
from websockets.asyncio.server import ServerConnection
from websockets.http11 import Request, Response

from poinsot.app.viser_private.version import ViserChanged

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
