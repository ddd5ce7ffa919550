"""The followers' frames encoded once per process (:mod:`poinsot.app.live.classroom.cast`).

Probes stand for the browsers; every wait is on an event they receive or a count the server
keeps, never on wall-clock time.
"""

from __future__ import annotations

import asyncio
import threading

import numpy as np

from poinsot.app.devtools.probe import Probe, decode_frame
from poinsot.app.live.classroom.cast import OWN_FPS, OWN_MIN_FPS, OWN_PROCESS_FRAMES, own_fps
from tests.app.test_follow import _follow, _lead, _ready, _says, _set
from tests.conftest import wait_until

POSE = "/space/body"


class Frames:
    """The raw frames a probe receives that carry the body's pose, and their messages."""

    def __init__(self, probe: Probe) -> None:
        self.raw: list[bytes] = []
        self._lock = threading.Lock()
        probe.add_raw_listener(self._on_frame)

    def _on_frame(self, frame: bytes) -> None:
        messages = decode_frame(frame)
        if any(m["type"] == "SetOrientationMessage" and m.get("name") == POSE for m in messages):
            with self._lock:
                self.raw.append(frame)

    def since(self, start: int) -> list[bytes]:
        with self._lock:
            return self.raw[start:]

    def __len__(self) -> int:
        with self._lock:
            return len(self.raw)


def _class(app, make_probe, followers: int = 2):
    lead = _ready(make_probe(app))
    _lead(lead, app.follow.code)
    probes = [_ready(make_probe(app)) for _ in range(followers)]
    frames = [Frames(p) for p in probes]
    for probe in probes:
        _follow(probe)
    sessions = sorted(app.sessions().values(), key=lambda s: s.client.client_id)[1:]
    assert wait_until(lambda: all(s.shared.shared for s in sessions), 30), "never shared"
    return lead, probes, frames, sessions


#: The messages of the cast's window (:meth:`poinsot.app.live.classroom.cast.Source.messages`).
CAST_TYPES = {"SetOrientationMessage", "SetPositionMessage", "SceneNodeUpdateMessage"}


def _is_cast(frame: bytes) -> bool:
    """A window of the cast's: the pose messages alone. A session's own frame that carries the
    pose (sent before it joined the cast, and still in its queue) has others (its traces, its
    time readout)."""
    return all(m["type"] in CAST_TYPES and "name" in m for m in decode_frame(frame))


def _content(frame: bytes) -> tuple[tuple[object, ...], ...]:
    """A pose frame's messages, their owner aside (what two followers' copies share)."""
    return tuple(
        (m["type"], m["name"], repr(m.get("wxyz")), repr(m.get("position")))
        for m in decode_frame(frame)
    )


def _owners(frame: bytes) -> set[str]:
    return {str(m.get("owner")) for m in decode_frame(frame)}


def test_followers_of_one_worker_receive_one_window_each_for_its_own_nodes(poinsot_app, make_probe):
    """One window a frame for both followers, each copy stamped with the owner of that
    follower's nodes (viser's client applies a pose to that scope's node only): the poses
    move each probe's body, as they move a browser's (``tests/browser/test_live_page.py``)."""
    _, probes, frames, sessions = _class(poinsot_app, make_probe)
    cast = poinsot_app.follow.cast
    starts = [len(f) for f in frames]
    turned = [p.snapshot()[0][POSE].wxyz for p in probes]
    dropped = [p.dropped for p in probes]
    assert wait_until(
        lambda: all(len(f) >= s + 20 for f, s in zip(frames, starts, strict=True)), 30
    )
    received = [f.since(s) for f, s in zip(frames, starts, strict=True)]
    # A session's own frame with the pose can still be on its way at the join (a few: it was
    # queued before); every other frame that poses the body is the cast's.
    assert all(sum(not _is_cast(f) for f in r) <= 2 for r in received), received
    first, second = ([f for f in r if _is_cast(f)] for r in received)
    common = {_content(f) for f in first} & {_content(f) for f in second}
    # Most frames are common (a frame one of them skipped, still writing the last, is the only
    # difference), and each follower's copies carry its own nodes' owner, no other.
    assert len(common) >= 10, (len(first), len(second), len(common))
    owners = [p.snapshot()[0][POSE].owner for p in probes]
    assert owners[0] != owners[1] and "" not in owners
    for probe_frames, owner in zip((first, second), owners, strict=True):
        assert set().union(*map(_owners, probe_frames)) == {owner}
    assert cast.encoded > 0 and cast.handed >= 2 * len(common)
    # Every pose applies: each body turned, nothing dropped (a pose sent for another scope's
    # node would be, and the follower's body would stand still in its browser).
    for probe, before, drops in zip(probes, turned, dropped, strict=True):
        assert probe.snapshot()[0][POSE].wxyz != before
        assert probe.dropped == drops
    # What they are: viser's own window of the body's pose, its tip and the ω arrow, which
    # the probe (a decoder of viser's wire format) reads as any frame of a session's own.
    messages = decode_frame(first[-1])
    assert [m["type"] for m in messages][:2] == ["SetOrientationMessage", "SetPositionMessage"]
    assert np.isclose(np.linalg.norm(messages[0]["wxyz"]), 1.0)
    # Their sessions draw their own frames (traces, labels, plot) at the follower's low rate,
    # without the pose: the session's frames are far fewer than the frames received.
    for session in sessions:
        assert session.pacer.cap == OWN_FPS and session.scene.send_pose is False


