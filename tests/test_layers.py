"""The package arrows of DESIGN.md's "Who owns what" table, and no import cycle, checked on the
source (every `import`, deferred and `TYPE_CHECKING` ones included, and `importlib` calls with a
literal module name), so a forbidden route cannot hide inside a function."""

from __future__ import annotations

import ast
import sys
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

# package -> the project packages it may import (DESIGN.md's "may import" column)
ALLOWED: dict[str, frozenset[str]] = {
    "worldfile": frozenset(),
    "firmware_link": frozenset(),
    "planners": frozenset(),
    "logs": frozenset(),
    "sitl": frozenset({"worldfile"}),
    "gcs": frozenset({"firmware_link", "planners", "logs", "worldfile"}),
    "lab": frozenset({"gcs", "sitl", "firmware_link", "planners", "logs", "worldfile"}),
}
PRODUCT = tuple(ALLOWED)
PROJECT = frozenset(ALLOWED) | {"tests", "bench"}

# import names of the third-party libraries pyproject declares (its dependencies and extras)
THIRD_PARTY = frozenset({
    "pymavlink", "serial", "numpy", "textual", "textual_plotext", "mcap", "contourpy",
    "shapely", "sdl2", "sdl2dll", "foxglove", "matplotlib", "ray", "optuna", "pyarrow",
    "mypy_extensions", "rich", "fastcrc",
})
STDLIB = frozenset(sys.stdlib_module_names) | {"_typeshed", "typing_extensions", "__future__"}


@dataclass(frozen=True, slots=True)
class Import:
    """One imported module name, where it is imported from."""

    module: str  # the importing module, e.g. "gcs.station.loop"
    target: str  # the imported module or name, dotted
    line: int


def module_name(path: Path) -> str:
    """The dotted name of a source file under ROOT (a package's __init__ is the package)."""
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def sources(packages: tuple[str, ...]) -> Iterator[Path]:
    """Every .py file of the packages."""
    for pkg in packages:
        yield from sorted((ROOT / pkg).rglob("*.py"))


def _absolute(module: str, is_package: bool, level: int, name: str | None) -> str:
    # `from ..x import y` inside module a.b.c: level 2 climbs to a
    base = module.split(".")
    if not is_package:
        base = base[:-1]
    if level > 1:
        base = base[: len(base) - (level - 1)]
    return ".".join([*base, name] if name else base)


def imports_of(path: Path) -> list[Import]:
    """Every module a file imports, at any depth in the file."""
    module = module_name(path)
    is_package = path.name == "__init__.py"
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    found: list[Import] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found.extend(Import(module, a.name, node.lineno) for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = (
                _absolute(module, is_package, node.level, node.module)
                if node.level
                else node.module or ""
            )
            # `from pkg import name`: pkg.name when it is a submodule, else pkg itself (the
            # longest known module of the dotted name is what `_resolve` takes)
            found.extend(Import(module, f"{base}.{a.name}" if a.name != "*" else base,
                                node.lineno) for a in node.names)
        elif isinstance(node, ast.Call) and _is_import_call(node.func):
            arg = node.args[0] if node.args else None
            if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
                found.append(Import(module, arg.value, node.lineno))
            elif isinstance(arg, ast.JoinedStr) and arg.values:
                head = arg.values[0]
                if isinstance(head, ast.Constant) and isinstance(head.value, str):
                    found.append(Import(module, head.value.rstrip("."), node.lineno))
    return found


def _is_import_call(func: ast.expr) -> bool:
    if isinstance(func, ast.Attribute):
        return func.attr == "import_module" or (
            func.attr == "__import__" and isinstance(func.value, ast.Name)
        )
    return isinstance(func, ast.Name) and func.id in {"import_module", "__import__"}


def _known_modules() -> set[str]:
    return {module_name(p) for p in sources(PRODUCT)}


def _resolve(target: str, known: set[str]) -> str | None:
    """The longest known module that `target` names or lies in (None: not a project module)."""
    parts = target.split(".")
    for n in range(len(parts), 0, -1):
        name = ".".join(parts[:n])
        if name in known:
            return name
    return None


def arrow_violations() -> list[str]:
    """`file:line: package -> target` for every import the table does not allow."""
    bad: list[str] = []
    for path in sources(PRODUCT):
        for imp in imports_of(path):
            own = imp.module.split(".")[0]
            top = imp.target.split(".")[0]
            if not top or top == own or top in STDLIB or top in THIRD_PARTY:
                continue
            if top in PROJECT and top not in ALLOWED[own]:
                where = path.relative_to(ROOT)
                bad.append(f"{where}:{imp.line}: {own} may not import {imp.target}")
            elif top not in PROJECT:
                where = path.relative_to(ROOT)
                bad.append(f"{where}:{imp.line}: {imp.target} is neither stdlib nor declared")
    return sorted(set(bad))


def import_graph() -> dict[str, set[str]]:
    """Module -> the project modules it imports (the named module, not its parents)."""
    known = _known_modules()
    graph: dict[str, set[str]] = {m: set() for m in known}
    for path in sources(PRODUCT):
        for imp in imports_of(path):
            target = _resolve(imp.target, known)
            if target is not None and target != imp.module:
                graph.setdefault(imp.module, set()).add(target)
                graph.setdefault(target, set())
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    stack: list[str] = []
    found: list[list[str]] = []
    counter = 0
    for root in sorted(graph):
        if root in index:
            continue
        work: list[tuple[str, Iterator[str]]] = [(root, iter(sorted(graph[root])))]
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
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component: list[str] = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    found.append(sorted(component))
    return sorted(found)


def test_the_finder_sees_deferred_and_importlib_imports(tmp_path: Path) -> None:
    src = (
        "from typing import TYPE_CHECKING\n"
        "import importlib\n"
        "if TYPE_CHECKING:\n    from sitl.world import World\n"
        "def f():\n    from ..x import y\n    return importlib.import_module('sitl.lockstep')\n"
    )
    pkg = ROOT / "gcs"
    path = pkg / "_layer_probe_tmp.py"
    try:
        path.write_text(src, encoding="utf-8")
        targets = {i.target for i in imports_of(path)}
    finally:
        path.unlink()
    assert {"sitl.world.World", "sitl.lockstep", "x.y", "typing.TYPE_CHECKING"} <= targets


def test_cycle_finder_finds_a_cycle_and_only_it() -> None:
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}, "e": set()}
    assert cycles(graph) == [["a", "b", "c"]]


