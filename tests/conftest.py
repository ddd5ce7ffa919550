"""Shared fixtures: a live Poinsot server, websocket probes, and headless Chromium pages.

Browser tests use Debian's Chromium through playwright (``executable_path``, no
``playwright install``). If Chromium is missing they are skipped locally with the reason, but
FAIL when ``CI`` is set: CI must never pass by silently skipping them.

Reusable pieces (also for the screenshot and export tests):
- ``poinsot_app`` (factory ``make_app``): a :class:`poinsot.app.live.server.PoinsotApp` on a
  free port;
- ``probe`` (factory ``make_probe``): a headless websocket client
  (:mod:`poinsot.app.devtools.probe`);
- ``chromium`` (session scope): a launched playwright Browser;
- ``open_page``: ``open_page(url, width=..., height=...) -> BrowserPage`` with the console
  errors collected, the canvas ready and the software-WebGL notice hidden;
- ``BrowserPage`` helpers to drive viser's widgets by their label, and ``screenshot_rgb``.
"""

from __future__ import annotations

import contextlib
import dataclasses
import io
import math
import os
import re
import shutil
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pytest

from poinsot.app import report as report_command
from poinsot.app import viser_private
from poinsot.app.cli.main import main as cli_main
from poinsot.app.devtools.probe import Probe
from poinsot.app.exports.chromium import CHROMIUM_ARGS, CHROMIUM_ENV, DEFAULT_CHROMIUM
from poinsot.app.lessons import SCENES
from poinsot.app.live.lecture.lecture import LectureControls
from poinsot.app.live.panel.panel import shown_label
from poinsot.app.live.server import PoinsotApp
from poinsot.app.live.session.session import Session
from poinsot.app.model.presets import DEFAULT_PRESET, Preset
from poinsot.app.report import ReportSummary
from poinsot.app.report.measure.study import CaseResult

if TYPE_CHECKING:
    from playwright.sync_api import FloatRect, Page

CHROMIUM = os.environ.get(CHROMIUM_ENV, DEFAULT_CHROMIUM)
#: Console messages that are not errors of ours (they are emitted at "warning" level anyway;
#: listed so that a change of level in a later viser does not fail the suite silently).
BENIGN_CONSOLE = ("GPU stall due to ReadPixels", "THREE.Clock: This module has been deprecated")


def in_ci() -> bool:
    return os.environ.get("CI", "").lower() not in ("", "0", "false", "no")


def chromium_or_fail() -> str:
    """The Chromium executable; skip (locally) or fail (CI) with instructions if missing."""
    path = CHROMIUM if os.path.isabs(CHROMIUM) else shutil.which(CHROMIUM)
    if path and os.access(path, os.X_OK):
        return path
    message = (
        f"Chromium not found at {CHROMIUM!r}: run `make chromium` (Debian's chromium package) "
        "or set POINSOT_CHROMIUM"
    )
    if in_ci():
        pytest.fail(message + " [CI=true: browser tests must run]")
    pytest.skip(message)


# -- how the suite is split (`make test-fast`, pytest-xdist) --------------------------------
#: Fixtures that start a live server or a browser: a test that uses one is marked ``server``
#: (or ``browser``), which ``make test-fast`` leaves out.
SERVER_FIXTURES = frozenset({"make_app", "poinsot_app", "make_probe", "probe"})
BROWSER_FIXTURES = frozenset({"chromium", "open_page", "open_module_page"})
#: Real-browser tests outside tests/browser/ (collection fails if one is not listed).
BROWSER_ELSEWHERE = frozenset(
    {"tests/app/test_ghost.py::test_the_ghost_shows_a_second_ellipsoid_in_the_browser"}
)


