"""The package layering holds: imports run one way, bpy stays in the Blender edge.

Walks every module's imports with ``ast`` (module-level and function-level alike, so a lazy
import cannot hide a back edge) and checks them against :data:`ALLOWED`, the layer table
docs/architecture.md shows, and that no package has an import circle among its modules
and sub-packages (:func:`test_no_import_circle_inside_a_package`).
"""

from __future__ import annotations

import ast
from collections import defaultdict
from pathlib import Path

import pytest

from kits.paths import ROOT

#: Bottom of the house: imported by anything, import nothing of ours but each other.
BASE = {"generator", "errors", "atomic", "rng", "safeload", "progress"}  # safeload is a package of its own

#: Package -> the packages it may import (besides BASE). ``generator`` is the package root
#: (``__version__``); ``assets_procedural`` is the top-level asset package.
ALLOWED: dict[str, set[str]] = {
    "labels": set(),
    "materials": set(),
    "spec": set(),
    "weather": set(),
    "geometry": {"labels", "materials"},
    "world": {"geometry", "spec"},
    "assets_procedural": {"geometry", "labels", "materials"},
    "layout": {"assets_procedural", "geometry", "labels", "materials", "spec", "world"},
    "traffic": {"geometry", "labels", "layout", "spec", "world"},
    "lidar": {"geometry", "labels", "materials", "spec", "world"},
    "postfx": {"weather"},
    "imaging": {"labels", "spec", "weather"},
    "detection": {"geometry", "labels", "spec", "world"},
    "formats": {"detection", "geometry", "labels", "spec", "world"},
    "previews": {"imaging", "labels", "postfx", "weather", "world"},
    "remission": {"formats", "labels", "materials", "spec"},
    "stats": {"dataset", "formats", "imaging", "labels", "previews", "weather"},
    "scan_effects": {"labels", "remission", "spec", "weather"},
    "fusion": {"formats", "geometry", "imaging", "labels", "stats", "world"},
    "motion": {"fusion", "geometry", "lidar", "world"},
    "blender": {"geometry", "labels", "materials", "spec", "weather", "world"},
    "jobs": {"blender", "dataset", "detection", "formats", "geometry", "imaging", "labels", "layout", "lidar",
             "materials", "motion", "postfx", "previews", "remission", "scan_effects", "spec", "stats", "traffic",
             "weather", "world"},
    "commands": {"dataset", "detection", "exports", "formats", "fusion", "gap", "geometry", "imaging", "jobs", "labels",
                 "layout", "lidar", "materials", "motion", "previews", "remission", "scan_effects", "spec", "stats",
                 "traffic", "weather", "world"},
    "exports": {"dataset", "detection", "formats", "fusion", "geometry", "imaging", "jobs", "labels", "lidar",
                "previews", "spec", "world"},
    "dataset": {"formats", "imaging", "labels"},
    "gap": {"dataset", "formats", "geometry", "imaging", "labels", "lidar", "stats"},
    "cli": {"commands"},
}


def _package(module: str) -> str:
    parts = module.split(".")
    if parts[0] == "assets_procedural":
        return "assets_procedural"
    return "generator" if len(parts) == 1 else parts[1]


def _modules():
    for path in sorted([*ROOT.glob("generator/**/*.py"), *ROOT.glob("assets_procedural/**/*.py")]):
        rel = path.relative_to(ROOT).with_suffix("")
        parts = list(rel.parts)
        is_init = parts[-1] == "__init__"
        if is_init:
            parts = parts[:-1]
        yield ".".join(parts), is_init, path


def _imports(module: str, is_init: bool, path: Path) -> set[str]:
    """Every module ``module`` imports (absolute names), at any nesting level."""
    pkg = module if is_init else module.rsplit(".", 1)[0]
    out = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = pkg.split(".")[: len(pkg.split(".")) - (node.level - 1)]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            out.add(target)
            out.update(f"{target}.{a.name}" for a in node.names)  # `from pkg import module`
    return out


@pytest.fixture(scope="module")
def graph() -> dict[str, set[str]]:
    """Module -> the project modules and packages it imports."""
    g = {}
    for module, is_init, path in _modules():
        g[module] = {
            m for m in _imports(module, is_init, path) if m.split(".")[0] in ("generator", "assets_procedural")
        }
    return g


def _known(g: dict[str, set[str]], name: str) -> bool:
    return name in g


def test_every_package_is_in_the_layer_table(graph):
    packages = {_package(m) for m in graph} - BASE
    missing = sorted(packages - set(ALLOWED))
    assert packages <= set(ALLOWED), f"add these packages to ALLOWED (and docs/architecture.md): {missing}"


def test_imports_follow_the_layer_table(graph):
    bad = []
    for module, targets in graph.items():
        src = _package(module)
        for t in targets:
            if not _known(graph, t):
                continue  # `from generator.x import name`: the name, not a module
            dst = _package(t)
            if dst == src or dst in BASE:
                continue
            if src in BASE:
                bad.append(f"{module} (base) imports {t}")
            elif dst not in ALLOWED[src]:
                bad.append(f"{module} imports {t} ({src} -> {dst} is not in the layer table)")
    assert not bad, "\n".join(sorted(bad))


