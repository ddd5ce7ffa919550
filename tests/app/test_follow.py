"""Follow the lecturer: a lead, its followers on two workers, and what a follower may not do.

Headless probes stand for the browsers (:mod:`poinsot.app.devtools.probe`); every wait is on
an event the probes receive (a widget's value, a readout's text), never on wall-clock time.
"""

from __future__ import annotations

import asyncio
import multiprocessing
import re
import threading
import types
from typing import Any

import pytest

from poinsot.app.construction.sampled.motion import KEPT_BATCHES
from poinsot.app.devtools.probe import Probe
from poinsot.app.live.classroom import links
from poinsot.app.live.classroom.follow import ENDED, MAX_WRONG_CODES, FollowHub, LeadState
from poinsot.app.live.classroom.lead import HELD
from poinsot.app.live.panel.body_controls import run_writes
from poinsot.app.live.panel.widgets import on_loop
from poinsot.app.live.relay import Relay
from poinsot.app.model.elements import Element
from poinsot.app.viser_private import wire_message
from tests.app.test_workers import start_classroom, stop_classroom
from tests.conftest import after_frames, session_of, wait_until

D = "D = |L|²/2T"
POLHODES = "Scene: the polhode family"
FAMILY = "polhode family (by kind)"  # one of that scene's parts


def _markdown(probe: Probe, prefix: str) -> str:
    """The text of the probe's markdown widget that starts with ``prefix`` ("" if none)."""
    _, widgets = probe.snapshot()
    for widget in widgets.values():
        text = str(widget.props.get("_markdown", ""))
        # (a table may stand under a headline: its header row starts a line of the text)
        if widget.type == "GuiMarkdownMessage" and (
            text.startswith(prefix) or f"\n{prefix}" in text
        ):
            return text
    return ""


def _says(probe: Probe, words: str) -> bool:
    _, widgets = probe.snapshot()
    return any(words in str(w.props.get("_markdown", "")) for w in widgets.values())


def _value(probe: Probe, label: str) -> object:
    return probe.widget(label)[1].value


def _set(probe: Probe, label: str, value: object = True) -> None:
    probe.set_value(probe.widget(label)[0], value)


def _ready(probe: Probe) -> Probe:
    """The probe, once the class folder answers: its widgets are sent before their callbacks
    are bound (a click in between was lost, once in 23 runs beside four busy loops); the
    lecture's keys line is made after, by the tools the session mounts last."""
    assert probe.wait_for(lambda p: p.has_widget("Explore from here"), 60), "no panel"
    assert probe.wait_for(lambda p: _says(p, "Keys: **space**"), 60), "no lecture tools"
    return probe


def _lead(probe: Probe, code: str) -> None:
    _set(probe, "Lecturer code", code)
    _set(probe, "Lead this class")
    assert probe.wait_for(lambda p: _says(p, "You lead this class"), 30), _texts(probe)


def _texts(probe: Probe) -> list[str]:
    """Every markdown text the probe shows (what a failed wait saw)."""
    _, widgets = probe.snapshot()
    return [
        str(w.props.get("_markdown", ""))[:120]
        for w in widgets.values()
        if w.props.get("_markdown")
    ]


def _follow(probe: Probe) -> None:
    _set(probe, "Follow the lecturer", True)
    assert probe.wait_for(lambda p: _says(p, "Following the lecturer"), 30)


def _class_of_three(app, make_probe) -> tuple[Probe, list[Probe], Any, list[Any]]:
    """A lead and three followers in ``app``'s process: their probes, then their sessions."""
    lead = _ready(make_probe(app))
    _lead(lead, app.follow.code)
    probes = [_ready(make_probe(app)) for _ in range(3)]
    for probe in probes:
        _follow(probe)
    lead_session, *followers = sorted(app.sessions().values(), key=lambda s: s.client.client_id)
    return lead, probes, lead_session, followers


