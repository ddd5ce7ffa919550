"""The followers' frames encoded once per process (:mod:`poinsot.app.live.classroom.cast`).

Probes stand for the browsers; every wait is on an event they receive or a count the server
keeps, never on wall-clock time.
"""

from __future__ import annotations

import asyncio
import dataclasses
import threading
from types import SimpleNamespace

import numpy as np

from poinsot.app.devtools.probe import Probe, decode_frame
from poinsot.app.live.classroom import cast as cast_module
from poinsot.app.live.classroom.cast import (
    OWN_FPS,
    OWN_MIN_FPS,
    OWN_PROCESS_FRAMES,
    FollowCast,
    Member,
    Source,
    own_fps,
)
from poinsot.app.live.classroom.shared_frames import SharedFrames
from poinsot.app.model.elements import Element
from poinsot.app.viser_private import props_message, wire_message
from tests.app.test_follow import D, _follow, _lead, _ready, _says, _set
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


class _OwnedGate:
    """The cast's draw gate, saying which thread holds it."""

    def __init__(self, lock: threading.Lock) -> None:
        self.lock, self.holder = lock, 0

    def __enter__(self) -> None:
        self.lock.acquire()
        self.holder = threading.get_ident()

    def __exit__(self, *exc: object) -> None:
        self.holder = 0
        self.lock.release()


def test_a_process_s_followers_draw_their_own_frames_one_at_a_time(poinsot_app, make_probe):
    """A hall's followers would all want the interpreter at once, the cast's thread behind
    them: each shared follower draws its own frame holding the process's one gate; a detached
    one, its own again, draws without it."""
    _, probes, _, sessions = _class(poinsot_app, make_probe)
    cast = poinsot_app.follow.cast
    gate = cast.draw_gate = _OwnedGate(cast.draw_gate)  # type: ignore[assignment]
    held: dict[int, list[tuple[bool, bool]]] = {id(s): [] for s in sessions}
    for session in sessions:
        advance = session.scene.advance

        def recording(t, s=session, advance=advance):
            held[id(s)].append((s.shared.shared, gate.holder == threading.get_ident()))
            return advance(t)

        session.scene.advance = recording
    assert wait_until(lambda: all(len(v) >= 6 for v in held.values()), 30)
    detached = sessions[0]
    _set(probes[0], "Explore from here")
    assert wait_until(lambda: not detached.shared.shared, 30)
    count = len(held[id(detached)])
    assert wait_until(lambda: len(held[id(detached)]) >= count + 10, 30)
    for session in sessions:
        # Shared: drawn inside the gate, by its own thread; its own again: outside it. (Its
        # first frame recorded may have taken the gate before the gate was watched.)
        drawn = held[id(session)][1:]
        assert all(shared == inside for shared, inside in drawn), drawn
    assert any(not shared for shared, _ in held[id(detached)])


def test_a_process_s_followers_rebuild_the_lead_s_move_one_at_a_time_but_its_maker(
    poinsot_app, make_probe
):
    """After the lead's move every follower of the process rebuilds: each holds the gate its
    own frames pass (the cast's thread then waits for one, not for all), but for the move's
    maker, whom the others wait for (the gate is no queue: in a hall, behind the others' own
    frames, it kept the maker from the new body up to 2 s); the lead, no follower, rebuilds
    without it."""
    lead, _, _, sessions = _class(poinsot_app, make_probe, followers=3)
    cast = poinsot_app.follow.cast
    gate = cast.draw_gate = _OwnedGate(cast.draw_gate)  # type: ignore[assignment]
    everyone = list(poinsot_app.sessions().values())
    held: dict[int, list[bool]] = {id(s): [] for s in everyone}
    for session in everyone:
        rebuild = session.build.rebuild

        def recording(showcase, s=session, rebuild=rebuild):
            held[id(s)].append(gate.holder == threading.get_ident())
            return rebuild(showcase)

        session.build.rebuild = recording
    _set(lead, D, 2.3)
    assert wait_until(lambda: all(held[id(s)] for s in everyone), 30), held
    # Each follower's rebuild of the move: the maker's outside, the two others' inside.
    assert sorted(held[id(s)][0] for s in sessions) == [False, True, True], held
    (leader,) = [s for s in everyone if s not in sessions]
    assert not any(held[id(leader)]), held[id(leader)]  # the lead's: outside


