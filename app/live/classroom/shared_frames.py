"""A follower's session's side of its process's cast (:mod:`.cast`): it joins the cast while its
frame is the lead's and leaves it at once when not, draws and rebuilds through the cast's gate,
hands its fit to the lead's new body round, and makes or waits for the lead's move."""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator
from typing import Any

import viser

from poinsot.app.construction.construction import PoinsotScene, no_fitting
from poinsot.app.construction.sampled.motion import Motion
from poinsot.app.live.classroom.cast import (
    FIT_WAIT,
    FollowCast,
    Member,
    Source,
    own_fps,
    updates_only,
)
from poinsot.app.live.hardening.pacing import Pacer
from poinsot.app.viser_private import held_back, queue_held


class SharedFrames:
    """A session's side of the cast (its frame thread only): :meth:`update` after its work."""

    def __init__(
        self, cast: FollowCast, client: viser.ClientHandle, pacer: Pacer, scene: PoinsotScene
    ) -> None:
        self.cast, self.client, self.pacer, self.scene = cast, client, pacer, scene
        #: Makes its frame loop's next frame due at once (set once the loop exists).
        self.draw_now: Callable[[], None] = lambda: None
        self.member: Member | None = None
        self._claimed = False  # it has asked for the lead's move since its last work
        self._made: Callable[[], None] | None = None  # its maker's: called once it is made
        self._query: str | None = None  # the lead's state it last opened

    @property
    def shared(self) -> bool:
        return self.member is not None

    def drawing(self) -> contextlib.AbstractContextManager[Any]:
        """Around an own frame or a rebuild of a member: the process's followers draw and
        rebuild one at a time (:attr:`FollowCast.draw_gate`). A hall's hundred frame threads
        would otherwise all want the interpreter at once (after the lead's move, all
        rebuilding), and the cast's thread, which poses them all, waits behind them; one at a
        time, it waits for one. The maker of the lead's move (:meth:`FollowCast.claim_move`)
        passes: every other follower waits for its new body, and the gate is no queue (a
        lock's next holder is whichever thread the system wakes first): in a hall of 150 a
        worker, wanted by the others' own frames and by the rebuilds of those that had waited
        long enough, it kept the maker from the new body 0.14 to 2.2 s after the move."""
        if self.member is None or self._made is not None:
            return contextlib.nullcontext()
        return self.cast.draw_gate

    def update(self, source: Source | None) -> None:
        """Join the cast with ``source``, or leave it at once (None)."""
        if source is None:
            self.leave()
            return
        member = self.member
        if member is None:
            member = self.member = self.cast.join(id(self), self.client)
            if member is None:  # its socket cannot be reached: its own frames, as ever
                return
            member.geometry = source.motion.geometry  # what its browser shows now
            self.scene.send_pose = False
            self.scene.fitting = self._fitting
        self.pacer.cap = own_fps(self.cast.members)
        shown = member.source
        if (
            shown is not None
            and member.geometry is not source.motion.geometry
            and shown.motion.geometry is member.geometry
            and shown.layout == source.layout
        ):
            # Its rebuild was of a lead's state left since, whose fit the cast did not send:
            # its browser shows the body a share took it to, posed from that body's motion
            # (posed from this one, it would turn wrongly, and hold the next move's frames:
            # :meth:`FollowCast.hold`), until its next rebuild.
            return
        member.source = source

    def leave(self) -> None:
        """Its own frames again, the next one at once, pose included."""
        if self.member is None:
            return
        self.cast.leave(id(self))
        self.member = None
        self.scene.send_pose = True
        self.scene.fitting = no_fitting
        self.pacer.cap = None
        self.draw_now()

    @contextlib.contextmanager
    def _fitting(self, motion: Motion) -> Iterator[None]:
        """The scene's fit to ``motion``'s body (its :attr:`~PoinsotScene.fitting`): what it
        queues is held back, and sent through the cast, to this follower and to the followers
        still showing the body this one showed (:meth:`FollowCast.share_fit`); dropped if the
        cast has sent it this body already, or if the lead has left the state it is of."""
        member = self.member
        if member is None:
            yield
            return
        geometry = motion.geometry
        before = self.cast.fitting(member, geometry)
        with held_back(self.client) as messages:
            try:
                yield
            except BaseException:
                self.cast.forget_geometry(member)
                raise
        if messages is None:  # sent as ever
            return
        if before is geometry and updates_only(messages) and not member.socket.failed:
            return  # its browser has this body: the messages would only repeat it
        if not self.cast.share_fit(member, before, motion, messages, self._query):
            # Sent as ever, after every window handed to it, so that no share older than
            # its own fit is written after it.
            member.socket.wait_written(FIT_WAIT)
            queue_held(self.client, messages)

    def moving(self, query: str) -> None:
        """The lead's new body or scene, its state of ``query``, is about to be opened (its
        frame thread): the first follower of the cast to open it makes it, the others wait for
        it here (:meth:`FollowCast.claim_move`); :meth:`worked` after its work."""
        member, self._query = self.member, query
        if member is not None and not self._claimed:
            self._claimed = True
            self._made = self.cast.claim_move(member)

    def worked(self) -> None:
        """The session's work before its frame is done (its rebuild included): if it made the
        lead's new body, the followers waiting for it go on."""
        made, self._made, self._claimed = self._made, None, False
        if made is not None:
            made()
