"""The ray caster: Embree called directly is the backend in use; watertight, it gives embreex's hits bit for bit, and
its fast default test hits the same triangles at the same distances but for a ray in a million."""

from __future__ import annotations

import sys
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from generator.lidar import embree_native
from generator.lidar.caster import EmbreeCaster
from generator.lidar.sensors import load_preset


def _terrain(n: int = 120, cell: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    """A rolling height field with walls: many shared edges and grazing angles, (V, 3) and (F, 3)."""
    x, y = np.meshgrid(np.arange(n + 1) * cell - n * cell / 2, np.arange(n + 1) * cell - n * cell / 2)
    z = 0.4 * np.sin(x / 3.0) * np.cos(y / 4.0) + np.where(np.abs(x) > n * cell * 0.4, 3.0, 0.0)
    v = np.stack([x, y, z], -1).reshape(-1, 3)
    i = np.arange(n * (n + 1)).reshape(n, n + 1)[:, :n].ravel()
    quads = np.stack([i, i + 1, i + n + 2, i + n + 1], 1)
    return v, np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])


@pytest.fixture(scope="module")
def rays():
    o_l, d_l, _ = load_preset("hdl64e").local_rays()
    d = np.ascontiguousarray(d_l.reshape(-1, 3), np.float32)
    o = np.ascontiguousarray(o_l.reshape(-1, 3) + [3.3, -1.7, 1.73], np.float32)
    return o, d


@pytest.fixture(scope="module")
def casters():
    """The direct caster as the scanner builds it (fast test) and embreex's (watertight)."""
    v, f = _terrain()
    return EmbreeCaster(v, f, center=np.zeros(3)), EmbreeCaster(v, f, center=np.zeros(3), native=False)


@pytest.fixture(scope="module")
def watertight():
    v, f = _terrain()
    return EmbreeCaster(v, f, center=np.zeros(3), robust=True)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the embreex wheel layout is checked on Linux")
def test_embree_is_called_directly_on_linux():
    assert embree_native.available()
    assert embree_native.version().startswith("4.")
    assert EmbreeCaster(*_terrain(4)).native


@pytest.mark.parametrize("max_distance", [60.0, "per ray"])
def test_watertight_direct_calls_hit_what_embreex_hits_bit_for_bit(casters, watertight, rays, max_distance):
    _, x = casters
    o, d = rays
    if max_distance == "per ray":
        max_distance = np.random.default_rng(0).uniform(2.0, 40.0, len(o)).astype(np.float32)
    a, b = watertight.intersect_local(o, d, max_distance), x.intersect_local(o, d, max_distance)
    assert np.isfinite(a[0]).sum() > len(o) // 3  # the terrain is hit, not missed
    np.testing.assert_array_equal(a[1], b[1])
    np.testing.assert_array_equal(a[0].view(np.uint32), b[0].view(np.uint32))


def test_the_fast_test_hits_the_watertight_triangles_at_their_distances(casters, watertight, rays):
    """The default (non-watertight) scene: the same triangle (or miss) but for a ray in 10^5 at most, and
    on the same triangle the distance within float32 rounding of the watertight one."""
    fast, _ = casters
    o, d = rays
    # many sensor positions over the terrain: ~1.3 M rays, each crossing shared edges at grazing angles
    shifts = np.random.default_rng(1).uniform([-20, -20, 0.0], [20, 20, 1.0], (10, 3)).astype(np.float32)
    n = other = 0
    for s in shifts:
        a, b = fast.intersect_local(o + s, d, 60.0), watertight.intersect_local(o + s, d, 60.0)
        same = a[1] == b[1]
        hit = same & (a[1] >= 0)
        assert hit.sum() > len(o) // 3
        np.testing.assert_allclose(a[0][hit], b[0][hit], rtol=0, atol=1e-3)  # float32 rounding, not a surface
        n, other = n + len(o), other + int((~same).sum())
    assert other <= 1e-5 * n  # measured: 2 rays of 1.33 M (a slip through an edge, a neighbour across one)


def test_a_miss_keeps_its_max_distance_unless_marked(casters, rays):
    native, _ = casters
    o, d = rays
    up = d[:, 2] > 0.01  # nothing above the sensor within 15 m (the walls stand 20 m away)
    dist, prim = native.intersect_local(o[up], d[up], 15.0, mark_misses=False)
    assert up.sum() > 1000 and (prim == -1).all() and (dist == np.float32(15.0)).all()
    dist, _ = native.intersect_local(o[up], d[up], 15.0)
    assert np.isinf(dist).all()


def test_hits_beyond_max_distance_are_misses(casters, rays):
    native, _ = casters
    o, d = rays
    full, prim = native.intersect_local(o, d, 200.0)
    near, near_prim = native.intersect_local(o, d, 10.0)
    hit = prim >= 0
    np.testing.assert_array_equal(near_prim >= 0, hit & (full < 10.0))
    np.testing.assert_array_equal(near[near_prim >= 0], full[near_prim >= 0])


