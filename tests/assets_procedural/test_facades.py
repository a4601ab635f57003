"""Issue 14 item 4: facades that vary from building to building (window rhythm, shop fronts,
balconies, curtain walls) and rest on the ground with every face still labelled ``building``.

Tree species are tested with the other tree tests in ``test_assets.py``. No Blender.
"""

from __future__ import annotations

import numpy as np
import pytest
from trimesh.ray.ray_pyembree import RayMeshIntersector

from generator.geometry import Mesh, face_normals
from generator.labels import class_table
from generator.materials import material_table
from kits.building_kit import FH, L_SHAPE, RECT, build, mat


def facing(m: Mesh, d) -> np.ndarray:
    return face_normals(m) @ np.asarray(d, float) > 0.99


def front_layout(m: Mesh) -> tuple[int, float, float]:
    """(panes on the front above the ground floor, their mean width, their mean height), metres."""
    sel = mat(m, "window_glass") & facing(m, (0, -1, 0))
    tri = m.vertices[m.faces[sel]]
    tri = tri[tri[:, :, 2].min(1) > FH]
    quads = tri.reshape(-1, 2, 3, 3).reshape(-1, 6, 3)
    w = np.ptp(quads[:, :, 0], axis=1)
    h = np.ptp(quads[:, :, 2], axis=1)
    return len(quads), float(w.mean()), float(h.mean())


def test_window_layouts_vary_between_buildings():
    """Same footprint and height, different seeds: the window count, size and the details differ."""
    layouts, details = set(), []
    for seed in range(16):
        m = build(seed, height=5 * FH, facade="plaster")
        n, w, h = front_layout(m)
        layouts.add((n, round(w, 1), round(h, 1)))
        details.append((mat(m, "shop_glass").any(), mat(m, "awning").any(),
                        (m.vertices[:, 1] < RECT[:, 1].min() - 0.5).any()))   # something proud of the front
    assert len(layouts) >= 10, layouts
    widths = sorted({w for _, w, _ in layouts})
    assert widths[-1] - widths[0] > 0.4, "window widths should range over several tens of centimetres"
    shops, awnings, proud = (np.array(c) for c in zip(*details, strict=False))
    assert 0 < shops.sum() < len(shops) and 0 < awnings.sum() <= shops.sum()
    assert 0 < proud.sum() < len(proud), "balconies or awnings on some buildings, flat fronts on others"


def test_some_side_walls_have_blank_bays_but_every_wall_keeps_windows():
    counts = []
    for seed in range(16):
        m = build(seed, height=4 * FH, facade="brick")
        counts.append((facing(m, (1, 0, 0)) & mat(m, "window_glass")).sum())
        for d in ((1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0)):
            assert (facing(m, d) & mat(m, "window_glass", "shop_glass")).any()
    assert len(set(counts)) >= 3, counts


def test_shop_fronts_sit_on_the_front_ground_floor_with_headroom_under_awnings():
    shops = 0
    for seed in range(12):
        m = build(seed, height=5 * FH, facade="concrete")
        shop = mat(m, "shop_glass")
        if not shop.any():
            continue
        shops += 1
        y_front = RECT[:, 1].min()
        sv = m.vertices[m.faces[shop]]
        assert facing(m, (0, -1, 0))[shop].all() and sv[:, :, 2].max() < FH and sv[:, :, 2].min() > 0.3
        sign = m.vertices[m.faces[mat(m, "shop_sign")]]
        assert sign.size and sign[:, :, 2].min() > sv[:, :, 2].max()
        boards = sign[sign[:, :, 1].min(1) > y_front - 0.15]       # blade signs reach further, 0.65 m
        assert boards.size and sign[:, :, 1].min() >= y_front - 0.65 - 1e-9
        aw = m.vertices[m.faces[mat(m, "awning")]]
        if aw.size:
            assert aw[:, :, 2].min() > 1.9, "people walk under an awning"
            assert y_front - 1.2 < aw[:, :, 1].min() and aw[:, :, 1].max() <= y_front
    assert 3 <= shops < 12


def test_balconies_stand_in_front_of_upper_floor_doors_only():
    found = 0
    for seed in range(20):
        m = build(seed, height=5 * FH, facade="plaster")
        slab = m.vertices[m.faces[mat(m, "facade_concrete")]]
        out = slab[(slab[:, :, 1] < RECT[:, 1].min() - 0.5).all(1) | (slab[:, :, 1] > RECT[:, 1].max() + 0.5).all(1)]
        if not len(out):
            continue
        found += 1
        assert out[:, :, 2].min() > FH - 0.3, "no balcony on the ground floor"
        assert np.abs(out[:, :, 1]).max() < RECT[:, 1].max() + 1.4
        assert (np.abs(out[:, :, 0]) < RECT[:, 0].max()).all(), "balconies stay within the facade"
    assert 3 <= found < 20


