"""The README and the user guide: the guide builds with ``--strict`` (and a broken link fails
it), the API page documents ``FreeRigidBody``, every code block of the tutorials and of the
README runs, the figures agree with the code, and the servers answer the built guide at
``/docs/`` (the Help link's browser test is ``tests/browser/test_help_page.py``)."""

from __future__ import annotations

import argparse
import http.client
import importlib.util
import re
import shlex
import shutil
import subprocess
from pathlib import Path
from types import ModuleType

import pytest
import yaml
from uploading import toss_recording

from poinsot.app.cli.main import build_parser, main
from poinsot.app.lessons import scene_names
from poinsot.app.live.landing import Balancer, LandingServer
from poinsot.app.model import docs_site
from poinsot.app.model.presets import MENU, PRESETS
from tests.conftest import build_docs

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
DOCS = ROOT / "docs"
TUTORIALS = sorted((DOCS / "tutorials").glob("*.md"))
FENCE = re.compile(r"^( *)```(\w+)\n(.*?)^\1```", re.DOTALL | re.MULTILINE)


def blocks(path: Path, language: str) -> list[str]:
    """The fenced blocks of ``language`` in a Markdown file, in order, dedented."""
    found = []
    for indent, lang, body in FENCE.findall(path.read_text()):
        if lang == language:
            found.append("".join(line[len(indent) :] + "\n" for line in body.splitlines()))
    return found


def commands(path: Path) -> list[list[str]]:
    """Each command of the file's ``sh`` blocks as its words (comments dropped)."""
    out = []
    for block in blocks(path, "sh"):
        for line in block.splitlines():
            words = shlex.split(line, comments=True)
            if words:
                out.append(words)
    return out


def load_hooks() -> ModuleType:
    """The guide's MkDocs hooks (``docs/_hooks/poinsot_docs.py``) as a module."""
    spec = importlib.util.spec_from_file_location(
        "poinsot_docs", DOCS / "_hooks" / "poinsot_docs.py"
    )
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def default_port() -> int:
    serve = build_parser().parse_args(["serve"])
    return int(serve.port)


# -- the README --------------------------------------------------------------------------------
def test_the_readme_is_short_and_about_using_poinsot():
    text = README.read_text()
    assert len(text.splitlines()) <= 200
    for internal in ("PAGE_MAX_FPS", "NO_MSAA_JS", "xdist", "loadgroup", "| scene | settings |"):
        assert internal not in text, internal


def run_command(words: list[str], where: Path) -> None:
    """Run a command of the README or a tutorial as a test can: ``make`` targets as a dry run
    (the target and its variables exist), ``poinsot serve`` parsed by the real parser (it would
    serve until stopped), ``poinsot fit`` for real on a recording made here."""
    if words[0] == "make":
        done = subprocess.run(
            ["make", "-n", *words[1:]], cwd=ROOT, capture_output=True, text=True, timeout=60
        )
        assert done.returncode == 0, done.stderr
        return
    program, *argv = words
    assert program in ("poinsot", ".venv/bin/poinsot"), f"no way to run {words}"
    if argv[0] == "serve":
        args = build_parser().parse_args(argv)
        assert args.command == "serve" and args.func.__name__ == "serve"
        return
    assert argv[0] == "fit", f"a tutorial's command this test does not run: {words}"
    (where / argv[1]).write_bytes(toss_recording())
    assert main(argv) == 0
    for name in argv[2:]:
        if not name.startswith("-"):
            assert (where / name).exists(), name


