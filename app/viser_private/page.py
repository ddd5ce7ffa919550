"""A client's page: its websocket handshake, JavaScript run in it, and its localStorage (the
page's own address, the clipboard, a narrow page's bottom sheet).

Private names:
  - ``ViserServer._websock_server._live_connections[client_id].request``: the websocket
    handshake of a client (:func:`handshake_origin`). viser keeps the connection to itself; its
    ``ClientHandle`` exposes no header. Used to tell a web page (it always sends ``Origin``) from
    a tool (the probe, the load test), which runs no JavaScript.
  - ``ClientHandle._websock_connection``: ``queue_message``, ``register_handler`` and
    ``unregister_handler`` of one client's connection, with the message classes
    ``viser._messages.RunJavascriptMessage``, ``LocalStorageGetItemRequestMessage`` and
    ``LocalStorageGetItemResponseMessage`` (:func:`page_address`, :func:`copy_to_clipboard`).
    viser's client connects its websocket to the page's address *without* the query
    (``getDefaultServerFromUrl`` drops everything after ``?``) and sends nothing of the page's
    address on connect, so a link's query never reaches the server by a public way. A line of
    JavaScript run in the page writes ``window.location.href`` to the page's ``localStorage``
    under a key of this connection alone, and viser's own localStorage request reads it back;
    :meth:`viser.LocalStorageHandle.get_item` does the same read but blocks a thread, where this
    awaits on the event loop (a page that never answers holds no thread).
  - ``"viser-user:"``: the prefix viser's client puts before the keys of its localStorage API
    (``LOCAL_STORAGE_PREFIX`` in the client's ``MessageHandler.tsx``).
  - The bottom sheet of a narrow page (the client's ``ControlPanel/BottomPanel.tsx``): a
    ``position: fixed; bottom: 0`` Mantine ``Paper`` whose bar (``cursor: pointer``,
    ``height: 3.5em``) toggles it; it is open when it mounts (its state is the page's own,
    ``useDisclosure(true)``: no message and no GUI handle folds it). :func:`fold_bottom_sheet`
    taps that bar once, from the page, as a finger would.
"""

from __future__ import annotations

import asyncio
import json
import uuid
from typing import Any

import viser
from viser import _messages

#: The client's prefix of the keys its localStorage API reads and writes.
LOCAL_STORAGE_PREFIX = "viser-user:"


def handshake_origin(server: viser.ViserServer, client_id: int) -> str | None:
    """The ``Origin`` header of the client's websocket handshake (None: not a web page, or
    the connection is gone)."""
    connection: Any = server._websock_server._live_connections.get(client_id)
    request = getattr(connection, "request", None)
    if request is None:
        return None
    origin = request.headers.get("Origin")
    return str(origin) if origin is not None else None


def _run_javascript(client: viser.ClientHandle, source: str) -> None:
    client._websock_connection.queue_message(_messages.RunJavascriptMessage(source=source))


async def page_address(client: viser.ClientHandle, timeout: float) -> str | None:
    """The address of the page of ``client`` (``window.location.href``, its query included),
    or None if the page does not answer within ``timeout`` seconds or has no localStorage. Run
    on viser's event loop, outside its connect handler (the answer arrives only once viser
    reads the connection, after the handler)."""
    key = f"poinsot-page-{uuid.uuid4().hex}"
    request_uuid = uuid.uuid4().hex
    answer: asyncio.Future[str | None] = asyncio.get_running_loop().create_future()

    def got(client_id: int, message: _messages.LocalStorageGetItemResponseMessage) -> None:
        del client_id
        if message.request_uuid == request_uuid and not answer.done():
            answer.set_result(message.value if message.error is None else None)

    connection = client._websock_connection
    connection.register_handler(_messages.LocalStorageGetItemResponseMessage, got)
    try:
        name = json.dumps(LOCAL_STORAGE_PREFIX + key)
        _run_javascript(
            client, f"try {{ localStorage.setItem({name}, window.location.href); }} catch (e) {{}}"
        )
        connection.queue_message(
            _messages.LocalStorageGetItemRequestMessage(key=key, request_uuid=request_uuid)
        )
        client.flush()
        return await asyncio.wait_for(answer, timeout)
    except TimeoutError:
        return None
    finally:
        connection.unregister_handler(_messages.LocalStorageGetItemResponseMessage, got)
        client.local_storage.remove_item(key)


