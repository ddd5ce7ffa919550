"""A body of one's own in a live session: the "Your own toss" and "Any body from its mesh"
folders, their uploads, and the fitted or measured body they put on screen.

Flow of an upload: the browser sends the file in parts (:class:`TransferGuard` drops one over
the cap while it arrives) -> viser calls the button's callback on its thread pool, which checks
the size again and hands the bytes to a worker (:data:`WORKERS`, shared by all sessions: a
fit takes a fraction of a second to seconds) -> the worker reads and fits or measures
(:mod:`poinsot.app.model.own_bodies`) -> the result is posted to the session's frame thread, which
alone touches the widgets and the scene: it keeps the fitted toss (or mesh body), fills the
readout, and chooses the preset made from it, which then plays like any other. A failure only
writes its message in the folder: the scene shown is kept.

The folders exist only while the preset declares their controls (:data:`Control.TOSS`,
:data:`Control.MESH`); choosing "Fitted toss" or "Body from a mesh" in the menu brings back the
session's own toss or mesh body, if it has one (:meth:`UploadControls.resolve`).
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Any, Protocol

import viser

from poinsot.app.live.hardening.transfers import TransferGuard, handle_id
from poinsot.app.live.panel.overlay import Measured
from poinsot.app.live.panel.panel import ControlPanel
from poinsot.app.live.panel.widgets import Removable, Sent, on_user
from poinsot.app.model import own_bodies
from poinsot.app.model.bodies import BUNDLED, MeshBody, bundled_body
from poinsot.app.model.elements import Control
from poinsot.app.model.own_bodies import FittedToss
from poinsot.app.model.presets import FITTED_TOSS, MESH_BODY, Preset

log = logging.getLogger(__name__)

#: Order of the folders in the control panel (the Scene folder is 0, the moments 10).
TOSS_ORDER = 5.0
MESH_ORDER = 6.0
#: What the file choosers offer.
RECORDING_ACCEPT = ".zip,.csv,.txt,application/zip,text/csv"
MESH_ACCEPT = ".stl,.obj,.ply,.glb"
#: The bundled bodies' menu: a first entry that loads nothing.
CHOOSE = "choose a body…"
TOSS_HELP = (
    "Throw a phone spinning and catch it, with phyphox's *Gyroscope (rotation rate)* "
    "experiment running; upload the export (.zip) or a CSV of t, ωx, ωy, ωz. The free flight is "
    "fitted by the exact torque-free motion, which then plays here."
)
MESH_HELP = (
    "Pick a bundled body or upload a closed mesh (STL, OBJ, PLY, GLB): its moments at uniform "
    "density drive the scene and the mesh is drawn as the body."
)

#: Uploads are read and fitted here, a few at a time for the whole server, never on viser's
#: callback threads nor a session's frame thread.
WORKERS = ThreadPoolExecutor(max_workers=2, thread_name_prefix="poinsot-upload")


class Host(Protocol):
    """What the uploads ask of their session's front: its client and queue, and a preset."""

    client: viser.ClientHandle

    def post(self, action: Callable[[], None]) -> None: ...
    def choose_preset(self, preset: Preset) -> None: ...
    def report(self, error: BaseException) -> None: ...


class _Folder:
    """The status and readout lines of the folder of ``group``, kept here and mirrored into
    its widgets while they exist: while the panel shows the group or keeps it put away on its
    shelf (hidden, shown again as it is); a group it retired is deleted, and no update may
    reach a deleted widget (a later declaration builds the folder anew from these lines)."""

    def __init__(self, group: Control, panel: ControlPanel) -> None:
        self.group, self.panel = group, panel
        self.status_md: viser.GuiMarkdownHandle | None = None
        self.readout_md: viser.GuiMarkdownHandle | None = None
        self.status = ""
        self.readout = ""

    def show(self, status: str | None = None, readout: str | None = None) -> None:
        """Change the lines (frame thread); mirrored into the widgets if they exist."""
        if self.group not in self.panel.groups and self.group not in self.panel.shelf:
            self.status_md = self.readout_md = None
        if status is not None:
            self.status = status
            if self.status_md is not None:
                self.status_md.content = _status_text(status)
        if readout is not None:
            self.readout = readout
            if self.readout_md is not None:
                self.readout_md.content = readout


