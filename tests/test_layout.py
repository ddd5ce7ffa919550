"""The package boundary: physics/ imports numpy and scipy only."""

import ast
import functools
import pathlib
import re

ROOT = pathlib.Path(__file__).resolve().parents[1]


@functools.cache
def _nodes(path: pathlib.Path) -> tuple[ast.AST, ...]:
    """Every node of the module at ``path``: parsed and walked once for all this file's tests."""
    return tuple(ast.walk(ast.parse(path.read_text())))


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
    names: set[str] = set()
    for node in _nodes(path):
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
    names: set[str] = set()
    for node in _nodes(path):
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


#: A room holds at most this many modules (``__init__.py`` and ``__main__.py`` count): past it,
#: a reader no longer finds a module by its room, and the room wants rooms of its own.
MAX_ROOM_MODULES = 15
#: The app's root holds only its front: the package, ``python -m poinsot.app`` and the notebook's
#: ``show`` (everything else lives in a room named by what it holds).
MAX_APP_ROOT_MODULES = 5


def test_rooms_hold_few_modules():
    crowded = {}
    for top in ("physics", "app"):
        for folder in sorted(p for p in (ROOT / top).rglob("*") if p.is_dir()):
            count = len(list(folder.glob("*.py")))
            if count > MAX_ROOM_MODULES:
                crowded[str(folder.relative_to(ROOT))] = count
    assert not crowded, f"folders of more than {MAX_ROOM_MODULES} modules: {crowded}"
    root = sorted(p.name for p in (ROOT / "app").glob("*.py"))
    assert len(root) <= MAX_APP_ROOT_MODULES, f"app/ holds {root} at its root"


def _module_name(path: pathlib.Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(["poinsot", *parts])


def _import_graph() -> dict[str, set[str]]:
    """Every module of physics/ and app/ to the modules of ours it imports, wherever the import
    stands (a function, ``if TYPE_CHECKING:``): ``from a import b`` is an import of ``a.b`` when
    that is a module, of ``a`` otherwise."""
    files = {_module_name(f): f for f in _code_files()}
    graph = {}
    for name, f in files.items():
        found = set()
        for node in _nodes(f):
            if isinstance(node, ast.Import):
                found.update(a.name for a in node.names)
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                for a in node.names:
                    full = f"{node.module}.{a.name}"
                    found.add(full if full in files else node.module)
        graph[name] = {m for m in found if m in files and m != name}
    return graph


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found = []
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is None:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    component = []
                    while True:
                        top = stack.pop()
                        on_stack.discard(top)
                        component.append(top)
                        if top == node:
                            break
                    if len(component) > 1:
                        found.append(sorted(component))
            elif child not in index:
                index[child] = low[child] = len(index)
                stack.append(child)
                on_stack.add(child)
                work.append((child, iter(sorted(graph[child]))))
            elif child in on_stack:
                low[node] = min(low[node], index[child])
    return found


def test_no_module_imports_itself_round_a_cycle():
    """No cycle between modules, type-only imports included (a cycle is two rooms that are one)."""
    assert _cycles(_import_graph()) == []


def test_the_cycle_search_finds_one():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}, "e": set()}
    assert _cycles(graph) == [["a", "b", "c"]]
    assert _cycles({"a": {"b"}, "b": set()}) == []


def _self_given(source: str) -> list[int]:
    """Lines where a method hands ``self`` (or a lambda over it) to a call."""
    lines = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Call):
            given = [*node.args, *(k.value for k in node.keywords)]
            if any(isinstance(a, ast.Name) and a.id == "self" for a in given):
                lines.append(node.lineno)
    return lines