# -- one lead, three followers, two workers ------------------------------------------------
@pytest.mark.slow
def test_followers_on_two_workers_follow_detach_and_keep_the_last_state():
    room = start_classroom()
    probes: list[Probe] = []
    try:
        code = re.search(r"Lecturer code: (\w+)", "".join(room.stdout)).group(1)
        first, second = room.worker_ports
        lead, *followers = [_ready(Probe(p)) for p in (first, first, second, second)]
        probes += [lead, *followers]
        _lead(lead, code)
        for follower in followers:
            _follow(follower)

        # A slider move: every follower's slider and body readouts show the lead's.
        before = _markdown(lead, "| quantity")
        _set(lead, D, 2.3)
        assert lead.wait_for(lambda p: _markdown(p, "| quantity") != before, 30)
        table = _markdown(lead, "| quantity")
        for follower in followers:
            assert follower.wait_for(lambda p: _value(p, D) == pytest.approx(2.3), 30)
            assert follower.wait_for(lambda p: _markdown(p, "| quantity") == table, 30)

        # A scene change, then a pause: the followers show the scene, paused at the lead's t.
        _set(lead, "Preset", POLHODES)
        for follower in followers:
            assert follower.wait_for(lambda p: _value(p, "Preset") == POLHODES, 60)
        # The lead hides one of the scene's parts: so does every follower, its checkbox too.
        assert lead.wait_for(lambda p: p.has_widget(FAMILY), 60)
        _set(lead, FAMILY, False)
        for follower in followers:
            assert follower.wait_for(
                lambda p: p.has_widget(FAMILY) and _value(p, FAMILY) is False, 30
            )
        _set(lead, "Pause")
        assert lead.wait_for(lambda p: "_paused_" in _markdown(p, "**t ="), 30)
        paused_at = _markdown(lead, "**t =")
        for follower in followers:
            assert follower.wait_for(lambda p: _markdown(p, "**t =") == paused_at, 30)

        # One follower explores from here; the lead goes on: the others follow, it does not.
        explorer, *rest = followers
        _set(explorer, "Explore from here")
        assert explorer.wait_for(lambda p: _says(p, "Exploring on your own"), 30)
        _set(lead, "Preset", "Sphere (a cube)")
        for follower in rest:
            assert follower.wait_for(lambda p: _value(p, "Preset") == "Sphere (a cube)", 60)
        assert _value(explorer, "Preset") == POLHODES
        assert _markdown(explorer, "**t =") == paused_at  # paused at the lecturer's time

        # The lead leaves: the followers keep its last state and are told.
        lead.close()
        for follower in rest:
            assert follower.wait_for(lambda p: _says(p, "The lecturer left"), 30)
            assert _value(follower, "Preset") == "Sphere (a cube)"
    finally:
        for probe in probes:
            probe.close()
        stop_classroom(room)


# -- bad input -----------------------------------------------------------------------------
def test_a_wrong_code_is_refused_and_too_many_close_the_page(poinsot_app, make_probe):
    probe = _ready(make_probe(poinsot_app))
    session = session_of(poinsot_app)
    for attempt in range(1, MAX_WRONG_CODES):
        _set(probe, "Lecturer code", f"nope{attempt}")
        _set(probe, "Lead this class")
        left = MAX_WRONG_CODES - attempt
        assert probe.wait_for(lambda p, n=left: _says(p, f"({n} tries left)"), 30)
    assert session.follow.mode == "own" and poinsot_app.follow.token == ""
    _set(probe, "Lead this class")
    assert probe.wait_for(lambda p: p.closed, 30), "the page was not closed"


def test_a_follower_cannot_change_its_controls_the_lead_or_another_follower(
    poinsot_app, make_probe
):
    lead = _ready(make_probe(poinsot_app))
    lead_session = session_of(poinsot_app, 1)
    _lead(lead, poinsot_app.follow.code)
    one, other = _ready(make_probe(poinsot_app)), _ready(make_probe(poinsot_app))
    _follow(one), _follow(other)
    follower = session_of(poinsot_app, 3)
    before = lead_session.params.D
    _set(one, D, 2.1)  # refused, put back, said once
    assert one.wait_for(lambda p: _says(p, HELD), 30)
    assert one.wait_for(lambda p: _value(p, D) == pytest.approx(before), 30)
    _set(one, "Pause")
    _set(one, "Lead this class")  # no code: refused, whoever asks
    assert one.wait_for(lambda p: _says(p, "Wrong lecturer code"), 30)
    after_frames(lead_session), after_frames(follower)
    assert lead_session.params.D == before and not lead_session.clock.paused
    assert all(s.params.D == before for s in poinsot_app.sessions().values())
    assert _value(other, D) == pytest.approx(before)
    assert lead_session.follow.mode == "lead"


