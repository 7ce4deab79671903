"""The package's floors: each imports only lower ones, and no private name crosses a module.

Floors, lowest first (symdyn/__init__.py): errors (with generated_modules, module_aliases,
leftovers and progress); spatial and symbolic; model; parsers, algorithms and the numeric oracle
(symdyn/oracle, with its public entry symdyn/rnea.py); dynamics (with lumped, the lumped
constants of a derivation); codegen; apps; cli; regenerate. A module may import its own floor and
any lower one; `__version__` may come from the package root. Inside apps, each application is a
package, and they are floors too (APPLICATIONS). No module imports itself back through others,
inside a floor or across floors.
"""

from __future__ import annotations

import ast
import importlib
import pickle
import subprocess
import sys
from pathlib import Path

import pytest

import symdyn
from symdyn.module_aliases import MOVED

PACKAGE = Path(symdyn.__file__).parent
RANK = {
    "errors": 0,
    "spatial": 1,
    "symbolic": 1,
    "model": 2,
    "parsers": 3,
    "algorithms": 3,
    "oracle": 3,
    "dynamics": 4,
    "codegen": 5,
    "apps": 6,
    "cli": 7,
    "regenerate": 8,
}
#: The applications' packages inside apps, lowest first: each imports only lower ones (and the
#: shared apps/output.py). A simulation writes the log that identification reads (its columns).
APPLICATIONS = {
    "output": 0,
    "compilation": 1,
    "checking": 1,
    "drawing": 1,
    "identification": 2,
    "analysis": 2,
    "simulation": 3,
}


def _modules():
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(PACKAGE).with_suffix("").parts
        if parts == ("__init__",):
            continue  # the root re-exports every floor
        yield path, parts


def _imports(path: Path, parts: tuple[str, ...]):
    """(target module parts inside symdyn, imported names) for each relative import."""
    package = parts[:-1]  # the package the module lives in (itself for an __init__)
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.level:
            base = package[: len(package) - (node.level - 1)]
            target = (*base, *node.module.split(".")) if node.module else base
            yield target, [a.name for a in node.names]


def _floor(parts: tuple[str, ...]) -> str:
    if parts[0] == "lumped":  # works on a Dynamics, as dynamics does
        return "dynamics"
    helpers = ("generated_modules", "module_aliases", "leftovers", "progress", "destination")
    if parts[0] in helpers:  # helpers of every floor that use only errors
        return "errors"
    return "oracle" if parts[0] == "rnea" else parts[0]  # symdyn.rnea: the oracle's public entry


@pytest.mark.parametrize(
    "path,parts", list(_modules()), ids=lambda x: "/".join(x) if isinstance(x, tuple) else ""
)
def test_floors_import_only_lower_floors(path, parts):
    own = RANK[_floor(parts)]
    for target, names in _imports(path, parts):
        if not target:
            assert names == ["__version__"], (parts, names)
            continue
        floor = _floor(target)
        assert floor == _floor(parts) or RANK[floor] < own, f"{'.'.join(parts)} imports {'.'.join(target)}"


def _application(parts: tuple[str, ...]) -> str | None:
    """The application package of apps that `parts` (a module or a package) lies in, "output" for
    the shared module, else None."""
    if parts[:1] != ("apps",) or len(parts) < 2 or parts[1] == "__init__":
        return None
    return parts[1]


def test_every_application_has_a_floor():
    """Every package and module directly under apps is ranked in APPLICATIONS."""
    found = {
        p.stem for p in (PACKAGE / "apps").iterdir() if p.name != "__init__.py" and p.name != "__pycache__"
    }
    assert found == set(APPLICATIONS), found ^ set(APPLICATIONS)


@pytest.mark.parametrize(
    "path,parts",
    [(path, parts) for path, parts in _modules() if _application(parts)],
    ids=lambda x: "/".join(x) if isinstance(x, tuple) else "",
)
def test_applications_import_only_lower_applications(path, parts):
    own = _application(parts)
    for target, _ in _imports(path, parts):
        other = _application(target)
        if other is not None and other != own:
            assert APPLICATIONS[other] < APPLICATIONS[own], f"{'.'.join(parts)} imports {'.'.join(target)}"


