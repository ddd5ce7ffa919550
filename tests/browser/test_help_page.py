"""The panel's Help link, as a lecturer's browser follows it: ``poinsot serve --workers 2`` with a
built guide, the page opened through the landing port, the link followed to the guide's page
for the scene on screen, all in the suite's Chromium, which reaches nothing past loopback
(``CHROMIUM_ARGS``: every other host name resolves to nothing), and with every request of the
guide's page checked to stay on this machine."""

from __future__ import annotations

import re
import urllib.parse
from collections.abc import Iterator
from pathlib import Path

import pytest

from poinsot.app.lessons import scene_by_name
from poinsot.app.model import docs_site
from tests.app.test_workers import Classroom, start_classroom, stop_classroom
from tests.conftest import wait_until

pytestmark = pytest.mark.slow

LOCAL = ("http://127.0.0.1:", "data:", "blob:")


@pytest.fixture
def classroom_with_guide(built_docs: Path, monkeypatch) -> Iterator[Classroom]:
    """Two workers behind a landing, each browser starting on the Dzhanibekov scene, the guide
    built from this checkout (the workers inherit where it is)."""
    monkeypatch.setenv(docs_site.SITE_VARIABLE, str(built_docs))
    room = start_classroom("--scene", "dzhanibekov", workers=2)
    yield room
    stop_classroom(room)


def test_the_help_link_opens_the_guide_for_the_scene_shown(classroom_with_guide, open_page):
    room = classroom_with_guide
    app = open_page(f"http://127.0.0.1:{room.port}/", live_view=False)
    worker = urllib.parse.urlsplit(app.page.url).port
    assert worker in room.worker_ports  # the landing sent the browser to a worker
    link = app.page.get_by_role("link", name=re.compile("^Help"))
    link.wait_for(timeout=20000)
    assert link.get_attribute("href") == "/docs/explanation/separatrix/"
    assert "make docs" not in link.locator("xpath=..").inner_text()  # the guide is built

    requests: list[str] = []
    failed: list[str] = []
    app.page.context.on("request", lambda r: requests.append(r.url))
    app.page.context.on("requestfailed", lambda r: failed.append(r.url))
    assert link.get_attribute("target") == "_blank"  # beside the scene: the session stays
    with app.page.context.expect_page() as opened:
        link.click()
    guide = opened.value
    guide.wait_for_load_state("load")
    assert guide.url == f"http://127.0.0.1:{worker}/docs/explanation/separatrix/"
    assert (
        guide.locator("article h1").first.inner_text().rstrip("¶") == "The separatrix and the flip"
    )
    assert guide.locator("article math").count() > 0  # the equations, drawn with no script
    assert requests and not failed, failed
    assert all(url.startswith(LOCAL) for url in requests), [
        url for url in requests if not url.startswith(LOCAL)
    ]

    # Another scene: the link follows what is on screen.
    app.choose("Preset", scene_by_name("tennis-racket").label)
    assert wait_until(
        lambda: link.get_attribute("href") == "/docs/explanation/tennis-racket/", 20
    ), link.get_attribute("href")

    # The landing answers the guide itself (a reader is no browser on its way to a worker).
    guide.goto(f"http://127.0.0.1:{room.port}/docs/")
    assert guide.url == f"http://127.0.0.1:{room.port}/docs/"
    assert guide.locator("article h1").first.inner_text().rstrip("¶") == "Poinsot"