def _computed_batches(sampler: Any) -> list[tuple[tuple[int, int], tuple[int, int]]]:
    """From now on, every batch ``sampler`` evaluates (a physics call): the grid range a frame
    asked for, and the range evaluated."""
    computed: list[tuple[tuple[int, int], tuple[int, int]]] = []
    batch, lock = sampler.batch, threading.Lock()

    def recording(k_first: int, k_last: int, *args: Any) -> Any:
        with lock:
            before = sampler.evaluations
            samples = batch(k_first, k_last, *args)
            if sampler.evaluations > before:
                computed.append(((k_first, k_last), (int(samples.k[0]), int(samples.k[-1]))))
            return samples

    sampler.batch = recording
    return computed


def test_followers_share_one_build_mirror_what_is_shown_and_cannot_point(poinsot_app, make_probe):
    """A lead and three followers in one process: the lead's slider move builds its body once
    for all the followers (not once each), whose frames draw from that one motion; the lead's
    trail length and hidden elements are mirrored; a follower's click or drag on the
    ellipsoid is refused and told once, until it explores from here."""
    lead, probes, lead_session, followers = _class_of_three(poinsot_app, make_probe)
    motions = poinsot_app.follow.motions
    builds = motions.builds
    gated = _gated_rebuilds(poinsot_app.budget)
    _set(lead, D, 2.3)
    for probe in probes:
        assert probe.wait_for(lambda p: _value(p, D) == pytest.approx(2.3), 30)
    # Only the lead's own rebuild held the other sessions' frames, not the followers' mirrors.
    assert wait_until(lambda: lead_session.generation > 0 and gated, 30)
    assert set(gated) == {lead_session.loop.name}, gated
    assert motions.builds == builds + 1  # one build for the three followers
    shared = followers[0].scene.motion
    assert shared is not None and shared.body.D == pytest.approx(2.3)
    assert all(f.scene.motion is shared and f.body is shared.body for f in followers)
    assert lead_session.scene.motion is not shared  # the lead's own session builds its own
    evaluations = shared.sampler.evaluations
    computed = _computed_batches(shared.sampler)
    for follower in followers:
        after_frames(follower)
    # The followers' frames read the same batches: one physics call per batch. A frame asks for
    # the grid range since the one before; no call evaluates a range that a batch evaluated
    # before (and kept) holds, however many batches the frames took meanwhile (a follower
    # held back on a busy machine asks for a longer range, which a new batch starts at).
    assert len(computed) == shared.sampler.evaluations - evaluations
    for i, ((first, last), _) in enumerate(computed):
        kept = [done for _, done in computed[max(0, i - KEPT_BATCHES) : i]]
        assert not any(a <= first and last <= b for a, b in kept), computed

    # The lead's new speed: the followers share the motion on the new grid too.
    _set(lead, "Speed", 0.5)
    for follower in followers:
        assert wait_until(lambda f=follower: f.clock.speed == pytest.approx(0.5), 30)
    assert wait_until(lambda: followers[0].scene.motion is not shared, 30)
    regridded = followers[0].scene.motion
    assert wait_until(lambda: all(f.scene.motion is regridded for f in followers), 30)
    assert regridded is not shared and regridded.body.D == pytest.approx(2.3)
    assert motions.builds == builds + 2

    # The lead's trail length and the elements it hides, on every follower.
    _set(lead, "Trail length", 500)
    _set(lead, "principal axes", False)
    for probe, follower in zip(probes, followers, strict=True):
        assert probe.wait_for(lambda p: _value(p, "Trail length") == 500, 30)
        assert probe.wait_for(lambda p: _value(p, "principal axes") is False, 30)
        assert follower.scene.trail_points == 500
        assert not follower.scene.is_visible(Element.AXES)

    # A follower's pointer on the ellipsoid: refused, said once; its own again after Explore.
    follower, probe = followers[0], probes[0]
    pointer = follower.pointer
    down = ((0.0, 0.0, 5.0), (0.0, 0.0, -1.0))  # through the centre: it meets the ellipsoid
    click = types.SimpleNamespace(client=follower.client, ray_origin=down[0], ray_direction=down[1])
    drag = types.SimpleNamespace(client=follower.client, phase="update", end_position=(0, 0, 0))
    _run(pointer._on_drag(drag))
    _run(pointer._on_click(click))
    assert probe.wait_for(lambda p: _says(p, HELD), 30)
    after_frames(follower)
    assert pointer.starts == 0 and pointer.previews == 0 and not follower.clock.paused
    assert follower.params == followers[1].params
    _set(probe, "Explore from here")
    assert probe.wait_for(lambda p: _says(p, "Exploring on your own"), 30)
    _run(pointer._on_click(click))
    assert wait_until(lambda: pointer.starts == 1, 30)