#: The real-browser tests by group, each group on a worker of its own with a Chromium of its
#: own. Two groups: the second holds the files whose tests neither type into the body's sliders
#: nor point at the scene (renders, exports, the video, uploads); the first, the rest. Two
#: groups split otherwise made those tests flaky twice before (with every page drawing, then in
#: two of six full runs: a slider's arrow keys, a click on Landau's sphere), before a slider
#: stopped jumping back under keys pressed faster than the body is rebuilt. With these two
#: groups, at idle, three full runs in a row were green, the parallel stage 312-314 s against
#: 350-360 s with one group. A browser file that is not listed joins
#: :data:`BROWSER_LAST_GROUP`.
BROWSER_GROUPS: dict[str, str] = {
    f"tests/browser/{name}.py": "browser-2"
    for name in (
        "test_scenes_page",
        "test_video_page",
        "test_exports_page",
        "test_strobe_picture",
        "test_uploads_page",
        "test_challenges_page",
        "test_accessibility_page",
    )
}
BROWSER_LAST_GROUP = "browser-1"
#: Browser files that share no browser: their tests start a Chromium of their own (the
#: command line's, in a process of its own, or one under strace). Each is a group of its own,
#: off the browser group's worker (whose tests are the suite's long pole), run once a worker
#: is free.
BROWSER_APART = frozenset(
    {
        "tests/browser/test_video.py",
        "tests/browser/test_exports_cli.py",
        "tests/browser/test_loopback.py",
    }
)
#: Groups that take a minute or more without a browser: they start right after the browser
#: groups (a long group started last would be the suite's long pole).
LONG_GROUPS = (
    "tests/app/test_workers.py",
    "tests/app/test_load.py",
    "tests/app/test_follow.py",
    "tests/physics/test_accuracy.py",
    "report",
    "tests/physics/test_reference.py",
    "tests/physics/test_properties.py",
    "tests/app/test_cli_fit.py",
    "tests/physics/test_regimes.py",
    "tests/app/test_server.py",
)

#: Modules that run in a browser file's group because they share a session fixture with it
#: (built once in a worker): the guide's tests build the guide (``built_docs``) that the help
#: page's test serves.
WITH_BROWSER_FILE = {"tests/test_docs.py": "tests/browser/test_help_page.py"}


def xdist_group(nodeid: str) -> str:
    """The worker group of a test (``make test``: pytest-xdist, ``--dist loadgroup``): the
    real-browser tests in the :data:`BROWSER_GROUPS`, so that each Chromium draws for one
    worker; tests/report/ in one (``quick_report`` and ``small_study`` are built once); every
    other module in its own (its fixtures are built once), but for :data:`WITH_BROWSER_FILE`.
    From the node id alone: xdist's controller collects nothing."""
    path = nodeid.split("::")[0]
    path = WITH_BROWSER_FILE.get(path, path)
    if path in BROWSER_APART:
        return path
    if path.startswith("tests/browser/") or nodeid.split("[")[0] in BROWSER_ELSEWHERE:
        return BROWSER_GROUPS.get(path, BROWSER_LAST_GROUP)
    if path.startswith("tests/report/"):
        return "report"
    return path


def group_rank(nodeid: str) -> tuple[int, int]:
    """Where a test's group starts: the browser groups first (the longest), then the
    :data:`LONG_GROUPS`, then the others in their collection order."""
    group = xdist_group(nodeid)
    if group.startswith("browser-"):
        return (0, int(group.removeprefix("browser-")))
    if group in LONG_GROUPS:
        return (1, LONG_GROUPS.index(group))
    return (2, 0)