def test_the_cast_holds_its_frames_for_a_session_s_rebuild_as_a_session_holds_its_own(
    poinsot_app, make_probe
):
    """A session's own rebuild (the lead's move among them) holds the other sessions' frames
    (:class:`~poinsot.app.live.hardening.budget.RebuildGate`), the followers' shared ones
    too, each for at most ``HOLD_SECONDS``: a rebuild that never ends (here) does not freeze
    the hall."""
    _, _, frames, sessions = _class(poinsot_app, make_probe)
    cast = poinsot_app.follow.cast
    with poinsot_app.budget.rebuild():
        held = cast.held
        assert wait_until(lambda: cast.held > held, 30)
        starts = [len(f) for f in frames]
        assert wait_until(
            lambda: all(len(f) >= s + 2 for f, s in zip(frames, starts, strict=True)), 30
        )
        held, ticks = cast.held, cast.ticks  # its hold is over: no tick is held any more
        assert wait_until(lambda: cast.ticks >= ticks + 3, 30)
        assert cast.held == held
    starts = [len(f) for f in frames]
    assert wait_until(lambda: all(len(f) >= s + 2 for f, s in zip(frames, starts, strict=True)), 30)


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
    assert own_fps(1) == own_fps(20) == own_fps(40) == OWN_FPS
    assert own_fps(60) == OWN_PROCESS_FRAMES / 60 < OWN_FPS
    assert own_fps(150) == OWN_PROCESS_FRAMES / 150 < 1.0  # a hall of 300 on two workers
    assert own_fps(240) == own_fps(400) == OWN_MIN_FPS  # traces and plot every 2 s, at least
    # Their sum is bounded up to 240 followers a process.
    assert max(n * own_fps(n) for n in range(1, 241)) <= OWN_PROCESS_FRAMES + 1e-9


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
    cast.hold("held by the test")
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


ELLIPSOID = "/space/body/ellipsoid"


class Sizes:
    """The ellipsoid's sizes a probe is sent (each update of its scale), and their windows."""

    def __init__(self, probe: Probe) -> None:
        self.scales: list[tuple[float, ...]] = []
        self.windows: list[bytes] = []
        self._lock = threading.Lock()
        probe.add_raw_listener(self._on_frame)

    def _on_frame(self, frame: bytes) -> None:
        for m in decode_frame(frame):
            if m.get("name") == ELLIPSOID and "scale" in m.get("updates", {}):
                with self._lock:
                    self.scales.append(tuple(m["updates"]["scale"]))
                    self.windows.append(frame)


def _fitted_content(frame: bytes) -> tuple[tuple[object, ...], ...]:
    """A fit's window, its owner aside."""
    return tuple(
        (m["type"], m["name"], repr(m.get("updates")), repr(m.get("position")))
        for m in decode_frame(frame)
    )


def test_a_lead_s_move_is_fitted_once_and_handed_to_every_follower(
    poinsot_app, make_probe, monkeypatch
):
    """The lead's new body: the first follower of the process to open it makes it (the others
    wait for it: a bound long enough here that none stops waiting), and what its drawings'
    fit queued goes, encoded once, to it and to every other follower; their own fits to the
    same body send nothing. Each browser is sent the new size once, the session's own."""
    monkeypatch.setattr(cast_module, "MAKER_WAIT", 60.0)
    lead, probes, _, sessions = _class(poinsot_app, make_probe, followers=4)
    cast = poinsot_app.follow.cast
    sizes = [Sizes(p) for p in probes]
    fits, copies = cast.fits, cast.fit_copies
    generations = [s.generation for s in sessions]
    _set(lead, "I₂", 1.7)
    for session, generation in zip(sessions, generations, strict=True):
        assert wait_until(lambda s=session, g=generation: s.generation > g, 30)
    assert cast.fits == fits + 1 and cast.fit_copies == copies + len(sessions) - 1
    meshes = [s.scene.drawing(Element.ELLIPSOID).mesh for s in sessions]
    assert wait_until(lambda: all(len(z.scales) >= 1 for z in sizes), 30)
    for size, mesh in zip(sizes, meshes, strict=True):
        assert len(size.scales) == 1, size.scales  # the cast's copy alone, not its own too
        assert np.allclose(size.scales[0], mesh.scale)
    # The same window for all, each stamped with its own follower's owner.
    assert len({_fitted_content(z.windows[0]) for z in sizes}) == 1
    owners = [set().union(*map(_owners, z.windows)) for z in sizes]
    assert all(len(o) == 1 for o in owners) and len(set.union(*owners)) == len(sessions)
    assert all(s.stats.errors == 0 for s in sessions)