# Findings accepted for now (none today); a new finding fails at once, a fixed one must leave
# these lists.
KNOWN_ARROWS: frozenset[str] = frozenset()
KNOWN_CYCLES: frozenset[tuple[str, ...]] = frozenset()


def _lines(found: Iterable[object]) -> str:
    return "\n".join(str(f) for f in found)


def test_no_new_import_against_the_design() -> None:
    bad = set(arrow_violations())
    assert bad <= KNOWN_ARROWS, "imports against DESIGN.md's table:\n" + _lines(
        sorted(bad - KNOWN_ARROWS))
    gone = KNOWN_ARROWS - bad
    assert not gone, "fixed: remove from KNOWN_ARROWS:\n" + _lines(sorted(gone))


def test_no_new_import_cycle() -> None:
    found = {tuple(c) for c in cycles(import_graph())}
    assert found <= KNOWN_CYCLES, "import cycles:\n" + _lines(sorted(found - KNOWN_CYCLES))
    gone = KNOWN_CYCLES - found
    assert not gone, "fixed: remove from KNOWN_CYCLES:\n" + _lines(sorted(gone))


def test_every_package_imports_only_what_the_design_allows() -> None:
    bad = arrow_violations()
    assert not bad, "imports against DESIGN.md's table:\n" + "\n".join(bad)


def test_the_station_never_reaches_the_sitl() -> None:
    bad = [
        f"{p.relative_to(ROOT)}:{i.line}: {i.target}"
        for p in sources(("gcs",))
        for i in imports_of(p)
        if i.target.split(".")[0] == "sitl"
    ]
    assert not bad


def test_no_import_cycle() -> None:
    found = cycles(import_graph())
    assert not found, "import cycles:\n" + "\n".join(" <-> ".join(c) for c in found)


def package_graph(depth: int = 2) -> dict[str, set[str]]:
    """The module graph with each module replaced by its package `depth` levels deep (gcs.tui,
    gcs.gamepad ...; a loose module stands for itself)."""
    def cut(m: str) -> str:
        return ".".join(m.split(".")[:depth])

    graph: dict[str, set[str]] = {}
    for m, targets in import_graph().items():
        graph.setdefault(cut(m), set()).update(cut(t) for t in targets if cut(t) != cut(m))
    for targets in list(graph.values()):
        for t in targets:
            graph.setdefault(t, set())
    return graph


KNOWN_PACKAGE_CYCLES: frozenset[tuple[str, ...]] = frozenset({
    # sitl/link/ and the SITL's top-level modules import each other
    ("sitl.companion", "sitl.link", "sitl.mocap_server", "sitl.simulation", "sitl.truth_server"),
})


def test_no_new_cycle_between_subpackages() -> None:
    found = {tuple(c) for c in cycles(package_graph())
             if not any(len(m.split(".")) < 2 for m in c)}
    assert found <= KNOWN_PACKAGE_CYCLES, "cycles between packages:\n" + _lines(
        sorted(found - KNOWN_PACKAGE_CYCLES))
    assert ("gcs.gamepad", "gcs.tui") not in found