_COPY_JS = """
const text = %s;
const fallback = () => {
  const area = document.createElement("textarea");
  area.value = text;
  area.style.position = "fixed";
  area.style.opacity = "0";
  document.body.appendChild(area);
  area.select();
  try { document.execCommand("copy"); } catch (e) {}
  area.remove();
};
if (navigator.clipboard && window.isSecureContext) {
  navigator.clipboard.writeText(text).catch(fallback);
} else {
  fallback();
}
"""


_FOLD_SHEET_JS = """
(() => {
  if (window.poinsotSheetFolded) return;
  const until = Date.now() + %d;
  const fold = () => {
    const sheet = [...document.querySelectorAll(".mantine-Paper-root")].find(
      (e) => e.style.position === "fixed" && e.style.bottom === "0px");
    const bar = sheet && [...sheet.querySelectorAll("div")].find(
      (e) => e.style.cursor === "pointer" && e.style.height === "3.5em");
    if (bar && sheet.getBoundingClientRect().height > 1.5 * bar.getBoundingClientRect().height) {
      window.poinsotSheetFolded = true;
      bar.click();
    } else if (Date.now() < until) {
      setTimeout(fold, 100);
    }
  };
  fold();
})();
"""


def fold_bottom_sheet(client: viser.ClientHandle, wait_ms: int = 10000) -> None:
    """Fold the page's bottom sheet (a narrow page's) once, as one tap on its bar does, as soon
    as it is there and open (looked for during ``wait_ms``; a wide page has none). Its bar then
    opens and closes it with one tap each, as ever."""
    _run_javascript(client, _FOLD_SHEET_JS % int(wait_ms))
    client.flush()


def copy_to_clipboard(client: viser.ClientHandle, text: str) -> None:
    """Ask the page of ``client`` to put ``text`` on the clipboard (the browser may refuse:
    the caller also shows the text)."""
    _run_javascript(client, _COPY_JS % json.dumps(text))
    client.flush()


_SHOW_BUTTON_JS = """
(() => {
  const label = %s, folder = %s;
  const until = Date.now() + %d, hold = %d;
  let opened = false, held = 0, left = false;
  const stop = () => { left = true; };
  for (const e of ["wheel", "touchstart", "keydown", "pointerdown"]) {
    window.addEventListener(e, stop, {once: true, passive: true, capture: true});
  }
  const find = () => [...document.querySelectorAll("button")].find(
      (b) => b.textContent.trim() === label);
  const show = () => {
    if (left) return;  // the user scrolls, types or clicks: the page is theirs again
    const button = find();
    const box = button && button.getBoundingClientRect();
    const shown = box && box.height > 0;
    if (button && !shown && !opened && folder) {  // in a folded folder: open it, as a click does
      const header = [...document.querySelectorAll("div")].find(
        (e) => e.style.cursor === "pointer" && e.textContent.trim() === folder);
      if (header) { header.click(); opened = true; }
    }
    if (shown && (box.top < 0 || box.bottom > window.innerHeight)) {
      button.scrollIntoView({block: "center"});
    }
    if (shown) held = held || Date.now();
    // Kept in view a moment after it first shows (what loads with it may push it down).
    if ((!held && Date.now() < until) || (held && Date.now() < held + hold)) {
      setTimeout(show, 100);
    }
  };
  show();
})();
"""


def scroll_to_button(
    client: viser.ClientHandle,
    label: str,
    folder: str = "",
    wait_ms: int = 5000,
    hold_ms: int = 3000,
) -> None:
    """Scroll the panel holding the button labelled ``label`` until the button is in the middle
    of the screen (what stands above it, too), as soon as the page shows it (looked for during
    ``wait_ms``), and keep it there for ``hold_ms`` (what loads with it may push it down), unless
    the user scrolls, types or clicks meanwhile; if it is in the folded folder titled
    ``folder``, that folder is opened first (one click on its title, as a user's)."""
    args = (json.dumps(label), json.dumps(folder), int(wait_ms), int(hold_ms))
    _run_javascript(client, _SHOW_BUTTON_JS % args)
    client.flush()
