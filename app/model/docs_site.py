"""The user guide, offline: the built documentation site (``make docs`` writes ``site/``) served
at ``/docs/`` by ``poinsot serve``, and the guide's page for what a browser shows.

A lecture hall may have no internet: the guide is the project's own MkDocs site, built once on
the lecturer's machine and served by the same server as the scene (each worker, and the landing
port in front of them). Without a built site every ``/docs/`` address answers a short page that
says how to build it. This module knows files and names only (no HTTP library, no viser): the
servers turn an :class:`Answer` into their own response.

The site is ``$POINSOT_DOCS_SITE`` if set, else ``site/`` beside the ``mkdocs.yml`` found above
this file (a checkout's, where ``make docs`` builds it).
"""

from __future__ import annotations

import dataclasses
import html
import mimetypes
import os
import urllib.parse
from pathlib import Path

#: Where the guide is served, on every port of ``poinsot serve``.
PREFIX = "/docs/"
#: The environment variable naming a built site elsewhere (tests, an installed copy).
SITE_VARIABLE = "POINSOT_DOCS_SITE"
BUILD_COMMAND = "make docs"

#: The guide's page (a folder of the site: MkDocs' directory URLs) for what a browser shows,
#: by the preset's key or the scene's name; anything else opens the guide's front page.
PAGES: dict[str, str] = {
    # The presets: the construction, the separatrix, the symmetric closed forms.
    "major": "explanation/poinsot/",
    "minor": "explanation/poinsot/",
    "t_handle": "explanation/separatrix/",
    "near_separatrix": "explanation/separatrix/",
    "separatrix": "explanation/separatrix/",
    "oblate": "explanation/closed-forms/",
    "prolate": "explanation/closed-forms/",
    "sphere": "explanation/closed-forms/",
    "custom": "tutorials/explore/",
    "fitted_toss": "tutorials/own-toss/",
    "mesh_body": "tutorials/mesh-body/",
    # The lecture scenes.
    "polhode-family": "explanation/poinsot/",
    "dzhanibekov": "explanation/separatrix/",
    "symmetric-top": "explanation/closed-forms/",
    "gyroscope-torque": "explanation/scenes/",
    "long-cylinder": "explanation/scenes/",
    "explorer-1": "explanation/scenes/",
    "geometric-phase": "explanation/geometric-phase/",
    "tennis-racket": "explanation/tennis-racket/",
}


@dataclasses.dataclass(frozen=True)
class Answer:
    """An HTTP answer to a request for the guide: status, headers and body."""

    status: int
    headers: tuple[tuple[str, str], ...]
    body: bytes

    @property
    def reason(self) -> str:
        return {200: "OK", 301: "Moved Permanently", 404: "Not Found"}.get(self.status, "")


def site_dir() -> Path | None:
    """The built site's folder, or None when it has not been built (no ``index.html``)."""
    named = os.environ.get(SITE_VARIABLE)
    if named:
        root: Path | None = Path(named)
    else:
        root = next(
            (p / "site" for p in Path(__file__).resolve().parents if (p / "mkdocs.yml").exists()),
            None,
        )
    return root if root is not None and (root / "index.html").is_file() else None


def page_for(key: str) -> str:
    """The address of the guide's page for the preset or scene ``key``."""
    return PREFIX + PAGES.get(key, "")


def help_markdown(key: str) -> str:
    """The panel's "Help" line for what is shown: a link to its page of the guide, opened beside
    the scene (a new tab: the session stays), and how to build the guide when it has not been
    built."""
    link = (
        f'<a href="{page_for(key)}" target="_blank" rel="noopener">'
        "Help: the guide to what you see</a>"
    )
    if site_dir() is None:
        return f"<small>{link} (not built yet: run `{BUILD_COMMAND}`, then reload)</small>"
    return f"<small>{link}</small>"


def answer(path: str) -> Answer | None:
    """The answer to a GET of ``path`` (with its query, as the request line has it), or None
    when ``path`` is not the guide's."""
    route = urllib.parse.urlsplit(path).path
    if route == PREFIX.rstrip("/"):
        return _redirect(PREFIX)
    if not route.startswith(PREFIX):
        return None
    root = site_dir()
    if root is None:
        return _page(404, _NOT_BUILT)
    parts = [urllib.parse.unquote(p) for p in route[len(PREFIX) :].split("/")]
    if any(p in ("..", ".") or "\\" in p or "\0" in p for p in parts):
        return _page(404, _MISSING)
    target = root.joinpath(*[p for p in parts if p])
    if target.is_dir():
        if not route.endswith("/"):  # a page's relative links need its folder's address
            return _redirect(route + "/")
        target = target / "index.html"
    try:
        resolved = target.resolve()
        inside = resolved.is_relative_to(root.resolve())
        body = resolved.read_bytes() if inside and resolved.is_file() else None
    except OSError:
        body = None
    if body is None:
        return _page(404, _MISSING)
    kind = mimetypes.guess_type(resolved.name)[0] or "application/octet-stream"
    if kind.startswith("text/") or kind in ("application/javascript", "application/json"):
        kind += "; charset=utf-8"
    return Answer(200, _headers(kind, body), body)


def _headers(kind: str, body: bytes) -> tuple[tuple[str, str], ...]:
    return (
        ("Content-Type", kind),
        ("Content-Length", str(len(body))),
        ("Cache-Control", "no-cache"),
    )


def _redirect(location: str) -> Answer:
    return Answer(301, (("Location", location), ("Content-Length", "0")), b"")


_NOT_BUILT = (
    "The guide has not been built on this machine.",
    f"In Poinsot's folder run <code>{BUILD_COMMAND}</code> (it writes <code>site/</code>), "
    "then reload this page.",
)
_MISSING = ("No such page in the guide.", f'Its front page is <a href="{PREFIX}">{PREFIX}</a>.')


def _page(status: int, lines: tuple[str, str]) -> Answer:
    title, text = lines
    body = (
        f"<!doctype html><html lang=en><meta charset=utf-8><title>{html.escape(title)}</title>"
        f"<body style='font-family:sans-serif;max-width:40em;margin:3em auto'>"
        f"<h1>{html.escape(title)}</h1><p>{text}</p></body></html>\n"
    ).encode()
    return Answer(status, _headers("text/html; charset=utf-8", body), body)