def test_the_layer_table_has_no_cycle():
    state: dict[str, int] = defaultdict(int)

    def visit(p: str, trail: list[str]) -> None:
        if state[p] == 1:
            raise AssertionError("cycle: " + " -> ".join(trail + [p]))
        if state[p] == 2:
            return
        state[p] = 1
        for q in ALLOWED.get(p, ()):
            visit(q, trail + [p])
        state[p] = 2

    for p in ALLOWED:
        visit(p, [])


def test_the_blender_edge_calls_nothing_above_it(graph):
    for module, targets in graph.items():
        if _package(module) == "blender":
            above = {t for t in targets if _package(t) in ("jobs", "commands", "cli", "layout")}
            assert not above, f"{module} imports {sorted(above)}"


def test_only_the_blender_edge_imports_bpy():
    for module, is_init, path in _modules():
        if module.startswith("generator.blender"):
            continue
        names = _imports(module, is_init, path)
        assert not {n for n in names if n.split(".")[0] in ("bpy", "mathutils")}, f"{module} imports bpy"


def test_only_the_placement_step_imports_assets(graph):
    users = {m for m, targets in graph.items()
             if _package(m) != "assets_procedural" and any(_package(t) == "assets_procedural" for t in targets)}
    assert users == {"generator.layout.placement.prototypes"}


def _module_edges() -> dict[str, set[str]]:
    """Module -> the project modules it imports (module-level and lazy), each edge to the module itself:
    ``from pkg import module`` is an edge to ``pkg.module``, ``from pkg import name`` one to ``pkg``
    (its ``__init__``), ``from pkg.module import name`` one to ``pkg.module``."""
    known = {m for m, _, _ in _modules()}
    out: dict[str, set[str]] = {}
    for module, is_init, path in _modules():
        pkg = module if is_init else module.rsplit(".", 1)[0]
        edges = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                for a in node.names:
                    name = a.name
                    while name and name not in known:
                        name = name.rpartition(".")[0]
                    if name:
                        edges.add(name)
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = pkg.split(".")[: len(pkg.split(".")) - (node.level - 1)]
                    target = ".".join(base + ([node.module] if node.module else []))
                else:
                    target = node.module or ""
                for a in node.names:
                    if f"{target}.{a.name}" in known:
                        edges.add(f"{target}.{a.name}")
                    elif target in known:
                        edges.add(target)
        out[module] = edges - {module}
    return out


def _circles(edges: dict[str, set[str]]) -> list[list[str]]:
    """One circle (a list of nodes, first repeated last) per strongly connected group of ``edges``."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    out = []

    def connect(v: str) -> None:     # Tarjan's algorithm
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in edges.get(v, ()):
            if w not in index:
                connect(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = set()
            while True:
                w = stack.pop()
                group.add(w)
                if w == v:
                    break
            if len(group) > 1:
                out.append(_circle_in(edges, group))

    for v in sorted(edges):
        if v not in index:
            connect(v)
    return out


def _circle_in(edges: dict[str, set[str]], group: set[str]) -> list[str]:
    """A shortest circle through the first node of ``group`` (breadth first inside the group)."""
    start = min(group)
    paths = {start: [start]}
    todo = [start]
    while todo:
        v = todo.pop(0)
        for w in sorted(edges.get(v, ())):
            if w == start:
                return paths[v] + [start]
            if w in group and w not in paths:
                paths[w] = paths[v] + [w]
                todo.append(w)
    return sorted(group)


def test_no_import_circle_inside_a_package():
    """Inside every package the modules and sub-packages import one way: collapse every module below a
    package to the package's child it lives in (a module or a sub-package), and the children's imports,
    lazy ones included, form no circle. A package's ``__init__`` is the package itself."""
    modules = _module_edges()
    packages = sorted({m for m, is_init, _ in _modules() if is_init})
    bad = []
    for pkg in packages:
        def child(m: str, pkg: str = pkg) -> str | None:
            if m == pkg:
                return pkg
            return pkg + "." + m[len(pkg) + 1:].split(".")[0] if m.startswith(pkg + ".") else None

        edges: dict[str, set[str]] = defaultdict(set)
        for m, targets in modules.items():
            a = child(m)
            if a is None:
                continue
            for t in targets:
                b = child(t)
                if b is not None and b != a:
                    edges[a].add(b)
        bad += [f"{pkg}: " + " -> ".join(c) for c in _circles(edges)]
    assert not bad, "import circles (lazy imports included):\n" + "\n".join(bad)


def test_the_circle_finder_finds_circles():
    edges = {"p.a": {"p.b"}, "p.b": {"p.c"}, "p.c": {"p.a", "p.d"}, "p.d": set()}
    assert _circles(edges) == [["p.a", "p.b", "p.c", "p.a"]]
    assert _circles({"p.a": {"p.b"}, "p.b": set()}) == []


def test_modules_stay_small():
    big = {str(p.relative_to(ROOT)): n for _, _, p in _modules()
           if (n := len(p.read_text(encoding="utf-8").splitlines())) > 350}
    assert not big, f"split these modules (over 350 lines): {big}"
