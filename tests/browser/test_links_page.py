"""Links to the exact state, opened by a real browser: straight on a server and through the
landing in front of two servers; the state read back from the panel and the readouts (and the
session's clock and camera), and "Copy link" gives a link that opens the same state."""

from __future__ import annotations

import dataclasses
import re
import urllib.parse

import numpy as np
import pytest

from poinsot.app.construction.cameras import space_view
from poinsot.app.live.landing import Balancer, LandingServer
from poinsot.app.live.server import PoinsotApp
from poinsot.app.model.presets import DEFAULT_PRESET, preset_by_key
from tests.app.test_nginx import balancer  # noqa: F401 (the guide's nginx, a fixture)
from tests.conftest import PAGE_OPEN_S, BrowserPage, session_of, wait_until

pytestmark = [pytest.mark.browser, pytest.mark.slow]

EPSILON = "ε from the intermediate axis"


@dataclasses.dataclass
class AppBackend:
    """A server of this process as the landing sees a worker."""

    app: PoinsotApp
    pid: int | None = None
    alive: bool = True

    @property
    def port(self) -> int:
        return self.app.port

    @property
    def clients(self) -> int:
        return len(self.app.sessions())

    @property
    def connects(self) -> int:
        return len(self.app.sessions())


def new_session(app: PoinsotApp, known: set[int]):
    """The session of the browser that arrived after those in ``known`` (added to it)."""
    assert wait_until(lambda: bool(set(app.sessions()) - known), 20), "no new session"
    client_id = max(set(app.sessions()) - known)
    known.add(client_id)
    return app.sessions()[client_id]


def time_readout(page: BrowserPage) -> tuple[float, str]:
    text = page.page.locator("p").filter(has_text=re.compile(r"t = +-?\d")).first.inner_text()
    match = re.search(r"t = +(-?[\d.]+)\s+(\w+)", text)
    assert match, text
    return float(match.group(1)), match.group(2)


def check_preset_link(page: BrowserPage, session) -> None:
    """?preset=t_handle&t=12&view=side&paused=1"""
    preset = preset_by_key("t_handle")
    assert wait_until(lambda: page.dropdown_value("Preset") == preset.label, 20)
    assert wait_until(lambda: time_readout(page) == (12.0, "paused"), 20)
    assert session.preset is preset and session.clock.paused
    # The server's copy of the camera is the browser's last report: a report of the first view,
    # sent before the browser took the link's, can come after it; the next one is the side view.
    # The side view's direction (framed for the browser's view: moved along it).
    assert wait_until(lambda: looks_along(session.client.camera, space_view("side")), 20), (
        session.client.camera.position
    )
    # Paused at t = 12, its plot is drawn all the same: the motion up to t, not one point.
    plot = session.panel.motion.plot
    assert plot is not None
    assert wait_until(lambda: len(plot.data[0]) > 100 and abs(plot.data[0][-1] - 12.0) < 0.2, 20)
    assert np.all(np.isfinite(np.asarray(plot.data[1:4])))
    assert page.page.get_by_role("button", name="Play", exact=True).count() == 1


def looks_along(camera, view) -> bool:
    """Does ``camera`` look in ``view``'s direction (wherever it stands along it)?"""
    forward = np.subtract(camera.look_at, camera.position)
    wanted = np.subtract(view.look_at, view.position)
    return bool(
        np.allclose(forward / np.linalg.norm(forward), wanted / np.linalg.norm(wanted), atol=1e-3)
    )


def check_scene_link(page: BrowserPage, session) -> None:
    """?scene=dzhanibekov&epsilon=1e-8"""
    assert wait_until(lambda: page.control_count(EPSILON) == 1, 20)
    assert page.dropdown_value(EPSILON) == "1e-8"
    assert session.showcase.spec.name == "dzhanibekov"
    assert wait_until(lambda: session.showcase.showcase.model.epsilon == 1e-8, 20)
    # the readouts: ε is the model's, read back from the table in the page
    assert wait_until(lambda: page.page.get_by_text("1e-08").count() >= 1, 20)


def check_body_link(page: BrowserPage, session) -> None:
    """?I=1,2,2.6&D=2.1&side=major&pole=plus&w=1.2&speed=0.5&paused=1"""
    assert wait_until(lambda: page.dropdown_value("Preset") == "Custom (edited)", 20)
    # The sliders' values reach the page in messages of their own, after the preset's name.
    wanted = {"I₁": 1.0, "I₂": 2.0, "I₃": 2.6, "D = |L|²/2T": 2.1, "|ω₀|": 1.2, "Speed": 0.5}

    def sliders() -> dict[str, float]:
        return {label: page.slider_value(label) for label in wanted}

    def shown() -> bool:
        values = sliders()
        return all(
            values[k] == pytest.approx(v, abs=1e-3 if k[0] == "D" else 1e-9)
            for k, v in wanted.items()
        )

    assert wait_until(shown, 20), sliders()
    assert wait_until(lambda: time_readout(page) == (0.0, "paused"), 20)
    assert session.params.inertia == (1.0, 2.0, 2.6) and session.params.pole_sign == 1
    assert session.clock.speed == 0.5