def test_a_follower_mirrors_a_move_into_its_sliders_in_one_wake_of_its_loop(
    poinsot_app, make_probe
):
    """A follower shows each body the lead moves to in its sliders with one call to viser's
    event loop for the whole body (its writes in order), not one a slider: a class of
    followers wakes the loop once each for a move of the lecturer's."""
    lead, probes, _, followers = _class_of_three(poinsot_app, make_probe)
    loop = poinsot_app.server.get_event_loop()
    threads = {follower.loop.name: follower for follower in followers}
    calls: dict[str, list[Any]] = {name: [] for name in threads}
    real = loop.call_soon_threadsafe

    def counting(callback, *args, **kwargs):
        name = threading.current_thread().name
        if name in calls:
            calls[name].append(callback)
        return real(callback, *args, **kwargs)

    before = {name: follower.generation for name, follower in threads.items()}
    loop.call_soon_threadsafe = counting  # type: ignore[method-assign]
    try:
        for value in (2.3, 2.2):
            _set(lead, D, value)
            for probe in probes:
                assert probe.wait_for(lambda p, v=value: _value(p, D) == pytest.approx(v), 30)
        for name, follower in threads.items():  # (the sliders are shown before it ends)
            assert wait_until(lambda f=follower, n=name: f.generation >= before[n] + 2, 30)
    finally:
        del loop.call_soon_threadsafe  # the loop's own method again
    for name, follower in threads.items():
        rebuilds = follower.generation - before[name]
        mirrors = [c for c in calls[name] if c is run_writes]
        # one call per body shown (a rebuild begun before the count may have mirrored already)
        assert 2 <= len(mirrors) <= rebuilds, (name, rebuilds, calls[name])
        alone = [c for c in calls[name] if "_mirror" in getattr(c, "__qualname__", "")]
        assert alone == [], alone  # never a slider on its own


def test_a_write_for_a_stopped_server_s_loop_goes_to_nobody():
    """A session's frame thread may still rebuild while its server stops (a test's teardown,
    Ctrl-C): the writes it hands viser's loop (its sliders mirrored, a value shown) go to
    nobody once the loop is closed, instead of raising into the frame thread, which reported
    "Event loop is closed" as an internal error, with its traceback in the server's log."""
    loop = asyncio.new_event_loop()
    ran: list[int] = []
    assert on_loop(loop, ran.append, 1)
    loop.call_soon(loop.stop)  # runs what is ready, then stops
    # On a thread of its own, as viser's loop runs (this thread may hold the event loop of a
    # real-browser test that ran before, in this process: ``python -m pytest`` without workers).
    thread = threading.Thread(target=loop.run_forever)
    thread.start()
    thread.join(30)
    assert not thread.is_alive(), "the loop did not stop"
    assert ran == [1]
    loop.close()
    assert not on_loop(loop, ran.append, 2)
    assert ran == [1]


def test_followers_share_one_build_of_the_lead_s_scene(poinsot_app, make_probe):
    """The lead chooses a scene, then moves its D slider: the three followers of the process
    draw one model and one motion of each (built once, not once each), the lead its own."""
    lead, probes, lead_session, followers = _class_of_three(poinsot_app, make_probe)
    scenes = poinsot_app.follow.scenes

    def shared_once(D_shown: float, builds: int) -> None:
        for follower in followers:
            assert wait_until(
                lambda f=follower: (
                    f.showcase is not None
                    and f.showcase.showcase.settings.get("D") == pytest.approx(D_shown, abs=0.01)
                    and f.showcase.loaded
                ),
                60,
            ), [f.showcase and dict(f.showcase.showcase.settings) for f in followers]
        model = followers[0].showcase.showcase.model
        motion = followers[0].scene.motion
        assert model is not None and motion is not None
        assert all(f.showcase.showcase.model is model for f in followers)
        assert all(f.scene.motion is motion for f in followers)
        assert lead_session.showcase.showcase.model is not model  # the lead builds its own
        assert scenes.builds == builds + 2  # one model and one motion for three followers

    builds = scenes.builds
    _set(lead, "Preset", POLHODES)
    shared_once(1.6, builds)
    builds = scenes.builds
    # The scene's D slider (the preset's, hidden, came before it), once the lead's page has it.
    assert lead.wait_for(lambda p: len(_uuids(p, D)) == 2, 30), _uuids(lead, D)
    lead.set_value(_uuids(lead, D)[-1], 2.2)
    shared_once(2.2, builds)
    assert all(f.stats.errors == 0 for f in followers), [f.stats.last_error for f in followers]
    assert not any(_says(p, "could not be shown") for p in probes)


