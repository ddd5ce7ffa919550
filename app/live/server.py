"""The viser server and its sessions: one :class:`~poinsot.app.live.session.session.Session` per
browser."""

from __future__ import annotations

import asyncio
import contextlib
import functools
import logging
import threading
import warnings
from collections.abc import Iterable
from concurrent.futures import Future

import viser
from websockets.datastructures import Headers
from websockets.http11 import Response

from poinsot.app.lessons.support.spec import SceneSpec
from poinsot.app.live.classroom import links
from poinsot.app.live.classroom.follow import FollowHub
from poinsot.app.live.hardening.backlog import BacklogLimit, BacklogWatch
from poinsot.app.live.hardening.budget import RebuildGate
from poinsot.app.live.hardening.eventloop import libuv_loops
from poinsot.app.live.hardening.guard import HandshakeGate, WireGuard, guarded_viser
from poinsot.app.live.hardening.pacing import frame_share
from poinsot.app.live.hardening.upkeep import MemoryTrim, fixed_pool
from poinsot.app.live.session.session import MAX_FPS, Session, SessionOptions
from poinsot.app.model import docs_site
from poinsot.app.model.presets import DEFAULT_PRESET, Preset
from poinsot.app.viser_private import (
    handshake_origin,
    message_buffer,
    page_address,
    quiet_if_closed,
    senders_woken_on_their_loop,
)

log = logging.getLogger(__name__)

#: Seconds a new page has to say its address (its link) before it opens the default scene.
PAGE_TIMEOUT = 10.0


def built_session(
    client: viser.ClientHandle, link: links.Opening, options: SessionOptions
) -> Session:
    """The session of ``client`` showing ``link`` (not started). A browser may leave while its
    session is built (30-300 ms): what the build sends it then goes to nobody, and is dropped
    without viser's warning of a write to a closed connection (the session is then closed,
    never started: :meth:`PoinsotApp._connect`)."""
    with quiet_if_closed(message_buffer(client)):
        session = Session(client, link.preset, options)
        links.apply(session, link)
    return session


def guide_page(path: str) -> Response | None:
    """The guide's page or file at ``path`` (:mod:`poinsot.app.model.docs_site`), or None."""
    found = docs_site.answer(path)
    if found is None:
        return None
    return Response(found.status, found.reason, Headers(list(found.headers)), found.body)


#: The guarded viser server of :mod:`.hardening.guard`, answering the guide at /docs/ too.
_guarded_viser = functools.partial(guarded_viser, pages=guide_page)


def _viser(
    host: str, port: int, verbose: bool, allow_origins: Iterable[str], serving: bool
) -> tuple[viser.ViserServer, HandshakeGate]:
    """The guarded viser server; a serving process's on libuv's event loop
    (:mod:`.hardening.eventloop`: viser makes its loop while it starts)."""
    with libuv_loops() if serving else contextlib.nullcontext():
        return _guarded_viser(host, port, verbose=verbose, allow_origins=allow_origins)


