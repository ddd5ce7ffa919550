"""Helpers for the scene tests: start a server on a scene, read what it sends through the
websocket probe (poses, positions, arrows, trails, readouts, plots) at chosen times.

The times are set on the session's clock (paused, then reset to each time); the data are read
from the probe's model of the scene as sent, once the browser-side pose equals the one the
session drew for that time."""

from __future__ import annotations

import html
import itertools
import re

import numpy as np
from conftest import session_of, wait_until
from scipy.spatial.transform import Rotation

from poinsot.app.construction.sampled.batch import Frame
from poinsot.app.construction.sampled.frames import xyzw_from_wxyz
from poinsot.app.devtools.probe import Node, Probe
from poinsot.app.live.server import PoinsotApp
from poinsot.app.live.session.builder import MAX_FPS
from poinsot.app.live.session.session import Session
from poinsot.app.model.elements import Element

#: Nodes every session has, whatever it shows.
ALWAYS = {"/WorldAxes", "/space", "/space/body", "/space/tip", "/lights", "/lights/fill"}
#: Trail groups of the Poinsot construction (their chunks come and go).
CONSTRUCTION_TRAILS = ("/space/body/polhode", "/space/herpolhode")


def start(make_app, make_probe, spec) -> tuple[PoinsotApp, Session, Probe]:
    """A server whose browsers start with scene ``spec``, a probe on it, once it has drawn; at
    the server's own frame rate (a scene's time grid is a share of a frame's time)."""
    app = make_app(scene=spec, max_fps=MAX_FPS)
    probe = make_probe(app)
    session = session_of(app)
    assert wait_until(lambda: session.running and session.stats.frames > 3, 30), "no frames"
    assert wait_until(lambda: session.showcase is not None and session.showcase.loaded, 30)
    # The scene's controls as the probe has them (sent before the frames, read after them).
    labels = {control.label for control in spec.controls}
    assert probe.wait_for(lambda p: labels <= set(p.labels()), 30), (labels, probe.labels())
    return app, session, probe


def sent_at(session: Session, probe: Probe, t: float) -> tuple[Frame, dict[str, Node]]:
    """Pause the clock at ``t`` and return the session's frame and the nodes as sent."""
    session.clock.paused = True
    session.clock.reset(t)

    def drawn() -> bool:
        frame = session.frame
        return frame is not None and t - 0.06 < frame.t <= t + 1e-9

    assert wait_until(drawn, 30), f"the session did not draw t = {t}"
    frame = session.frame
    assert frame is not None
    assert probe.wait_for(
        lambda p: (
            "/space/body" in p.nodes
            and np.allclose(p.nodes["/space/body"].wxyz, frame.wxyz, atol=1e-9)
        ),
        30,
    ), "the pose never arrived"
    nodes, _ = probe.snapshot()
    return frame, nodes


def rotation(node: Node) -> Rotation:
    return Rotation.from_quat(xyzw_from_wxyz(np.asarray(node.wxyz)))


def arrow_tip(node: Node) -> np.ndarray:
    """The end of a one-arrow node as sent (its points are (1, 2, 3))."""
    return np.asarray(node.props["points"], dtype=np.float64).reshape(-1, 2, 3)[0, 1]


def segments(node: Node) -> np.ndarray:
    """A line-segments node's points as sent, (n, 2, 3)."""
    return np.asarray(node.props["points"], dtype=np.float64).reshape(-1, 2, 3)


def trail_points(nodes: dict[str, Node], group: str) -> np.ndarray:
    """The points of a trail as sent: the chunks ``group/g<layer>/c<n>`` of its newest layer
    shown (a cleared layer is hidden, then removed), in order, chained."""
    pattern = re.compile(re.escape(group) + r"/g(\d+)/c(\d+)")
    found = [(m, node) for name, node in nodes.items() if (m := pattern.fullmatch(name))]
    shown = [int(m[1]) for m, _ in found if nodes[f"{group}/g{m[1]}"].visible]
    chunks = sorted((int(m[2]), node) for m, node in found if shown and int(m[1]) == max(shown))
    if not chunks:
        return np.zeros((0, 3))
    parts = [segments(node) for _, node in chunks]
    segs = np.concatenate(parts)
    return np.concatenate([segs[:, 0], segs[-1:, 1]])


def drawn_traces(session: Session, probe: Probe) -> dict[str, np.ndarray]:
    """Every trace of the scene as sent (by group name), once all the points the session has
    drawn have reached the probe: the traces are sent every few frames, and paused, the last
    points go out with the next frame drawn (for traces not yet trimmed to their length)."""
    assert wait_until(lambda: session.scene.traces_complete, 30), "the traces were not all sent"
    drawn = {
        trail.group.name: len(trail.points())
        for element in Element
        if (trail := session.scene.trail(element)) is not None
    }

    def arrived(p: Probe) -> bool:
        return all(len(trail_points(p.nodes, name)) == n for name, n in drawn.items())

    assert probe.wait_for(arrived, 30), f"the traces never arrived in full: {drawn}"
    nodes, _ = probe.snapshot()
    return {name: trail_points(nodes, name) for name in drawn}


