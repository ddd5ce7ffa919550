"""The builder of a session: :func:`compose` makes its parts, in order, and wires them.

Each part is given the narrow things it uses, never the session: the panel, the uploads, the
lecture tools, the "Class" folder and the pointers the session's :class:`~.front.Front` (its
client, clock, construction, what it shows, read-only, and its requests), each typed by a
Protocol of its own; the rebuild where its motion comes from (:mod:`.source`); the frame
thread's work (:mod:`.frames`) the parts it drives. :class:`SessionOptions` holds the knobs a
server sets.
"""

from __future__ import annotations

import dataclasses

import viser

from poinsot.app.construction.cameras import RIDE_ALONG
from poinsot.app.construction.construction import PoinsotScene
from poinsot.app.construction.view import DEFAULT_VIEW, View, apply_theme
from poinsot.app.lessons.support.spec import SceneSpec
from poinsot.app.live.classroom.follow import FollowHub
from poinsot.app.live.classroom.lead import LeadControls
from poinsot.app.live.classroom.shared_frames import SharedFrames
from poinsot.app.live.hardening.budget import RebuildGate
from poinsot.app.live.hardening.pacing import Outbox, Pacer, SessionStats
from poinsot.app.live.lecture.layout import Layout
from poinsot.app.live.lecture.lecture import LectureControls, add_lecture_controls
from poinsot.app.live.panel.clock import SimClock
from poinsot.app.live.panel.ghost_controls import GhostControls, add_ghost_controls
from poinsot.app.live.panel.panel import ControlPanel
from poinsot.app.live.panel.playback import Playback
from poinsot.app.live.panel.uploads import UploadControls
from poinsot.app.live.panel.widgets import Retirement
from poinsot.app.live.pointing.pointer import Pointer
from poinsot.app.live.pointing.sphere_pointer import SpherePointer
from poinsot.app.live.session.actions import MAX_ACTIONS, ActionQueue
from poinsot.app.live.session.choice import Choice
from poinsot.app.live.session.frame_loop import FrameLoop
from poinsot.app.live.session.frames import FrameWork
from poinsot.app.live.session.front import FollowerMirror, Front, Status
from poinsot.app.live.session.rebuild import BodyBuild
from poinsot.app.live.session.refresh import Refresh
from poinsot.app.live.session.source import MotionSource
from poinsot.app.model.presets import Preset
from poinsot.app.viser_private import make_accessible

#: The animation rate cap per client [frames per second].
MAX_FPS = 60.0


@dataclasses.dataclass(frozen=True)
class SessionOptions:
    """A server's settings for its sessions. Frames: as many as taken, up to ``max_fps``
    (:class:`~..hardening.pacing.Pacer`); ``view``: the first camera; ``budget``: the server's
    rebuild gate (the session's own if None); ``scene``: start with it, not the preset;
    ``max_actions``: :mod:`.actions`; ``user_agent``: the browser's (:mod:`..lecture.layout`);
    ``follow``: the process's hub (:mod:`..classroom.lead`; the session's own if None)."""

    max_fps: float = MAX_FPS
    view: View = DEFAULT_VIEW
    budget: RebuildGate | None = None
    scene: SceneSpec | None = None
    max_actions: int = MAX_ACTIONS
    user_agent: str = ""
    follow: FollowHub | None = None


@dataclasses.dataclass(frozen=True)
class Core:
    """What the session runs: its client, front, pacing, statistics and motion, its body and
    the preset or scene shown, the panel, and its frame thread."""

    client: viser.ClientHandle
    front: Front
    pacer: Pacer
    stats: SessionStats
    budget: RebuildGate
    source: MotionSource
    panel: ControlPanel
    playback: Playback
    build: BodyBuild
    choice: Choice
    refresh: Refresh
    retirement: Retirement
    frames: FrameWork
    loop: FrameLoop


@dataclasses.dataclass(frozen=True)
class Tools:
    """What works on the session's body: the ghost, the uploads, the "Class" folder, the
    lecture tools, the page's layout and the two pointers."""

    ghost: GhostControls
    uploads: UploadControls
    follow: LeadControls
    lecture: LectureControls
    layout: Layout
    pointer: Pointer
    sphere_pointer: SpherePointer


