"""The package boundary: physics/ imports numpy and scipy only."""

import ast
import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[1]
ALLOWED = {
    "numpy",
    "scipy",
    "math",
    "enum",
    "dataclasses",
    "typing",
    "__future__",
    "functools",
    "time",
    "argparse",
    "sys",
    "collections",
    "warnings",
    "fractions",
    "decimal",
}


def _top_level_imports(path: pathlib.Path) -> set[str]:
    tree = ast.parse(path.read_text())
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(a.name.split(".")[0] for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module.split(".")[0])
    return names


def test_physics_imports_only_numpy_and_scipy():
    files = sorted((ROOT / "physics").rglob("*.py"))
    assert files
    for f in files:
        bad = _top_level_imports(f) - ALLOWED - {"poinsot"}
        assert not bad, f"{f.name} imports {sorted(bad)}"


def _imported_modules(path: pathlib.Path) -> set[str]:
    tree = ast.parse(path.read_text())
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module)
    return names


def test_physics_imports_nothing_of_the_app():
    for f in sorted((ROOT / "physics").rglob("*.py")):
        ours = {m for m in _imported_modules(f) if m.split(".")[0] == "poinsot"}
        bad = {m for m in ours if not (m + ".").startswith("poinsot.physics.")}
        assert not bad, f"{f.name} imports {sorted(bad)}"


def test_code_imports_through_the_one_namespace():
    """``poinsot.physics`` and ``poinsot.app`` only: never a bare ``physics`` or ``app``."""
    for f in sorted(ROOT.glob("*/**/*.py")):
        if f.parts[len(ROOT.parts)] not in ("physics", "app", "tests"):
            continue
        bare = {m for m in _imported_modules(f) if m.split(".")[0] in ("physics", "app")}
        assert not bare, f"{f.relative_to(ROOT)} imports {sorted(bare)}"


def test_every_package_folder_ships():
    """pyproject's package list names every folder with an ``__init__.py`` (a forgotten one
    works in the editable install but is missing from a wheel)."""
    import tomllib

    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    listed = set(config["packages"])
    found = set()
    for top in ("physics", "app"):
        for init in (ROOT / top).rglob("__init__.py"):
            rel = init.parent.relative_to(ROOT).parts
            found.add(".".join(("poinsot",) + rel))
    assert listed == found


#: A module holds one concern: about 500 lines at most.
MAX_MODULE_LINES = 500
#: A function does one step: about 60 lines at most, unless the line before it says why
#: (a comment starting with "# long:").
MAX_FUNCTION_LINES = 60


def _code_files() -> list[pathlib.Path]:
    return sorted(p for top in ("physics", "app") for p in (ROOT / top).rglob("*.py"))


def test_modules_are_small_rooms():
    big = {}
    for f in _code_files():
        n = len(f.read_text().splitlines())
        if n > MAX_MODULE_LINES:
            big[str(f.relative_to(ROOT))] = n
    assert not big, f"modules over {MAX_MODULE_LINES} lines: {big}"


def test_functions_do_one_step():
    long = {}
    for f in _code_files():
        lines = f.read_text().splitlines()
        for node in ast.walk(ast.parse("\n".join(lines))):
            if not isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                continue
            assert node.end_lineno is not None
            first = min([node.lineno] + [d.lineno for d in node.decorator_list])
            length = node.end_lineno - node.lineno + 1
            said_why = first >= 2 and lines[first - 2].strip().startswith("# long:")
            if length > MAX_FUNCTION_LINES and not said_why:
                long[f"{f.relative_to(ROOT)}:{node.lineno} {node.name}"] = length
    assert not long, f"functions over {MAX_FUNCTION_LINES} lines: {long}"


def test_comments_cite_only_what_the_repo_holds():
    """Sources are cited by the keys of docs/REFERENCES.md, never by private notes, seed
    files or issue numbers that a reader of the repository cannot open."""
    import re

    pattern = re.compile(r"\bseed \d|\bissue \d|shared/|PHYSICS\.md", re.IGNORECASE)
    hits = []
    for f in _code_files() + sorted((ROOT / "tests").rglob("*.py")):
        if f == pathlib.Path(__file__).resolve():
            continue
        for k, line in enumerate(f.read_text().splitlines(), 1):
            if pattern.search(line):
                hits.append(f"{f.relative_to(ROOT)}:{k}: {line.strip()}")
    assert not hits, "\n".join(hits)


def test_cited_keys_are_in_the_reference_list():
    import re

    listed = set(
        re.findall(
            r"^\| \*\*([A-Za-z0-9]+)\*\* \|", (ROOT / "docs" / "REFERENCES.md").read_text(), re.M
        )
    )
    assert {"LL76", "FM06", "Pars65", "DLMF"} <= listed
    cited = set()
    for f in _code_files():
        cited.update(re.findall(r"\[([A-Z][A-Za-z]*\d\d)[\] ,§]", f.read_text()))
    assert cited - listed == set(), f"cited but not in docs/REFERENCES.md: {sorted(cited - listed)}"