@pytest.mark.server  # it starts a process of its own
def test_every_command_of_the_readme_runs_from_a_fresh_clone(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    found = commands(README)
    assert [w[:2] for w in found[:2]] == [["make", "run"], ["make", "test"]]
    for words in found:
        run_command(words, tmp_path)
    # The command table: each row parses with the real parser (files in capitals are the
    # reader's own).
    rows = re.findall(r"^\| `(poinsot [^`]+)` \|", README.read_text(), re.MULTILINE)
    assert len(rows) >= 8
    for row in rows:
        for word in shlex.split(row):
            if re.fullmatch(r"[A-Z]+\.\w+", word):
                (tmp_path / word).touch()
        args = build_parser().parse_args(shlex.split(row)[1:])
        assert args.command == row.split()[1]
    # Its Python block runs.
    for block in blocks(README, "python"):
        exec(compile(block, str(README), "exec"), {})
    # Every make target it names exists.
    for target in set(re.findall(r"`make (\w[\w-]*)", README.read_text())):
        assert re.search(rf"^{target}:", (ROOT / "Makefile").read_text(), re.MULTILINE), target


def test_the_readme_links_only_to_files_that_exist():
    for target in re.findall(r"\]\(([^)#:]+)\)", README.read_text()):
        assert (ROOT / target).exists(), target


# -- figures against the code ------------------------------------------------------------------
def test_every_port_written_in_the_readme_and_the_guide_is_the_code_s():
    """The port is read from the parser in the guide (``%%port%%``); where a page writes it
    out (the README, the nginx example), it is the parser's default and the Makefile's."""
    port = default_port()
    makefile = (ROOT / "Makefile").read_text()
    assert re.search(r"^PORT\s*\?=\s*(\d+)", makefile, re.MULTILINE).group(1) == str(port)
    pattern = re.compile(r"(?:localhost|HOST|BALANCER|\d+\.\d+\.\d+\.\d+):(\d{4,5})\b|--port (\d+)")
    pages = [README, *sorted(DOCS.rglob("*.md"))]
    written = [int(a or b) for page in pages for a, b in pattern.findall(page.read_text())]
    assert written and set(written) - {0} == {port}


def test_every_figure_the_guide_reads_from_the_code_exists():
    hooks = load_hooks()
    named = {m for page in DOCS.rglob("*.md") for m in hooks.FIGURE.findall(page.read_text())}
    assert named and named <= set(hooks.FIGURES)
    assert hooks.figure("port") == str(default_port())
    with pytest.raises(Exception, match="unknown figure"):
        hooks.figure("no_such_figure")


# -- the tutorials -----------------------------------------------------------------------------
@pytest.mark.server  # it starts a process of its own
@pytest.mark.parametrize("page", TUTORIALS, ids=lambda p: p.stem)
def test_every_code_block_of_a_tutorial_runs(page: Path, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    namespace: dict[str, object] = {}
    for block in blocks(page, "python"):
        exec(compile(block, str(page), "exec"), namespace)
    for words in commands(page):
        run_command([w.replace("%%port%%", str(default_port())) for w in words], tmp_path)
    assert blocks(page, "python") or commands(page) or page.stem == "explore"


# -- the build ---------------------------------------------------------------------------------
@pytest.mark.slow
def test_the_guide_builds_strictly_with_the_physics_api(built_docs: Path):
    assert (built_docs / "index.html").is_file()
    api = (built_docs / "reference" / "physics" / "index.html").read_text()
    text = re.sub(r"<[^>]+>", " ", api)
    for name in ("FreeRigidBody", "inertia", "omega0", "attitude0", "from_energy", "omega"):
        assert name in text, name
    assert "Parameters:" in text
    for method in ("from_energy", "omega", "attitude", "contact_point", "sample", "polhode"):
        assert f'id="poinsot.physics.FreeRigidBody.{method}"' in api, method
    models = (built_docs / "reference" / "models" / "index.html").read_text()
    for module in ("family", "flip", "symmetric", "gyroscope", "dissipation", "racket"):
        assert f'id="poinsot.physics.models.{module}"' in models, module
    cli = (built_docs / "reference" / "cli" / "index.html").read_text()
    for command in build_parser()._subparsers._group_actions[0].choices:  # type: ignore[union-attr]
        assert f"poinsot {command}" in cli, command
    # Offline: nothing fetched from another host.
    for page in built_docs.rglob("*.html"):
        assert not re.search(r"""(src|href)=["']https?://(?!localhost)""", _head(page)), page


def _head(page: Path) -> str:
    text = page.read_text()
    return text[: text.find("<body")]


@pytest.mark.slow
def test_a_broken_link_fails_the_strict_build(tmp_path: Path):
    """The same configuration and pages, one link broken: the build fails and names it."""
    docs = tmp_path / "docs"
    shutil.copytree(DOCS, docs, ignore=shutil.ignore_patterns("__pycache__"))
    index = docs / "index.md"
    index.write_text(index.read_text() + "\nSee [a page](no-such-page.md).\n")
    config = yaml.safe_load((ROOT / "mkdocs.yml").read_text())
    config["docs_dir"] = str(docs)
    config["hooks"] = [str(ROOT / hook) for hook in config["hooks"]]
    python = config["plugins"][1]["mkdocstrings"]["handlers"]["python"]
    python["paths"] = [str(ROOT / path) for path in python["paths"]]
    (tmp_path / "mkdocs.yml").write_text(yaml.safe_dump(config, allow_unicode=True))
    done = build_docs(tmp_path / "mkdocs.yml", tmp_path / "site")
    said = done.stdout + done.stderr
    assert done.returncode != 0
    assert "contains a link 'no-such-page.md'" in said and "in strict mode" in said, said


# -- served at /docs/ --------------------------------------------------------------------------
def test_every_preset_and_scene_has_its_page_of_the_guide():
    keys = {p.key for p in (*PRESETS, *MENU)} | set(scene_names())
    assert keys <= set(docs_site.PAGES)
    for page in docs_site.PAGES.values():
        assert (DOCS / (page.rstrip("/") + ".md")).is_file(), page


@pytest.fixture
def site(tmp_path, monkeypatch) -> Path:
    root = tmp_path / "site"
    (root / "explanation" / "separatrix").mkdir(parents=True)
    (root / "index.html").write_text("<h1>front</h1>")
    (root / "explanation" / "separatrix" / "index.html").write_text("<h1>separatrix</h1>")
    (tmp_path / "secret.txt").write_text("not the guide's")
    monkeypatch.setenv(docs_site.SITE_VARIABLE, str(root))
    return root


def test_the_guide_s_files_are_answered_and_nothing_outside_it(site: Path):
    assert docs_site.answer("/") is None and docs_site.answer("/poinsot-status") is None
    assert docs_site.answer("/docs/").body == b"<h1>front</h1>"
    page = docs_site.answer("/docs/explanation/separatrix/?q=1")
    assert page.status == 200 and page.body == b"<h1>separatrix</h1>"
    assert ("Content-Type", "text/html; charset=utf-8") in page.headers
    moved = docs_site.answer("/docs/explanation/separatrix")
    assert moved.status == 301 and ("Location", "/docs/explanation/separatrix/") in moved.headers
    assert docs_site.answer("/docs").status == 301
    for outside in ("/docs/../secret.txt", "/docs/%2e%2e/secret.txt", "/docs/nothing.html"):
        assert docs_site.answer(outside).status == 404, outside
    assert "make docs" not in docs_site.help_markdown("dzhanibekov")
    assert 'href="/docs/explanation/separatrix/"' in docs_site.help_markdown("dzhanibekov")


def test_without_a_built_guide_the_link_and_the_page_say_how_to_build_it(tmp_path, monkeypatch):
    monkeypatch.setenv(docs_site.SITE_VARIABLE, str(tmp_path / "not-built"))
    assert "`make docs`" in docs_site.help_markdown("t_handle")
    answer = docs_site.answer("/docs/explanation/separatrix/")
    assert answer.status == 404 and b"<code>make docs</code>" in answer.body


def get(port: int, path: str) -> tuple[int, dict[str, str], bytes]:
    connection = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    try:
        connection.request("GET", path)
        response = connection.getresponse()
        return response.status, dict(response.getheaders()), response.read()
    finally:
        connection.close()


def test_a_server_and_the_landing_answer_the_guide(site: Path, make_app):
    app = make_app()
    status, headers, body = get(app.port, "/docs/explanation/separatrix/")
    assert (status, body) == (200, b"<h1>separatrix</h1>")
    assert get(app.port, "/")[0] == 200  # viser's page still answers the rest
    landing = LandingServer("127.0.0.1", 0, Balancer([]))
    landing.start()
    try:
        status, headers, body = get(landing.port, "/docs/")
        assert (status, body) == (200, b"<h1>front</h1>"), headers  # answered, not redirected
        assert get(landing.port, "/")[0] == 503  # no worker: the redirect's path is unchanged
    finally:
        landing.shutdown()
        landing.server_close()


def test_the_parser_the_guide_documents_is_the_command_line_s():
    hooks = load_hooks()
    parser = hooks.build_parser()
    assert isinstance(parser, argparse.ArgumentParser)
    assert parser.format_help() == build_parser().format_help()