def test_the_session_gives_its_parts_no_self():
    """The session is composed, not reached through: its builder and the session hand their
    parts narrow things (the front, the clock, the construction, callbacks), never the
    session (tests/app/test_session_parts.py walks the parts of a live one)."""
    session = ROOT / "app" / "live" / "session"
    given = {
        f.name: lines for f in sorted(session.glob("*.py")) if (lines := _self_given(f.read_text()))
    }
    assert given == {}, given
    init = ast.parse((session / "session.py").read_text())
    (cls,) = [n for n in init.body if isinstance(n, ast.ClassDef) and n.name == "Session"]
    (constructor,) = [
        n for n in cls.body if isinstance(n, ast.FunctionDef) and n.name == "__init__"
    ]
    assert len(constructor.args.args) + len(constructor.args.kwonlyargs) <= 4


def test_the_self_search_finds_one():
    assert _self_given("def f(self):\n    Part(self, 1)\n    Other(x=self)\n") == [2, 3]
    assert _self_given("def f(self):\n    Part(self.front)\n") == []


def test_functions_do_one_step():
    long = {}
    for f in _code_files():
        lines = f.read_text().splitlines()
        for node in _nodes(f):
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
    ("tests/app/test_wire.py", "poll"): "the sampling period of a peak-memory poller",
}
#: Browser tests: the same reason as above, for each module (the page gives no "drawn" event).
SLEEPS_ALLOWED_IN = {
    "tests/browser/test_loopback.py",
    "tests/browser/test_picture_page.py",
    "tests/browser/test_scenes_page.py",
    "tests/browser/test_uploads_page.py",
    # Not a test: the script that makes the README's pictures of the page (`make pictures`);
    # its pauses let the traces grow for the picture.
    "tests/browser/page_pictures.py",
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
        rel = str(path.relative_to(ROOT))
        found += [(rel, f) for f in _nodes(path) if isinstance(f, ast.FunctionDef)]
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


def _private_viser_uses(source: str | pathlib.Path) -> list[str]:
    """Where ``source`` (a module's text, or its path) names a private part of viser: an import
    of a private viser module or name, ``viser._x``, ``x.<private attribute>`` (``self``/``cls``
    excepted), or a ``getattr``/``setattr``/``hasattr`` of one."""
    found = []
    nodes = _nodes(source) if isinstance(source, pathlib.Path) else ast.walk(ast.parse(source))
    for node in nodes:
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


#: The adapter's own tests: they pin each private name the adapter relies on, so that a viser
#: release that moves one fails there, naming the version (every other test goes through the
#: adapter, hostile messages included).
ADAPTER_TESTS = frozenset(
    {ROOT / "tests" / "app" / "test_viser_private.py", ROOT / "tests" / "app" / "test_updates.py"}
)


def test_viser_s_private_names_are_used_only_in_the_adapter():
    """One door to viser's internals: app/viser_private/ (its docstring is the inventory), for
    the app and for the tests alike."""
    used = {}
    files = [*(ROOT / "app").rglob("*.py"), *(ROOT / "tests").rglob("*.py")]
    for f in sorted(files):
        if VISER_ADAPTER in f.parents or f in ADAPTER_TESTS:
            continue
        found = _private_viser_uses(f)
        if found:
            used[str(f.relative_to(ROOT))] = found
    assert not used, f"private viser names outside app/viser_private/: {used}"


def test_the_adapter_is_entered_by_its_front_door():
    """Every import of the adapter goes through its package, whose ``__all__`` is its front
    (``from poinsot.app.viser_private import X`` or ``from poinsot.app import viser_private``),
    never one of its modules."""
    side_doors = {}
    files = [*(ROOT / "app").rglob("*.py"), *(ROOT / "tests").rglob("*.py")]
    for f in sorted(files):
        if VISER_ADAPTER in f.parents or f in ADAPTER_TESTS:
            continue
        for node in _nodes(f):
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module, *(f"{node.module}.{a.name}" for a in node.names)]
            else:
                continue
            inner = [n for n in names if n.startswith("poinsot.app.viser_private.")]
            inner = [n for n in inner if (VISER_ADAPTER / f"{n.split('.')[3]}.py").is_file()]
            if inner:
                side_doors.setdefault(str(f.relative_to(ROOT)), []).extend(inner)
    assert not side_doors, f"imports of the adapter's modules, past its package: {side_doors}"


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
