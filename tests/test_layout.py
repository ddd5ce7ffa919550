"""The package boundary: physics/ imports numpy and scipy only."""

import ast
import pathlib
import re

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


def _floors_of_contract(name_start: str) -> list[list[str]]:
    """The layers of the import contract whose name starts with ``name_start``, each a list of
    its rooms, top first."""
    import tomllib

    config = tomllib.loads((ROOT / "pyproject.toml").read_text())
    for contract in config["tool"]["importlinter"]["contracts"]:
        if contract["name"].startswith(name_start):
            return [re.split(r"\s*[|:]\s*", layer.strip()) for layer in contract["layers"]]
    raise AssertionError(f"no import contract named {name_start!r}...")


def _floors_of_page(heading: str) -> list[list[str]]:
    """The rooms column of the floors table whose header row starts with ``heading`` in
    docs/ARCHITECTURE.md, each floor a list of its rooms, top first."""
    text = (ROOT / "docs" / "ARCHITECTURE.md").read_text()
    table = text[text.index(heading) :].split("\n\n")[0].splitlines()[2:]  # past the header
    cells = [re.split(r"(?<!\\)\|", row) for row in table]
    return [re.findall(r"`([\w.]+)`", row[2]) for row in cells]


def test_the_architecture_tables_are_the_layered_contracts():
    """docs/ARCHITECTURE.md's floors are the layers of pyproject.toml's contracts, in order."""
    app = _floors_of_page("| floor | rooms (`poinsot.app.…`)")
    live = _floors_of_page("| floor | rooms (`poinsot.app.live.…`)")
    assert app == _floors_of_contract("the app's floors")
    assert live == _floors_of_contract("the live server")


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


# -- tests wait for events, not for the clock ----------------------------------------------------
#: Clock readings: an assert on a value computed from one turns red on a loaded machine (rates
#: and latencies are ``poinsot benchmark``'s figures, not the tests').
CLOCKS = {"monotonic", "perf_counter", "time", "monotonic_ns", "perf_counter_ns", "time_ns"}
#: Tests that read the clock once as the origin of times they make up, by (file, function).
CLOCK_ALLOWED: dict[tuple[str, str], str] = {
    ("tests/app/test_wire.py", "test_what_a_client_gets_through_is_bounded_by_its_budget"): (
        "synthetic arrival times after one reading (the budget starts at time.monotonic())"
    ),
}
#: The sleeps the tests may keep, by (file, function), with the reason: each one is a rhythm or a
#: sampling period, or a render for which the page gives no event. Any other sleep must become a
#: wait on the event it stands for (``wait_until``, ``probe.wait_for``, ``after_frames``).
SLEEPS_ALLOWED: dict[tuple[str, str], str] = {
    ("tests/conftest.py", "wait_until"): "the poll period of the one waiting primitive",
    ("tests/app/test_server.py", "test_random_input_never_raises_nor_sends_nan"): (
        "the storm's irregular rhythm of input, not a wait"
    ),
    ("tests/app/test_wire.py", "frames_in"): (
        "two equal windows, quiet and flooded, in which the frames are counted and compared"
    ),
    ("tests/app/test_wire.py", "poll"): "the sampling period of a peak-memory poller",
}
#: Browser tests: the same reason as above, for each module (the page gives no "drawn" event).
SLEEPS_ALLOWED_IN = {
    "tests/browser/test_loopback.py",
    "tests/browser/test_picture_page.py",
    # Not a test: the script that makes the README's phone and drag pictures; its pauses let
    # the traces grow for the picture.
    "tests/browser/touch_pictures.py",
}


def _is_clock_call(node: ast.AST) -> bool:
    if not isinstance(node, ast.Call):
        return False
    func = node.func
    name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
    return name in CLOCKS and (not isinstance(func, ast.Attribute) or _dotted(func.value) == "time")


def _dotted(node: ast.AST) -> str:
    return node.id if isinstance(node, ast.Name) else ""


def _clock_names(function: ast.AST) -> set[str]:
    """Names bound (directly or through other such names) to a value read off a clock."""
    names: set[str] = set()
    assigns = [n for n in ast.walk(function) if isinstance(n, ast.Assign | ast.AugAssign)]
    changed = True
    while changed:
        changed = False
        for node in assigns:
            if _touches_clock(node.value, names):
                targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                for target in targets:
                    for leaf in ast.walk(target):
                        if isinstance(leaf, ast.Name) and leaf.id not in names:
                            names.add(leaf.id)
                            changed = True
    return names


def _touches_clock(node: ast.AST, names: set[str]) -> bool:
    return any(
        _is_clock_call(n) or (isinstance(n, ast.Name) and n.id in names) for n in ast.walk(node)
    )


def _test_functions() -> list[tuple[str, ast.FunctionDef]]:
    found = []
    for path in sorted((ROOT / "tests").rglob("*.py")):
        tree = ast.parse(path.read_text())
        rel = str(path.relative_to(ROOT))
        found += [(rel, f) for f in ast.walk(tree) if isinstance(f, ast.FunctionDef)]
    return found


def test_no_test_asserts_on_the_wall_clock():
    found = []
    for rel, function in _test_functions():
        if (rel, function.name) in CLOCK_ALLOWED:
            continue
        names = _clock_names(function)
        for node in ast.walk(function):
            if isinstance(node, ast.Assert) and _touches_clock(node.test, names):
                found.append(f"{rel}:{node.lineno}")
    assert not found, f"asserts on the wall clock (count events instead): {found}"