@pytest.hookimpl(optionalhook=True)  # `-p no:xdist` leaves the hook unknown: no error then
def pytest_xdist_make_scheduler(config: pytest.Config, log):
    """``--dist loadgroup`` by :func:`xdist_group` (xdist's own reads ``xdist_group`` marks
    through ``item._nodeid``, which pytest 9 no longer has). A worker takes a group whole."""
    if config.getvalue("dist") != "loadgroup":
        return None
    from xdist.scheduler import LoadScopeScheduling

    class SuiteGroups(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return xdist_group(nodeid)

    return SuiteGroups(config, log)


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Mark the tests by what they start; the longest groups first (:func:`group_rank`: with
    ``--no-loadscope-reorder`` the first workers start on them at once). The same order in every
    worker, as xdist requires."""
    for item in items:
        fixtures = set(getattr(item, "fixturenames", ()))
        if fixtures & BROWSER_FIXTURES and item.get_closest_marker("browser") is None:
            item.add_marker(pytest.mark.browser)
        if fixtures & SERVER_FIXTURES:
            item.add_marker(pytest.mark.server)
        group = xdist_group(item.nodeid)
        if (
            item.get_closest_marker("browser")
            and not group.startswith("browser-")
            and group not in BROWSER_APART
        ):
            raise pytest.UsageError(f"{item.nodeid} drives a browser: add it to BROWSER_ELSEWHERE")
    items.sort(key=lambda item: group_rank(item.nodeid))


# -- servers and probes ------------------------------------------------------------------
#: The most frames a second a test's server sends each browser or probe [frames/s] (``make``'s
#: default; a test whose figures are shares of the server's own frames passes
#: ``max_fps=MAX_FPS``). At the server's default, 60, a parked page of a playing session costs
#: the machine 0.62 core (Chromium takes and applies every frame's messages; the server draws
#: them); at 30, 0.34; at 15, 0.26 (10 s of one page, the whole machine's CPU). Tests wait for
#: frames counted or for events, so fewer a second only spaces them out.
TEST_MAX_FPS = 20.0


@contextlib.contextmanager
def _app_maker() -> Iterator[Callable[..., PoinsotApp]]:
    apps: list[PoinsotApp] = []

    def make(preset: Preset = DEFAULT_PRESET, **kwargs) -> PoinsotApp:
        kwargs.setdefault("max_fps", TEST_MAX_FPS)
        app = PoinsotApp("127.0.0.1", 0, preset=preset, **kwargs)
        apps.append(app)
        return app

    try:
        yield make
    finally:
        for app in apps:
            app.stop()


@pytest.fixture
def make_app() -> Iterator[Callable[..., PoinsotApp]]:
    """Served apps for one test (stopped after it)."""
    with _app_maker() as make:
        yield make


@pytest.fixture(scope="module")
def make_module_app() -> Iterator[Callable[..., PoinsotApp]]:
    """Served apps shared by the tests of one module (stopped after its last test): for tests
    that each open a page of their own on the same app."""
    with _app_maker() as make:
        yield make


@pytest.fixture
def poinsot_app(make_app) -> PoinsotApp:
    return make_app()


@pytest.fixture
def make_probe() -> Iterator[Callable[..., Probe]]:
    probes: list[Probe] = []

    def make(app: PoinsotApp, **kwargs) -> Probe:
        probe = Probe(app.port, **kwargs)
        probes.append(probe)
        return probe

    yield make
    for probe in probes:
        probe.close()


@pytest.fixture
def probe(poinsot_app, make_probe) -> Probe:
    """A probe connected to ``poinsot_app``, once its session has drawn the scene."""
    p = make_probe(poinsot_app)
    session = session_of(poinsot_app)
    assert wait_until(lambda: session.running, 15), "the session never started"
    # The ellipsoid's size is sent by the first rebuild, after the panel's widgets: once it
    # has arrived, so has everything the session queued before it.
    assert p.wait_for(
        lambda p: (
            "/space/body/ellipsoid" in p.nodes
            and np.allclose(
                p.nodes["/space/body/ellipsoid"].props.get("scale", 0.0),
                session.scene.geometry.semi_axes,
            )
        ),
        15,
    ), "scene never arrived"
    return p


def run_command(argv: list[str], timeout: float = 900.0) -> subprocess.CompletedProcess[str]:
    """``poinsot ARGV`` in a process of its own (its output as text), as a lecturer runs it."""
    return subprocess.run(
        [sys.executable, "-m", "poinsot.app.cli", *argv],
        capture_output=True,
        text=True,
        timeout=timeout,
        check=False,
    )


def session_of(app: PoinsotApp, count: int = 1, timeout: float = 60.0) -> Session:
    """The newest session of ``app`` (waiting until ``count`` sessions exist: a condition the
    app notifies, so the timeout only bounds a failure; at load 18, a session took over 10 s
    to be built)."""
    sessions = app.wait_for_sessions(count, timeout)
    assert len(sessions) >= count, f"only {len(sessions)} sessions"
    return max(sessions, key=lambda s: s.client.client_id)


def lecture_of(session: Session) -> LectureControls:
    """The session's lecture controls (mounted by the session itself)."""
    lecture = getattr(session, "lecture", None)
    assert isinstance(lecture, LectureControls), "the session did not mount the lecture panel"
    return lecture


def css_pixel(camera, box: dict, point: np.ndarray) -> tuple[float, float]:
    """Where the browser's ``camera`` draws the world ``point``, in the page's CSS pixels,
    for the 3D view's ``box`` (``x``, ``y``, ``width``, ``height``: a perspective camera whose
    vertical field of view spans the box's height)."""
    position = np.asarray(camera.position, float)
    forward = np.asarray(camera.look_at, float) - position
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, np.asarray(camera.up_direction, float))
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    q = np.asarray(point, float) - position
    scale = box["height"] / 2.0 / math.tan(camera.fov / 2.0) / (q @ forward)
    x = box["x"] + box["width"] / 2.0 + scale * (q @ right)
    y = box["y"] + box["height"] / 2.0 - scale * (q @ up)
    return float(x), float(y)


