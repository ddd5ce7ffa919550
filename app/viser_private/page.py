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
  - The page's accessibility (:func:`make_accessible`), inside viser's React client, whose
    widgets leave out what a screen reader and a keyboard need (viser 1.1 has no public hook
    for it; its ``hint=`` is a tooltip, not a name):

    - a slider (Mantine ``Slider``, ``components/Slider.tsx``) gets its ``<label
      for=uuid>`` on its root ``div``, which no control is: the thumb (``role=slider``) and
      the number box beside it are nameless; so are the boxes of a ``Vector3`` after the
      first, a ``TextInput`` (its input's id is Mantine's own) and a button group's buttons
      as a group. The script names each from the label on its row (``aria-label``).
    - A folder's header (``components/Folder.tsx``: a ``Paper`` with an ``onClick``, its
      chevron ``svg.tabler-icon-chevron-up`` when open) takes no focus: it is given
      ``role=button``, ``tabindex=0``, ``aria-expanded`` (from its chevron) and Enter/Space.
    - The panel's header icons (``ActionIcon``: a Tabler ``svg`` inside a ``Tooltip``) and a
      notification's close button have no text: named from their icon; the server's address
      in the configuration view (``ServerControls.tsx``: a ``TextInput`` whose left section
      is viser's logo, named by a tooltip only) is named "Server URL", the logo an empty
      ``alt``; a scene node's "edit" popover target in its scene tree (a ``div`` with
      ``aria-haspopup``, ``SceneTreeTable.tsx``) is made a named button.
    - Text marked "dimmed" (``--mantine-color-dimmed``: the controls' labels, the slider
      ticks) is at 4.0:1 on dark and 3.3:1 on light: a style sheet sets colours at 4.5:1 or
      more and the ticks a size a little larger. A link in a text (a markdown's) is told
      from the text by its colour alone, under 3:1 from it on dark: it is underlined.
    - A panel that scrolls (Mantine's ``ScrollArea`` viewport) with nothing focusable in it
      cannot be scrolled from the keyboard: it is given ``tabindex=0`` while it scrolls.
    - A button group (``components/ButtonGroup.tsx``) shows no choice: the server says which
      option is on (:func:`show_pressed`, through the group's GUI: ``handle._impl`` with its
      ``uuid`` and ``gui_api._websock_interface``), the script sets ``aria-pressed`` and a
      style.
    - viser's scene nodes answer a press through react-three-fiber's ``pointerdown``
      listener on the canvas's wrapper, registered passive, and one that can be dragged calls
      ``preventDefault()`` on it (``SceneTree.tsx``): the browser ignores the call and logs
      "Unable to preventDefault inside passive event listener invocation." on every press.
      The only other ``pointerdown`` listener there (camera-controls', not passive) never
      cancels it, so the script drops exactly that ignored call (a ``pointerdown``'s
      ``preventDefault`` while its listener is the wrapper's): nothing changes but the log.
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


#: Colours of viser's "dimmed" text (the controls' labels, the slider ticks) per theme, at
#: 4.5:1 or more on the panels' backgrounds (viser's: #828282 on #242424 is 4.0:1, Mantine's
#: gray 6 on white 3.3:1). Measured by axe-core's color-contrast rule in the browser tests.
DIMMED_DARK, DIMMED_LIGHT = "#a3a3a3", "#5c636a"
#: Names of viser's header icon buttons, by their Tabler icon (``ControlPanel.tsx``'s
#: tooltips); any other nameless icon button is named after its icon.
ICON_NAMES = {
    "adjustments": "Configuration & diagnostics",
    "arrow-back": "Return to the controls",
    "list-search": "Commands",
    "share": "Share",
    "x": "Close",
}

#: A folded column's title, written down its rail (a tablet's page, the projector's control
#: panel): the client's ``FloatingPanel`` cuts it at ``max-height: 14em``, which on a tablet held
#: upright cut the label "t = 5.8 · polhode around the major axis" after "around the".
RAIL_TITLE = '[style*="writing-mode: vertical-rl"]'
_A11Y_CSS = """
:root[data-mantine-color-scheme="dark"] { --mantine-color-dimmed: %(dark)s; }
:root[data-mantine-color-scheme="light"] { --mantine-color-dimmed: %(light)s; }
.mantine-Slider-markLabel { font-size: 0.7rem !important; color: var(--mantine-color-dimmed); }
:where(p, li, td, th) a[href] { text-decoration: underline !important; }
[data-poinsot-folder]:focus-visible, [data-poinsot-scroll]:focus-visible {
  outline: 2px solid var(--mantine-primary-color-filled); outline-offset: -2px;
}
button[aria-pressed="true"] {
  background: var(--mantine-primary-color-filled) !important;
  color: var(--mantine-primary-color-contrast) !important;
  font-weight: 700;
}
button[aria-pressed="true"]::before { content: "\\2713\\00a0"; }
%(rail)s { max-height: none !important; }
"""

_A11Y_JS = """
(() => {
  if (window.poinsotA11y) { window.poinsotA11y.apply(); return; }
  const ICONS = %(icons)s;
  const OURS = "data-poinsot-name";
  const pressed = window.poinsotPressed || (window.poinsotPressed = {});
  const style = document.createElement("style");
  style.textContent = %(css)s;
  document.head.appendChild(style);

  const set = (e, key, value) => {
    if (value === null) { if (e.hasAttribute(key)) e.removeAttribute(key); }
    else if (e.getAttribute(key) !== value) e.setAttribute(key, value);
  };
  // A name of ours, or none where the page has one of its own.
  const name = (e, text) => {
    const own = (e.labels && e.labels.length) || e.hasAttribute("aria-labelledby") ||
      ((e.getAttribute("aria-label") || "").trim() && !e.hasAttribute(OURS));
    if (own) return;
    set(e, "aria-label", text);
    set(e, OURS, "");
  };
  const fields = "[role=slider], input:not([type=hidden]), textarea";

  const nameRows = () => {
    for (const label of document.querySelectorAll("label[for]")) {
      const row = label.closest(".mantine-Flex-root");
      if (!row || !row.contains(label) || row.lastElementChild.contains(label)) continue;
      const text = label.textContent.trim();
      const inputs = [...row.lastElementChild.querySelectorAll(fields)];
      const slider = inputs.find((e) => e.getAttribute("role") === "slider");
      inputs.forEach((e, i) => {
        if (e === slider || inputs.length === 1) name(e, text);
        else if (slider) name(e, text + " value");
        else name(e, text + " (" + (i + 1) + " of " + inputs.length + ")");
      });
      const buttons = [...row.lastElementChild.querySelectorAll("button")];
      if (buttons.length > 1 && !inputs.length) {
        const group = buttons[0].parentElement;
        set(group, "role", "group");
        set(group, "aria-label", text);
        const on = pressed[label.htmlFor];
        if (on !== undefined) {
          for (const b of buttons) set(b, "aria-pressed", String(b.textContent.trim() === on));
        }
      }
    }
  };

  const folders = () => {
    const icons = "svg.tabler-icon-chevron-up, svg.tabler-icon-chevron-down";
    for (const icon of document.querySelectorAll(icons)) {
      const header = icon.parentElement;
      if (!header.classList.contains("mantine-Paper-root") ||
          !header.parentElement.classList.contains("mantine-Paper-root")) continue;
      const live = icon.style.display !== "none";  // an empty folder does not open
      set(header, "data-poinsot-folder", "");
      set(header, "role", live ? "button" : null);
      set(header, "tabindex", live ? "0" : null);
      set(header, "aria-expanded", live ?
        String(icon.classList.contains("tabler-icon-chevron-up")) : null);
      pressable(header);
    }
  };

  // Enter and Space press a div made a button, as they press a <button>.
  const pressable = (e) => {
    if (e.poinsotKeys) return;
    e.poinsotKeys = true;
    e.addEventListener("keydown", (event) => {
      if (event.target !== e || e.getAttribute("role") !== "button") return;
      if (event.key !== "Enter" && event.key !== " ") return;
      event.preventDefault();
      event.stopPropagation();
      e.click();
    });
  };

  // viser's configuration view: a scene node's "edit" popover target (a div), its logo.
  const configuration = () => {
    for (const e of document.querySelectorAll("div[aria-haspopup]:not([role])")) {
      set(e, "role", "button");
      set(e, "tabindex", "0");
      name(e, "Edit " + (e.parentElement.getAttribute("data-scene-node") || "properties"));
      pressable(e);
    }
    for (const img of document.querySelectorAll("img:not([alt])")) set(img, "alt", "");
  };

  const iconButtons = () => {
    const buttons = ".mantine-ActionIcon-root, .mantine-CloseButton-root";
    for (const b of document.querySelectorAll(buttons)) {
      if (b.textContent.trim()) continue;
      const svg = b.querySelector("svg[class*=tabler-icon-]");
      const icon = svg ? [...svg.classList].find((c) => c.startsWith("tabler-icon-")) : null;
      const key = icon ? icon.slice("tabler-icon-".length) : "x";
      name(b, ICONS[key] || key.replace(/-/g, " "));
    }
  };

  // The server's address in viser's configuration view (its tooltip says "Server URL").
  const serverBox = () => {
    for (const input of document.querySelectorAll(".mantine-TextInput-input")) {
      const wrapper = input.closest(".mantine-Input-wrapper");
      if (wrapper && wrapper.querySelector(".mantine-Input-section img")) name(input, "Server URL");
    }
  };

  // A scrolled panel with nothing focusable in it: the keyboard scrolls it once it has focus.
  const scrollers = () => {
    const focusable = "a[href], button, input, select, textarea, [tabindex]:not([tabindex='-1'])";
    for (const view of document.querySelectorAll(".mantine-ScrollArea-viewport")) {
      const scrolls = view.scrollHeight > view.clientHeight || view.scrollWidth > view.clientWidth;
      const needs = scrolls && !view.querySelector(focusable);
      if (needs === view.hasAttribute("data-poinsot-scroll")) continue;
      set(view, "tabindex", needs ? "0" : null);
      set(view, "data-poinsot-scroll", needs ? "" : null);
    }
  };

  const apply = () => {
    nameRows(); folders(); iconButtons(); serverBox(); configuration(); scrollers();
  };
  let queued = false;
  const later = () => {
    if (queued) return;
    queued = true;
    setTimeout(() => { queued = false; apply(); }, 50);
  };
  new MutationObserver(later).observe(document.body, { childList: true, subtree: true });

  // The press on a draggable scene node: react-three-fiber's passive listener on the
  // canvas's wrapper, where preventDefault is ignored (and logged) by the browser.
  const prevent = Event.prototype.preventDefault;
  Event.prototype.preventDefault = function () {
    const at = this.currentTarget;
    if (this.type === "pointerdown" && at instanceof HTMLElement &&
        at.querySelector(":scope > div > canvas[data-engine]")) return undefined;
    return prevent.call(this);
  };
  window.poinsotA11y = { apply };
  apply();
})();
"""


def make_accessible(client: viser.ClientHandle) -> None:
    """Make the page of ``client`` accessible where viser's client is not (see the module's
    notes): names for the controls and the header icons, folders that open from the keyboard,
    text at 4.5:1 contrast, the pressed option of a button group shown (:func:`show_pressed`),
    no console error on a press on a draggable node. Once per page; it follows the panel as
    it changes."""
    css = _A11Y_CSS % {"dark": DIMMED_DARK, "light": DIMMED_LIGHT, "rail": RAIL_TITLE}
    source = _A11Y_JS % {"icons": json.dumps(ICON_NAMES), "css": json.dumps(css)}
    _run_javascript(client, source)
    client.flush()


def show_pressed(group: Any, option: str) -> None:
    """Show ``option`` of the button group ``group`` as the one on, in the page that shows the
    group (``aria-pressed`` and the pressed style, see :func:`make_accessible`), kept across
    the group's redraws until told another. The group's GUI (``handle._impl.gui_api``) sends
    it: a client's GUI to its page."""
    impl = group._impl
    uuid = json.dumps(str(impl.uuid))
    source = (
        f"(window.poinsotPressed = window.poinsotPressed || {{}})[{uuid}] = {json.dumps(option)};"
        " if (window.poinsotA11y) window.poinsotA11y.apply();"
    )
    impl.gui_api._websock_interface.queue_message(_messages.RunJavascriptMessage(source=source))


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
