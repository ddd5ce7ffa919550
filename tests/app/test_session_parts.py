"""A session is composed, not reached through: its parts are given narrow things (its front,
the clock, the construction, callbacks), never the session itself, and following is the
motion source's one switch."""

from __future__ import annotations

import inspect
import types
from collections import deque

from conftest import session_of, wait_until

from poinsot.app.live.session.front import Front
from poinsot.app.live.session.session import Session
from poinsot.app.live.session.source import MotionSource


def _referents(obj: object) -> list[object]:
    """What a Poinsot object holds: its attributes, the items of its containers, a bound
    method's object and a function's closure."""
    if isinstance(obj, types.MethodType):
        return [obj.__self__, obj.__func__]
    if isinstance(obj, types.FunctionType):
        return [cell.cell_contents for cell in obj.__closure__ or ()]
    if isinstance(obj, dict):
        return [*obj.keys(), *obj.values()]
    if isinstance(obj, (list, tuple, set, frozenset, deque)):
        return list(obj)
    held = list(getattr(obj, "__dict__", {}).values())
    for cls in type(obj).__mro__:
        held += [getattr(obj, s, None) for s in getattr(cls, "__slots__", ())]
    return held


def _ours(obj: object) -> bool:
    """Poinsot's own objects, and the containers and callables that hold them (viser's,
    numpy's and the standard library's objects are not walked)."""
    if isinstance(obj, (types.MethodType, types.FunctionType, dict, list, tuple, set, deque)):
        return True
    return type(obj).__module__.startswith("poinsot.")


def _paths_to(session: Session) -> list[str]:
    """Every path from one of the session's parts back to the session."""
    seen: set[int] = {id(session)}
    queue = deque((f"session.{k}", v) for k, v in vars(session).items())
    found: list[str] = []
    while queue:
        path, obj = queue.popleft()
        if obj is session:
            found.append(path)
            continue
        if id(obj) in seen or not _ours(obj) or inspect.isclass(obj) or inspect.ismodule(obj):
            continue
        seen.add(id(obj))
        queue.extend((f"{path}>{type(held).__name__}", held) for held in _referents(obj))
    return found


def test_no_part_of_a_session_holds_the_session(poinsot_app, probe):
    session = session_of(poinsot_app)
    assert len(vars(session)) >= 20  # the parts are there to be walked
    assert _paths_to(session) == []
    # The tools hold the front, whose type says what it offers: no frame loop, no queue run.
    for tool in (session.pointer, session.sphere_pointer, session.layout, session.follow):
        assert tool.session is session.front and isinstance(tool.session, Front)
    assert session.lecture.session is session.front
    assert session.uploads.host is session.front
    assert session.panel.actions is session.front
    assert not hasattr(session.front, "loop") and not hasattr(session.front, "start")


def test_the_walk_finds_a_part_that_holds_the_session(poinsot_app, probe):
    """The check above can fail: a part given the session (a bound method of it, or itself)
    is found."""
    session = session_of(poinsot_app)
    session.pointer.back = session.start  # type: ignore[attr-defined]
    session.lecture.back = session  # type: ignore[attr-defined]
    try:
        paths = _paths_to(session)
    finally:
        del session.pointer.back  # type: ignore[attr-defined]
        del session.lecture.back  # type: ignore[attr-defined]
    assert len(paths) >= 2, paths


def test_following_is_the_motion_sources_one_switch(poinsot_app, probe):
    """The frame's time and the rebuild's caches come from the source: the session's own
    until it follows, the lead's (the hub's) while it does."""
    session = session_of(poinsot_app)
    source = session.source
    assert isinstance(source, MotionSource) and session.build.source is source
    assert not source.follows and source.holds_others
    assert source.motions is None and source.scenes is None
    session.follow.start_following()
    assert wait_until(lambda: source.follows, 15)
    hub = session.follow.hub
    assert source.motions is hub.motions and source.scenes is hub.scenes
    assert not source.holds_others
    assert hub.now() is None  # no lead yet: the session's own time goes on
    session.toggle_pause()
    assert wait_until(lambda: session.clock.paused, 15)
    assert source.now() == session.clock.now()


def test_a_deferred_action_waits_for_the_next_frame_and_a_posted_one_wakes_the_thread():
    """The readouts of a new body are deferred (:meth:`Front.defer`): they run before the
    frame thread's next frame, not at once, so that they do not compete with the sending of
    the new body's window; a request is posted and wakes the thread."""
    from poinsot.app.live.hardening.pacing import SessionStats
    from poinsot.app.live.session.actions import ActionQueue
    from poinsot.app.live.session.front import Status

    queue = ActionQueue()
    front = Front(None, None, None, queue, Status(SessionStats(), "parts"))  # type: ignore[arg-type]
    wakes: list[int] = []
    front.wake = lambda: wakes.append(1)
    ran: list[str] = []
    front.defer(lambda: ran.append("readouts"), "readouts")
    front.defer(lambda: ran.append("newer readouts"), "readouts")  # replaces the queued one
    assert wakes == [] and len(queue) == 1 and ran == []
    front.post(lambda: ran.append("slider"))
    assert wakes == [1] and len(queue) == 2
    queue.run(lambda exc: None)
    assert ran == ["newer readouts", "slider"]