def _uuids(probe: Probe, label: str) -> list[str]:
    """The probe's widgets labelled ``label``, oldest first."""
    _, widgets = probe.snapshot()
    return [u for u, w in widgets.items() if w.props.get("label") == label]


def _run(coroutine) -> None:
    """Run a pointer's callback to the end on a thread of its own, as viser's loop would (this
    thread may hold the event loop of a real-browser test that ran before, in this worker)."""
    thread = threading.Thread(target=asyncio.run, args=(coroutine,))
    thread.start()
    thread.join(30)
    assert not thread.is_alive(), "the pointer's callback did not end"


def _gated_rebuilds(gate) -> list[str]:
    """The frame threads whose rebuilds take ``gate`` from now on (their names, in order)."""
    names: list[str] = []
    rebuild = gate.rebuild

    def recorded():
        names.append(threading.current_thread().name)
        return rebuild()

    gate.rebuild = recorded
    return names


def test_a_second_leader_takes_over_and_the_first_is_told(poinsot_app, make_probe):
    first, second = _ready(make_probe(poinsot_app)), _ready(make_probe(poinsot_app))
    _lead(first, poinsot_app.follow.code)
    _lead(second, poinsot_app.follow.code)
    assert first.wait_for(lambda p: _says(p, "Another lecturer took over"), 30)
    sessions = sorted(poinsot_app.sessions().values(), key=lambda s: s.client.client_id)
    assert [s.follow.mode for s in sessions] == ["own", "lead"]


def test_a_follower_may_take_the_lecturers_camera(poinsot_app, make_probe):
    lead = _ready(make_probe(poinsot_app))
    _lead(lead, poinsot_app.follow.code)
    lead.send(
        wire_message(
            "ViewerCameraMessage",
            wxyz=(1.0, 0.0, 0.0, 0.0),
            position=(1.0, 2.0, 3.0),
            fov=0.8,
            near=0.01,
            far=100.0,
            image_height=720,
            image_width=1280,
            look_at=(0.0, 0.0, 0.5),
            up_direction=(0.0, 0.0, 1.0),
        )
    )
    follower = _ready(make_probe(poinsot_app))
    session = session_of(poinsot_app, 2)
    _set(follower, "Lecturer's camera", True)
    _follow(follower)
    camera = session.client.camera
    # The position and then look_at are set (the position moves look_at along): both, at once.
    lecturers = pytest.approx((1.0, 2.0, 3.0, 0.0, 0.0, 0.5))
    assert wait_until(lambda: (*camera.position, *camera.look_at) == lecturers, 30)


def test_a_link_with_follow_follows(poinsot_app, make_probe):
    probe = _ready(make_probe(poinsot_app))
    session = session_of(poinsot_app)
    page = "http://127.0.0.1:8080/?follow=1"
    links.apply(session, links.opening(page, session.preset, None))
    assert probe.wait_for(lambda p: _says(p, "Waiting for the lecturer"), 30)
    assert session.follow.mode == "follow" and _value(probe, "Follow the lecturer") is True


def test_a_link_asks_to_follow():
    assert links.parse("follow=1").follow and not links.parse("t=2").follow
    with pytest.raises(links.LinkError, match="follow='maybe' is not 0 or 1"):
        links.parse("follow=maybe")


def test_a_dead_lead_worker_leaves_its_followers_the_last_state():
    """The relay between workers: a worker whose pipe closes while it held the lead (it
    ended, even by kill -9) is reported to the others as a lead gone."""
    lead_parent, lead_worker = multiprocessing.Pipe()
    other_parent, other_worker = multiprocessing.Pipe()
    relay = Relay([lead_parent, other_parent]).start()
    hub = FollowHub("code")
    try:
        state = LeadState("tok", "preset=major", 1.5, 0.0, True, 1.0)
        for message in (("lead", "tok"), ("state", state)):
            lead_worker.send(message)
            assert other_worker.poll(30)
            hub.deliver(other_worker.recv())
        lead_worker.close()  # the lead's worker is gone
        assert other_worker.poll(30)
        hub.deliver(other_worker.recv())
        assert hub.gone == ENDED and hub.state == state and hub.now() == 1.5
    finally:
        relay.stop()