def test_threads_cast_at_once_give_the_same_hits(casters, rays):
    native, _ = casters
    o, d = rays
    one = native.intersect_local(o, d, 120.0)
    parts = np.array_split(np.arange(len(o)), 8)
    with ThreadPoolExecutor(4) as pool:
        got = list(pool.map(lambda i: native.intersect_local(o[i], d[i], 120.0), parts))
    np.testing.assert_array_equal(np.concatenate([g[1] for g in got]), one[1])
    np.testing.assert_array_equal(np.concatenate([g[0] for g in got]), one[0])


@pytest.mark.skipif(not embree_native.available(), reason="needs Embree called directly")
def test_the_corners_the_return_model_reads_are_the_vertices_embree_casts_against():
    v, f = _terrain(20)
    caster = EmbreeCaster(v, f, native=True)
    corners = caster.triangle_corners()
    np.testing.assert_array_equal(corners, (v - caster.center).astype(np.float32)[f])
    assert np.shares_memory(caster._local, caster._scene._v)  # one copy of the vertices, not two


@pytest.mark.skipif(not embree_native.available(), reason="needs Embree called directly")
def test_rays_cast_into_scenes_of_their_own_hit_what_each_scene_gives_them(rays):
    """The actors' one-loop cast: each ray meets only its own scene, exactly as that scene alone casts it."""
    o, d = rays
    a, b = EmbreeCaster(*_terrain(40), center=np.zeros(3)), EmbreeCaster(*_terrain(40, 0.7), center=np.zeros(3))
    which = np.random.default_rng(2).integers(0, 2, len(o))
    tfar = np.full(len(o), 40.0, np.float32)
    dist, prim = embree_native.intersect_many([a.direct_scene, b.direct_scene], which, o, d, tfar)
    for k, c in enumerate((a, b)):
        m = which == k
        want = c.intersect_local(o[m], d[m], 40.0, mark_misses=False)
        assert (want[1] >= 0).sum() > m.sum() // 4
        np.testing.assert_array_equal(prim[m], want[1])
        np.testing.assert_array_equal(dist[m].view(np.uint32), want[0].view(np.uint32))
    assert not np.array_equal(*(c.intersect_local(o, d, 40.0)[1] for c in (a, b)))  # the scenes differ


def _cube(half: float) -> tuple[np.ndarray, np.ndarray]:
    v = np.array([[x, y, z] for x in (-half, half) for y in (-half, half) for z in (-half, half)], np.float64)
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    return v, np.array([t for a, b, c, e in quads for t in ((a, b, c), (a, c, e))], np.int64)


@pytest.mark.skipif(not embree_native.available(), reason="needs Embree called directly")
def test_rays_that_pass_outside_a_scenes_box_are_the_misses_embree_gives():
    """intersect_many skips the rays whose segment passes outside their scene's box: the same misses, the same tfar;
    rays grazing a cube's faces (which lie on its box) and rays that end before the box are among them."""
    g = np.random.default_rng(5)
    cube, plate = EmbreeCaster(*_cube(1.0), center=np.zeros(3)), EmbreeCaster(*_cube(0.4), center=np.zeros(3))
    n = 4000
    o = g.normal(size=(n, 3))
    o = (10.0 * o / np.linalg.norm(o, axis=1, keepdims=True)).astype(np.float32)
    aim = g.uniform(-1.0, 1.0, (n, 3)) * g.choice([0.9, 1.0, 1.0 + 1e-6, 1.2], (n, 1))  # faces, edges, just outside
    d = aim - o
    d = (d / np.linalg.norm(d, axis=1, keepdims=True)).astype(np.float32)
    tfar = g.uniform(7.0, 14.0, n).astype(np.float32)
    which = g.integers(0, 2, n)
    dist, prim = embree_native.intersect_many([cube.direct_scene, plate.direct_scene], which, o, d, tfar)
    for k, c in enumerate((cube, plate)):
        m = which == k
        want = c.direct_scene.intersect(o[m], d[m], tfar[m])
        np.testing.assert_array_equal(prim[m], want[1])
        np.testing.assert_array_equal(dist[m].view(np.uint32), want[0].view(np.uint32))
    box = np.array([c.direct_scene.box for c in (cube, plate)])[which]
    with np.errstate(divide="ignore", invalid="ignore"):
        ta, tb = (box[:, :3] - o) / d, (box[:, 3:] - o) / d
    outside = np.maximum(np.minimum(ta, tb).max(1), 0) > np.minimum(np.maximum(ta, tb).min(1), tfar)
    assert 0.2 * n < outside.sum() < (prim < 0).sum()  # many skipped, and misses inside the box were cast
    assert (prim >= 0).sum() > n // 4
