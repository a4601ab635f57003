"""The test run's shared prototype store (:mod:`kits.proto_store`) is exact: a mesh read from it is the
mesh the build makes and leaves the generator where the build leaves it; derived data likewise."""

from __future__ import annotations

import numpy as np
import pytest

from assets_procedural import catalog
from assets_procedural.proto_cache import PrototypeCache
from generator.rng import stream
from kits import proto_store


@pytest.fixture
def store(tmp_path, monkeypatch):
    """A fresh cache with the disk layer over it in ``tmp_path`` (the process's own cache untouched)."""
    cache = PrototypeCache()
    monkeypatch.setattr("assets_procedural.proto_cache.CACHE", cache)
    monkeypatch.setitem(proto_store._STATE, "folder", None)
    monkeypatch.setattr(proto_store, "WORTH_S", 0.0)   # every build kept, however quick
    proto_store.install(tmp_path / "protos")
    return cache, tmp_path / "protos"


def _tree(cache):
    g = stream(3, "assets", "tree", 1)
    mesh = cache.build("tree", g, {"height": 5.5}, catalog.BUILDERS["tree"])
    return mesh, g.random(4)


def test_a_stored_mesh_is_the_built_one_and_the_generator_ends_where_the_build_left_it(store):
    cache, folder = store
    g = stream(3, "assets", "tree", 1)
    fresh = catalog.BUILDERS["tree"](g, height=5.5)
    after = g.random(4)
    built, draws = _tree(cache)                      # a miss: built and written
    assert len(list(folder.glob("*.pickle"))) == 1
    cache.clear()                                    # as another worker: nothing in memory
    read, draws_read = _tree(cache)
    assert cache.misses == 1 and read is not built   # served by the file, not by the process's cache
    for m in (built, read):
        assert all(np.array_equal(getattr(m, a), getattr(fresh, a))
                   for a in ("vertices", "faces", "face_class", "face_material"))
        assert m.anchors.keys() == fresh.anchors.keys()
        assert all(np.array_equal(m.anchors[k], fresh.anchors[k]) for k in fresh.anchors)
    assert np.array_equal(draws, after) and np.array_equal(draws_read, after)
    with pytest.raises(ValueError):                  # still read-only, like a built one
        read.vertices[0, 0] = 1.0


def test_another_builder_or_another_state_is_another_file(store):
    cache, folder = store
    _tree(cache)
    cache.clear()
    g = stream(3, "assets", "tree", 1)
    stand_in = cache.build("tree", g, {"height": 5.5}, lambda rng, height: catalog.BUILDERS["bush"](rng, size=1.0))
    assert len(list(folder.glob("*.pickle"))) == 2
    assert stand_in.vertices.shape != _tree(PrototypeCache())[0].vertices.shape
    cache.build("tree", stream(3, "assets", "tree", 2), {"height": 5.5}, catalog.BUILDERS["tree"])
    assert len(list(folder.glob("*.pickle"))) == 3


CALLS = []  # not in the function's closure: what a closure holds is part of the key


def _count(m):
    CALLS.append(1)
    return m.vertices.sum(0)


def test_derived_data_is_stored_by_what_the_mesh_holds(store):
    cache, folder = store
    mesh, _ = _tree(cache)
    calls, count = CALLS, _count
    calls.clear()
    first = cache.derive(mesh, "sum", count)
    cache.clear()
    again, _ = _tree(cache)
    assert np.array_equal(cache.derive(again, "sum", count), first) and calls == [1]
    with proto_store.bypassed():
        cache.clear()
        cache.derive(_tree(cache)[0], "sum", count)
    assert calls == [1, 1]


def test_a_quick_build_is_not_kept(store, monkeypatch):
    cache, folder = store
    monkeypatch.setattr(proto_store, "WORTH_S", 60.0)
    _tree(cache)
    assert not list(folder.glob("*.pickle"))


def test_a_value_pickle_refuses_is_not_kept_and_still_returned(store):
    cache, folder = store
    mesh, _ = _tree(cache)
    n = len(list(folder.glob("*.pickle")))
    value = cache.derive(mesh, "closure", _unpicklable)
    assert value() == 1 and len(list(folder.glob("*.pickle"))) == n and not list(folder.glob(".*.tmp"))


def _unpicklable(m):
    return lambda: 1


def test_a_builder_is_named_alike_in_every_process():
    """The workers are separate processes: a builder's identity must not hold an address (a nested code
    object's repr does), or no worker would ever read what the other built."""
    import subprocess
    import sys

    from generator.geometry.proxy import label_proxy
    from kits.paths import ROOT

    code = ("import sys; sys.path.insert(0, 'tests'); from kits.proto_store import _code_of; "
            "from generator.geometry.proxy import label_proxy; from assets_procedural import catalog; "
            "print(_code_of(label_proxy)); print(_code_of(catalog.BUILDERS['hedge']))")
    child = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=True)
    here = [proto_store._code_of(label_proxy), proto_store._code_of(catalog.BUILDERS["hedge"])]
    assert child.stdout.split() == here
