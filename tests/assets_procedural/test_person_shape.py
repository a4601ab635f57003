"""People are shaped, not tubes (assets_procedural/person_shape.py, person_head.py): limbs taper and bulge
where bodies do, breadths and heights fall in adult anthropometric ranges, garments have their own
silhouettes, every body part is a closed, outward-facing skin, and a seed gives the same bytes."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from assets_procedural import catalog
from assets_procedural import person as P
from assets_procedural import person_head as head
from assets_procedural import person_shape as shape
from generator.materials import material_table

H = 1.75


def _of(m, *names: str) -> np.ndarray:
    return np.isin(m.face_material, [material_table().id(n) for n in names])


def _seed(garment: str, **want) -> int:
    """The first seed whose figure wears ``garment`` (and the other draws in ``want``)."""
    for s in range(200):
        d = P._draw(np.random.default_rng(s), "standing", None)
        if d["garment"] == garment and all(d[k] == v for k, v in want.items()):
            return s
    raise AssertionError(garment)


def _section(m, faces: np.ndarray, z: float) -> np.ndarray:
    """(x extent, y extent) of the cut of ``faces`` of ``m`` by the plane at height ``z``, metres."""
    tm = trimesh.Trimesh(m.vertices, m.faces[faces], process=False)
    cut = tm.section(plane_origin=[0.0, 0.0, z], plane_normal=[0.0, 0.0, 1.0])
    assert cut is not None, z
    return np.ptp(cut.vertices[:, :2], axis=0)


def test_a_bare_leg_tapers_to_the_knee_bulges_at_the_calf_and_thins_to_the_ankle():
    m = catalog.build("person", np.random.default_rng(_seed("skirt", arms=["hanging", "hanging"])), height=H)
    c = m.vertices[m.faces].mean(1)
    left_leg = _of(m, "skin") & (c[:, 1] > 0.01) & (c[:, 1] < 0.09 * H) & (c[:, 2] < 0.5 * H)    # not the hand
    # knee joint at 0.3 H (the gait's ANKLE_Z + SHIN), the calf's bulge a third down the shin
    thigh, knee, calf, ankle = (_section(m, left_leg, f * H)[0] for f in (0.44, 0.3, 0.22, 0.085))
    assert thigh > 1.25 * knee                                   # thigh wider than the knee
    assert calf > 1.1 * knee and calf > 1.4 * ankle              # a calf, not a cone
    assert 0.13 < thigh < 0.2                                    # a thigh 13-20 cm deep at 1.75 m


def test_an_arm_has_a_shoulder_and_a_flat_wrist():
    rings = shape.chain_rings(np.array([[0, 0, 0.8], [0, 0, 0.625], [0, 0, 0.475]]), shape.ARM, np.array([0, 1.0, 0]))
    width = np.ptp(rings[..., 1], axis=1)                         # across the body
    depth = np.ptp(rings[..., 0], axis=1)                         # front to back
    s = shape.ARM[:, 0]
    deltoid, elbow, wrist = np.argmin(np.abs(s - 0.02)), np.argmin(np.abs(s - 1.0)), np.argmin(np.abs(s - 1.95))
    assert width[deltoid] > 1.5 * width[elbow] > 1.5 * width[wrist] * 0.75
    assert depth[wrist] > 1.3 * width[wrist]                      # a wrist is flat, wide front to back


@pytest.mark.parametrize("sex", ["female", "male"])
def test_breadths_and_heights_fall_in_adult_ranges(sex):
    """Shoulders (bideltoid) 0.23-0.32 of stature (ANSUR II: men 0.28, women 0.26 on average), the pelvis
    0.15-0.24 (the thighs' tops add to the hips), the crotch at 0.44-0.5, the head
    (chin to crown) 1/7 to 1/8.2 of stature (adult anthropometric tables)."""
    for seed in (1, 5, 12, 17):                                    # trousers, both arms hanging
        m = catalog.build("person", np.random.default_rng(seed), height=H, sex=sex)
        body = _of(m, "clothing", "clothing_bottom", "skin")
        shoulders = _section(m, body, 0.79 * H)[1]
        assert 0.23 * H < shoulders < 0.32 * H, shoulders
        tm = trimesh.Trimesh(m.vertices, m.faces, process=False)
        up = tm.ray.intersects_location([[0.0, 0.0, 0.01]], [[0.0, 0.0, 1.0]])[0]
        assert 0.44 * H < up[:, 2].min() < 0.5 * H                    # the crotch, up between the legs
    for girth in (0.88, 1.12):                                     # the builds drawn
        rings, _ = P.torso_sections(girth, 1.0, sex, "trousers")
        hips = max(np.ptp(r[:, 1]) for r in rings if 0.49 < r[0, 2] < 0.52)
        assert 0.15 < hips < 0.24
    ratio = {}
    for who in ("female", "male"):                                 # hips to shoulders, and waist to hips
        rings, _ = P.torso_sections(1.0, 1.0, who, "trousers")
        w = {round(float(r[0, 2]), 3): np.ptp(r[:, 1]) for r in rings}
        ratio[who] = (w[0.5] / w[0.8], w[0.6] / w[0.5])
    assert ratio["female"][0] > ratio["male"][0] and ratio["female"][1] < ratio["male"][1]
    c = np.zeros(3)
    skull = head.head(c, H, "person").vertices
    assert 1 / 8.2 < np.ptp(skull[:, 2]) / H < 1 / 7


def test_garments_have_their_own_silhouettes():
    def low(m, name):
        f = _of(m, name)
        return m.vertices[np.unique(m.faces[f])][:, 2].min() / H

    coat = catalog.build("person", np.random.default_rng(_seed("coat")), height=H)
    assert low(coat, "clothing") < 0.38                           # a coat to mid-thigh
    skirt = catalog.build("person", np.random.default_rng(_seed("skirt")), height=H)
    assert 0.3 < low(skirt, "clothing_bottom") < 0.4               # a skirt to above the knee ...
    flare = _section(skirt, _of(skirt, "clothing_bottom"), 0.37 * H)
    assert flare[1] > _section(skirt, _of(skirt, "clothing_bottom"), 0.5 * H)[1]   # ... flaring from the hips
    shorts = catalog.build("person", np.random.default_rng(_seed("shorts")), height=H)
    assert 0.35 < low(shorts, "clothing_bottom") < 0.42            # shorts end above the knee
    jacket = catalog.build("person", np.random.default_rng(_seed("trousers", jacket=True)), height=H)
    shirt = catalog.build("person", np.random.default_rng(_seed("trousers", jacket=False)), height=H)
    top = "clothing"
    torso = lambda m: _of(m, top) & (np.abs(m.vertices[m.faces].mean(1)[:, 1]) < 0.06 * H)  # noqa: E731
    assert m_low(jacket, torso(jacket)) < 0.5 < m_low(shirt, torso(shirt))                 # a jacket covers the hips
    trousers = _of(shirt, "clothing_bottom") & (shirt.vertices[shirt.faces].mean(1)[:, 2] < 0.12 * H)
    assert trousers.any()                                         # trousers reach down to the shoes


def m_low(m, faces: np.ndarray) -> float:
    return float(m.vertices[np.unique(m.faces[faces])][:, 2].min() / H)


def _closed(mesh) -> trimesh.Trimesh:
    tm = trimesh.Trimesh(mesh.vertices, mesh.faces, process=True)
    assert tm.is_watertight and tm.is_winding_consistent and tm.volume > 0
    return tm


@pytest.mark.parametrize("garment", ["trousers", "shorts", "skirt", "coat"])
def test_body_parts_are_closed_skins_facing_outward(garment):
    legs, mats = P._legs_table(garment)
    joints = np.array([[0, 0.05, 0.53], [0.02, 0.05, 0.3], [0.0, 0.05, 0.05]])
    leg = shape.limb(joints, legs, np.array([0, 1.0, 0]), "person", mats)
    assert len(mats) == len(legs) - 1
    _closed(leg)
    rings, bands = P.torso_sections(1.0, 1.0, "female", garment, jacket=garment == "trousers")
    _closed(shape.skin(rings, "person", bands, rings[0].mean(0) - [0, 0, 0.01], rings[-1].mean(0) + [0, 0, 0.01]))
    _closed(head.head(np.zeros(3), 1.0, "person"))
    _closed(shape.shoe(np.zeros(3), 0.2, "person", "shoes"))
    _closed(shape.hand(np.zeros(3), np.array([0, 0, 0.15]), 1.0, "person", "skin"))
    m = catalog.build("person", np.random.default_rng(_seed(garment)), height=H, pose="walking")
    tri = m.vertices[m.faces]
    assert (np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1) > 1e-9).all()


@pytest.mark.parametrize("pose", ["standing", "walking"])
def test_same_seed_same_bytes(pose):
    a, b = (catalog.build("person", np.random.default_rng(4), height=1.6, pose=pose, age=9.0) for _ in range(2))
    c = catalog.build("person", np.random.default_rng(5), height=1.6, pose=pose, age=9.0)
    for name in ("vertices", "faces", "face_class", "face_material"):
        assert getattr(a, name).tobytes() == getattr(b, name).tobytes()
    assert set(a.anchors) == set(b.anchors) and all(np.array_equal(a.anchors[k], b.anchors[k]) for k in a.anchors)
    assert a.vertices.shape != c.vertices.shape or not np.array_equal(a.vertices, c.vertices)
