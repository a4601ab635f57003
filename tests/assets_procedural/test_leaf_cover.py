"""A hedge's leaf skin: the LiDAR hits separate leaves at many depths, the label hull stays solid."""

from __future__ import annotations

import numpy as np

from assets_procedural.leaf_cover import leaf_cover
from assets_procedural.shrubs import hedge
from generator.geometry import icosphere
from generator.geometry.proxy import label_proxy
from generator.materials import material_table


def _first_hits(mesh, origins: np.ndarray, direction) -> tuple[np.ndarray, np.ndarray]:
    """(face index or -1, hit point) of the first hit of each ray from ``origins`` along ``direction``."""
    from trimesh.ray.ray_pyembree import RayMeshIntersector

    d = np.tile(np.asarray(direction, float), (len(origins), 1))
    loc, ray, tri = RayMeshIntersector(mesh.to_trimesh()).intersects_location(origins, d, multiple_hits=False)
    face, point = np.full(len(origins), -1), np.full((len(origins), 3), np.nan)
    face[ray], point[ray] = tri, loc
    return face, point


def test_the_lidar_hits_leaves_at_many_depths_where_the_label_hull_is_one_solid_face():
    """Beams from the street side meet a hedge mostly on its leaves (geometry, the very triangles the
    camera sees), and reach a few centimetres to a decimetre into it: the returns have depth, as a real
    hedge's do; the hull the label pass draws blocks every one of those beams on one flat face."""
    leaf_id = material_table().id("hedge_leaves")
    for seed in range(3):
        m = hedge(np.random.default_rng(seed), 6.0, 1.3, 0.9)
        lo, hi = m.bounds()
        y, z = np.meshgrid(np.linspace(-2.5, 2.5, 60), np.linspace(0.4, 1.1, 20))
        o = np.c_[y.ravel(), np.full(y.size, lo[1] - 1.0), z.ravel()]
        face, point = _first_hits(m, o, (0, 1, 0))
        hull_face, hull_point = _first_hits(label_proxy(m), o, (0, 1, 0))
        hit = face >= 0
        assert hit.mean() > 0.95 and (hull_face[hit] >= 0).all(), "the hull blocks every beam that meets the hedge"
        assert (m.face_material[face[hit]] == leaf_id).mean() > 0.25, "beams end on leaves"
        depth = point[hit, 1] - hull_point[hit, 1]
        assert (depth > -1e-6).all()
        p10, p90 = np.percentile(depth, [10, 90])
        assert p90 - p10 > 0.05 and p90 > 0.08, (p10, p90)


def test_leaves_cover_the_outside_of_a_body_not_its_buried_faces_or_its_underside():
    rng = np.random.default_rng(0)
    body = icosphere(1.0, "vegetation", "hedge_body", 1)
    cover = leaf_cover(rng, body, np.zeros(body.n_faces, int), np.zeros((1, 3)), np.ones((1, 3)), 2.0,
                       "vegetation", "hedge_leaves", floor=-0.3, density=400.0)
    t = cover.vertices[cover.faces]
    assert len(np.unique(cover.faces)) == 3 * cover.n_faces, "each leaf its own island"
    assert 0.5 * 400 * 4 * np.pi < cover.n_faces < 400 * 4 * np.pi
    r = np.linalg.norm(t.mean(1), axis=1)
    assert (r > 0.9).all() and (r < 1.12).all(), "leaves sit on the skin"
    assert (t.mean(1)[:, 2] > -0.3 - 0.05).all()
    a, b = leaf_cover(np.random.default_rng(5), body, np.zeros(body.n_faces, int), np.zeros((1, 3)),
                      np.ones((1, 3)), 2.0, "vegetation", "hedge_leaves"), \
        leaf_cover(np.random.default_rng(5), body, np.zeros(body.n_faces, int), np.zeros((1, 3)),
                   np.ones((1, 3)), 2.0, "vegetation", "hedge_leaves")
    assert a.vertices.tobytes() == b.vertices.tobytes()
