"""The package's floors: each imports only lower ones, and no private name crosses a module.

Floors, lowest first (symdyn/__init__.py): errors (with loading and leftovers); spatial and
symbolic; model; parsers, algorithms and the numeric oracle rnea (with rnea_inputs); dynamics
(with lumped, the lumped constants of a derivation); codegen; apps; cli; regenerate. A module
may import its own floor and any lower one; `__version__` may come from the package root.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import symdyn

PACKAGE = Path(symdyn.__file__).parent
RANK = {
    "errors": 0,
    "spatial": 1,
    "symbolic": 1,
    "model": 2,
    "parsers": 3,
    "algorithms": 3,
    "rnea": 3,
    "dynamics": 4,
    "codegen": 5,
    "apps": 6,
    "cli": 7,
    "regenerate": 8,
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
    if parts[0] in ("loading", "leftovers"):  # helpers of codegen and apps that use only errors
        return "errors"
    return (
        "rnea" if parts[0] in ("rnea_inputs", "rnea_spatial", "rnea_regressor", "rnea_frames") else parts[0]
    )  # the oracle


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


@pytest.mark.parametrize(
    "path,parts", list(_modules()), ids=lambda x: "/".join(x) if isinstance(x, tuple) else ""
)
def test_no_private_name_crosses_a_module(path, parts):
    modules = set()  # names bound to symdyn modules here (`from ..spatial import vectors as v3`)
    for target, names in _imports(path, parts):
        private = [n for n in names if n.startswith("_") and n != "__version__"]
        assert not private, f"{'.'.join(parts)} imports {private} from {'.'.join(target)}"
    tree = ast.parse(path.read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.level:
            modules.update(a.asname or a.name for a in node.names)
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id in modules:
            assert not node.attr.startswith("_"), f"{'.'.join(parts)} uses {node.value.id}.{node.attr}"


def _module_of(target: tuple[str, ...], name: str) -> tuple[str, ...]:
    """The module `from <target> import <name>` loads: the submodule `name` when there is one."""
    sub = PACKAGE.joinpath(*target, name)
    if sub.with_suffix(".py").is_file() or (sub / "__init__.py").is_file():
        return (*target, name)
    return target


def _import_graph() -> dict[tuple[str, ...], set[tuple[str, ...]]]:
    """Module -> the symdyn modules it imports (relative imports anywhere in it, lazy ones too,
    within a floor or across); a package is its __init__, named by the package's parts."""
    graph = {}
    for path, parts in _modules():
        module = parts[:-1] if parts[-1] == "__init__" else parts
        edges = graph.setdefault(module, set())
        for target, names in _imports(path, parts):
            if target:  # the package root (`from .. import __version__`) re-exports, lazily
                edges.update(_module_of(target, name) for name in names)
        edges.discard(module)
    return graph


def test_no_import_cycle():
    """No chain of imports leads from a module back to itself (depth-first search for a back edge)."""
    graph = _import_graph()
    assert ("codegen", "functions") in graph and ("codegen", "function_rows") in graph[
        ("codegen", "functions")
    ]
    state: dict[tuple[str, ...], int] = {}  # 1: on the current path, 2: done

    def visit(module, path):
        state[module] = 1
        for target in sorted(graph.get(module, ())):
            assert state.get(target) != 1, "import cycle: " + " -> ".join(
                ".".join(m) for m in (*path[path.index(target) :], target)
            )
            if target not in state:
                visit(target, [*path, target])
        state[module] = 2

    for module in sorted(graph):
        if module not in state:
            visit(module, [module])