#: :func:`wait_until`'s first pause between two asks, and its longest [s]: each pause is half
#: as long again as the one before. A predicate that reads a page is a round trip to Chromium:
#: asked every 20 ms, a locator's count kept a parked page at 0.65 core where it idles at
#: 0.23 (every 100 ms: 0.33), and the suite's browser tests spend much of their time waiting.
FIRST_POLL, LONGEST_POLL = 0.02, 0.1


def wait_until(
    predicate: Callable[[], bool], timeout: float = 10.0, poll: float | None = None
) -> bool:
    """Whether ``predicate()`` came true within ``timeout`` seconds, asked every ``poll``
    seconds (by default from :data:`FIRST_POLL`, slowing down to :data:`LONGEST_POLL`)."""
    deadline = time.monotonic() + timeout
    pause = FIRST_POLL if poll is None else poll
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(pause)
        if poll is None:
            pause = min(1.5 * pause, LONGEST_POLL)
    return predicate()


def after_frames(session: Session, frames: int = 10, timeout: float = 30.0) -> None:
    """Wait until ``session`` drew ``frames`` more frames: what was asked of it before has been
    drained (its frame thread drains its actions before each frame) and drawn. The event to
    wait for instead of a sleep before checking that something did NOT happen."""
    first = session.stats.frames
    assert wait_until(lambda: session.stats.frames >= first + frames, timeout), "no more frames"


def record_frame_times(session: Session) -> list[float]:
    """The frame thread's own clock reading for every frame ``session`` draws from now on
    (the time it hands to the frame): the gaps between them show its pacing by its own logic,
    whatever the machine's load."""
    drawn_at: list[float] = []
    frame_if_taken = session.frames.draw

    def recording(now: float) -> bool:
        drawn = frame_if_taken(now)
        if drawn:
            drawn_at.append(now)
        return drawn

    session.frames.draw = recording  # type: ignore[method-assign]
    return drawn_at


def record_messages(server) -> list:
    """Every message ``server`` queues from now on (appended as it is queued)."""
    sent: list = []
    transport = viser_private.infra(server)
    original = transport.queue_message

    def queue_message(message) -> None:
        sent.append(message)
        original(message)

    transport.queue_message = queue_message
    return sent


# -- browsers ------------------------------------------------------------------------------
@pytest.fixture(scope="session")
def chromium():
    path = chromium_or_fail()
    from playwright.sync_api import sync_playwright

    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=path, headless=True, args=CHROMIUM_ARGS)
        yield browser
        browser.close()