def test_the_application_floors_are_not_vacuous():
    """Imports across applications are found: simulation's trajectory reads identification's log
    columns, analysis uses compilation."""
    crossing = {
        (_application(parts), _application(target))
        for path, parts in _modules()
        for target, _ in _imports(path, parts)
        if _application(parts) and _application(target) and _application(parts) != _application(target)
    }
    assert {
        ("simulation", "identification"),
        ("analysis", "compilation"),
        ("simulation", "output"),
    } <= crossing


@pytest.mark.parametrize(
    "path,parts", list(_modules()), ids=lambda x: "/".join(x) if isinstance(x, tuple) else ""
)
def test_no_private_name_crosses_a_module(path, parts):
    modules = set()  # names bound to symdyn modules here (`from ..spatial import vectors as v3`)
    for target, names in _imports(path, parts):
        private = [n for n in names if n.startswith("_") and not (n.startswith("__") and n.endswith("__"))]
        assert not private, f"{'.'.join(parts)} imports {private} from {'.'.join(target)}"
    tree = ast.parse(path.read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.level:
            modules.update(a.asname or a.name for a in node.names)
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id in modules:
            assert not node.attr.startswith("_"), f"{'.'.join(parts)} uses {node.value.id}.{node.attr}"


def _module_name(parts: tuple[str, ...]) -> str | None:
    """The dotted name of the symdyn module `parts` (a package stands for its __init__), or None."""
    if (PACKAGE.joinpath(*parts).with_suffix(".py")).is_file():
        return ".".join(parts)
    if (PACKAGE.joinpath(*parts) / "__init__.py").is_file():
        return ".".join((*parts, "__init__"))
    return None


def _import_graph() -> dict[str, set[str]]:
    """module -> the symdyn modules it imports (relative imports, at any depth of the file; a
    name imported from a package that is itself a module counts as that module)."""
    graph: dict[str, set[str]] = {}
    for path, parts in _modules():
        edges = graph.setdefault(".".join(parts), set())
        for target, names in _imports(path, parts):
            for name in names:
                found = _module_name((*target, name)) or _module_name(target)
                if found:
                    edges.add(found)
    return graph


def _cycles(graph: dict[str, set[str]]) -> set[tuple[str, ...]]:
    """The import cycles of `graph`: its strongly connected components of more than one module
    (or a module importing itself), each as its sorted members (Tarjan's algorithm)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    cycles = set()

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while not component or component[-1] != v:
                component.append(stack.pop())
            if len(component) > 1 or v in graph.get(v, ()):
                cycles.add(tuple(sorted(component)))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return cycles


def test_no_import_cycles():
    """The import graph of symdyn's modules (its root __init__ aside, which re-exports every
    floor lazily) is acyclic, inside a floor as well as across floors."""
    cycles = _cycles(_import_graph())
    assert not cycles, f"import cycles: {sorted(cycles)}"


def test_the_cycle_finder_finds_cycles():
    """_cycles is not vacuous: a -> b -> c -> a and d -> d are cycles, e -> a is not."""
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"d"}, "e": {"a"}}
    assert _cycles(graph) == {("a", "b", "c"), ("d",)}
    assert _cycles({"a": {"b"}, "b": set()}) == set()
    assert {"errors", "oracle.inputs"} <= _import_graph()["oracle.singular"]  # edges are found


@pytest.mark.parametrize("old,new", sorted(MOVED.items()))
def test_old_module_paths_import_the_moved_modules(old, new):
    """A moved module's old path (docs/layout.md, "Moved modules") gives the very module of its new
    home, and a pickle that names a class by the old path loads the class itself."""
    module = importlib.import_module(new)
    assert importlib.import_module(old) is module
    assert module.__spec__.name == new and module.__name__ == new
    public = [n for n in getattr(module, "__all__", ()) if isinstance(getattr(module, n), type)]
    for name in public[:1]:
        assert pickle.loads(f"c{old}\n{name}\n.".encode()) is getattr(module, name)


def test_an_alias_imported_after_its_module_is_that_module():
    """In a fresh interpreter, `symdyn.inertia` after `symdyn.model.inertia` (and an old path after
    the new one) is the module already imported, not a second copy run again."""
    code = (
        "import symdyn.model.inertia as a, symdyn.inertia as b; assert a is b\n"
        "import symdyn.apps.simulation.trajectory as c, symdyn.apps.trajectory as d; assert c is d\n"
        "import symdyn.apps.compile as e; from symdyn.apps.compilation import compile as f; assert e is f\n"
        "import symdyn; assert symdyn.compile is f.compile\n"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