def test_a_playing_lead_publishes_its_clock_at_the_state_s_own_instant(poinsot_app, make_probe):
    """A follower extrapolates the lead's time from a state's ``t`` and ``at``: they must be
    the lead's clock at ``at`` exactly, else every state looks like a jump of the lead's to
    the next frame, and is published again at once (followers resynchronised every frame)."""
    lead = _ready(make_probe(poinsot_app))
    session = session_of(poinsot_app)
    hub = session.follow.hub
    published: list[LeadState] = []
    publish = hub.publish

    def recorded(controls: Any, state: LeadState) -> bool:
        published.append(state)
        return publish(controls, state)

    hub.publish = recorded  # type: ignore[method-assign]
    _lead(lead, poinsot_app.follow.code)
    assert wait_until(lambda: len(published) >= 4, 30)
    clock = session.clock
    playing = [s for s in published if not s.paused and s.speed == clock.speed]
    assert len(playing) >= 3
    assert [s.t for s in playing] == pytest.approx([clock.at(s.at) for s in playing], abs=1e-12)


def test_a_lead_publishes_its_new_body_as_soon_as_it_is_rebuilt(poinsot_app, make_probe):
    """The lead's new body is published right after its rebuild, before the lead draws another
    frame: its followers start their rebuilds at once (not up to a frame interval later)."""
    lead = _ready(make_probe(poinsot_app))
    session = session_of(poinsot_app)
    hub, build = session.follow.hub, session.build
    rebuilt: list[tuple[int, int]] = []  # (generation, frames drawn) as each rebuild ended
    published: list[tuple[str, int]] = []  # (query, frames drawn) at each publish
    rebuild, publish = build.rebuild, hub.publish

    def recorded_rebuild(showcase: Any) -> None:
        rebuild(showcase)
        rebuilt.append((build.generation, session.stats.frames))

    def recorded_publish(controls: Any, state: LeadState) -> bool:
        published.append((state.query, session.stats.frames))
        return publish(controls, state)

    build.rebuild = recorded_rebuild  # type: ignore[method-assign]
    hub.publish = recorded_publish  # type: ignore[method-assign]
    _lead(lead, poinsot_app.follow.code)
    assert wait_until(lambda: len(published) >= 1, 30)
    for value in (2.3, 2.2):
        queries = {query for query, _ in published}
        _set(lead, D, value)
        assert wait_until(lambda q=queries: any(p[0] not in q for p in published), 30), value
        query, frames = next(p for p in published if p[0] not in queries)
        assert f"D={value:g}" in query, query
        assert frames == rebuilt[-1][1], (frames, rebuilt)  # no frame drawn in between


def test_a_state_published_again_wakes_no_follower_and_a_change_does():
    """A lead publishes its state a few times a second; the same state again (its clock
    re-anchored where it had got to) wakes no follower, since they read the time from the hub.
    Something shown, another lead, or a jump in time wakes them once each."""
    hub = FollowHub("abcdef")
    woken: list[int] = []
    hub.watch(1, lambda: woken.append(1))
    hub.deliver(("lead", "tok"))
    assert len(woken) == 1
    first = LeadState("tok", "preset=major", 1.0, 10.0, False, 0.5)
    hub.deliver(("state", first))
    assert len(woken) == 2 and hub.state is first
    again = LeadState("tok", "preset=major", 1.125, 10.25, False, 0.5)  # where its clock got to
    hub.deliver(("state", again))
    assert len(woken) == 2 and hub.state is again and hub.quiet == 1
    assert hub.now() is not None and hub.delivered == 2
    changes = [
        LeadState("tok", "preset=minor", 1.25, 10.5, False, 0.5),  # another body
        LeadState("tok", "preset=minor", 1.25, 10.5, True, 0.5),  # paused
        LeadState("tok", "preset=minor", 3.0, 10.75, True, 0.5),  # a jump in time
        LeadState("tok", "preset=minor", 3.0, 11.0, True, 0.5, trail=100),  # the trail
    ]
    for k, state in enumerate(changes, start=3):
        hub.deliver(("state", state))
        assert len(woken) == k, state
    hub.deliver(("state", LeadState("tok", "preset=minor", 3.0, 11.25, True, 0.5, trail=100)))
    assert len(woken) == 6 and hub.quiet == 2
    hub.deliver(("gone", "tok", "left"))  # the lead left: told
    assert len(woken) == 7
