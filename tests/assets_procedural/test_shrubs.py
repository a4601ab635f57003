"""Bushes and hedges: the batched hedge body is the clump-by-clump one, byte for byte; leafy gaps.

``shrubs.hedge_body`` draws all clumps' random numbers in one block and shapes all clumps in
array operations; a hedge's bytes (and every town's digest) depend on that being the very
stream and arithmetic of building one ``_blob`` per clump in turn, which this reference does.
"""

from __future__ import annotations

import numpy as np
import pytest

from assets_procedural.shrubs import bush, hedge, hedge_body
from generator.geometry import Mesh, icosphere, merge, on_ground
from generator.materials import material_table


def _blob(rng, center, radii, cls: str, material: str, jitter: float = 0.18, detail: int = 1,
          yaw: float = 0.0) -> Mesh:
    """A leaf cluster: an ellipsoid icosphere (80 triangles, 20 at ``detail`` 0) with radial noise,
    its x half-axis turned to ``yaw`` radians."""
    m = icosphere(1.0, cls, material, detail)
    r = 1.0 + rng.uniform(-jitter, jitter, len(m.vertices))
    v = m.vertices * r[:, None] * radii
    c, s = np.cos(yaw), np.sin(yaw)
    m.vertices = np.c_[c * v[:, 0] - s * v[:, 1], s * v[:, 0] + c * v[:, 1], v[:, 2]] + center
    return m


def _hedge_one_clump_at_a_time(rng, length, height=1.2, depth=0.8):
    spacing = float(rng.uniform(0.45, 0.6))
    n = max(1, int(round(length / spacing)))
    rx = length / n / 2
    xs = -length / 2 + rx + np.arange(n) * 2 * rx
    parts = []
    for x in xs:
        radii = np.array([rx * rng.uniform(1.1, 1.3), depth / 2 * rng.uniform(0.9, 1.0),
                          height / 2 * rng.uniform(0.92, 1.0)])
        c = np.array([x + rng.uniform(-0.05, 0.05) * rx, rng.uniform(-0.04, 0.04) * depth, radii[2]])
        m = _blob(rng, c, radii, "vegetation", "hedge_leaves", 0.12)
        rel = (m.vertices - c) / radii
        m.vertices = c + np.sign(rel) * np.abs(rel) ** 0.6 * radii
        reach = np.abs(m.vertices[:, 0] - c[0]).max()
        room = length / 2 - abs(c[0])
        if reach > room:
            m.vertices[:, 0] = c[0] + (m.vertices[:, 0] - c[0]) * (room / reach)
        parts.append(m)
    return on_ground(merge(parts))


@pytest.mark.parametrize("seed,length,height,depth", [(0, 0.5, 0.3, 0.2), (1, 2.3, 1.2, 0.8), (2, 7.77, 2.0, 1.5),
                                                      (3, 31.0, 4.0, 3.0), (4, 12.5, 0.9, 0.6)])
def test_batched_hedge_is_the_clump_by_clump_hedge(seed, length, height, depth):
    a = np.random.default_rng(seed)
    b = np.random.default_rng(seed)
    got = hedge_body(a, length, height, depth)
    want = _hedge_one_clump_at_a_time(b, length, height, depth)
    for x, y in ((got.vertices, want.vertices), (got.faces, want.faces), (got.face_class, want.face_class),
                 (got.face_material, want.face_material)):
        assert x.dtype == y.dtype and np.array_equal(x, y)
    assert a.bit_generator.state == b.bit_generator.state  # the generator is left where the loop left it


def _through(mesh, origins: np.ndarray, direction) -> np.ndarray:
    """(n,) bool: rays from ``origins`` along ``direction`` that miss every face of ``mesh``."""
    from trimesh.ray.ray_pyembree import RayMeshIntersector

    d = np.tile(np.asarray(direction, float), (len(origins), 1))
    return ~RayMeshIntersector(mesh.to_trimesh()).intersects_any(origins, d)


def _grid(lo, hi, axis: int, n: int = 40) -> np.ndarray:
    """Ray origins in front of [lo, hi] along ``axis`` over the central 90 % of the other two axes."""
    c, half = (lo + hi) / 2, (hi - lo) / 2 * 0.9
    a, b = [i for i in range(3) if i != axis]
    ga, gb = np.meshgrid(np.linspace(c[a] - half[a], c[a] + half[a], n), np.linspace(c[b] - half[b], c[b] + half[b], n))
    o = np.zeros((ga.size, 3))
    o[:, axis], o[:, a], o[:, b] = lo[axis] - 1.0, ga.ravel(), gb.ravel()
    return o


@pytest.mark.parametrize("kind", ["hedge", "bush"])
def test_leafy_shrubs_let_some_beams_through_where_the_hull_fills_the_mask(kind):
    """A LiDAR beam through a hedge or a bush sometimes gets through (between clumps, between
    leaves) while the label hull, which fills the camera mask, blocks every ray that meets a leaf."""
    from generator.geometry.proxy import label_proxy

    for seed in range(3):
        rng = np.random.default_rng(seed)
        m = hedge(rng, 6.0, 1.3, 0.9) if kind == "hedge" else bush(rng, 1.4)
        assert (m.face_material == material_table().id("hedge_leaves")).sum() > 0.3 * m.n_faces
        hull = label_proxy(m)
        lo, hi = m.bounds()
        o = _grid(lo, hi, 1)
        through, blocked = _through(m, o, (0, 1, 0)), ~_through(hull, o, (0, 1, 0))
        assert not (~through & ~blocked).any(), "the hull must block every ray that meets the shrub"
        frac = through[blocked].mean()
        assert 0.01 < frac < (0.25 if kind == "hedge" else 0.6), frac


def test_hedge_and_bush_are_the_same_bytes_for_the_same_seed():
    for make in (lambda g: hedge(g, 5.5), lambda g: bush(g, 1.2)):
        a, b = make(np.random.default_rng(3)), make(np.random.default_rng(3))
        assert a.vertices.tobytes() == b.vertices.tobytes() and a.faces.tobytes() == b.faces.tobytes()
