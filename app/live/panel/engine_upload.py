"""Check a physics engine's log in the browser: an upload button and a moments field in the
numerical ghost's folder, and the verdict of ``poinsot check-engine`` below them
(:mod:`poinsot.app.model.engine_logs`).

Threads, as for the other uploads (:mod:`~poinsot.app.live.panel.uploads`): the button's callback
(viser's thread pool) hands the bytes to the shared upload workers; a worker reads and judges
the log and stores the answer under a lock; the session's frame thread alone writes it into
the panel (:meth:`EngineLogUpload.on_frame`). A log that cannot be read gets its one line; the
scene is never touched. The transfer itself is capped by the session's transfer guard (20 MB
for a button it is not told about, the size :data:`engine_logs.MAX_BYTES` allows).
"""

from __future__ import annotations

import logging
import threading
from concurrent.futures import Future

import viser

from poinsot.app.live.panel.uploads import WORKERS
from poinsot.app.model import engine_logs
from poinsot.app.model.own_bodies import display_name

log = logging.getLogger(__name__)

BUTTON = "Check an engine's log (.csv)"
MOMENTS = "Log's moments I1,I2,I3"
HELP = (
    "A game engine's log of one free body: a CSV with the header t, wx, wy, wz (body frame, "
    "rad/s), optionally qw, qx, qy, qz. Give the moments here or in a '# inertia: I1, I2, I3' "
    "line. The answer says whether it stays on one polhode, flips when the exact motion does, "
    "and which game step it looks like."
)


class EngineLogUpload:
    """The widgets (created inside the caller's folder) and the latest answer."""

    def __init__(self, client: viser.ClientHandle, order: float) -> None:
        gui = client.gui
        self.moments = gui.add_text(
            MOMENTS,
            "",
            order=order,
            hint="The principal moments in the log's body axes; empty: the log's own "
            "'# inertia:' line.",
        )
        self.button = gui.add_upload_button(
            BUTTON,
            icon=viser.Icon.UPLOAD,
            mime_type=".csv,.txt,text/csv",
            order=order + 0.1,
            hint=HELP,
        )
        self.answer = gui.add_markdown("", order=order + 0.2)
        self._lock = threading.Lock()
        self._text = self._shown = ""
        self._ticket = 0
        #: Logs judged or refused; tests wait on it.
        self.finished = 0
        self.button.on_upload(self._uploaded)

    def _uploaded(self, event: viser.GuiEvent[viser.GuiUploadButtonHandle]) -> None:
        """viser's thread pool: hand the bytes to a worker, never raise."""
        try:
            file = event.target.value
            name = display_name(file.name)
            data, moments = bytes(file.content), str(self.moments.value)
            with self._lock:
                self._ticket += 1
                ticket = self._ticket
                self._text = f"*Checking {name}…*"
            future = WORKERS.submit(judge_upload, data, name, moments)
            future.add_done_callback(lambda f: self._done(ticket, f))
        except Exception as exc:  # never into viser's thread pool
            log.exception("engine log upload failed")
            self._store(None, f"⚠ Internal error ({type(exc).__name__}).")

    def _done(self, ticket: int, future: Future[str]) -> None:
        try:
            text = future.result()
        except Exception as exc:
            log.exception("engine log check failed")
            text = f"⚠ Internal error ({type(exc).__name__}: {exc})."
        self._store(ticket, text)

    def _store(self, ticket: int | None, text: str) -> None:
        with self._lock:
            if ticket is None or ticket == self._ticket:  # the newest upload wins
                self._text = text
            self.finished += 1

    def on_frame(self) -> None:
        """The frame thread: mirror the latest answer into the panel (the usual frame: one
        comparison; the answer is a new string whenever it changes)."""
        text = self._text  # one reference, read whole
        if text is not self._shown:
            self._shown = text
            self.answer.content = text


def judge_upload(data: bytes, name: str, moments: str) -> str:
    """The answer to one uploaded log as markdown (worker thread): the verdict and its
    figures, or the one line that says why the log cannot be read."""
    try:
        if len(data) > engine_logs.MAX_BYTES:
            raise engine_logs.LogError(f"{name}: more than {engine_logs.MAX_BYTES:,} bytes")
        parsed = engine_logs.parse_engine_log(data, name)
        if moments.strip():
            inertia = engine_logs.parse_inertia(moments, "the moments")
        elif parsed.inertia is not None:
            inertia = parsed.inertia
        else:
            raise engine_logs.LogError(
                f"{name}: no moments: type I1,I2,I3 above or add a '# inertia:' line"
            )
        verdict = engine_logs.judge(parsed, inertia)
    except engine_logs.LogError as exc:
        return f"**⚠ {exc}**"
    head, *rest = verdict.lines[-1:] + verdict.lines[:-1]
    return "  \n".join([f"**{name}: {head.removeprefix('Verdict: ')}**", *rest])