@dataclasses.dataclass
class BrowserPage:
    """A page on the app with its console errors; helpers drive viser's widgets by label."""

    page: Page
    errors: list[str]

    def widget_id(self, label: str) -> str:
        exact = re.compile(f"^{re.escape(label)}$")
        loc = self.page.locator("label").filter(has_text=exact)
        widget = loc.first.get_attribute("for")
        assert widget is not None, f"the label {label!r} names no widget"
        return widget

    def control_count(self, label: str) -> int:
        """How many input widgets carry this label (0 once a control is removed)."""
        exact = re.compile(f"^{re.escape(label)}$")
        return self.page.locator("label").filter(has_text=exact).count()

    def press_slider(self, label: str, key: str, times: int = 1) -> None:
        """Move a slider with the keyboard (each press = one step, like a user would): the
        thumb is focused once, then the keys go to it as typed (no locator round trip per key,
        which costs a busy software-WebGL page over half a second); it must still hold the
        focus after the last one."""
        thumb = self.page.locator(f"[id='{self.widget_id(label)}'] [role=slider]")
        thumb.focus()
        for _ in range(times):
            self.page.keyboard.press(key)
        assert thumb.evaluate("e => e === document.activeElement"), f"{label!r} lost the focus"

    def press_slider_to(
        self, label: str, target: float, step: float, server_value: Callable[[], float]
    ) -> None:
        """The arrow keys until the slider ``label`` shows ``target``, as a user would: once
        the server (``server_value()``) and the page agree, the steps still missing. On a
        loaded machine the server's answer to an earlier key can come back between two
        presses and take the slider back a step or three."""
        for _ in range(5):
            assert wait_until(
                lambda: server_value() == pytest.approx(self.slider_value(label), abs=1e-9), 30
            ), (label, server_value(), self.slider_value(label))
            steps = round((target - self.slider_value(label)) / step)
            if not steps:
                return
            self.press_slider(label, "ArrowRight" if steps > 0 else "ArrowLeft", times=abs(steps))
        raise AssertionError(f"{label!r} shows {self.slider_value(label)}, not {target}")

    def slider_value(self, label: str) -> float:
        thumb = self.page.locator(f"[id='{self.widget_id(label)}'] [role=slider]")
        value = thumb.get_attribute("aria-valuenow")
        assert value is not None, f"the slider {label!r} has no value"
        return float(value)

    def choose(self, label: str, option: str) -> None:
        """Pick ``option`` in the dropdown labelled ``label`` (a menu entry by its value: the
        menu shows a scene's under its heading, without "Scene: ")."""
        self.page.locator(f"[id='{self.widget_id(label)}']").click()
        self.page.get_by_role("option", name=shown_label(option), exact=True).click()

    def dropdown_value(self, label: str) -> str:
        """The value chosen (a menu entry's, as :meth:`choose` takes it)."""
        shown = self.page.locator(f"[id='{self.widget_id(label)}']").input_value()
        scene = next((s.label for s in SCENES if shown_label(s.label) == shown), None)
        return shown if scene is None or label != "Preset" else scene

    def click_button(self, text: str) -> None:
        self.page.get_by_role("button", name=text, exact=True).click()

    def open_folder(self, title: str) -> None:
        """Expand a collapsed folder of the control panel by clicking its title."""
        self.page.get_by_text(title, exact=True).first.click()

    def set_checkbox(self, label: str, checked: bool) -> None:
        box = self.page.locator(f"[id='{self.widget_id(label)}']")
        if box.is_checked() != checked:
            box.click()

    def screenshot_rgb(self) -> np.ndarray:
        """The viewport as an (H, W, 3) uint8 array."""
        from PIL import Image

        png = self.page.screenshot(type="png")
        return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"))

    def set_live_view(self, on: bool) -> None:
        """Draw the live 3D view (on), or only the renders asked of it (off: the view is kept
        out of the viewport, see :data:`NO_LIVE_VIEW_JS`), until the page is loaded again.
        Switched on, it returns once the view has drawn two frames in the viewport (a paused
        scene draws about one a second): the page's pixels are then the scene's now."""
        drawn = self.frames_drawn()
        flag = "true" if not on else "false"
        assert self.page.evaluate(
            f"() => {{ window.__poinsotParked = {flag}; return window.__poinsotPark(); }}"
        )
        if on:
            assert wait_until(lambda: self.frames_drawn() >= drawn + 2, 30), "no frame drawn"

    def drawn_after(self, client) -> None:
        """Return once the page has drawn everything sent to ``client`` (its viser client)
        before this call: a render asked of the page now comes back once the page has applied
        the messages in front of it (viser answers a render request after them, in order); the
        live view, if on (:meth:`set_live_view`), then draws two more frames. The events a
        picture of the page waits for, not a fixed wait nor two screenshots alike (a paused
        page draws about a frame a second: on a loaded machine two screenshots can agree
        between two frames, not all drawn yet)."""
        client.get_render(8, 8, timeout=60.0)
        if self.page.evaluate("() => window.__poinsotParked === true"):
            return
        drawn = self.frames_drawn()
        assert wait_until(lambda: self.frames_drawn() >= drawn + 2, 30), "no frame drawn"

    def frames_drawn(self) -> int:
        """The frames the page's 3D view has drawn (three.js counts them; viser exposes its
        renderer's counters for browser tests)."""
        return int(self.page.evaluate(FRAMES_DRAWN_JS))

    def settled_canvas(self, client, timeout: float = 20.0) -> FloatRect:
        """The canvas's box, once the live view has drawn two more frames (what was sent is on
        the page) and the camera this page reports to ``client`` has the canvas's size (a page
        just opened, or whose panels fold, reports its camera again as the canvas changes):
        what the page draws is then in the reported camera's pixels, where a click lands."""
        drawn = self.frames_drawn()
        assert wait_until(lambda: self.frames_drawn() >= drawn + 2, timeout), "no frame drawn"
        camera = client.camera
        box = self.canvas_box()

        def fits() -> bool:
            nonlocal box
            box = self.canvas_box()
            return (camera.image_width, camera.image_height) == (
                round(box["width"]),
                round(box["height"]),
            )

        assert wait_until(fits, timeout), (camera.image_width, camera.image_height, box)
        return box

    def canvas_box(self) -> FloatRect:
        box = self.page.locator("canvas").first.bounding_box()
        assert box is not None, "the canvas is not visible"
        return box