class PoinsotApp:
    """Serve the Poinsot scene: each connecting browser gets its own session."""

    def __init__(
        self,
        host: str = "127.0.0.1",
        port: int = 8080,
        *,
        preset: Preset = DEFAULT_PRESET,
        scene: SceneSpec | None = None,
        max_fps: float = MAX_FPS,
        verbose: bool = False,
        allow_origins: Iterable[str] = (),
        backlog: BacklogLimit | None = None,
        landing_port: int = 0,
        follow: FollowHub | None = None,
        serving: bool = False,
    ) -> None:
        """Each new browser starts with ``preset``, or with ``scene`` if one is given. A
        browser's websocket is refused unless it comes from a page this server served, or from
        one of ``allow_origins`` (``scheme://host[:port]``); see :mod:`.hardening.guard`. A browser
        that leaves more than ``backlog`` untaken for longer than its grace is disconnected
        (:mod:`.hardening.backlog`; its defaults if None). ``landing_port``: a landing in front of
        this server (:mod:`.landing`), named by the links copied from the pages served here.
        ``follow``: the lead and its followers (:mod:`.classroom.follow`; its own if None).
        ``serving``: this process only serves (``poinsot serve``): on libuv's event loop
        (:mod:`.hardening.eventloop`), a hall's heap settled (:mod:`.hardening.upkeep`)."""
        self.preset, self.scene, self.landing_port = preset, scene, landing_port
        #: The lecturer code, the lead and its followers (:mod:`.classroom.follow`).
        self.follow = follow if follow is not None else FollowHub()
        self.follow.cast.fps = min(self.follow.cast.fps, max_fps)  # the followers' poses too
        self.max_fps = max_fps
        self._lock, self._stopping = threading.Lock(), threading.Event()  # set by stop()
        self._sessions: dict[int, Session] = {}
        # Clients whose disconnect came while their session was being built (viser's callbacks
        # run on a pool, in either order): both handlers decide under ``_lock``.
        self._departed: set[int] = set()
        self._arrivals: set[asyncio.Task[None]] = set()  # pages asked for their address
        self.discarded = 0  # sessions built for a client that had left, closed unstarted
        self._connected = threading.Condition(self._lock)
        self.budget = budget = RebuildGate()  # a session's rebuild holds the followers' frames
        self.follow.cast.yield_to = lambda: budget.rebuilding  # (the gate: not the app's self)
        # Handshakes checked before viser sees them, the share tunnel off (:mod:`.hardening.guard`).
        self.server, gate = _viser(host, port, verbose, allow_origins, serving)
        self.server.gui.configure_theme(dark_mode=True, show_share_button=False, show_logo=False)
        self.server.scene.world_axes.visible = False
        # First of this app's handlers: every message passes the guard before viser's.
        self.guard = WireGuard(self.server, gate)
        # A session's frame thread may draw one last frame between the browser leaving and the
        # disconnect callback stopping it; viser then warns once that the message is dropped.
        # That is expected here, not a leak: the thread stops right after.
        warnings.filterwarnings("ignore", message=r"Queued a \w+ on a closed connection")
        # Sessions are built on a fixed pool (:mod:`.hardening.upkeep`), which also runs the
        # widgets' worker-thread callbacks; a departure is handled on viser's event loop (it only
        # stops a thread) and, once quiet, memory is handed back.
        self.pool = fixed_pool()
        self.server.get_event_loop().set_default_executor(self.pool)
        self.memory = MemoryTrim(sessions=self._count if serving else None)
        self.server.on_client_connect(self._on_connect)
        self.server.on_client_disconnect(self._on_disconnect)
        #: Closes the connection of a client leaving too much untaken (:mod:`.hardening.backlog`).
        self.backlog = BacklogWatch(self.sessions, backlog).start()

    @property
    def port(self) -> int:
        return self.server.get_port()

    @property
    def url(self) -> str:
        host = self.server.get_host()
        shown = "localhost" if host in ("0.0.0.0", "::") else host
        return f"http://{shown}:{self.port}"

    def _count(self) -> int:
        with self._lock:
            return len(self._sessions)

    def sessions(self) -> dict[int, Session]:
        with self._lock:
            return dict(self._sessions)

    def wait_for_sessions(self, count: int, timeout: float = 10.0) -> list[Session]:
        """Block until at least ``count`` sessions exist (tests, benchmark)."""
        with self._connected:
            self._connected.wait_for(lambda: len(self._sessions) >= count, timeout)
            return list(self._sessions.values())

    async def _on_connect(self, client: viser.ClientHandle) -> None:
        senders_woken_on_their_loop(client)  # before the session pushes
        if handshake_origin(self.server, client.client_id) is None:  # a tool: no page, no link
            self._build(client, None)
            return
        # A web page says its address (the link it was opened with) once viser reads the
        # socket, after this handler: asked in a task of its own, which then builds the session.
        task = asyncio.get_running_loop().create_task(self._arrive(client))
        self._arrivals.add(task)
        task.add_done_callback(self._arrivals.discard)

    async def _arrive(self, client: viser.ClientHandle) -> None:
        self._build(client, await page_address(client, PAGE_TIMEOUT))

    def _build(self, client: viser.ClientHandle, address: str | None) -> None:
        # Not awaited: viser goes on with the socket. A failure is logged, as viser's would be.
        self.pool.submit(self._connect, client, address).add_done_callback(self._log_failure)

    async def _on_disconnect(self, client: viser.ClientHandle) -> None:
        self._disconnect(client)
        self.memory.departed()

    def _log_failure(self, future: Future[None]) -> None:
        """A session's build that raised: an error, unless the server was stopping (the build
        then meets a closed event loop, and nobody is left to serve)."""
        exc = future.exception() if not future.cancelled() else None
        if exc is not None and self._stopping.is_set():
            log.debug("a session being built as the server stopped: %r", exc)
        elif exc is not None:
            log.error("a session could not be built", exc_info=exc)

    def _connect(self, client: viser.ClientHandle, address: str | None = None) -> None:
        """Build the session outside the lock (30-300 ms), then register and start it under
        the lock, unless the client left meanwhile: then it is closed and never started. The
        page's ``address`` may carry a link to a state (:mod:`.ui.links`)."""
        with self._lock:
            if client.client_id in self._departed:
                self._departed.discard(client.client_id)
                self.discarded += 1
                return
        if self._stopping.is_set():
            return
        link = links.opening(address, self.preset, self.scene, (self.port, self.landing_port))
        options = SessionOptions(
            max_fps=self.max_fps,
            budget=self.budget,
            scene=link.scene,
            user_agent=self.guard.user_agent(client.client_id),
            follow=self.follow,
        )
        session = built_session(client, link, options)
        with self._connected:
            if self._stopping.is_set():
                left = True
            elif client.client_id in self._departed:
                self._departed.discard(client.client_id)
                self.discarded += 1
                left = True
            else:
                left = False
                self._sessions[client.client_id] = session
                self._share_frames()
                session.start()
                self._connected.notify_all()
        if left:
            session.close()
        else:
            self.memory.arrived()

    def _disconnect(self, client: viser.ClientHandle) -> None:
        with self._lock:
            session = self._sessions.pop(client.client_id, None)
            if session is None:  # its connect handler has not registered it (yet)
                self._departed.add(client.client_id)
            self._share_frames()
        if session is not None:
            session.close()

    def _share_frames(self) -> None:
        """Under ``_lock``: each browser's frame-rate cap for this many sharing the process."""
        cap = frame_share(self.max_fps, len(self._sessions))
        for session in self._sessions.values():
            session.pacer.max_fps = cap

    def pending_departures(self) -> int:
        """Clients that left before their session was registered, not yet reconciled."""
        with self._lock:
            return len(self._departed)

    def stop(self) -> None:
        self._stopping.set()
        self.follow.cast.close()
        self.backlog.stop()
        self.memory.stop()
        for session in self.sessions().values():
            session.close(timeout=2.0)
        self.server.stop()
        self.pool.shutdown(wait=False, cancel_futures=True)
