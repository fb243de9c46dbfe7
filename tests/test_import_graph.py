"""No import circles between the modules of robots/ planner/ measure/ cell/, nor between the
units of cell/ (its folders and loose modules).

Every module is parsed with ``ast``; imports inside functions and ``if TYPE_CHECKING`` blocks
count too (a circle through a function-level import is still a circle of concepts).

How an import statement becomes edges (module -> module):

* ``import a.b.c`` -> ``a.b.c``;
* ``from a.b import x`` -> ``a.b.x`` when ``a/b/x.py`` (or ``a/b/x/``) exists, else ``a.b``
  (the name comes from ``a/b/__init__.py`` or ``a/b.py``);
* relative imports are resolved against the importing module's package.

The initialisation of parent packages that Python does on the way (``import a.b.c`` runs
``a/__init__`` and ``a/b/__init__``) is *not* an edge: a package ``__init__`` that re-exports
its submodules and a submodule that imports a sibling are no circle at import time. A
submodule that takes a name from its own package's ``__init__`` while that ``__init__``
imports it back is an edge both ways and therefore a circle.
"""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("robots", "planner", "measure", "cell")


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def all_modules() -> dict[str, Path]:
    """Every module of the four packages: dotted name -> file."""
    modules: dict[str, Path] = {}
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            modules[_module_name(path)] = path
    return modules


def _resolve_relative(module: str, is_package: bool, level: int, target: str | None) -> str:
    base = module.split(".")
    if not is_package:
        base = base[:-1]
    if level > 1:
        base = base[: len(base) - (level - 1)]
    return ".".join([*base, *(target.split(".") if target else [])])


