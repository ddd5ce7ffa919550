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
    files = sorted((ROOT / "physics").glob("*.py"))
    assert files
    for f in files:
        bad = _top_level_imports(f) - ALLOWED - {"physics"}
        assert not bad, f"{f.name} imports {sorted(bad)}"
