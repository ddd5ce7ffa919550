"""A size cap on file uploads while they arrive, before viser has gathered them.

viser 1.1 buffers every part of an upload in memory and hands the whole file to the button's
callback only at the end, whatever its size; the browser sends a file in parts of 512 KiB, and
announces its size first. :class:`TransferGuard` watches one client's transfers to the upload
buttons it is told about: a file announced as larger than its button's cap, or one whose parts
add up to more, is dropped at once (viser forgets it, the parts that follow are counted and
acknowledged, never kept), and ``refused`` is called, so that the student reads why. The
browser's progress notice completes as usual.

It also bounds what a client that is not a browser could make the server hold: a transfer to a
widget that is not an upload button is forgotten at once; one client has at most
:data:`MAX_TRANSFERS` transfers in progress, announcing at most :data:`MAX_PENDING_BYTES` in all;
a transfer whose parts add up to more than it announced is dropped. Parts held for a transfer
that never completes are freed when the client leaves (viser drops its transfers then);
:meth:`TransferGuard.pending_bytes` counts them.

This reaches into two of viser 1.1's internals, both through the adapter
:mod:`poinsot.app.viser_private`: the client's message interface, where the handlers are
registered, and the GUI's tables of widgets and of transfers in progress.
"""

from __future__ import annotations

import dataclasses
import threading
from collections.abc import Callable
from typing import Any

import viser

from poinsot.app import viser_private

#: Transfers one client may have in progress at once.
MAX_TRANSFERS = 2
#: Bytes one client's transfers in progress may announce in all (the largest upload cap).
MAX_PENDING_BYTES = 20_000_000
#: Refused transfers whose remaining parts are still answered, per client (older ones are
#: forgotten: their parts are then ignored by viser, unanswered).
MAX_DROPPED = 16

#: ``refused(button id, file name, size in bytes or the bytes so far, cap)``.
Refusal = Callable[[str, str, int, int], None]


#: The wire id of a GUI handle.
handle_id = viser_private.handle_id


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
        # Registered after viser's own handlers, so each runs once viser has seen the message.
        viser_private.on_client_message(client, "FileTransferStartUpload", self._on_start)
        viser_private.on_client_message(client, "FileTransferPart", self._on_part)

    def watch(self, handle: Any, cap: int) -> None:
        """Cap uploads to the button ``handle`` at ``cap`` bytes."""
        self.caps[handle_id(handle)] = int(cap)

    @property
    def dropped(self) -> int:
        """Refused transfers whose parts are still arriving."""
        with self._lock:
            return len(self._dropped)

    def pending_bytes(self) -> int:
        """Bytes of this client's uploads held in memory, waiting for their other parts."""
        return sum(
            sum(len(part) for part in list(state["parts"].values()))
            for state in list(self._states().values())
            if state.get("client_id") == self._client.client_id
        )

    def _pending(self, excluding: str) -> tuple[int, int]:
        """(transfers, bytes announced) of this client's other transfers in progress."""
        others = [
            state
            for uuid, state in list(self._states().items())
            if uuid != excluding and state.get("client_id") == self._client.client_id
        ]
        return len(others), sum(int(state["total_bytes"]) for state in others)

    # -- handlers (viser's event loop: short, never raising) -----------------------------
    def _states(self) -> dict[str, Any]:
        return viser_private.upload_states(self._client.gui)

    def _on_start(self, client_id: int, message: Any) -> None:
        uuid, button = message.transfer_uuid, message.source_component_uuid
        if uuid not in self._states():
            return  # viser took nothing (no such widget)
        handle = viser_private.gui_widget(self._client.gui, button)
        if not isinstance(handle, viser.GuiUploadButtonHandle):
            self._states().pop(uuid, None)  # no browser uploads to a slider
            return
        cap = self.caps.get(button, MAX_PENDING_BYTES)
        size = int(message.size_bytes)
        transfers, announced = self._pending(excluding=uuid)
        too_many = transfers >= MAX_TRANSFERS or announced + size > MAX_PENDING_BYTES
        if size > cap or size < 0 or too_many:
            self._drop(uuid, button, max(size, 0))
            if button in self.caps:
                self._refused(button, message.filename, size, min(cap, MAX_PENDING_BYTES))
            return
        if button in self.caps:
            self._names[uuid] = message.filename

    def _on_part(self, client_id: int, message: Any) -> None:
        uuid = message.transfer_uuid
        with self._lock:
            dropped = self._dropped.get(uuid)
        if dropped is not None:
            self._acknowledge(uuid, dropped, len(message.content))
            return
        button = message.source_component_uuid or ""
        cap = self.caps.get(button, MAX_PENDING_BYTES)
        state = self._states().get(uuid)
        if state is None:
            self._names.pop(uuid, None)  # finished (or never ours)
            return
        received = int(state["transferred_bytes"])
        if received > cap or received > int(state["total_bytes"]):  # more than announced
            button = str(message.source_component_uuid)
            self._drop(uuid, button, int(state["total_bytes"]))
            with self._lock:
                self._dropped[uuid].received = received
            if button in self.caps:
                self._refused(button, self._names.get(uuid, "the file"), received, cap)

    def _drop(self, uuid: str, button: str, total: int) -> None:
        self._states().pop(uuid, None)  # viser keeps nothing more of it
        with self._lock:
            self._dropped[uuid] = _Dropped(button, total)
            while len(self._dropped) > MAX_DROPPED:  # the oldest first (dicts keep order)
                forgotten = next(iter(self._dropped))
                del self._dropped[forgotten]
                self._names.pop(forgotten, None)

    def _acknowledge(self, uuid: str, dropped: _Dropped, size: int) -> None:
        """Count a part of a refused transfer, and tell the browser it arrived."""
        dropped.received += size
        viser_private.send_to_client(
            self._client,
            "FileTransferPartAck",
            source_component_uuid=dropped.button,
            transfer_uuid=uuid,
            transferred_bytes=min(dropped.received, dropped.total),
            total_bytes=dropped.total,
        )
        if dropped.received >= dropped.total:
            with self._lock:
                self._dropped.pop(uuid, None)
            self._names.pop(uuid, None)
