"""The code's shape: dependencies point one way (worker -> webapp -> facaid: the worker stores through the site's
models, the site sends it jobs by name and never imports it), no module imports a private name of another, and no
import cycle, counting imports inside functions (type-checking imports aside)."""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("facaid", "webapp", "worker")


def _modules() -> dict[str, Path]:
    out = {}
    for package in PACKAGES:
        for path in (ROOT / package).rglob("*.py"):
            if "migrations" in path.parts:
                continue
            parts = list(path.relative_to(ROOT).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            out[".".join(parts)] = path
    return out


MODULES = _modules()


_TYPE_CHECKING = ("TYPE_CHECKING", "typing.TYPE_CHECKING")


def _imports(path: Path) -> list[tuple[str, list[str]]]:
    """(module, names) of every import in the file, in functions too, except under ``if TYPE_CHECKING``."""
    tree = ast.parse(path.read_text())
    # only the body of ``if TYPE_CHECKING:`` itself (``if not TYPE_CHECKING:`` runs, and so does an ``else``)
    skip = {id(n) for node in ast.walk(tree) if isinstance(node, ast.If) and ast.unparse(node.test) in _TYPE_CHECKING
            for statement in node.body for n in ast.walk(statement)}
    found = []
    for node in ast.walk(tree):
        if id(node) in skip:
            continue
        if isinstance(node, ast.ImportFrom) and node.level:  # relative: the rules could not see where it points
            found.append((f"<relative import in {path.name}>", []))
        elif isinstance(node, ast.ImportFrom) and node.module:
            found.append((node.module, [a.name for a in node.names]))
        elif isinstance(node, ast.Import):
            found += [(a.name, []) for a in node.names]
    return found


def _graph() -> dict[str, set[str]]:
    graph = {}
    for name, path in MODULES.items():
        edges = set()
        for module, names in _imports(path):
            for n in names or [None]:
                target = f"{module}.{n}" if n and f"{module}.{n}" in MODULES else module
                if target in MODULES and target != name:
                    edges.add(target)
        graph[name] = edges
    return graph


def test_dependencies_point_one_way():
    """Issue 69: the worker is the Celery app and its task; it calls facaid and stores through the site's models. The
    site submits jobs by name (`webapp.facades.queue`) and imports no module of the worker; facaid imports neither,
    nor Django, DRF or Celery."""
    layer = {"facaid": 0, "webapp": 1, "worker": 2}
    for name, path in MODULES.items():
        for module, _ in _imports(path):
            top = module.split(".")[0]
            if top in layer:
                assert layer[top] <= layer[name.split(".")[0]], f"{name} imports {module}"
            if name.startswith("facaid"):
                assert top not in ("django", "rest_framework", "celery", "kombu", "redis"), f"{name} imports {module}"
        if name.startswith("webapp"):  # nor by name: importlib.import_module("worker.tasks")
            named = [n.value for n in ast.walk(ast.parse(path.read_text())) if isinstance(n, ast.Constant)
                     and isinstance(n.value, str) and n.value.startswith("worker.")
                     and all(part.isidentifier() for part in n.value.split("."))]
            assert not named, f"{name} names {named}"
    # and the rule is not met by there being no worker: its task stores through the site's models
    assert "worker.tasks" in MODULES and "worker.app" in MODULES
    assert any(module.startswith("webapp.facades.models") for module, _ in _imports(MODULES["worker.tasks"]))


def test_imports_are_absolute():
    """The rules above read each import's module by name: a relative import would pass them unseen."""
    bad = [(name, module) for name, path in MODULES.items() for module, _ in _imports(path) if module.startswith("<")]
    assert bad == []


def test_no_module_imports_a_private_name_of_another():
    bad = [(name, module, n) for name, path in MODULES.items() for module, names in _imports(path)
           if module.split(".")[0] in PACKAGES for n in names if n.startswith("_") and not n.startswith("__")]
    assert not bad


def test_no_import_cycles():
    graph = _graph()
    index, low, stack, on, cycles, counter = {}, {}, [], set(), [], [0]

    def visit(v):  # Tarjan's strongly connected components
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                cycles.append(sorted(component))

    for v in graph:
        if v not in index:
            visit(v)
    assert not cycles
    assert len(graph) > 60  # the walk found the code


# facaid's own layers: a package may import those of its layer and below, never one above (issue 59)
BELOW = {
    "facaid.native": {"facaid.labels"},
    "facaid.grammar": {"facaid.labels", "facaid.numbers", "facaid.segmentation", "facaid.native"},
    "facaid.formats": {"facaid.labels", "facaid.numbers", "facaid.segmentation", "facaid.native", "facaid.grammar",
                       "facaid.paths", "facaid.editing.parameters"},  # the CGA's attributes: the named parameters
    "facaid.photo": {"facaid.labels", "facaid.numbers", "facaid.segmentation", "facaid.native", "facaid.grammar",
                     "facaid.metrics", "facaid.defaults"},
    "facaid.tokenizer": {"facaid.labels", "facaid.numbers", "facaid.segmentation", "facaid.native", "facaid.grammar"},
}
ABOVE_ALL = ("facaid.cli", "facaid.evaluation", "facaid.docs")  # only the command line and the lab import these


def _package(module: str) -> str:
    parts = module.split(".")
    name = ".".join(parts[:2])
    return name if name in MODULES or f"{name}.__init__" in MODULES else module


def test_facaid_imports_point_down():
    bad = []
    for name, path in MODULES.items():
        if not name.startswith("facaid."):
            continue
        mine = ".".join(name.split(".")[:2])
        for module, _ in _imports(path):
            if not module.startswith("facaid.") or module.startswith(mine):
                continue
            theirs = ".".join(module.split(".")[:2])
            if mine in BELOW and theirs not in BELOW[mine] and module not in BELOW[mine]:
                bad.append(f"{name} imports {module}")
            if theirs in ABOVE_ALL and mine not in ABOVE_ALL:
                bad.append(f"{name} imports {module}")
    assert bad == []


def test_facaid_has_at_most_12_top_level_modules_and_no_source_file_over_400_lines():
    """Issue 69: facaid's stages are its folders (model, reading, editing, decoding, ...); at its top level at most 12
    modules, its front door among them; no source file (facaid, webapp, worker, bench, frontend, tests) over 400
    lines."""
    top = list((ROOT / "facaid").glob("*.py"))
    assert len(top) <= 12, sorted(p.name for p in top)
    sources = [p for folder in ("facaid", "webapp", "worker", "bench", "tests") for p in (ROOT / folder).rglob("*.py")
               if "migrations" not in p.parts]
    sources += [p for p in (ROOT / "frontend").rglob("*.js") if "tests" not in p.parts]
    sources += list((ROOT / "facaid" / "native").glob("*.c"))
    long = {str(p.relative_to(ROOT)): n for p in sources if (n := len(p.read_text().splitlines())) > 400}
    assert long == {}


def test_every_package_opens_on_a_short_front_door():
    """Issue 69: a package's `__init__.py` says what it holds and re-exports its names (at most 100 lines); its
    algorithm lives in named modules."""
    doors = [p for folder in ("facaid", "webapp", "worker") for p in (ROOT / folder).rglob("__init__.py")
             if "migrations" not in p.parts]
    long = {str(p.relative_to(ROOT)): n for p in doors if (n := len(p.read_text().splitlines())) > 100}
    assert len(doors) > 10 and long == {}
    # a door holds no algorithm: no function or class of its own (facaid's lazy ``__getattr__`` opens its names)
    code = {str(p.relative_to(ROOT)): node.name for p in doors for node in ast.parse(p.read_text()).body
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef) and node.name != "__getattr__"}
    assert code == {}


def test_frontend_is_a_folder_per_page():
    """Issue 69: the browser's modules sit in a folder per page (`editor/`, `procedure/`, `job/`) and `common/` for
    what more than one page imports; at most 8 scripts at `frontend/`'s top level, none over 400 lines."""
    top = list((ROOT / "frontend").glob("*.js"))
    assert len(top) <= 8, sorted(p.name for p in top)
    assert {"editor", "procedure", "job", "common"} <= {p.name for p in (ROOT / "frontend").iterdir() if p.is_dir()}
    scripts = [p for p in (ROOT / "frontend").rglob("*.js") if "tests" not in p.parts]
    long = {str(p.relative_to(ROOT)): n for p in scripts if (n := len(p.read_text().splitlines())) > 400}
    assert long == {}