#: Hides viser's "Software WebGL rendering detected" notice (SwiftShader; a GPU browser never
#: shows it) with a style sheet that is in the page before viser's script runs: the notice never
#: covers the canvas, and no test waits for it to appear in order to close it.
HIDE_SOFTWARE_WEBGL_NOTICE_JS = """(() => {
  const hide = () => {
    const style = document.createElement('style');
    style.textContent = '#webgl-software-rendering { display: none !important; }';
    document.head.appendChild(style);
  };
  if (document.head) hide(); else document.addEventListener('DOMContentLoaded', hide);
})();"""


#: Keeps viser's 3D view out of the window's viewport (the panel stays where it is), on every
#: page of the context, reloads included: the client then draws no live frames, only the
#: renders asked of it (``client.get_render``), as the offline exports' pages do. A playing
#: page's live view otherwise keeps software WebGL busy on both cores (measured: Chromium at
#: 2.4 cores and 12 frames/s, against 0.3 core; a 1280x800 render 1.6 s against 0.3 s).
NO_LIVE_VIEW_JS = """(() => {
  window.__poinsotParked = %s;
  window.__poinsotPark = () => {
    const canvas = document.querySelector('canvas[data-engine]');  // three.js's, not an overlay
    let view = canvas ? canvas.parentElement : null;
    while (view && !(view.style.position === 'relative' && view.style.zIndex === '0')) {
      view = view.parentElement;
    }
    if (!view) return false;
    const wanted = window.__poinsotParked ? 'translateX(-100000px)' : '';
    if (view.style.transform !== wanted) view.style.transform = wanted;
    return true;
  };
  setInterval(window.__poinsotPark, 100);
})();"""


#: The most frames a second a test's page draws [frames/s]. A live 1280 x 800 view otherwise
#: draws as many as software WebGL can, 7 to 11 a second at 1.7 to 1.8 cores of Chromium;
#: capped at 5, it takes 1.2. The pictures are the same at a given pixel ratio, but viser lowers
#: the canvas's ratio (to 0.75 at the least) sooner on a page that draws few frames: a test that
#: compares two pictures' pixels holds it (``?fixedDpr=1``). A test waits for frames drawn or a
#: picture, not for the time that so many frames would take.
PAGE_MAX_FPS = 5