def scene_node_names(probe: Probe, trails: tuple[str, ...]) -> set[str]:
    """The nodes as sent, without the layers and chunks of the given trail groups."""
    nodes, _ = probe.snapshot()
    return {name for name in nodes if not any(name.startswith(group + "/g") for group in trails)}


def visible_labels(probe: Probe) -> set[str]:
    _, widgets = probe.snapshot()
    return {
        str(w.props["label"])
        for w in widgets.values()
        if w.props.get("label") and w.props.get("visible", True)
    }


def plot_titles(probe: Probe) -> set[str]:
    _, widgets = probe.snapshot()
    return {
        str(w.props.get("title"))
        for w in widgets.values()
        if w.type == "GuiUplotMessage" and w.props.get("visible", True)
    }


def plot_data(probe: Probe, title: str) -> list[np.ndarray]:
    """The data last sent to the plot titled ``title``: [x, series...]."""
    _, widgets = probe.snapshot()
    for w in widgets.values():
        if w.type == "GuiUplotMessage" and w.props.get("title") == title:
            return [np.asarray(a, dtype=np.float64) for a in w.props["data"]]
    raise KeyError(title)


_CELL = re.compile(r"(?<!\\)\|")


_HOVER = re.compile(r'<span title="([^"]*)">(.*)</span>')


def shown(cell: str) -> str:
    """A cell's text as shown (a quantity's definition on hover left out)."""
    match = _HOVER.fullmatch(cell)
    return html.unescape(match.group(2)) if match else cell


def every_digit(cell: str) -> str:
    """A number cell with every digit the page carries (on hover, where the screen rounds)."""
    match = _HOVER.fullmatch(cell)
    return html.unescape(match.group(1)) if match else cell


def readout_table(probe: Probe) -> dict[str, tuple[str, str]]:
    """The readout table as shown: quantity -> (theory, measured), every digit the page
    carries (the screen shows 4 significant figures, the rest on hover)."""
    _, widgets = probe.snapshot()
    for w in widgets.values():
        text = str(w.props.get("_markdown", ""))
        if w.type == "GuiMarkdownMessage" and text.startswith("| quantity | theory | measured |"):
            rows = {}
            for line in text.splitlines()[2:]:
                if not line.startswith("|"):
                    break
                cells = [c.strip().replace("\\|", "|") for c in _CELL.split(line)[1:-1]]
                rows[shown(cells[0])] = (every_digit(cells[1]), every_digit(cells[2]))
            return rows
    return {}


def number_in(text: str) -> float:
    """The first number of a readout cell ("1.234 (+2e-09)", "12.5 %", "30.000000°")."""
    match = re.search(r"[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?", text.replace("−", "-"))
    assert match, f"no number in {text!r}"
    return float(match.group(0))


def wait_readouts(probe: Probe, names, timeout: float = 10.0) -> dict[str, tuple[str, str]]:
    """The readout table once it shows every quantity in ``names``."""
    assert probe.wait_for(lambda p: set(names) <= set(readout_table(p)), timeout), readout_table(
        probe
    )
    return readout_table(probe)


def construction_nodes() -> dict:
    """The nodes each element of the Poinsot construction creates, read off a bare
    :class:`PoinsotScene` on a server of its own (so that the scene tests follow whatever
    nodes the construction draws for an element)."""
    import viser

    from poinsot.app.construction.construction import PoinsotScene
    from poinsot.app.model.elements import Element
    from poinsot.app.model.parameters import Parameters
    from poinsot.app.model.presets import DEFAULT_PRESET

    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    try:
        probe = Probe(server.get_port())
        scene = PoinsotScene(server.scene, frozenset())
        scene.load(Parameters.from_preset(DEFAULT_PRESET).build(), DEFAULT_PRESET.solid)
        base = _drawn_names(server, probe, scene, frozenset())
        nodes = {}
        for element in Element:
            names = _drawn_names(server, probe, scene, frozenset({element}))
            nodes[element] = {n for n in names - base if not _is_chunk(n)}
        probe.close()
        return nodes
    finally:
        server.stop()


def _is_chunk(name: str) -> bool:
    tail = name.rsplit("/", 1)[-1]
    return tail.startswith("c") and tail[1:].isdigit()


#: The name of the marks :func:`received_names` sends after what it waits for, and their count.
MARK = "/received-mark"
_MARKS = itertools.count()


def _drawn_names(server, probe: Probe, scene, elements) -> set[str]:
    """Declare ``elements``, draw a frame, and return the node names the probe has then."""
    scene.declare(elements)
    scene.advance(0.5)
    scene.flush_trails()
    return received_names(server, probe)


def received_names(server, probe: Probe, timeout: float = 60.0) -> set[str]:
    """The node names ``probe`` has once everything ``server`` queued before this call reached
    it: a mark node added now, after them, has arrived (a connection's messages arrive in the
    order they were queued; viser drops a queued message only for a later one on the same
    node). The event to wait for, not a quiet period: a loaded machine delivers late."""
    mark = f"{MARK}/{next(_MARKS)}"
    handle = server.scene.add_frame(mark, show_axes=False)
    try:
        assert probe.wait_for(lambda p: mark in p.nodes, timeout), "the mark never arrived"
        nodes, _ = probe.snapshot()
    finally:
        handle.remove()
    return {name for name in nodes if not name.startswith(MARK)}
