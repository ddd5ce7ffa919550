"""Following across hosts: the lead's messages through one Redis (``poinsot serve --redis URL``).

Every server process (each worker of every host) links its hub
(:class:`~.classroom.follow.FollowHub`) to one Redis channel with :class:`RedisLink`: what its hub
sends (its lead's "lead", "state" and "gone") is published there, and what the other processes
publish is delivered to its hub, so that one lead is followed on every host. Pub/sub, not a stream:
a follower needs only the newest state, the lead publishes its state again every quarter second
(``lead.REPUBLISH``), so a message lost while a host reconnects is superseded at once, and nothing
accumulates in Redis.

- The channel carries only the hub's messages, as JSON (:func:`encode`); a received one is
  parsed and validated field by field (:func:`decode`) and refused and counted
  (:attr:`RedisLink.refused`) if it does not parse or validate. A state carries its time at
  publication; the receiving host anchors it at its own clock on receipt (hosts' monotonic
  clocks are unrelated; the channel's latency is ignored).
- The lecturer code is shared through Redis (:func:`shared_code`): the first host to start sets
  it, the others read it; ``--lecturer-code`` sets it on every host instead.
- Redis unreachable at start: one line, and following stays within the host. Lost during a
  lecture: one line; the followers of a lead on another host keep its last state (told so), and
  the link reconnects every :data:`RETRY_SECONDS` (sleeping between tries) until it returns,
  when the lead's next state is followed again.

redis-py is an optional extra (``pip install 'poinsot[redis]'``), imported only with ``--redis``.
"""

from __future__ import annotations

import json
import logging
import math
import queue
import threading
import uuid
from typing import Any

from poinsot.app.live.classroom.follow import FollowHub, LeadState, Message

log = logging.getLogger(__name__)

CHANNEL = "poinsot:follow"
CODE_KEY = "poinsot:follow:code"
#: Seconds between two tries to reach a lost Redis, and a call's timeout.
RETRY_SECONDS = 1.0
TIMEOUT_SECONDS = 1.0
#: Messages waiting to be published; past it the oldest are dropped (a state supersedes them).
MAX_QUEUED = 64
#: Bounds of a message's fields (a state's query is a link's query).
MAX_TEXT = 4096
MAX_NAMES = 64
LOST = "The link between the classroom's servers was lost; you keep the last state."


class Junk(ValueError):
    """A message on the channel that does not parse or validate."""


def _text(value: Any, limit: int = MAX_TEXT) -> str:
    if not isinstance(value, str) or len(value) > limit:
        raise Junk("not a bounded string")
    return value