def imports_of(name: str, path: Path, modules: dict[str, Path]) -> set[str]:
    """The modules of the four packages that module ``name`` imports anywhere in its body."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    is_package = path.name == "__init__.py"
    found: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = (
                _resolve_relative(name, is_package, node.level, node.module)
                if node.level
                else node.module or ""
            )
            for alias in node.names:
                sub = f"{base}.{alias.name}"
                found.add(sub if sub in modules else base)
    return {target for target in found if target in modules and target != name}


def import_graph() -> dict[str, set[str]]:
    modules = all_modules()
    return {name: imports_of(name, path, modules) for name, path in modules.items()}


def import_cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components with more than one module (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    stack: list[str] = []
    components: list[list[str]] = []
    counter = 0
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    components.append(sorted(component))
    return sorted(components)


def _describe(component: list[str], graph: dict[str, set[str]]) -> str:
    members = set(component)
    edges = [f"{a} -> {b}" for a in component for b in sorted(graph[a] & members)]
    return f"{len(component)} modules: " + "; ".join(edges)


def test_cycle_finder_finds_a_known_circle() -> None:
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}, "e": {"e"}}
    assert import_cycles(graph) == [["a", "b", "c"]]


def test_relative_and_from_imports_resolve(tmp_path: Path) -> None:
    modules = {"cell": ROOT / "cell/__init__.py", "cell.config": ROOT / "cell/config/load.py"}
    source = tmp_path / "x.py"
    source.write_text("def f():\n    from . import config\n    from .config import Thing\n")
    assert imports_of("cell.x", source, modules) == {"cell.config"}
    source.write_text("from .. import config\n")
    assert imports_of("cell.sub.x", source, modules) == {"cell.config"}


def test_a_package_init_counts_only_when_taken_from(tmp_path: Path) -> None:
    """``pkg/__init__`` re-exporting ``pkg.a`` is no circle with ``pkg.a`` importing its
    sibling ``pkg.b``; it is one when ``pkg.a`` takes a name from ``pkg`` itself."""
    (tmp_path / "init.py").write_text("from pkg.a import f\n")
    (tmp_path / "a_sibling.py").write_text("from pkg.b import g\n")
    (tmp_path / "a_from_init.py").write_text("from pkg import g\n")
    (tmp_path / "b.py").write_text("g = 1\n")
    modules = {"pkg": tmp_path / "init.py", "pkg.a": tmp_path / "a.py", "pkg.b": tmp_path / "b.py"}
    init = imports_of("pkg", tmp_path / "init.py", modules)
    b = imports_of("pkg.b", tmp_path / "b.py", modules)
    sibling = {"pkg": init, "pkg.a": imports_of("pkg.a", tmp_path / "a_sibling.py", modules)}
    assert import_cycles({**sibling, "pkg.b": b}) == []
    taken = {"pkg": init, "pkg.a": imports_of("pkg.a", tmp_path / "a_from_init.py", modules)}
    assert import_cycles({**taken, "pkg.b": b}) == [["pkg", "pkg.a"]]


def test_no_import_cycles() -> None:
    graph = import_graph()
    cycles = import_cycles(graph)
    assert not cycles, "import cycles:\n" + "\n".join(_describe(c, graph) for c in cycles)


def cell_unit(module: str) -> str | None:
    """The unit of ``cell/`` a module belongs to: the folder directly under ``cell/`` that holds
    it (``"calibration/"``) or the loose module itself (``"cli.py"``); None outside ``cell``
    and for ``cell/__init__``."""
    parts = module.split(".")
    if parts[0] != "cell" or len(parts) == 1:
        return None
    return parts[1] + "/" if (ROOT / "cell" / parts[1]).is_dir() else parts[1] + ".py"


def unit_graph(graph: dict[str, set[str]]) -> dict[str, set[str]]:
    """The module graph folded onto the units of ``cell/``: an edge between two units for every
    import between their modules (the parent-package rule of :func:`imports_of` applies)."""
    units: dict[str, set[str]] = {}
    for module, targets in graph.items():
        src = cell_unit(module)
        if src is None:
            continue
        units.setdefault(src, set())
        for target in targets:
            dst = cell_unit(target)
            if dst is not None and dst != src:
                units[src].add(dst)
                units.setdefault(dst, set())
    return units


def _unit_evidence(component: list[str], graph: dict[str, set[str]]) -> str:
    members = set(component)
    lines = []
    for module, targets in sorted(graph.items()):
        for target in sorted(targets):
            a, b = cell_unit(module), cell_unit(target)
            if a in members and b in members and a != b:
                lines.append(f"  cell/{a} -> cell/{b}: {module} imports {target}")
    return (
        f"{len(component)} units: "
        + ", ".join(f"cell/{u}" for u in component)
        + "\n"
        + ("\n".join(lines))
    )


def test_unit_graph_folds_modules_onto_folders() -> None:
    graph = {
        "cell.run.runner": {"cell.review.store", "cell.run.setup"},
        "cell.review.store": {"cell.run.results"},
        "cell.run.setup": set(),
        "cell.run.results": set(),
        "cell.cli": {"cell.errors"},
        "cell.errors": set(),
    }
    units = unit_graph(graph)
    assert units["run/"] == {"review/"} and units["review/"] == {"run/"}
    assert import_cycles(units) == [["review/", "run/"]]
    assert units["cli.py"] == {"errors.py"}


def test_no_circles_between_the_units_of_cell() -> None:
    """Taken as units (each folder directly under ``cell/`` and each loose module there), no
    two import each other, directly or through others: ``cell/`` is layered
    (docs/architecture.md draws the layers)."""
    graph = import_graph()
    cycles = import_cycles(unit_graph(graph))
    assert not cycles, "circles between the units of cell/:\n" + "\n".join(
        _unit_evidence(c, graph) for c in cycles
    )


def test_at_most_four_loose_modules_in_cell() -> None:
    loose = sorted(p.name for p in (ROOT / "cell").glob("*.py"))
    assert len(loose) <= 4, loose


if __name__ == "__main__":
    found = import_graph()
    for cycle in import_cycles(found):
        print(_describe(cycle, found))
    for cycle in import_cycles(unit_graph(found)):
        print(_unit_evidence(cycle, found))