def test_followers_that_wait_no_longer_send_their_own_fit_and_still_show_the_new_body(
    poinsot_app, make_probe, monkeypatch
):
    """A maker slower than the others' wait (none here): each follower makes the body itself,
    sent through the cast as the maker's is, and every browser still ends with the new size."""
    monkeypatch.setattr(cast_module, "MAKER_WAIT", 0.0)
    lead, probes, _, sessions = _class(poinsot_app, make_probe, followers=3)
    sizes = [Sizes(p) for p in probes]
    generations = [s.generation for s in sessions]
    _set(lead, "I₂", 1.9)
    for session, generation in zip(sessions, generations, strict=True):
        assert wait_until(lambda s=session, g=generation: s.generation > g, 30)
    meshes = [s.scene.drawing(Element.ELLIPSOID).mesh for s in sessions]
    shown = list(zip(sizes, meshes, strict=True))
    assert wait_until(
        lambda: all(z.scales and np.allclose(z.scales[-1], m.scale) for z, m in shown), 30
    )
    assert all(1 <= len(z.scales) <= len(sessions) for z in sizes)


class _Socket:
    """A follower's socket, as :func:`send_each` hands it windows (nothing written)."""

    def __init__(self, loop) -> None:
        self.loop, self.busy, self.handed, self.sent, self.failed = loop, False, 0, 0, 0


class _Loop:
    def __init__(self) -> None:
        self.calls: list[object] = []

    def call_soon_threadsafe(self, callback, *args) -> None:
        self.calls.append(args)


def _member(socket: _Socket, source: Source, geometry: object) -> Member:
    member = Member.__new__(Member)
    member.socket, member.owner, member.source = socket, f"owner-{id(socket)}", source
    member.geometry, member.shown = geometry, None
    return member


def test_a_new_body_goes_only_to_followers_showing_the_body_its_maker_showed():
    """A share takes a follower from the body its maker showed to the new one: a follower
    sent another body since (a newer move it made itself, or no known body) is not sent it,
    nor one that draws on other nodes; those sent it pose the new motion from then on."""
    geometry = [object(), object(), object()]  # what three motions' bodies would be
    motions = [SimpleNamespace(geometry=g) for g in geometry]
    loop = _Loop()
    cast = FollowCast(lambda: None)
    source = Source(motions[0], "/space/body", "/space/tip", None, frozenset({Element.ELLIPSOID}))
    other_nodes = Source(motions[0], "/views/body", "/views/tip", None, source.elements)
    sender = _member(_Socket(loop), source, geometry[0])
    behind = _member(_Socket(loop), source, geometry[0])
    newer = _member(_Socket(loop), source, geometry[2])
    unknown = _member(_Socket(loop), source, None)
    elsewhere = _member(_Socket(loop), other_nodes, geometry[0])
    for key, member in enumerate((sender, behind, newer, unknown, elsewhere)):
        cast._members[key] = member
    update = props_message("/space/body/ellipsoid", {"scale": (1.0, 0.8, 0.6)})
    assert cast.share_fit(sender, geometry[0], motions[1], [update], cast.query)
    assert behind.geometry is geometry[1] and behind.source.motion is motions[1]
    assert sender.source.motion is motions[1]  # posed from the new body at once, as the others
    assert newer.geometry is geometry[2] and unknown.geometry is None
    assert elsewhere.geometry is geometry[0] and elsewhere.source.motion is motions[0]
    handed = [socket for call in loop.calls for socket, _ in call[0]]
    assert handed == [sender.socket, behind.socket] and cast.fit_copies == 1
    # Not only node updates (a node removed): nothing is handed, the follower sends its own.
    removed = wire_message("RemoveSceneNodeMessage", "/space/body/solid")
    assert not cast.share_fit(sender, geometry[1], motions[2], [update, removed], cast.query)
    assert behind.geometry is geometry[1] and len(loop.calls) == 1