def _number(value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise Junk("not a finite number")
    return float(value)


def _names(value: Any) -> tuple[str, ...]:
    if not isinstance(value, list) or len(value) > MAX_NAMES:
        raise Junk("not a list of names")
    return tuple(_text(v, 64) for v in value)


def _camera(value: Any) -> tuple[tuple[float, ...], ...] | None:
    if value is None:
        return None
    if not isinstance(value, list) or len(value) != 3:
        raise Junk("not a camera")
    rows = []
    for row in value:
        if not isinstance(row, list) or len(row) != 3:
            raise Junk("not a camera")
        rows.append(tuple(_number(x) for x in row))
    return tuple(rows)


def encode(message: Message, origin: str, now: float) -> bytes:
    """A hub's message as the channel's JSON; a state's time taken at monotonic ``now``."""
    kind = message[0]
    body: dict[str, Any] = {"origin": origin, "kind": kind}
    if kind == "state":
        s: LeadState = message[1]
        body.update(
            leader=s.leader,
            query=s.query,
            t=s.time(now),
            paused=s.paused,
            speed=s.speed,
            camera=None if s.camera is None else [list(v) for v in s.camera],
            trail=s.trail,
            hidden=list(s.hidden),
            parts=list(s.parts),
        )
    else:
        body["token"] = message[1]
        if kind == "gone":
            body["message"] = message[2]
    return json.dumps(body, separators=(",", ":")).encode()


def decode(data: Any, now: float) -> tuple[str, Message]:
    """(origin, the hub's message) of a channel message received at monotonic ``now``; raises
    :class:`Junk` if it does not parse or validate."""
    try:
        body = json.loads(data)
    except (TypeError, ValueError, UnicodeDecodeError) as exc:
        raise Junk("not JSON") from exc
    if not isinstance(body, dict):
        raise Junk("not an object")
    origin, kind = _text(body.get("origin"), 64), body.get("kind")
    if kind in ("lead", "gone"):
        token = _text(body.get("token"), 64)
        if kind == "lead":
            return origin, ("lead", token)
        return origin, ("gone", token, _text(body.get("message"), 200))
    if kind != "state":
        raise Junk("no such kind")
    paused = body.get("paused")
    trail = body.get("trail")
    if not isinstance(paused, bool):
        raise Junk("paused is not a boolean")
    if trail is not None and (isinstance(trail, bool) or not isinstance(trail, int) or trail < 0):
        raise Junk("not a trail length")
    state = LeadState(
        leader=_text(body.get("leader"), 64),
        query=_text(body.get("query")),
        t=_number(body.get("t")),
        at=now,
        paused=paused,
        speed=_number(body.get("speed")),
        camera=_camera(body.get("camera")),
        trail=trail,
        hidden=_names(body.get("hidden", [])),
        parts=_names(body.get("parts", [])),
    )
    return origin, ("state", state)


def _client(url: str) -> Any:
    import redis  # the optional extra: only with --redis

    return redis.Redis.from_url(
        url, socket_timeout=TIMEOUT_SECONDS, socket_connect_timeout=TIMEOUT_SECONDS
    )


def _redis_errors() -> tuple[type[BaseException], ...]:
    import redis

    return (redis.RedisError, OSError)


def shared_code(url: str, given: str | None, fallback: str) -> tuple[str, str, bool]:
    """The lecturer code for every host, a line to print, and whether Redis answered:
    ``given`` (``--lecturer-code``) set in Redis, else the code already there, else ``fallback``
    set there. Redis unreachable: ``given or fallback``, a line saying following stays within
    this host, and False."""
    try:
        client = _client(url)
        if given:
            client.set(CODE_KEY, given)
            line = f"Redis {_safe(url)}: following across hosts, the lecturer code set there."
            return given, line, True
        client.set(CODE_KEY, fallback, nx=True)
        code = client.get(CODE_KEY)
        code = code.decode() if isinstance(code, bytes) else str(code)
        return (
            code,
            f"Redis {_safe(url)}: following across hosts, lecturer code shared there.",
            True,
        )
    except ImportError:
        line = "poinsot serve: --redis needs redis-py (pip install 'poinsot[redis]'); "
        return given or fallback, line + "following stays within this host.", False
    except _redis_errors() as exc:
        line = f"poinsot serve: Redis {_safe(url)} unreachable ({type(exc).__name__}); "
        return given or fallback, line + "following stays within this host.", False


def _safe(url: str) -> str:
    """The URL without its password (printed)."""
    if "@" not in url:
        return url
    scheme, _, rest = url.partition("://")
    return f"{scheme}://***@{rest.rpartition('@')[2]}"


class RedisLink:
    """One process's link between its hub and the channel: :meth:`start`, :meth:`close`."""

    def __init__(self, hub: FollowHub, url: str, channel: str = CHANNEL) -> None:
        self.hub, self.url, self.channel = hub, url, channel
        self.origin = uuid.uuid4().hex
        self._queue: queue.Queue[Message] = queue.Queue(MAX_QUEUED)
        self._stop = threading.Event()
        self._threads: list[threading.Thread] = []
        self.connected = threading.Event()
        #: Messages refused (junk), received, published; connections lost (tests, load test).
        self.refused = 0
        self.received = 0
        self.published = 0
        self.lost = 0

    def start(self) -> RedisLink:
        for target, name in ((self._subscribe, "sub"), (self._publish, "pub")):
            thread = threading.Thread(target=target, name=f"poinsot-redis-{name}", daemon=True)
            thread.start()
            self._threads.append(thread)
        return self

    def close(self, timeout: float = 2 * TIMEOUT_SECONDS + 1.0) -> None:
        self._stop.set()
        self._queue.put(("stop",))
        for thread in self._threads:
            thread.join(timeout)

    def send(self, message: Message) -> None:
        """The hub's uplink (any thread; never blocks): published by the link's thread."""
        while True:
            try:
                self._queue.put_nowait(message)
                return
            except queue.Full:
                try:
                    self._queue.get_nowait()  # the oldest: a newer state supersedes it
                except queue.Empty:
                    pass

    # -- the link's threads ----------------------------------------------------------------
    def _publish(self) -> None:
        import time

        client = _client(self.url)
        errors = _redis_errors()
        while not self._stop.is_set():
            message = self._queue.get()
            if message[0] == "stop":
                return
            try:
                client.publish(self.channel, encode(message, self.origin, time.monotonic()))
                self.published += 1
            except errors:  # lost: said by the subscriber; this message is superseded
                pass

    def _subscribe(self) -> None:
        errors = _redis_errors()
        while not self._stop.is_set():
            try:
                self._listen()
            except errors as exc:
                if self.connected.is_set():
                    self.connected.clear()
                    self.lost += 1
                    log.warning(
                        "Redis %s lost (%s): followers keep the last state; reconnecting.",
                        _safe(self.url),
                        type(exc).__name__,
                    )
                    self._keep_last_state()
            self._stop.wait(RETRY_SECONDS)

    def _listen(self) -> None:
        import time

        pubsub = _client(self.url).pubsub(ignore_subscribe_messages=True)
        try:
            pubsub.subscribe(self.channel)
            if not self.connected.is_set():
                if self.lost:
                    log.warning("Redis %s back: following across hosts again.", _safe(self.url))
                self.connected.set()
            while not self._stop.is_set():
                item = pubsub.get_message(timeout=TIMEOUT_SECONDS)
                if item is not None and item.get("type") == "message":
                    self._receive(item["data"], time.monotonic())
        finally:
            pubsub.close()

    def _receive(self, data: Any, now: float) -> None:
        try:
            origin, message = decode(data, now)
        except Junk as exc:
            self.refused += 1
            if self.refused == 1 or self.refused % 100 == 0:
                log.warning("Redis channel: a message refused (%s); %d so far", exc, self.refused)
            return
        if origin == self.origin:
            return  # this process's own, already delivered
        self.received += 1
        if message[0] == "state" and not self.hub.token:  # followed again after a loss
            self.hub.deliver(("lead", message[1].leader))
        self.hub.deliver(message)

    def _keep_last_state(self) -> None:
        """The lead, if on another host, is out of reach: its followers keep its last state."""
        token = self.hub.token
        if token and not self.hub.leads_here():
            self.hub.deliver(("gone", token, LOST))


def link_hub(hub: FollowHub, url: str) -> RedisLink:
    """Link ``hub`` to the channel at ``url``: its messages published, the others' delivered."""
    link = RedisLink(hub, url)
    hub.add_uplink(link.send)
    return link.start()