LINKS = {
    "preset=t_handle&t=12&view=side&paused=1": check_preset_link,
    "scene=dzhanibekov&epsilon=1e-8": check_scene_link,
    "I=1,2,2.6&D=2.1&side=major&pole=plus&w=1.2&speed=0.5&paused=1": check_body_link,
}


def copy_link(page: BrowserPage, session) -> str:
    lecture = session.lecture
    before = lecture.last_link
    page.click_button("Copy link")
    assert wait_until(lambda: lecture.last_link != before, 20)
    assert wait_until(lambda: page.page.get_by_text(lecture.last_link).count() >= 1, 20)
    return lecture.last_link


@pytest.fixture(scope="module")
def app(make_module_app) -> PoinsotApp:
    """One server for the module's links opened straight on a server."""
    return make_module_app()


def reopen(page: BrowserPage, url: str) -> BrowserPage:
    """Open ``url`` in the same page (its session leaves, a new one comes): the viser client
    comes from the page's cache, and one page renders at a time (software WebGL is slow)."""
    page.page.goto(url)
    page.page.locator("canvas").first.wait_for(state="visible", timeout=PAGE_OPEN_S * 1000)
    return page


@pytest.mark.parametrize("query", list(LINKS))
def test_a_link_opens_its_state_and_copy_link_gives_it_back(app, open_page, query):
    known = set(app.sessions())
    page = open_page(f"{app.url}/?{query}", live_view=False)
    session = new_session(app, known)
    LINKS[query](page, session)
    link = copy_link(page, session)
    assert link.startswith(f"{app.url}/?")
    assert page.errors == []
    assert session.stats.errors == 0, session.stats.last_error
    again = reopen(page, link)
    LINKS[query](again, new_session(app, known))
    assert again.errors == []


def test_links_through_the_landing_open_on_either_worker(make_app, make_probe, open_page):
    apps = [make_app(), make_app()]
    landing = LandingServer("127.0.0.1", 0, Balancer([AppBackend(a) for a in apps]))
    landing.start()
    for app in apps:  # as poinsot serve --workers tells its workers
        app.landing_port = landing.port
    known: dict[int, set[int]] = {id(a): set() for a in apps}
    used = []
    page = None
    try:
        for query, check in LINKS.items():
            link = f"http://127.0.0.1:{landing.port}/?{query}"
            page = open_page(link, live_view=False) if page is None else reopen(page, link)
            url = urllib.parse.urlsplit(page.page.url)
            assert url.query == query  # the redirect kept the link's state
            app = next(a for a in apps if a.port == url.port)
            used.append(app)
            session = new_session(app, known[id(app)])
            check(page, session)
            if len(used) == 1:  # a copied link names the landing, not the worker
                link = copy_link(page, session)
                assert link.startswith(f"http://127.0.0.1:{landing.port}/?")
            assert page.errors == []
            # The next link opens in this page (one rendering page at a time: software WebGL
            # is slow); its session leaves as the next is redirected.
            make_probe(app)  # holds that worker's load: the next browser goes to the other
            new_session(app, known[id(app)])
    finally:
        landing.shutdown()
        landing.server_close()
    assert {id(a) for a in used} == {id(a) for a in apps}


def test_a_link_through_the_readme_s_nginx_opens_its_state(balancer, open_page):  # noqa: F811
    """Through the guide's nginx in front of two servers: the state opens, and "Copy link"
    gives the address the browser sees (nginx's), not the server's behind it."""
    port, apps = balancer
    query = "preset=t_handle&t=12&view=side&paused=1"
    page = open_page(f"http://127.0.0.1:{port}/?{query}", live_view=False)
    assert wait_until(lambda: sum(len(a.sessions()) for a in apps) == 1, 30)
    session = session_of(next(a for a in apps if a.sessions()))
    check_preset_link(page, session)
    assert copy_link(page, session) == f"http://127.0.0.1:{port}/?{query}"
    assert page.errors == []


#: Two kinds of bad link in the page (a value no parameter takes, a body no body can be); the
#: messages of every kind are tests/app/test_links.py's, without a browser.
BAD = {
    "preset=nope": "preset='nope'",
    "I=1,1,5": "no body has I",
}


def test_a_bad_link_opens_the_default_scene_and_names_the_parameter(app, open_page):
    known = set(app.sessions())
    page = None
    for query, named in BAD.items():
        url = f"{app.url}/?{query}"
        page = open_page(url, live_view=False) if page is None else reopen(page, url)
        session = new_session(app, known)
        message = page.page.get_by_text("This link could not be opened")
        assert wait_until(lambda m=message: m.count() == 1, 20), query
        status = message.inner_text()
        assert named in status, (query, status)
        assert session.preset is DEFAULT_PRESET and session.showcase is None
        assert wait_until(lambda p=page: p.dropdown_value("Preset") == DEFAULT_PRESET.label, 10)
        assert session.stats.errors == 0 and page.errors == []