#: Caps a live page's animation frames at :data:`PAGE_MAX_FPS`: each ``requestAnimationFrame``
#: callback waits for the first frame at least 1/PAGE_MAX_FPS after the last one let through
#: (all the callbacks of a frame let through run in it, as they would). A parked page
#: (:data:`NO_LIVE_VIEW_JS`) is not capped: it draws only the renders asked of it, and viser's
#: client takes its messages and makes a render over several frames.
FRAME_CAP_JS = """(() => {
  const minGap = 1000 / MAX_FPS - 1;
  const request = window.requestAnimationFrame.bind(window);
  const cancel = window.cancelAnimationFrame.bind(window);
  const pending = new Map();  // our id -> the browser's id of the frame it waits for now
  let nextId = 1, decidedAt = -1, letThrough = true, lastThrough = -Infinity;
  window.requestAnimationFrame = (callback) => {
    const id = nextId++;
    const tick = (time) => {
      if (time !== decidedAt) {
        decidedAt = time;
        letThrough = window.__poinsotParked || time - lastThrough >= minGap;
        if (letThrough) lastThrough = time;
      }
      if (letThrough) {
        pending.delete(id);
        callback(time);
      } else {
        pending.set(id, request(tick));
      }
    };
    pending.set(id, request(tick));
    return id;
  };
  window.cancelAnimationFrame = (id) => {
    const frame = pending.get(id);
    if (frame !== undefined) cancel(frame);
    pending.delete(id);
  };
})();""".replace("MAX_FPS", str(PAGE_MAX_FPS))


#: Draws a test's page without multisampling: the WebGL context is asked for with ``antialias:
#: false``. Software WebGL shades every pixel of a multisampled canvas four times: without it a
#: live capped page takes 0.72 cores of Chromium instead of 0.96, and a 1280 x 800 render 0.22
#: core-seconds instead of 0.32. The suite's checks read colours, counts and places, not how
#: smooth an edge is; the README's pictures and ``poinsot screenshot``/``video`` keep their
#: antialiasing (pages of their own).
NO_MSAA_JS = """(() => {
  const getContext = HTMLCanvasElement.prototype.getContext;
  HTMLCanvasElement.prototype.getContext = function (type, attributes) {
    if (type === "webgl2" || type === "webgl") {
      attributes = Object.assign({}, attributes, { antialias: false });
    }
    return getContext.call(this, type, attributes);
  };
})();"""


#: The longest a page may take to open, its 3D view shown [s]: a bound for a failure, not a
#: wait. Opening a page costs Chromium 4 to 5 CPU-s (viser's client unpacks and compiles its
#: script, software WebGL starts): about 3 s alone, but 20 s were not enough once beside two
#: busy loops and three other workers on 2 cores.
PAGE_OPEN_S = 90


FRAMES_DRAWN_JS = """() => {
  const points = window.__viserTestpoints;
  return points ? points.rendererInfo.render.frame : 0;
}"""


@contextlib.contextmanager
def _page_opener(chromium) -> Iterator[Callable[..., BrowserPage]]:
    contexts = []

    def open_(
        url: str, width: int = 1280, height: int = 720, live_view: bool = True, **options
    ) -> BrowserPage:
        """``live_view=False``: the page draws only the renders asked of it
        (:data:`NO_LIVE_VIEW_JS`), for a test that reads neither the page's pixels nor points
        at its 3D view. ``options``: more of playwright's context options (touch, a
        User-Agent...)."""
        context = chromium.new_context(viewport={"width": width, "height": height}, **options)
        contexts.append(context)
        context.add_init_script(HIDE_SOFTWARE_WEBGL_NOTICE_JS)
        context.add_init_script(NO_LIVE_VIEW_JS % ("false" if live_view else "true"))
        context.add_init_script(FRAME_CAP_JS)
        context.add_init_script(NO_MSAA_JS)
        page = context.new_page()
        errors: list[str] = []
        page.on(
            "console",
            lambda m: (
                errors.append(m.text)
                if m.type == "error" and not any(b in m.text for b in BENIGN_CONSOLE)
                else None
            ),
        )
        page.on("pageerror", lambda e: errors.append(f"pageerror: {e}"))
        page.goto(url)
        page.locator("canvas").first.wait_for(state="visible", timeout=PAGE_OPEN_S * 1000)
        if not live_view:  # loudly, if viser's page is no longer laid out as assumed
            parked = "() => window.__poinsotPark()"
            assert wait_until(lambda: page.evaluate(parked), PAGE_OPEN_S), "not parked"
        return BrowserPage(page, errors)

    try:
        yield open_
    finally:
        for context in contexts:
            context.close()


