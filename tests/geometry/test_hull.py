"""The lean hull (generator/geometry/hull.py) gives trimesh's hull bit for bit.

Label proxies are part of every town's bytes (SceneModel.digest hashes them), so a faster
hull is only acceptable if vertices, faces and vertex normals are the very arrays
``trimesh.convex.convex_hull`` gives -- on the meshes the towns hull (fences, hedges, crowns,
bushes) and on the inputs that send it down trimesh's own path.
"""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from assets_procedural import catalog
from generator.geometry import hull
from generator.labels import class_table


def _trimesh(points):
    h = trimesh.convex.convex_hull(points)
    return np.asarray(h.vertices), np.asarray(h.faces), np.asarray(h.vertex_normals)


def _same(a, b) -> bool:
    return all(x.dtype == y.dtype and x.shape == y.shape and np.array_equal(x, y) for x, y in zip(a, b, strict=False))


def _asset_clouds():
    """The vertex sets the label proxies hull: each hull-policy class of fences, hedges, trees, bushes."""
    hull_classes = class_table().hull_classes
    out = []
    for i in range(8):
        for kind, params in (("fence", dict(length=2.5 + 3.1 * i, style=("bars", "pickets", "panels")[i % 3])),
                             ("hedge", dict(length=1.5 + 2.7 * i, height=0.8 + 0.1 * i)),
                             ("tree", dict(height=4.0 + i)),
                             ("bush", dict(size=0.4 + 0.3 * i))):
            m = catalog.build(kind, np.random.default_rng(100 + i), **params)
            for c in np.unique(m.face_class):
                if hull_classes[c]:
                    out.append((f"{kind}{i}", m.select(m.face_class == c).vertices))
    return out


CLOUDS = _asset_clouds()


@pytest.mark.parametrize("name,points", CLOUDS, ids=[n for n, _ in CLOUDS])
def test_asset_hulls_are_trimesh_hulls_bit_for_bit(name, points):
    assert _same(hull.hull_arrays(points), _trimesh(points))


def test_asset_hulls_take_the_fast_path():
    """The speed-up is real: the asset hulls do not all fall back to trimesh."""
    fast = sum(hull._fast(p) is not None for _, p in CLOUDS)
    assert fast >= 0.9 * len(CLOUDS), f"{fast} of {len(CLOUDS)} hulls on the fast path"


def test_random_clouds_and_boxes_match_trimesh():
    rng = np.random.default_rng(3)
    clouds = [rng.normal(size=(n, 3)) * rng.uniform(0.1, 20, 3) for n in (4, 9, 60, 700)]
    cube = np.array([[x, y, z] for x in (0, 1.5) for y in (0, 0.2) for z in (0, 2.0)], float)
    grid = np.stack(np.meshgrid(*[np.linspace(0, 1, 4)] * 3), -1).reshape(-1, 3)  # many coplanar points
    for p in (*clouds, cube, grid, cube + 1e6):
        assert _same(hull.hull_arrays(p), _trimesh(p))


@pytest.mark.parametrize("case", ["flat", "near-duplicates"])
def test_inputs_trimesh_treats_specially_fall_back_to_it(case):
    rng = np.random.default_rng(4)
    p = rng.uniform(-1, 1, (50, 3))
    if case == "flat":            # qhull fails without joggle: trimesh retries with QJ
        p[:, 2] = 0.0
    else:                         # two hull vertices closer than trimesh's merge distance
        p = np.concatenate([p, [[5.0, 5.0, 5.0], [5.0 + 1e-10, 5.0, 5.0]]])
    assert hull._fast(p) is None
    assert _outcome(hull.hull_arrays, p) == _outcome(_trimesh, p)


def _outcome(fn, p):
    """The arrays' bytes, or the exception type (trimesh's repair of a joggled flat hull needs
    networkx, which the venv may lack: then both must fail the same way)."""
    try:
        return tuple(a.tobytes() for a in fn(p))
    except Exception as e:  # noqa: BLE001 - the type is the outcome compared
        return type(e)


def test_merge_guard_is_trimesh_tolerance():
    """hull.py writes trimesh's merge tolerance out (so importing it does not import trimesh)."""
    assert hull.MERGE_GUARD == 1e3 * trimesh.constants.tol.merge