def _own_nodes(function: ast.FunctionDef) -> list[ast.AST]:
    """The function's nodes, without those of the functions defined inside it."""
    nodes, todo = [], list(ast.iter_child_nodes(function))
    while todo:
        node = todo.pop()
        nodes.append(node)
        if not isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.Lambda):
            todo.extend(ast.iter_child_nodes(node))
    return nodes


def _sleeps(function: ast.FunctionDef) -> list[int]:
    lines = []
    for node in _own_nodes(function):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute):
            if node.func.attr == "wait_for_timeout" or (
                node.func.attr == "sleep" and _dotted(node.func.value) in ("time", "asyncio")
            ):
                lines.append(node.lineno)
        elif isinstance(node, ast.Call) and _dotted(node.func) == "sleep":
            lines.append(node.lineno)
    return lines


def test_tests_sleep_only_where_the_list_says_why():
    """A new ``time.sleep`` (or a page's ``wait_for_timeout``) in a test fails here: wait for
    the event it stands for, or add it to SLEEPS_ALLOWED with the reason."""
    found, seen = [], set()
    for rel, function in _test_functions():
        lines = _sleeps(function)
        if lines and (rel, function.name) in SLEEPS_ALLOWED:
            seen.add((rel, function.name))
        elif lines and rel not in SLEEPS_ALLOWED_IN:
            found += [f"{rel}:{line} in {function.name}" for line in lines]
    assert not found, f"sleeps in tests (wait for the event instead): {found}"
    assert seen == set(SLEEPS_ALLOWED), f"allowed but gone: {set(SLEEPS_ALLOWED) - seen}"


#: Private attributes of viser's objects that Poinsot has reached for (viser 1.1.x). They are
#: recognised by name, since a scan cannot know an object's type: each is a name viser keeps
#: to itself on its server, its websocket server, a client's connection, a GUI, a scene API or
#: a handle, and each may move in any viser release. Their one home is app/viser_private/,
#: where tests/app/test_viser_private.py pins them; the names here are the ones that adapter
#: holds (a new private name goes there, and here). ``self._x``/``cls._x`` are our own.
PRIVATE_VISER_ATTRIBUTES = frozenset(
    {
        "_assignable_props_api",
        "_background_event_loop",
        "_client_state_from_id",
        "_connected_clients",
        "_current_file_upload_states",
        "_event_loop",
        "_gui_input_handle_from_uuid",
        "_impl",
        "_incoming_handlers",
        "_live_connections",
        "_marks",
        "_messages",
        "_prop_hints",
        "_queue_scene_message",
        "_thread_executor",
        "_viser_server",
        "_websock_connection",
        "_websock_server",
        # public names on viser's private message buffer
        "generator_cursors",
        "message_from_id",
        "message_counter",
        "get_message_buffer",
    }
)
VISER_ADAPTER = ROOT / "app" / "viser_private"


def _private_viser_uses(source: str) -> list[str]:
    """Where ``source`` names a private part of viser: an import of a private viser module or
    name, ``viser._x``, ``x.<private attribute>`` (``self``/``cls`` excepted), or a
    ``getattr``/``setattr``/``hasattr`` of one."""
    found = []
    for node in ast.walk(ast.parse(source)):
        line = getattr(node, "lineno", 0)
        if isinstance(node, ast.Import):
            modules = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            modules = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
        else:
            modules = []
        for module in modules:
            parts = module.split(".")
            if parts[0] == "viser" and any(p.startswith("_") for p in parts[1:]):
                found.append(f"{line}: import {module}")
        if isinstance(node, ast.Attribute):
            owner = node.value.id if isinstance(node.value, ast.Name) else None
            dunder = node.attr.startswith("__")
            if owner == "viser" and node.attr.startswith("_") and not dunder:
                found.append(f"{line}: viser.{node.attr}")
            elif node.attr in PRIVATE_VISER_ATTRIBUTES and owner not in ("self", "cls"):
                found.append(f"{line}: .{node.attr}")
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
            if node.func.id in ("getattr", "setattr", "hasattr") and len(node.args) >= 2:
                name = node.args[1]
                if isinstance(name, ast.Constant) and name.value in PRIVATE_VISER_ATTRIBUTES:
                    found.append(f"{line}: {node.func.id}(..., {name.value!r})")
    return found


def test_viser_s_private_names_are_used_only_in_the_adapter():
    """One door to viser's internals: app/viser_private/ (its docstring is the inventory)."""
    used = {}
    for f in sorted((ROOT / "app").rglob("*.py")):
        if VISER_ADAPTER in f.parents:
            continue
        found = _private_viser_uses(f.read_text())
        if found:
            used[str(f.relative_to(ROOT))] = found
    assert not used, f"private viser names outside app/viser_private/: {used}"


def test_the_private_name_scan_sees_each_form():
    source = "\n".join(
        [
            "from viser import _messages",
            "from viser._messages import GuiSliderMark",
            "import viser._viser",
            "from viser.infra._infra import WebsockServer",
            "x = viser._messages.Message",
            "slider._marks = ()",
            "loop = gui._event_loop",
            "c = server._websock_server._live_connections",
            "b = getattr(client, '_websock_connection', None)",
            "n = buffer.generator_cursors",
            "self._marks = []  # our own",
            "v = viser.__version__",
        ]
    )
    lines = {int(hit.split(":")[0]) for hit in _private_viser_uses(source)}
    assert lines == set(range(1, 11))
