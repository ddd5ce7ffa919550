"""The lead's state between the workers of ``poinsot serve --workers N``.

Each worker holds one end of a duplex :func:`multiprocessing.Pipe` (its "feed"), the parent the
other. A worker's hub (:class:`~.classroom.follow.FollowHub`) sends its lead's messages up its feed;
the parent's :class:`Relay` passes each one to every other worker, in the order it came, and a
reader thread in each worker delivers them to its hub. A worker whose feed closes (it ended, even by
``kill -9``) while it held the lead: the relay tells the others that the lead is gone. Within one
host only (pipes between the processes of one machine)."""

from __future__ import annotations

import multiprocessing.connection
import threading
from collections.abc import Sequence
from multiprocessing.connection import Connection

from poinsot.app.live.classroom.follow import ENDED, FollowHub, Message


def worker_hub(feed: Connection, code: str) -> FollowHub:
    """A worker's hub, linked to the others through ``feed`` (a reader thread delivers)."""
    lock = threading.Lock()

    def uplink(message: Message) -> None:
        with lock:
            try:
                feed.send(message)
            except OSError:  # the parent is gone: the worker stops soon
                pass

    hub = FollowHub(code, uplink)

    def read() -> None:
        while True:
            try:
                message = feed.recv()
            except (EOFError, OSError):
                return
            hub.deliver(message)

    threading.Thread(target=read, name="poinsot-follow-feed", daemon=True).start()
    return hub


class Relay:
    """In the parent: every worker's follow messages to every other worker."""

    def __init__(self, feeds: Sequence[Connection]) -> None:
        self._feeds = list(feeds)
        self._lead: tuple[Connection, str] | None = None  # the lead's worker and token
        self._stop = threading.Event()
        #: Messages passed on (tests, load test).
        self.relayed = 0
        self._thread = threading.Thread(target=self._run, name="poinsot-relay", daemon=True)

    def start(self) -> Relay:
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(2.0)

    def _run(self) -> None:
        while self._feeds and not self._stop.is_set():
            for feed in multiprocessing.connection.wait(self._feeds, 0.5):
                assert isinstance(feed, Connection)
                try:
                    message = feed.recv()
                except (EOFError, OSError):  # the worker ended
                    self._ended(feed)
                    continue
                self._note(feed, message)
                self._pass(feed, message)

    def _note(self, feed: Connection, message: Message) -> None:
        if message[0] == "lead":
            self._lead = (feed, message[1])
        elif message[0] == "gone" and self._lead is not None and self._lead[1] == message[1]:
            self._lead = None

    def _ended(self, feed: Connection) -> None:
        self._feeds.remove(feed)
        if self._lead is not None and self._lead[0] is feed:
            token, self._lead = self._lead[1], None
            self._pass(feed, ("gone", token, ENDED))

    def _pass(self, source: Connection, message: Message) -> None:
        for feed in self._feeds:
            if feed is not source:
                try:
                    feed.send(message)
                except OSError:  # ended: its EOF comes next
                    continue
        self.relayed += 1