def compose(
    client: viser.ClientHandle, preset: Preset, options: SessionOptions
) -> tuple[Core, Tools]:
    """A session's parts for ``client``, showing ``preset`` (or ``options.scene``), its first
    body built; its frame thread made, not started."""
    spec = options.scene
    apply_theme(client)
    make_accessible(client)  # names, keyboard, contrast: what viser's page leaves out
    options.view.apply(client.camera)
    stats = SessionStats()
    status = Status(stats, str(client.client_id))
    elements = preset.elements if spec is None else frozenset()
    scene = PoinsotScene(client.scene, elements, preset.trail_points, atomic=client.atomic)
    clock = SimClock(speed=preset.speed)
    front = Front(client, clock, scene, ActionQueue(options.max_actions), status)
    #: Widgets removed from the panel, deleted a moment later (frame thread).
    retirement = Retirement()
    panel = ControlPanel(client.gui, front, preset if spec is None else spec.identity(), retirement)
    status.show = panel.show_status
    playback = Playback(clock, scene, panel.show_playback, options.max_fps)
    # The ghost's controls; the ghost itself when switched on (fitted after each rebuild).
    ghost = add_ghost_controls(client, scene, retirement)
    hub = options.follow if options.follow is not None else FollowHub()
    follow = LeadControls(front, hub, FollowerMirror(front))
    source = MotionSource(clock, follow)
    uploads = UploadControls(front, panel)  # the toss and mesh folders, before a declaration
    budget = options.budget if options.budget is not None else RebuildGate()
    build = BodyBuild(
        preset,
        client=client,
        scene=scene,
        playback=playback,
        panel=panel,
        ghost=ghost,
        source=source,
        budget=budget,
        stats=stats,
        say=status.say,
        defer=front.defer,
    )
    choice = Choice(
        preset,
        build,
        client=client,
        scene=scene,
        panel=panel,
        playback=playback,
        retirement=retirement,
        actions=front,
        resolve=uploads.resolve,
    )
    front.attach(choice, panel, playback)
    front.apply_preset(preset) if spec is None else front.apply_scene(spec)
    build.rebuild(choice.showcase)
    lecture, layout, pointer, sphere_pointer = _mount_tools(front, panel, options.user_agent)
    tools = Tools(ghost, uploads, follow, lecture, layout, pointer, sphere_pointer)
    return _frame_thread(front, panel, choice, source, budget, retirement, tools, options), tools


def _frame_thread(
    front: Front,
    panel: ControlPanel,
    choice: Choice,
    source: MotionSource,
    budget: RebuildGate,
    retirement: Retirement,
    tools: Tools,
    options: SessionOptions,
) -> Core:
    """The frame thread's work and loop (made last: the front wakes it from then on)."""
    client, build = front.client, choice.build
    pacer = Pacer(Outbox(client), max_fps=options.max_fps)
    frames = _frame_work(front, panel, choice, source, retirement, tools, pacer)
    loop = FrameLoop(
        f"poinsot-session-{client.client_id}",
        pacer=pacer,
        budget=budget,
        stats=build.stats,
        max_fps=options.max_fps,
        work=frames.work,
        draw=lambda now: frames.draw(now),  # looked up late: tests wrap it
        report=front.status.report,
    )
    front.wake, frames.shared.draw_now = loop.wake, loop.draw_now
    front.moving = frames.shared.moving
    return Core(
        client=client,
        front=front,
        pacer=pacer,
        stats=build.stats,
        budget=budget,
        source=source,
        panel=panel,
        playback=build.playback,
        build=build,
        choice=choice,
        refresh=frames.refresh,
        retirement=retirement,
        frames=frames,
        loop=loop,
    )


def _frame_work(
    front: Front,
    panel: ControlPanel,
    choice: Choice,
    source: MotionSource,
    retirement: Retirement,
    tools: Tools,
    pacer: Pacer,
) -> FrameWork:
    """What the frame thread does, and the parts it drives that no one else holds (the
    refreshes at their rates; a follower's side of the process's cast)."""
    lecture = tools.lecture
    return FrameWork(
        front.client,
        pacer=pacer,
        queue=front.queue,
        status=front.status,
        choice=choice,
        source=source,
        clock=front.clock,
        refresh=Refresh(panel.motion, retirement),
        tools=(lecture, tools.ghost),
        publish=tools.follow,
        laid_out=lambda: lecture.display.laid_out_now,
        header=tools.layout.show_header,
        shared=SharedFrames(tools.follow.hub.cast, front.client, pacer, front.scene),
        own_view=lambda: lecture.camera == RIDE_ALONG or tools.ghost.wanted.enabled,
    )


def _mount_tools(
    front: Front, panel: ControlPanel, user_agent: str
) -> tuple[LectureControls, Layout, Pointer, SpherePointer]:
    """What works on the first body: the lecture's tools, the page's layout, pointing."""
    lecture = add_lecture_controls(front, panel.motion)  # exports, views, theme, hotkeys
    front.camera_of = lambda: lecture.camera  # the view a link names
    layout = Layout(front, panel.motion, user_agent)  # a phone's, a tablet's page
    pointer = Pointer(front, drag=not layout.touch)  # a start pointed at
    sphere_pointer = SpherePointer(front, drag=not layout.touch)
    sphere_pointer.bind()  # on Landau's sphere, in a scene that draws one
    front.after_preset.append(layout.reframe)  # a phone's view framed for its aspect
    front.after_scene.extend((sphere_pointer.bind, layout.reframe))
    return lecture, layout, pointer, sphere_pointer
