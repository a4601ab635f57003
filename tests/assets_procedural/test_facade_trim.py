"""Issue 29 item 5: facade trim as geometry -- window surrounds proud of the wall over wider sills,
rainwater pipes at the corners, parapet copings, sign boards per shop and blade signs. Each stays in a
thin band round the building's footprint, is class ``building``, costs a few triangles, and comes from
its own streams: the window rhythm of a seed is the one it was before the trim existed. No Blender."""

from __future__ import annotations

import hashlib

import numpy as np
import pytest
from trimesh.ray.ray_pyembree import RayMeshIntersector

from assets_procedural.building_roof import COPING_H, COPING_OUT
from assets_procedural.facade_trim import PIPE_OFF, PIPE_R, PIPE_SIDES, TRIM_T
from generator.geometry import face_normals
from generator.labels import class_table
from kits.building_kit import FH, L_SHAPE, RECT, build, mat


def outside(points: np.ndarray, rect: np.ndarray = RECT) -> np.ndarray:
    """(n,) metres a point lies outside the axis-aligned rectangle ``rect`` (0 inside)."""
    lo, hi = rect.min(0), rect.max(0)
    d = np.maximum(np.maximum(lo - points[:, :2], points[:, :2] - hi), 0.0)
    return np.linalg.norm(d, axis=1)


def test_the_window_rhythm_of_a_seed_is_unchanged_by_the_trim():
    """Window panes and doors of these buildings where they were before the trim came (digest of main
    1715fcf): the trim draws from sub-streams of its own."""
    h = hashlib.sha256()
    for seed in range(8):
        for fp, facade, roof, height in ((RECT, "plaster", "flat", 16.0), (L_SHAPE, "brick", "flat", 9.6),
                                         (RECT, "concrete", "gable", 6.4)):
            m = build(seed, footprint=fp, height=height, facade=facade, roof=roof)
            h.update(np.round(m.anchors["windows"], 6).tobytes())
            h.update(np.round(m.anchors["door"], 6).tobytes())
    assert h.hexdigest()[:16] == "cb4bdc0bd0ea4dd8"


def test_window_surrounds_stand_proud_of_the_wall_on_some_buildings():
    with_trim, per_window = 0, []
    for seed in range(12):
        m = build(seed, height=4 * FH, facade="plaster")
        trim = mat(m, "facade_trim") & (m.vertices[m.faces][:, :, 2].min(1) < 4 * FH - 0.2)   # not the coping
        if not trim.any():
            continue
        with_trim += 1
        tri = m.vertices[m.faces[trim]].reshape(-1, 3)
        assert outside(tri).max() <= 0.07 + 1e-9, "bars 4 cm proud, sills 7 cm"
        assert np.isclose(outside(tri), TRIM_T).any(), "bars stand TRIM_T in front of the wall"
        windows = len(m.anchors["windows"])
        per_window.append(trim.sum() / windows)
    assert 3 <= with_trim < 12
    assert max(per_window) <= 12 + 10 + 1e-9, "6 quads per surround, a 10-triangle sill"


def test_drainpipes_run_from_the_ground_up_the_corners_of_front_and_back():
    found = 0
    for seed in range(12):
        for roof, height in (("flat", 5 * FH), ("gable", 2 * FH)):
            m = build(seed, height=height, facade="brick", roof=roof)
            pipe = mat(m, "drainpipe")
            if not pipe.any():
                continue
            found += 1
            assert pipe.sum() % (2 * PIPE_SIDES) == 0
            v = m.vertices[m.faces[pipe]].reshape(-1, 3)
            assert v[:, 2].min() == pytest.approx(0.0) and v[:, 2].max() == pytest.approx(height - 0.1)
            assert outside(v).max() <= PIPE_OFF + 2 * PIPE_R + 1e-6
            assert (outside(v) >= PIPE_OFF - 1e-6).all(), "a gap between pipe and wall"
            assert (np.abs(np.abs(v[:, 0]) - 8.0) < 0.2).all(), "at the ends of the front and back walls"
            assert (np.abs(np.abs(v[:, 1]) - 5.0) < 0.2).all(), "on the front and back walls only"
    assert found >= 8
    assert not mat(build(0, height=8 * FH, facade="glass"), "drainpipe").any(), "curtain walls drain inside"


