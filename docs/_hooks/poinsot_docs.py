"""MkDocs hooks of Poinsot's guide (``mkdocs.yml``: ``hooks``).

- The command-line reference is generated from the ``poinsot`` parser itself at build time
  (``<!-- poinsot:cli -->`` in a page): it cannot go stale.
- Figures that are constants of the code (frame rates, ports, limits) are written in a page as
  ``%%name%%`` and read from the code here (:data:`FIGURES`); an unknown name fails the build.
- The pictures of ``assets/`` (made by the project's own commands, ``make pictures``) are part of
  the site, under ``assets/``.
- Equations (``$...$``, ``$$...$$``: pymdownx.arithmatex, generic) become MathML at build time:
  the browser draws them with no script and no font from the network (a lecture hall may be
  offline).
- ``poinsot.physics`` is found by the API reference (mkdocstrings, griffe) through a folder
  ``build/docs-api/poinsot/physics`` linked to ``physics/``: the package's import name differs
  from its folder's, which griffe's reading of an editable install does not follow.
"""

from __future__ import annotations

import argparse
import html
import io
import os
import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

from mkdocs.exceptions import PluginError
from mkdocs.structure.files import File, Files

ROOT = Path(__file__).resolve().parents[2]
API_PATH = ROOT / "build" / "docs-api"
CLI_MARK = "<!-- poinsot:cli -->"
FIGURE = re.compile(r"%%([a-z_]+)%%")
PICTURES = (".png", ".gif", ".jpg", ".svg")


def _link_physics() -> None:
    """``build/docs-api/poinsot/physics`` -> ``physics/`` (mkdocs.yml: the handler's ``paths``)."""
    link = API_PATH / "poinsot" / "physics"
    link.parent.mkdir(parents=True, exist_ok=True)
    # A regular package, not a namespace: griffe would take the `poinsot` console script in
    # the interpreter's folder (the first entry of the path) before a namespace portion.
    (link.parent / "__init__.py").write_text('"""Poinsot, as the API reference reads it."""\n')
    if not link.is_symlink() or link.resolve() != (ROOT / "physics").resolve():
        if link.is_symlink() or link.exists():
            link.unlink()
        link.symlink_to(ROOT / "physics", target_is_directory=True)


_link_physics()


# -- the command line -------------------------------------------------------------------------
def build_parser() -> argparse.ArgumentParser:
    """The one parser of ``poinsot`` (every command's options declared). The one place the
    guide names the command line's module."""
    from poinsot.app.cli.main import build_parser as poinsot_parser

    return poinsot_parser()


def _subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    raise PluginError("the poinsot parser has no subcommands")


def _help_text(parser: argparse.ArgumentParser) -> str:
    """``--help`` as a terminal 100 columns wide prints it, the core count written as such."""
    os.environ["COLUMNS"] = "100"
    buffer = io.StringIO()
    parser.print_help(buffer)
    cores = str(os.cpu_count() or 1)
    return buffer.getvalue().replace(f"here {cores})", "here the machine's count)")


def cli_reference() -> str:
    """The reference of every command: a summary table, then each command's ``--help``."""
    parser = build_parser()
    commands = _subcommands(parser)
    helps = {
        a.dest: a.help
        for a in parser._actions
        if isinstance(a, argparse._SubParsersAction)
        for a in a._choices_actions
    }
    rows = ["| command | what it does |", "|---|---|"]
    rows += [
        f"| [`poinsot {name}`](#poinsot-{name}) | {helps.get(name, '')} |" for name in commands
    ]
    parts = ["\n".join(rows), "## `poinsot`", "```text\n" + _help_text(parser) + "```"]
    for name, sub in commands.items():
        parts += [f"## `poinsot {name}` {{#poinsot-{name}}}", "```text\n" + _help_text(sub) + "```"]
    return "\n\n".join(parts) + "\n"


