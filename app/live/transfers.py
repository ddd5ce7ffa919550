"""A size cap on file uploads while they arrive, before viser has gathered them.

viser 1.1 buffers every part of an upload in memory and hands the whole file to the button's
callback only at the end, whatever its size; the browser sends a file in parts of 512 KiB, and
announces its size first. :class:`TransferGuard` watches one client's transfers to the upload
buttons it is told about: a file announced as larger than its button's cap, or one whose parts
add up to more, is dropped at once (viser forgets it, the parts that follow are counted and
acknowledged, never kept), and ``refused`` is called, so that the student reads why. The
browser's progress notice completes as usual.

This reaches into two of viser 1.1's internals, both kept in this module: the client's message
interface (``ClientHandle._websock_connection``), where the handlers are registered, and the
GUI's table of transfers in progress (``GuiApi._current_file_upload_states``).
"""

from __future__ import annotations

import dataclasses
import threading
from collections.abc import Callable
from typing import Any

import viser
from viser import _messages

#: ``refused(button id, file name, size in bytes or the bytes so far, cap)``.
Refusal = Callable[[str, str, int, int], None]


def handle_id(handle: Any) -> str:
    """The wire id of a GUI handle (viser 1.1 keeps it in ``handle._impl.uuid``)."""
    return str(handle._impl.uuid)


@dataclasses.dataclass
class _Dropped:
    """A refused transfer whose remaining parts are acknowledged and thrown away."""

    button: str
    total: int
    received: int = 0


class TransferGuard:
    """Cap the uploads of ``client`` to the buttons in :attr:`caps` (button id -> bytes)."""

    def __init__(self, client: viser.ClientHandle, refused: Refusal) -> None:
        self.caps: dict[str, int] = {}
        self._refused = refused
        self._client = client
        self._dropped: dict[str, _Dropped] = {}
        self._names: dict[str, str] = {}
        self._lock = threading.Lock()
        connection = client._websock_connection
        # Registered after viser's own handlers, so each runs once viser has seen the message.
        connection.register_handler(_messages.FileTransferStartUpload, self._on_start)
        connection.register_handler(_messages.FileTransferPart, self._on_part)

    def watch(self, handle: Any, cap: int) -> None:
        """Cap uploads to the button ``handle`` at ``cap`` bytes."""
        self.caps[handle_id(handle)] = int(cap)

    @property
    def dropped(self) -> int:
        """Refused transfers whose parts are still arriving."""
        with self._lock:
            return len(self._dropped)

    # -- handlers (viser's event loop: short, never raising) -----------------------------
    def _states(self) -> dict[str, Any]:
        return self._client.gui._current_file_upload_states

    def _on_start(self, client_id: int, message: _messages.FileTransferStartUpload) -> None:
        cap = self.caps.get(message.source_component_uuid)
        if cap is None:
            return
        self._names[message.transfer_uuid] = message.filename
        if message.size_bytes > cap:
            button = message.source_component_uuid
            self._drop(message.transfer_uuid, button, message.size_bytes)
            self._refused(button, message.filename, int(message.size_bytes), cap)

    def _on_part(self, client_id: int, message: _messages.FileTransferPart) -> None:
        uuid = message.transfer_uuid
        with self._lock:
            dropped = self._dropped.get(uuid)
        if dropped is not None:
            self._acknowledge(uuid, dropped, len(message.content))
            return
        cap = self.caps.get(message.source_component_uuid or "")
        state = self._states().get(uuid)
        if cap is None or state is None:
            self._names.pop(uuid, None)  # finished (or never ours)
            return
        received = int(state["transferred_bytes"])
        if received > cap:  # more than announced: a client that does not say its size
            button = str(message.source_component_uuid)
            self._drop(uuid, button, int(state["total_bytes"]))
            with self._lock:
                self._dropped[uuid].received = received
            self._refused(button, self._names.get(uuid, "the file"), received, cap)

    def _drop(self, uuid: str, button: str, total: int) -> None:
        self._states().pop(uuid, None)  # viser keeps nothing more of it
        with self._lock:
            self._dropped[uuid] = _Dropped(button, total)

    def _acknowledge(self, uuid: str, dropped: _Dropped, size: int) -> None:
        """Count a part of a refused transfer, and tell the browser it arrived."""
        dropped.received += size
        self._client._websock_connection.queue_message(
            _messages.FileTransferPartAck(
                source_component_uuid=dropped.button,
                transfer_uuid=uuid,
                transferred_bytes=min(dropped.received, dropped.total),
                total_bytes=dropped.total,
            )
        )
        if dropped.received >= dropped.total:
            with self._lock:
                self._dropped.pop(uuid, None)
            self._names.pop(uuid, None)