def test_a_detached_follower_encodes_its_own_frames_again(poinsot_app, make_probe):
    _, probes, frames, sessions = _class(poinsot_app, make_probe)
    cast = poinsot_app.follow.cast
    detached, kept = sessions
    _set(probes[0], "Explore from here")
    assert probes[0].wait_for(lambda p: _says(p, "Exploring on your own"), 30)
    assert wait_until(lambda: not detached.shared.shared, 30)
    assert cast.members == 1 and kept.shared.shared
    assert detached.pacer.cap is None and detached.scene.send_pose is True
    # From now on its poses come from its own session's frames: the cast hands windows to the
    # kept follower only (one a frame it received; one more may have been in flight).
    drawn = detached.stats.frames
    start0, start1, handed = len(frames[0]), len(frames[1]), cast.handed
    assert wait_until(lambda: len(frames[0]) >= start0 + 20 and len(frames[1]) >= start1 + 5, 30)
    assert detached.stats.frames >= drawn + 15  # its own frame rate again, not OWN_FPS
    assert cast.handed - handed <= len(frames[1]) - start1 + 2


class _Stuck:
    """A follower's connection whose transport has paused writing until released (a socket that
    does not drain: its browser reads nothing, or the network to it is gone). Its writes reach
    the real connection."""

    def __init__(self, connection, loop) -> None:
        self.connection, self.loop = connection, loop
        self.release = asyncio.Event()
        self.writes = 0
        self.paused = True
        self.send_in_progress = None
        self.protocol = self  # its protocol's send_binary is its own (counted)

    def send_binary(self, data: bytes) -> None:
        self.writes += 1
        self.connection.protocol.send_binary(data)

    def send_data(self) -> None:
        self.connection.send_data()

    async def drain(self) -> None:
        await self.release.wait()
        self.paused = False


def test_a_slow_follower_does_not_hold_the_others(poinsot_app, make_probe):
    _, probes, frames, sessions = _class(poinsot_app, make_probe, followers=3)
    cast = poinsot_app.follow.cast
    slow = sessions[0].shared.member
    assert slow is not None
    stuck = _Stuck(slow.socket.connection, slow.socket.loop)
    slow.socket.connection = stuck
    assert wait_until(lambda: slow.skipped >= 20, 60), "the stuck follower was never skipped"
    # Meanwhile the others go on receiving the frames the cast makes, and the stuck one was
    # handed one window only: its backlog is that window, whatever the others are sent.
    starts = [len(f) for f in frames[1:]]
    skipped = slow.skipped
    assert wait_until(
        lambda: all(len(f) >= s + 40 for f, s in zip(frames[1:], starts, strict=True)), 60
    )
    assert slow.skipped >= skipped + 30 and stuck.writes == 1 and slow.socket.busy
    assert cast.members == 3
    # Its socket drains again: it is sent frames again.
    count = len(frames[0])
    stuck.loop.call_soon_threadsafe(stuck.release.set)
    assert wait_until(lambda: len(frames[0]) >= count + 10, 60)
    assert stuck.writes >= 10


def test_a_large_hall_s_followers_draw_fewer_own_frames_each():
    assert own_fps(1) == own_fps(20) == OWN_FPS
    assert own_fps(40) == OWN_PROCESS_FRAMES / 40 < OWN_FPS
    assert own_fps(75) == own_fps(300) == OWN_MIN_FPS  # traces and plot twice a second
    assert max(n * own_fps(n) for n in range(1, 61)) <= OWN_PROCESS_FRAMES + 1e-9  # bounded