def test_flat_roofs_have_a_coping_lip_over_the_walls():
    for fp in (RECT, L_SHAPE):
        m = build(1, footprint=fp, height=4 * FH, facade="brick")
        lip = mat(m, "facade_trim") & (m.vertices[m.faces][:, :, 2].min(1) >= 4 * FH - COPING_H - 1e-9)
        v = m.vertices[m.faces[lip]].reshape(-1, 3)
        assert v[:, 2].max() == pytest.approx(4 * FH)
        lo, hi = fp.min(0), fp.max(0)
        assert v[:, :2].min(0) == pytest.approx(lo - COPING_OUT) and v[:, :2].max(0) == pytest.approx(hi + COPING_OUT)
        down = face_normals(m)[lip][:, 2] < -0.99
        assert down.any(), "the lip's underside closes it"


def test_every_shop_gets_its_own_sign_board_and_blade_signs_clear_heads():
    boards, blades = 0, 0
    for seed in range(30):
        m = build(seed, height=5 * FH, facade="concrete")
        sign = mat(m, "shop_sign")
        if not sign.any():
            continue
        shops = len(m.faces[mat(m, "shop_glass")]) // 2
        tri = m.vertices[m.faces[sign]]
        n = face_normals(m)[sign]
        front = (n[:, 1] < -0.99) & (tri[:, :, 1].max(1) < RECT[:, 1].min() - 0.05)
        board_faces = front & (tri[:, :, 1].min(1) > RECT[:, 1].min() - 0.11)
        assert 1 <= board_faces.sum() // 2 <= shops
        boards += board_faces.sum() // 2
        side = np.abs(n[:, 0]) > 0.99
        if (side & (tri[:, :, 1].min(1) < RECT[:, 1].min() - 0.3)).any():
            blades += 1
            assert tri[side][:, :, 2].min() > 2.5, "pedestrians walk under blade signs"
        assert (m.face_class == class_table().id("building")).all()
    assert boards >= 10 and blades >= 2


@pytest.mark.parametrize("facade", ["plaster", "brick", "concrete"])
def test_trim_costs_few_triangles(facade, monkeypatch):
    """Against the same building without surrounds and pipes: at most 12 triangles per window surround
    and 16 per pipe (four at most); the building stays under 10 000."""
    from assets_procedural import building as building_module
    from assets_procedural.facade_trim import Trim

    def direct(seed):      # not through catalog.build: it caches by generator state and parameters
        return building_module.building(np.random.default_rng(seed), RECT, 5 * FH, facade=facade)

    plain = {}
    with monkeypatch.context() as mp:
        mp.setattr(building_module, "draw_trim", lambda g, facade: Trim(0.0, (False, False), (False, False)))
        for seed in range(6):
            plain[seed] = direct(seed).n_faces
    added = []
    for seed in range(6):
        m = direct(seed)
        added.append(m.n_faces - plain[seed])
        assert 0 <= added[-1] <= 12 * len(m.anchors["windows"]) + 4 * 2 * PIPE_SIDES and m.n_faces < 10000
    assert sum(added) > 0


def test_nothing_lies_within_2_cm_of_trim_pipes_and_signs():
    """No surface lies within 2 cm in front of or behind a surround bar, sill, coping, pipe or sign
    board face along its normal (no z-fighting in any view)."""
    for seed in (0, 2, 4):
        m = build(seed, height=4 * FH, facade="plaster")
        faces = np.flatnonzero(mat(m, "facade_trim", "drainpipe", "shop_sign"))
        tri = m.vertices[m.faces[faces]]
        points = np.einsum("k,mkj->mj", [0.6, 0.2, 0.2], tri)
        normals = face_normals(m)[faces]
        rays = RayMeshIntersector(m.to_trimesh())
        origins = points + 0.001 * normals
        loc, idx, _ = rays.intersects_location(origins, normals, multiple_hits=True)
        ahead = np.linalg.norm(loc - origins[idx], axis=1)
        assert (ahead > 0.019).all(), f"a surface within 2 cm in front of face {faces[idx[np.argmin(ahead)]]}"
        loc, idx, _ = rays.intersects_location(origins, -normals, multiple_hits=True)
        dist = np.linalg.norm(loc - origins[idx], axis=1)
        for r in range(len(faces)):
            d = np.sort(dist[idx == r])
            assert len(d) and d[0] == pytest.approx(0.001, abs=2e-4)
            assert len(d) == 1 or d[1] - d[0] >= 0.0195 or d[1] - d[0] < 1e-4, f"surface within 2 cm of {faces[r]}"