@pytest.fixture
def open_page(chromium) -> Iterator[Callable[..., BrowserPage]]:
    """Pages for one test (closed after it)."""
    with _page_opener(chromium) as open_:
        yield open_


@pytest.fixture(scope="module")
def open_module_page(chromium) -> Iterator[Callable[..., BrowserPage]]:
    """Pages shared by the tests of one module (closed after its last test)."""
    with _page_opener(chromium) as open_:
        yield open_


# -- the report's study (one conftest for the whole suite: a second conftest.py in a subfolder
# would shadow this module's name for the tests that import helpers from it) ----------------
# ``quick_report``: one ``poinsot report --quick`` through the real command line (session
# scope, ~25 s on the 2-core CI machine), for the tests that read the files it writes.
# ``small_study``: three of that run's cases (Toutatis, 1 - m = 1e-14, the separatrix), for the
# tests that draw the figures again from the study's results.
SMALL_STUDY_CASES = ("Toutatis", "near-separatrix 1-m=1e-14", "separatrix")


#: What ``quick_report``'s run wrote on stderr (a file, as with ``poinsot report 2> file``).
STDERR_NAME = "stderr.txt"


@pytest.fixture(scope="session")
def quick_run(tmp_path_factory: pytest.TempPathFactory) -> ReportSummary:
    """``poinsot report --quick --out DIR`` through the real command line, and what its study
    found: the summary :func:`~poinsot.app.report.write_report` returned to the command, kept
    on its way (the study is run once for both)."""
    out = tmp_path_factory.mktemp("report")
    summaries: list[ReportSummary] = []
    write = report_command.write_report

    def kept(*args, **kwargs) -> ReportSummary:
        summaries.append(write(*args, **kwargs))
        return summaries[-1]

    with pytest.MonkeyPatch.context() as patch:  # stderr is a file: no variable says otherwise
        for name in ("FORCE_COLOR", "TTY_COMPATIBLE", "TTY_INTERACTIVE"):
            patch.delenv(name, raising=False)
        patch.setattr(report_command, "write_report", kept)
        with open(out / STDERR_NAME, "w") as err, contextlib.redirect_stderr(err):
            assert cli_main(["report", "--quick", "--out", str(out)]) == 0
    assert len(summaries) == 1 and summaries[0].out == out
    return summaries[0]


@pytest.fixture(scope="session")
def quick_report(quick_run: ReportSummary) -> Path:
    """The folder ``poinsot report --quick`` wrote (its stderr in :data:`STDERR_NAME`)."""
    return quick_run.out


@pytest.fixture(scope="session")
def small_study(quick_run: ReportSummary) -> list[CaseResult]:
    """The quick run's results for :data:`SMALL_STUDY_CASES`, in that order."""
    by_name = {result.case.name: result for result in quick_run.results}
    return [by_name[name] for name in SMALL_STUDY_CASES]


# -- the user guide ----------------------------------------------------------------------
def build_docs(config: Path, site: Path) -> subprocess.CompletedProcess[str]:
    """``mkdocs build --strict`` of ``config`` into ``site``, as ``make docs`` runs it (skipped
    locally, failed in CI, when MkDocs is not installed: the ``docs`` extra)."""
    try:
        import mkdocs  # noqa: F401
    except ImportError:
        message = "MkDocs is missing: `make install-test` installs the docs extra"
        if in_ci():
            pytest.fail(message + " [CI=true: the guide must build]")
        pytest.skip(message)
    return subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "-f", str(config), "-d", str(site)],
        cwd=Path(__file__).resolve().parents[1],
        env={**os.environ, "NO_MKDOCS_2_WARNING": "1"},
        capture_output=True,
        text=True,
        timeout=600,
    )


@pytest.fixture(scope="session")
def built_docs(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The guide built from this checkout (``mkdocs.yml``) into a folder of its own."""
    site = tmp_path_factory.mktemp("docs") / "site"
    done = build_docs(Path(__file__).resolve().parents[1] / "mkdocs.yml", site)
    assert done.returncode == 0, done.stderr[-3000:]
    return site