# -- figures read from the code ---------------------------------------------------------------
def _port() -> str:
    serve = _subcommands(build_parser())["serve"]
    return str(next(a.default for a in serve._actions if a.dest == "port"))


def _mb(value: float) -> str:
    return f"{value / 2**20:.3g}" if value % 2**20 == 0 else f"{value / 1e6:.3g}"


def _figures() -> dict[str, Callable[[], str]]:
    from poinsot.app.model import bodies, recordings
    from poinsot.app.exports import html as html_export
    from poinsot.app.exports import video
    from poinsot.app.live.hardening import backlog, pacing
    from poinsot.app.live.classroom import cast, follow, links
    from poinsot.app.live.session import session

    return {
        "port": _port,
        "max_fps": lambda: f"{session.MAX_FPS:g}",
        "process_frames": lambda: f"{pacing.PROCESS_FRAMES:g}",
        "shared_min_fps": lambda: f"{pacing.SHARED_MIN_FPS:g}",
        "mesh_mb": lambda: _mb(bodies.MAX_MESH_BYTES),
        "recording_mb": lambda: _mb(recordings.MAX_BYTES),
        "link_max_time": lambda: f"{links.MAX_TIME:g}",
        "wrong_codes": lambda: str(follow.MAX_WRONG_CODES),
        "own_fps": lambda: f"{cast.OWN_FPS:g}",
        "own_process_frames": lambda: f"{cast.OWN_PROCESS_FRAMES:g}",
        "own_min_every": lambda: f"{1 / cast.OWN_MIN_FPS:g}",
        "video_browser_seconds": lambda: f"{video.BROWSER_MAX_SECONDS:g}",
        "video_browser_size": lambda: "{}×{}".format(*video.BROWSER_MAX_SIZE),
        "video_max_seconds": lambda: f"{video.MAX_SECONDS:g}",
        "html_max_seconds": lambda: f"{html_export.HTML_MAX_SECONDS:g}",
        "backlog_messages": lambda: str(backlog.MAX_PENDING),
        "backlog_mb": lambda: _mb(backlog.MAX_UNACKED),
        "backlog_seconds": lambda: f"{backlog.GRACE_SECONDS:g}",
    }


FIGURES = _figures()


def figure(name: str) -> str:
    """The figure ``name`` as the code has it (a build error for a name not in FIGURES)."""
    if name not in FIGURES:
        raise PluginError(f"unknown figure %%{name}%% (docs/_hooks/poinsot_docs.py: FIGURES)")
    return FIGURES[name]()


# -- equations --------------------------------------------------------------------------------
_MATH = re.compile(r'<(span|div) class="arithmatex">\s*\\[\(\[](.*?)\\[\)\]]\s*</\1>', re.DOTALL)


def _mathml(match: re.Match[str]) -> str:
    from latex2mathml.converter import convert

    display = "block" if match.group(1) == "div" else "inline"
    try:
        return convert(html.unescape(match.group(2)).strip(), display=display)
    except Exception as exc:  # latex2mathml raises its own kinds for TeX it cannot read
        raise PluginError(f"cannot convert {match.group(2)!r} to MathML: {exc}") from exc


# -- the hooks --------------------------------------------------------------------------------
def on_files(files: Files, config: Any) -> Files:
    for path in sorted((ROOT / "assets").rglob("*")):
        if path.suffix in PICTURES:
            rel = path.relative_to(ROOT).as_posix()
            files.append(File(rel, str(ROOT), config["site_dir"], config["use_directory_urls"]))
    return files


def on_page_markdown(markdown: str, page: Any, config: Any, files: Files) -> str:
    if CLI_MARK in markdown:
        markdown = markdown.replace(CLI_MARK, cli_reference())
    return FIGURE.sub(lambda m: figure(m.group(1)), markdown)


def on_page_content(content: str, page: Any, config: Any, files: Files) -> str:
    return _MATH.sub(_mathml, content)
