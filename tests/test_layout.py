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
