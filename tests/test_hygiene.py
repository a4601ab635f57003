"""The test suite keeps its own house rules (walked with ``ast``, lazy imports included).

* A test never imports another test module (nor ``conftest``, nor anything through ``tests.``):
  what two test files share lives in ``tests/kits`` (imported as ``kits.<topic>``).
* Every test file finds the checkout and the shared reference through ``kits.paths`` (``ROOT``,
  ``SHARED``) or the ``root`` fixture, never through ``__file__``, which moves with the file.
"""

from __future__ import annotations

import ast

from kits.paths import ROOT

TESTS = ROOT / "tests"
#: the one module that may locate itself
LOCATES_ITSELF = {"kits/paths.py"}


def _files() -> list:
    return sorted(p for p in TESTS.rglob("*.py") if "__pycache__" not in p.parts)


def _test_module_names() -> set[str]:
    return {p.stem for p in TESTS.rglob("test_*.py")} | {"conftest"}


def _imports_of_tests(source: str, test_modules: set[str]) -> list[str]:
    """The imports in ``source`` that reach a test module (or are relative), as written."""
    bad = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                bad.append("." * node.level + (node.module or ""))
                continue
            names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
        else:
            continue
        for name in names:
            parts = name.split(".")
            if parts[0] == "tests" or any(p in test_modules for p in parts):
                bad.append(name)
                break
    return bad


def test_no_test_module_imports_another():
    names = _test_module_names()
    bad = {str(p.relative_to(TESTS)): found for p in _files()
           if (found := _imports_of_tests(p.read_text(encoding="utf-8"), names))}
    assert not bad, f"move what these share into tests/kits: {bad}"


def test_the_import_walk_finds_test_imports():
    names = {"test_streets", "conftest"}
    source = ("import numpy\nfrom kits.town_checks import no_collisions\n"
              "def f():\n    from test_streets import _no_collisions\n"
              "from tests.layout import test_town\nimport conftest\nfrom . import helper\n"
              "from layout import test_streets\n")
    assert sorted(_imports_of_tests(source, names)) == [
        ".", "conftest", "layout.test_streets", "test_streets", "tests.layout"]


def _uses_file(source: str) -> bool:
    return any(isinstance(n, ast.Name) and n.id == "__file__" for n in ast.walk(ast.parse(source)))


def test_no_test_locates_the_checkout_from_its_own_path():
    bad = [str(p.relative_to(TESTS)) for p in _files()
           if str(p.relative_to(TESTS)) not in LOCATES_ITSELF and _uses_file(p.read_text(encoding="utf-8"))]
    assert not bad, f"use kits.paths.ROOT / SHARED or the root fixture instead of __file__: {bad}"
    assert _uses_file("from pathlib import Path\nROOT = Path(__file__).parents[1]\n")


def test_tests_that_share_a_module_build_share_a_worker(request):
    """What the xdist scheduler reads from the files (kits.xdist_groups) covers every collected test
    that pytest itself resolves to a module-, class- or package-scoped fixture: those tests form one
    unit of work per module, so the module's build is made once under ``-n 2``."""
    from kits.xdist_groups import scope_of

    missed = []
    for item in request.session.items:
        info = getattr(item, "_fixtureinfo", None)
        if info is None:
            continue
        shared = any(d.scope in ("module", "class", "package")
                     for name in info.names_closure for d in info.name2fixturedefs.get(name, ()))
        module = item.nodeid.split("::")[0]
        if shared and scope_of(item.nodeid, ROOT) != module:
            missed.append(item.nodeid)
    assert not missed, f"the scheduler would split these from their module's build: {missed[:5]}"


def test_the_scheduler_reads_module_fixtures_through_other_fixtures(tmp_path):
    from kits.xdist_groups import scope_of

    (tmp_path / "test_x.py").write_text(
        "import pytest\n"
        "@pytest.fixture(scope='module')\ndef town(): ...\n"
        "@pytest.fixture\ndef world(town): ...\n"
        "def test_a(world): ...\n"
        "def test_b(tmp_path): ...\n"
        "class TestC:\n    def test_c(self, town): ...\n")
    assert scope_of("test_x.py::test_a[1-2]", tmp_path) == "test_x.py"
    assert scope_of("test_x.py::TestC::test_c", tmp_path) == "test_x.py"
    assert scope_of("test_x.py::test_b", tmp_path) == "test_x.py::test_b"
