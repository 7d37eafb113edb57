"""The house in layers: which package may import which, and no import loops between files.

Read from the source with :mod:`ast` (nothing is imported). Every ``import`` counts, at module
level or inside a function, because both run. Imports under ``if TYPE_CHECKING:`` never run:
the layer tests leave them out, the loop test counts them (two files that name each other's
types depend on each other, whether or not the import runs). Layers, lowest first
(docs/architecture.md, "Layers"):

    errors, hookspecs  <-  io  <-  core  <-  model, interop  <-  plugins  <-  tools  <-  cli, report, plots, examples

A module may import its own layer and the layers below it. The root package ``nmsm`` (the
facade ``nmsm.run``, ``nmsm.run_pipeline``, ``__version__``) is imported before any of its
modules, so importing it is no dependency; it stands above every layer. Plugins (``nmsm.terms``,
``nmsm.constraints``, ``nmsm.controllers``, ``nmsm.modifiers``) and ``plugins_example/`` stand
on the public API only: ``nmsm.core``, ``nmsm.model``, ``nmsm.interop``, ``nmsm.io``, ``nmsm.errors``.
"""

from __future__ import annotations

import ast
import pathlib
from collections import defaultdict

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]

#: layer of each top-level part of nmsm (lowest 0); parts not listed are checked for loops only
LAYERS: dict[str, int] = {
    "nmsm.errors": 0,
    "nmsm.version": 0,
    "nmsm.hookspecs": 0,
    "nmsm.cli_types": 0,
    "nmsm.io": 1,
    "nmsm.opensim_bridge": 1,
    "nmsm.core": 2,
    "nmsm.model": 3,
    "nmsm.interop": 3,
    "nmsm.terms": 4,
    "nmsm.constraints": 4,
    "nmsm.controllers": 4,
    "nmsm.modifiers": 4,
    "nmsm.tools": 5,
    "nmsm.__main__": 6,
    "nmsm.cli": 6,
    "nmsm.commands": 6,
    "nmsm.report": 6,
    "nmsm.plots": 6,
    "nmsm.testing": 6,
    "nmsm.results": 6,
    "nmsm.batch": 6,
    "nmsm.examples": 6,
}
PLUGIN_PARTS = ("nmsm.terms", "nmsm.constraints", "nmsm.controllers", "nmsm.modifiers")
PUBLIC_API = ("nmsm.core", "nmsm.model", "nmsm.interop", "nmsm.io", "nmsm.errors", "nmsm.hookspecs")

#: Imports of a higher layer allowed by name: none. The list only shrinks (an entry no longer
#: imported fails :func:`test_known_exceptions_are_still_real`).
KNOWN_UPWARD: frozenset[tuple[str, str]] = frozenset()


def _module_files(top: pathlib.Path, package: str) -> dict[str, tuple[pathlib.Path, bool]]:
    out = {}
    for path in top.rglob("*.py"):
        parts = [package, *path.relative_to(top).with_suffix("").parts]
        is_package = path.name == "__init__.py"
        if is_package:
            parts = parts[:-1]
        out[".".join(parts)] = (path, is_package)
    return out


def _type_checking_nodes(tree: ast.AST) -> set[int]:
    out: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            out.update(id(child) for child in ast.walk(node))
    return out


