"""Which tests must share a pytest-xdist worker: those of one module that use its module-scoped build.

Under ``pytest -n 2 --dist loadgroup`` every test is its own unit of work (whichever worker is free
takes it), except the tests that request a module-, class- or package-scoped fixture of their own
module: those form one unit per module, so the module's shared build (a rendered dataset, a town
with traffic) is made once, on one worker. The rule is read from the test files with ``ast`` in
the controlling process (which collects nothing): a test function's parameters, and the fixtures
of its module that depend on a module-scoped one.

pytest 9.2 builds node ids from a structured id, so pytest-xdist 3.8's own ``xdist_group`` marks
no longer group anything (pytest-xdist issue 1386); this scheduler does not depend on them, and
still honours an ``@group`` suffix where xdist manages to set one.
"""

from __future__ import annotations

import ast
import functools
from pathlib import Path

SHARED_SCOPES = {"module", "class", "package"}


def _fixture_scope(node: ast.FunctionDef) -> str | None:
    """The scope of a ``@pytest.fixture`` function (``"function"`` if not given); None if not a fixture."""
    for dec in node.decorator_list:
        call = dec if isinstance(dec, ast.Call) else None
        target = call.func if call else dec
        name = target.attr if isinstance(target, ast.Attribute) else getattr(target, "id", None)
        if name != "fixture":
            continue
        for kw in call.keywords if call else ():
            if kw.arg == "scope" and isinstance(kw.value, ast.Constant):
                return str(kw.value.value)
        return "function"
    return None


def _params(node: ast.FunctionDef) -> set[str]:
    """The fixtures ``node`` requests: its parameters less those ``@pytest.mark.parametrize`` sets."""
    names = {a.arg for a in (*node.args.posonlyargs, *node.args.args, *node.args.kwonlyargs)}
    for dec in node.decorator_list:
        if (isinstance(dec, ast.Call) and isinstance(dec.func, ast.Attribute) and dec.func.attr == "parametrize"
                and dec.args and isinstance(dec.args[0], ast.Constant) and isinstance(dec.args[0].value, str)):
            names -= {n.strip() for n in dec.args[0].value.split(",")}
    return names


@functools.cache
def shared_tests(path: Path) -> frozenset[str]:
    """Names (``test_x`` or ``Class::test_x``) of the tests in ``path`` that use one of its
    module-, class- or package-scoped fixtures, directly or through another fixture of the module."""
    try:
        tree = ast.parse(path.read_text(encoding="utf-8"))
    except (OSError, SyntaxError, UnicodeDecodeError):
        return frozenset()
    fixtures: dict[str, tuple[str, set[str]]] = {}
    tests: dict[str, set[str]] = {}

    def visit(body, prefix: str = "") -> None:
        for node in body:
            if isinstance(node, ast.ClassDef):
                visit(node.body, f"{prefix}{node.name}::")
            elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                scope = _fixture_scope(node)
                if scope is not None:
                    fixtures[node.name] = (scope, _params(node))
                elif node.name.startswith("test"):
                    tests[prefix + node.name] = _params(node)

    visit(tree.body)
    shared = {name for name, (scope, _) in fixtures.items() if scope in SHARED_SCOPES}
    grew = True
    while grew:                     # a fixture that requests a shared one is shared too
        grew = False
        for name, (_, needs) in fixtures.items():
            if name not in shared and needs & shared:
                shared.add(name)
                grew = True
    return frozenset(t for t, needs in tests.items() if needs & shared)


def scope_of(nodeid: str, rootpath: Path) -> str:
    """The unit of work of test ``nodeid``: its module's path if it uses the module's shared build,
    else the test itself."""
    path, sep, rest = nodeid.partition("::")
    if not sep:
        return nodeid
    name = rest.split("[", 1)[0]
    return path if name in shared_tests(rootpath / path) else nodeid