@dataclasses.dataclass
class _Hall:
    """A cast of three followers showing body A (``late``, ``maker``, ``other``), a lead's
    two bodies' motions ``a`` and ``b``, and a fit's node update."""

    a: SimpleNamespace
    b: SimpleNamespace
    loop: _Loop
    cast: FollowCast
    source: Source
    late: Member
    maker: Member
    other: Member
    update: object


def _hall_on_a() -> _Hall:
    a, b = SimpleNamespace(geometry=object()), SimpleNamespace(geometry=object())
    loop = _Loop()
    cast = FollowCast(lambda: None)
    source = Source(a, "/space/body", "/space/tip", None, frozenset({Element.ELLIPSOID}))
    late, maker, other = (_member(_Socket(loop), source, a.geometry) for _ in range(3))
    cast._members.update(enumerate((late, maker, other)))
    update = props_message("/space/body/ellipsoid", {"scale": (1.0, 0.8, 0.6)})
    return _Hall(a, b, loop, cast, source, late, maker, other, update)


def test_a_fit_of_a_state_the_lead_has_left_goes_to_nobody():
    """A lead going back and forth between two bodies (A, B, A: the process keeps their
    motions, so A's geometry comes back). A follower whose session took the state of the move
    to B, and fits B after the move back to A was handed round, sends nothing: its browser
    shows A, as every other (a fit handed round would take them all back to B, each of their
    own fits then all the others forth again); its next rebuild is of A."""
    hall = _hall_on_a()
    a, b, loop, cast = hall.a, hall.b, hall.loop, hall.cast
    late, maker, other, update = hall.late, hall.maker, hall.other, hall.update
    for query, motion in (("I=1,1.9,3", b), ("I=1,1.7,3", a)):  # to B, and back to A
        cast.hold(query)
        assert cast._holding(list(cast._members.values()))
        before = cast.fitting(maker, motion.geometry)
        assert cast.share_fit(maker, before, motion, [update], query)
        assert late.geometry is motion.geometry and other.geometry is motion.geometry
        # Every browser shows the new body, the maker's too: the hold ends with the share
        # (not with the maker's own rebuild, which the move's latency does not wait for).
        assert not cast._holding(list(cast._members.values()))
    calls, fits = len(loop.calls), cast.fits
    before = cast.fitting(late, b.geometry)  # its fit of the move to B, late
    assert cast.share_fit(late, before, b, [update], "I=1,1.9,3")  # taken care of: no window
    assert late.geometry is a.geometry and other.geometry is a.geometry
    assert len(loop.calls) == calls and cast.fits == fits


def test_a_late_rebuild_of_a_left_state_keeps_its_follower_posed_from_the_body_it_shows():
    """The follower whose fit of a left state went to nobody (above) ends its rebuild of that
    state: the cast goes on posing it from the body its browser shows, not from the left
    state's (its body would turn as the other one does; and the next move to that state would
    find a member posing the new motion already, and hold every frame for its whole bound)."""
    hall = _hall_on_a()
    a, b, cast, source = hall.a, hall.b, hall.cast, hall.source
    late, maker, update = hall.late, hall.maker, hall.update
    for query, motion in (("I=1,1.9,3", b), ("I=1,1.7,3", a)):  # to B, and back to A
        cast.hold(query)
        assert cast.share_fit(maker, cast.fitting(maker, motion.geometry), motion, [update], query)
    assert cast.share_fit(late, cast.fitting(late, b.geometry), b, [update], "I=1,1.9,3")
    frames = SharedFrames.__new__(SharedFrames)  # its session's side, its rebuild of B over
    frames.cast, frames.member, frames.pacer = cast, late, SimpleNamespace(cap=None)
    frames.update(dataclasses.replace(source, motion=b))
    assert late.source.motion is a and late.geometry is a.geometry
    # The lead to B again: the cast holds its frames until B's maker has handed B round.
    cast.hold("I=1,1.9,3b")
    assert cast._holding(list(cast._members.values()))
    before = cast.fitting(maker, b.geometry)
    assert cast.share_fit(maker, before, b, [update], "I=1,1.9,3b")
    assert not cast._holding(list(cast._members.values()))
    # A rebuild whose body its browser was sent (its own fit, or a share's): posed from it.
    frames.update(dataclasses.replace(source, motion=b))
    assert late.source.motion is b