def imported_names(path: pathlib.Path, module: str, is_package: bool, *, type_checking: bool = False) -> set[str]:
    """Absolute names of everything ``path`` imports when it runs (module- and function-level),
    and with ``type_checking`` also under ``if TYPE_CHECKING:``: ``from a.b import c`` gives
    ``a.b.c`` when that is a module, else ``a.b`` (see :func:`import_graph`), so both are listed."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    skip = set() if type_checking else _type_checking_nodes(tree)
    names: set[str] = set()
    for node in ast.walk(tree):
        if id(node) in skip:
            continue
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = module.split(".") if is_package else module.split(".")[:-1]
                base = base[: len(base) - (node.level - 1)]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            names.update(f"{target}.{alias.name}" for alias in node.names)
    return names


def import_graph(modules: dict[str, tuple[pathlib.Path, bool]], *, type_checking: bool = False
                 ) -> dict[str, set[str]]:
    """module -> the nmsm modules (files) it imports (with ``type_checking``: also under ``if
    TYPE_CHECKING:``): ``x.y.z`` counts as the longest module prefix (``from x.y import z`` is
    module ``x.y.z`` when it exists, else ``x.y``)."""
    def resolve(name: str) -> str | None:
        while name and name not in modules:
            name = name.rpartition(".")[0]
        return name or None

    graph: dict[str, set[str]] = defaultdict(set)
    for module, (path, is_package) in modules.items():
        if module == "nmsm":
            continue
        for name in imported_names(path, module, is_package, type_checking=type_checking):
            if name.startswith("nmsm."):
                target = resolve(name)
                if target not in (None, "nmsm", module):
                    graph[module].add(target)
    return graph


def loops(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected groups of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                group.append(w)
                if w == v:
                    break
            if len(group) > 1:
                found.append(sorted(group))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def layer_of(module: str) -> tuple[str, int] | None:
    for part in sorted(LAYERS, key=len, reverse=True):
        if module == part or module.startswith(part + "."):
            return part, LAYERS[part]
    return None


@pytest.fixture(scope="module")
def nmsm_graph() -> dict[str, set[str]]:
    """The imports that run."""
    return import_graph(_module_files(ROOT / "nmsm", "nmsm"))


@pytest.fixture(scope="module")
def nmsm_graph_with_type_checking() -> dict[str, set[str]]:
    """The imports that run and those under ``if TYPE_CHECKING:``."""
    return import_graph(_module_files(ROOT / "nmsm", "nmsm"), type_checking=True)


def _describe(graph: dict[str, set[str]], group: list[str]) -> str:
    members = set(group)
    return "; ".join(f"{v} -> {', '.join(sorted(w for w in graph[v] if w in members))}" for v in group)


def test_no_import_loops_between_files(nmsm_graph_with_type_checking: dict[str, set[str]]) -> None:
    graph = nmsm_graph_with_type_checking
    found = loops(graph)
    assert not found, "import loops:\n" + "\n".join(_describe(graph, group) for group in found)


def test_every_part_of_nmsm_has_a_layer(nmsm_graph: dict[str, set[str]]) -> None:
    unplaced = sorted(m for m in nmsm_graph if layer_of(m) is None)
    assert not unplaced, f"modules outside every layer of LAYERS: {unplaced}"


def test_no_module_imports_a_layer_above_its_own(nmsm_graph_with_type_checking: dict[str, set[str]]) -> None:
    """Type annotations count: a lower layer does not even name a higher layer's types."""
    upward = []
    for module, targets in sorted(nmsm_graph_with_type_checking.items()):
        here = layer_of(module)
        for target in sorted(targets):
            there = layer_of(target)
            if here is None or there is None or (module, target) in KNOWN_UPWARD:
                continue
            if there[1] > here[1]:
                upward.append(f"{module} ({here[0]}) -> {target} ({there[0]})")
    assert not upward, "imports of a higher layer:\n" + "\n".join(upward)


def test_plugins_import_only_the_public_api(nmsm_graph: dict[str, set[str]]) -> None:
    modules = _module_files(ROOT / "plugins_example" / "nmsm_stroke", "nmsm_stroke")
    offenders = []
    for module, (path, is_package) in sorted(modules.items()):
        for name in sorted(imported_names(path, module, is_package)):
            if name.startswith("nmsm.") and not name.startswith(PUBLIC_API):
                offenders.append(f"{path.relative_to(ROOT)} imports {name}")
    for module, targets in sorted(nmsm_graph.items()):
        if not module.startswith(PLUGIN_PARTS):
            continue
        for target in sorted(targets):
            if (module, target) not in KNOWN_UPWARD and not target.startswith(PUBLIC_API + PLUGIN_PARTS):
                offenders.append(f"{module} imports {target}")
    assert not offenders, "\n".join(offenders)


def test_known_exceptions_are_still_real(nmsm_graph: dict[str, set[str]]) -> None:
    gone = sorted(f"{a} -> {b}" for a, b in KNOWN_UPWARD if b not in nmsm_graph.get(a, set()))
    assert not gone, f"remove from KNOWN_UPWARD (no longer imported): {gone}"


def test_docs_plugin_examples_import_only_the_public_api() -> None:
    text = (ROOT / "docs" / "plugins.md").read_text(encoding="utf-8")
    private = sorted({line.strip() for line in text.splitlines()
                      if line.strip().startswith(("from nmsm.", "import nmsm."))
                      and not line.strip().split()[1].startswith(PUBLIC_API + ("nmsm.testing",))})
    assert not private, f"docs/plugins.md imports private modules: {private}"


def test_tools_never_import_a_plugin_class(nmsm_graph: dict[str, set[str]]) -> None:
    """Tools reach plugins through the registry (and the plugins' own methods), never by class."""
    offenders = sorted(f"{m} -> {t}" for m, targets in nmsm_graph.items() if m.startswith("nmsm.tools.")
                       for t in targets if t.startswith(PLUGIN_PARTS))
    assert not offenders, "\n".join(offenders)