def test_a_follower_s_own_view_falls_back_to_its_own_frames_and_back(poinsot_app, make_probe):
    """A ride-along camera or a ghost is the follower's own: its session draws all of its
    frames again (the pose included) while it lasts, and shares the lead's once it ends."""
    _, _, _, sessions = _class(poinsot_app, make_probe)
    own, kept = sessions
    cast = poinsot_app.follow.cast
    for start, end in (
        (lambda: own.lecture.set_camera("ride-along"), lambda: own.lecture.set_camera("default")),
        (lambda: own.ghost.configure(enabled=True), lambda: own.ghost.configure(enabled=False)),
    ):
        start()
        own.loop.wake()
        assert wait_until(lambda: not own.shared.shared, 30), "never fell back"
        assert own.scene.send_pose and own.pacer.cap is None and cast.members == 1
        assert kept.shared.shared
        end()
        own.loop.wake()
        assert wait_until(lambda: own.shared.shared, 30), "never shared again"
        assert not own.scene.send_pose and cast.members == 2


def test_a_follower_drawing_other_nodes_is_sent_its_own_group_s_window(poinsot_app, make_probe):
    """Followers are grouped by what they pose: one without the ω arrow (not drawn in its
    scene) gets a window of its own group, encoded once for that group, without the arrow."""
    _, probes, frames, sessions = _class(poinsot_app, make_probe)
    member = sessions[0].shared.member
    assert member is not None and member.source is not None and member.source.arrow
    # What its session's frame thread would set before each frame if its scene drew no ω
    # arrow. An update already under way sets the source with the arrow once more: two frames
    # later, none is.
    source = member.source
    without = type(source)(source.motion, source.body, source.tip, None)
    sessions[0].shared.update = lambda _source: setattr(member, "source", without)
    drawn = sessions[0].stats.frames
    assert wait_until(lambda: sessions[0].stats.frames >= drawn + 2, 30)
    start = len(frames[0])
    encoded = poinsot_app.follow.cast.encoded
    pose = ["SetOrientationMessage", "SetPositionMessage"]

    def since_switch() -> list[list[str]]:
        """Its windows from the first without the arrow on (those already on their way when
        the source changed still carry it: how many depends on how busy the machine is)."""
        types = [[m["type"] for m in decode_frame(f)] for f in frames[0].since(start)]
        return types[types.index(pose) :] if pose in types else []

    assert wait_until(lambda: len(since_switch()) >= 10, 30)
    types = since_switch()
    assert all(t == pose for t in types), types
    # Two groups now: two windows a frame (one each), never one per follower of a group.
    assert poinsot_app.follow.cast.encoded - encoded >= len(types)


def test_a_follower_that_leaves_leaves_the_cast(poinsot_app, make_probe):
    _, probes, frames, sessions = _class(poinsot_app, make_probe)
    cast = poinsot_app.follow.cast
    assert cast.members == 2
    probes[0].close()
    assert wait_until(lambda: cast.members == 1, 30), "the departed follower is still sent frames"
    start = len(frames[1])
    assert wait_until(lambda: len(frames[1]) >= start + 10, 30)  # the other one goes on


def test_a_move_holds_the_cast_s_frames_until_its_followers_rebuilt_at_most_a_bound(
    poinsot_app, make_probe
):
    """While every follower rebuilds the lead's new body, the cast sends nothing (the poses of
    the old one are outdated, and the rebuilds have the interpreter to themselves); it goes on
    once each poses the new motion, and a hold nobody ends (no follower rebuilds) lasts at most
    its bound."""
    lead, probes, frames, sessions = _class(poinsot_app, make_probe)
    cast = poinsot_app.follow.cast
    # A hold with nothing to end it: the frames stop (one tick's may still be in flight), then
    # come again once its bound has passed.
    held, handed = cast.held, cast.handed
    cast.hold()
    assert wait_until(lambda: cast.held >= held + 3, 30)
    assert cast.handed <= handed + len(sessions)
    assert wait_until(lambda: cast.handed > handed + 2 * len(sessions), 30)
    # A move: the hub holds the cast when the lead's body changes; every follower rebuilds and
    # poses the new motion, and the cast sends their frames again.
    old = {id(s.shared.member.source.motion) for s in sessions}
    generations = [s.generation for s in sessions]
    _set(lead, "D = |L|²/2T", 2.3)
    for session, generation in zip(sessions, generations, strict=True):
        assert wait_until(lambda s=session, g=generation: s.generation > g, 30)
    assert wait_until(
        lambda: all(
            s.shared.member is not None
            and s.shared.member.source is not None
            and id(s.shared.member.source.motion) not in old
            for s in sessions
        ),
        30,
    )
    handed = cast.handed
    assert wait_until(lambda: cast.handed >= handed + 2 * len(sessions), 30)
    starts = [len(f) for f in frames]
    assert wait_until(lambda: all(len(f) >= s + 2 for f, s in zip(frames, starts, strict=True)), 30)