def test_railings_of_the_rail_style_let_beams_through():
    """A LiDAR beam toward a balcony with a metal railing mostly passes the railing (it meets the
    wall or the glass behind it); one with a solid parapet stops it."""
    from assets_procedural.facade_layout import draw_style
    seen = set()
    for seed in range(40):
        m = build(seed, height=5 * FH, facade="plaster")
        st = draw_style(np.random.default_rng(seed), 5 * FH, FH, "plaster")
        rail = mat(m, "balcony_metal")
        if st.balconies == "none" or st.railing in seen:
            continue
        seen.add(st.railing)
        if st.railing == "rails":      # rays at the lowest balcony nearest x = 0, across its railing
            tri = m.vertices[m.faces[rail]]
            c = tri.mean(1)
            first = c[np.argmin(c[:, 2] + 0.01 * np.abs(c[:, 0]))]
            one = (np.abs(c[:, 0] - first[0]) < 1.6) & (np.abs(c[:, 2] - first[2]) < 1.1) & (c[:, 1] < 0)
            lo, hi = tri[one].reshape(-1, 3).min(0), tri[one].reshape(-1, 3).max(0)
            rail = rail & np.isin(np.arange(m.n_faces), np.flatnonzero(rail)[one])
            xs, zs = np.meshgrid(np.linspace(lo[0], hi[0], 60), np.linspace(lo[2], hi[2], 41))
            o = np.c_[xs.ravel(), np.full(xs.size, -20.0), zs.ravel()]
            only_rails = Mesh(m.vertices, m.faces[rail], m.face_class[rail], m.face_material[rail])
            hit = RayMeshIntersector(only_rails.to_trimesh()).intersects_any(o, np.tile([0, 1.0, 0], (len(o), 1)))
            assert 0.05 < hit.mean() < 0.5, hit.mean()
        else:
            assert not rail.any()
        if len(seen) == 2:
            return
    pytest.fail(f"only railing styles {seen} drawn in 40 seeds")


@pytest.mark.parametrize("height", [2 * FH, 4 * FH, 6 * FH, 9 * FH])
def test_the_top_storey_has_windows_under_a_flat_roof(height):
    for seed in range(6):
        m = build(seed, height=height, facade="brick")
        panes = m.anchors["windows"]
        assert panes[:, 2].max() > height - FH - 0.2, "a blind storey under the parapet"
        roof = m.vertices[m.faces[mat(m, "roof")]]
        assert roof[:, :, 2].min() > panes[:, 2].max(), "the roof slab cuts through the top windows"


def test_glass_curtain_walls():
    """Most of a curtain wall is glass: the front plane (wall, frames, panes 12-18 cm behind it)."""
    m = build(3, footprint=L_SHAPE, height=8 * FH, facade="glass")
    tri = m.vertices[m.faces]
    area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1) / 2
    front = facing(m, (0, -1, 0)) & (tri[:, :, 1] < L_SHAPE[:, 1].min() + 0.25).all(1)
    glazed = area[front & mat(m, "window_glass", "shop_glass")].sum() / area[front].sum()
    p = build(3, footprint=L_SHAPE, height=8 * FH, facade="plaster")
    tri = p.vertices[p.faces]
    area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1) / 2
    front = facing(p, (0, -1, 0)) & (tri[:, :, 1] < L_SHAPE[:, 1].min() + 0.25).all(1)
    assert glazed > 0.45 and glazed > 2 * area[front & mat(p, "window_glass", "shop_glass")].sum() / area[front].sum()
    assert mat(m, "facade_glass").any() and not mat(m, "balcony_metal").any()
    with pytest.raises(ValueError, match="facade"):
        build(0, height=9.0, facade="marble")


@pytest.mark.parametrize("facade", ["plaster", "brick", "concrete", "glass"])
def test_buildings_rest_on_the_ground_and_stay_building(facade):
    for seed in range(6):
        for fp in (RECT, L_SHAPE):
            m = build(seed, footprint=fp, height=float(3 + 3 * seed), facade=facade)
            assert m.vertices[:, 2].min() == pytest.approx(0.0, abs=1e-9)
            assert (m.face_class == class_table().id("building")).all()
            assert m.n_faces < 12000


def test_the_default_town_mixes_facades_colours_and_tree_species(default_scene):
    """The town is not one white block repeated: several wall materials, rendered buildings in
    several colours, a few curtain walls, balconies and shop fronts, and trees of several species."""
    names = [r.name for r in material_table().rows]
    buildings = [o for o in default_scene.objects if o.kind == "building"]
    facades = {o.attrs["facade"] for o in buildings}
    assert facades == {"plaster", "brick", "concrete", "glass"}
    plaster = np.array([o.attrs["facade_color"] for o in buildings if o.attrs["facade"] == "plaster"])
    hues = {int(np.argmax(c)) * 10 + int(np.argmin(c)) for c in plaster}          # which channel leads and lags
    assert len(hues) >= 3 and np.ptp(plaster[:, 2]) > 0.25
    mats = [{names[i] for i in np.unique(default_scene.prototypes[o.prototype].face_material)} for o in buildings]
    assert sum("balcony_metal" in m or "awning" in m for m in mats) >= 10
    assert 5 <= sum("facade_glass" in m for m in mats) <= len(buildings) // 4
    trees = [{names[i] for i in np.unique(default_scene.prototypes[o.prototype].face_material)}
             for o in default_scene.objects if o.kind == "tree"]
    assert any("bark_birch" in m for m in trees) and any("needles" in m for m in trees)
    assert sum("leaves" in m and bool(m & {"bark", "bark_plane"}) for m in trees) > len(trees) // 3