def _status_text(status: str) -> str:
    return f"**{status}**" if status else ""


class UploadControls:
    """The uploads of one session. Widgets and state change on the frame thread only."""

    def __init__(self, host: Host, panel: ControlPanel) -> None:
        """``panel``: the session's, which builds the toss and mesh folders when declared."""
        self.host, self.panel = host, panel
        self.toss: FittedToss | None = None
        self.toss_preset: Preset | None = None
        self.mesh: MeshBody | None = None
        self.mesh_preset: Preset | None = None
        self.toss_lines = _Folder(Control.TOSS, panel)
        self.mesh_lines = _Folder(Control.MESH, panel)
        #: Uploads finished (shown or refused); tests wait on it.
        self.finished = 0
        self._latest = {"toss": 0, "mesh": 0}
        self._tickets = 0
        self._kinds: dict[str, str] = {}  # upload button id -> "toss" or "mesh"
        self._lock = threading.Lock()
        self.guard = TransferGuard(host.client, self._refused_in_transit)
        panel.extend(Control.TOSS, self._build_toss)
        panel.extend(Control.MESH, self._build_mesh)

    def resolve(self, preset: Preset) -> Preset:
        """The session's own toss or mesh body for their menu entries (if it has one)."""
        if preset is FITTED_TOSS and self.toss_preset is not None:
            return self.toss_preset
        if preset is MESH_BODY and self.mesh_preset is not None:
            return self.mesh_preset
        return preset

    # -- the folders (built by the panel when a preset declares them; frame thread) -------
    def _build_toss(self) -> list[Removable]:
        gui = self.host.client.gui
        with gui.add_folder("Your own toss", order=TOSS_ORDER) as folder:
            button = gui.add_upload_button(
                "Upload a recording (.zip, .csv)",
                icon=viser.Icon.UPLOAD,
                mime_type=RECORDING_ACCEPT,
                hint="A phyphox export of the gyroscope, or a CSV of t, ωx, ωy, ωz in rad/s.",
            )
            self.toss_lines.status_md = gui.add_markdown(_status_text(self.toss_lines.status))
            self.toss_lines.readout_md = gui.add_markdown(self.toss_lines.readout or TOSS_HELP)
        self.guard.watch(button, own_bodies.MAX_RECORDING_BYTES)
        self._kinds[handle_id(button)] = "toss"
        button.on_upload(self._on_upload("toss", own_bodies.MAX_RECORDING_BYTES))
        return [folder]

    def _build_mesh(self) -> list[Removable]:
        gui = self.host.client.gui
        labels = {label: key for key, (_, label) in BUNDLED.items()}
        with gui.add_folder("Any body from its mesh", order=MESH_ORDER) as folder:
            menu = gui.add_dropdown(
                "Bundled body",
                (CHOOSE, *labels),
                initial_value=CHOOSE,
                hint="Real objects: their moments come from their shape at uniform density.",
            )
            button = gui.add_upload_button(
                "Upload a mesh (STL, OBJ, PLY, GLB)",
                icon=viser.Icon.UPLOAD,
                mime_type=MESH_ACCEPT,
                hint="A closed (watertight) surface; small holes are repaired.",
            )
            self.mesh_lines.status_md = gui.add_markdown(_status_text(self.mesh_lines.status))
            self.mesh_lines.readout_md = gui.add_markdown(self.mesh_lines.readout or MESH_HELP)
        self.guard.watch(button, own_bodies.MAX_MESH_BYTES)
        self._kinds[handle_id(button)] = "mesh"
        button.on_upload(self._on_upload("mesh", own_bodies.MAX_MESH_BYTES))

        def choose(sent: Sent) -> None:
            label = str(sent.value)
            if label in labels:
                self._submit("mesh", label, lambda: bundled_body(labels[label]))

        on_user(menu, choose, self.host.report)  # browser changes only, the value checked
        return [folder]

    # -- callbacks (viser's thread pool: short, never raising) ------------------------------
    def _guarded(self, callback: Callable[[Any], None]) -> Callable[[Any], None]:
        def run(event: Any) -> None:
            try:
                callback(event)
            except Exception as exc:
                self.host.report(exc)

        return run

    def _on_upload(self, kind: str, cap: int) -> Callable[[Any], None]:
        def uploaded(event: viser.GuiEvent[viser.GuiUploadButtonHandle]) -> None:
            file = event.target.value
            name = own_bodies.display_name(file.name)
            size = len(file.content)
            if size > cap:  # the guard drops these while they arrive; this is the backstop
                self._refused(kind, name, size, cap)
                return
            data = bytes(file.content)
            work = own_bodies.fit_recording if kind == "toss" else own_bodies.load_mesh
            self._submit(kind, name, lambda: work(data, name))

        return self._guarded(uploaded)

    def _refused_in_transit(self, button: str, name: str, size: int, cap: int) -> None:
        """The guard dropped a file while it arrived (viser's event loop)."""
        kind = self._kinds.get(button, "toss")
        self._refused(kind, own_bodies.display_name(name), size, cap)

    def _refused(self, kind: str, name: str, size: int, cap: int) -> None:
        """A file over the cap: say so, never parse it (any thread)."""
        message = f"⚠ {own_bodies.too_large(size, cap, name, kind)}. The body shown is kept."
        ticket = self._ticket(kind)
        self.host.post(lambda: self._show_failure(kind, ticket, message))

    def _ticket(self, kind: str) -> int:
        """A number for the newest upload of ``kind``: older results are dropped."""
        with self._lock:
            self._tickets += 1
            self._latest[kind] = self._tickets
            return self._tickets

    def _submit(self, kind: str, name: str, work: Callable[[], Any]) -> None:
        ticket = self._ticket(kind)
        verb = "Fitting" if kind == "toss" else "Measuring"
        lines = self.toss_lines if kind == "toss" else self.mesh_lines
        self.host.post(lambda: lines.show(status=f"{verb} {name}…"))
        future = WORKERS.submit(work)
        future.add_done_callback(lambda f: self._done(kind, ticket, name, f))

    def _done(self, kind: str, ticket: int, name: str, future: Future[Any]) -> None:
        """The worker finished (its thread): hand the result to the frame thread."""
        try:
            result = future.result()
            shown = self._presets(kind, result)
        except ValueError as exc:
            text = str(exc)
            if not text.startswith((name, repr(name))):  # a file's name is never capitalised
                text = text[:1].upper() + text[1:]
            message = f"⚠ {text}. The body shown is kept."
            self.host.post(lambda: self._show_failure(kind, ticket, message))
        except Exception as exc:
            log.exception("upload of a %s failed", kind)
            message = f"⚠ Internal error ({type(exc).__name__}: {exc}); the body shown is kept."
            self.host.post(lambda: self._show_failure(kind, ticket, message))
        else:
            self.host.post(lambda: self._show(kind, ticket, result, shown))

    @staticmethod
    def _presets(kind: str, result: Any) -> Preset:
        """The preset made from a result (worker thread; raises ValueError)."""
        if kind == "toss":
            return own_bodies.toss_preset(result)
        return own_bodies.mesh_preset(result)

    # -- results (frame thread) -------------------------------------------------------------
    def _current(self, kind: str, ticket: int) -> bool:
        with self._lock:
            return self._latest[kind] == ticket

    def _show_failure(self, kind: str, ticket: int, message: str) -> None:
        if self._current(kind, ticket):
            (self.toss_lines if kind == "toss" else self.mesh_lines).show(status=message)
        self.finished += 1

    def _show(self, kind: str, ticket: int, result: Any, preset: Preset) -> None:
        if not self._current(kind, ticket):
            self.finished += 1
            return
        if kind == "toss":
            toss: FittedToss = result
            self.toss, self.toss_preset = toss, preset
            motion = self.panel.motion
            motion.show_measured(Measured(toss.tau, toss.measured, toss.exact, toss.bound))
            self.toss_lines.show(status="", readout=own_bodies.toss_markdown(toss))
        else:
            body: MeshBody = result
            self.mesh, self.mesh_preset = body, preset
            note = own_bodies.repair_note(body)
            self.mesh_lines.show(status=note, readout=own_bodies.mesh_markdown(body))
        self.host.choose_preset(preset)
        self.finished += 1
