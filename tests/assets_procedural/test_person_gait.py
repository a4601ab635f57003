"""A walking person's gait cycle (assets_procedural/person.py, person_gait.py): phase meshes of one
topology, feet that alternate and stay planted, knees and elbows that bend, arms opposite the legs."""

from __future__ import annotations

import numpy as np
import pytest

from assets_procedural import catalog
from assets_procedural import person_gait as gait
from assets_procedural.person import GAIT_PHASES
from generator.materials import material_table

H = 1.75


def _phases(seed: int, height: float = H, **kw) -> tuple[object, list[np.ndarray], float]:
    m = catalog.build("person", np.random.default_rng(seed), height=height, pose="walking", **kw)
    ends = m.anchors["gait/stride"]
    return m, [m.anchors[f"gait/{k:02d}"] for k in range(GAIT_PHASES)], float(np.linalg.norm(ends[1] - ends[0]))


def _feet(m, v: np.ndarray) -> dict[float, np.ndarray]:
    """{side: (k, 3) vertices of that foot's shoe} (shoe faces low on the figure, by the sign of y)."""
    shoes = m.face_material == material_table().id("shoes")
    low = v[m.faces].mean(1)[:, 2] < 0.12 * H
    out = {}
    for side in (1.0, -1.0):
        f = shoes & low & (np.sign(v[m.faces].mean(1)[:, 1]) == side)
        out[side] = v[np.unique(m.faces[f])]
    return out


@pytest.mark.parametrize("seed", range(6))
def test_phases_share_faces_stand_on_the_ground_and_stay_in_budget(seed):
    m, phases, stride = _phases(seed)
    assert 1200 <= m.n_faces <= 2400                                 # shaped, not tubes; ~4 x the old 540
    np.testing.assert_array_equal(m.vertices, phases[0])               # the rest mesh is phase 0
    for v in phases:
        assert v.shape == m.vertices.shape
        assert v[:, 2].min() == pytest.approx(0.0, abs=1e-9)          # a foot always on the ground
        assert 0.95 * H < v[:, 2].max() <= H + 1e-9
    assert 0.65 * H < stride < 0.85 * H


@pytest.mark.parametrize("seed", range(4))
def test_feet_alternate_and_the_planted_foot_does_not_slide(seed):
    m, phases, stride = _phases(seed)
    ahead = [np.mean(_feet(m, v)[1.0][:, 0]) - np.mean(_feet(m, v)[-1.0][:, 0]) for v in phases]
    half = GAIT_PHASES // 2
    assert ahead[0] * ahead[half] < 0 and min(abs(ahead[0]), abs(ahead[half])) > 0.3 * H * 0.6
    # walking forward stride / n per phase, a foot flat on the ground keeps its place on the ground
    for side in (1.0, -1.0):
        world_x, flat = [], []
        for k, v in enumerate(phases):
            f = _feet(m, v)[side]
            world_x.append(f[:, 0].min() + k * stride / GAIT_PHASES)
            flat.append((f[:, 2] < 0.005).sum() >= 4)              # the sole down (within 5 mm)
        planted = np.flatnonzero(flat)
        assert len(planted) >= GAIT_PHASES // 4
        assert np.ptp(np.array(world_x)[planted]) < 0.03


def test_knees_bend_in_the_swing_and_stride_angles_stay_natural():
    a = np.radians(22.5)
    flex, hip, leg_angle = [], [], []
    for phi in np.linspace(0, 1, 32, endpoint=False):
        legs, _ = gait.legs(phi, a, 0.05)
        leg = legs[0]
        thigh, shin = leg.knee - leg.hip, leg.ankle - leg.knee
        flex.append(np.degrees(np.arccos(thigh @ shin / np.linalg.norm(thigh) / np.linalg.norm(shin))))
        hip.append(np.degrees(np.arctan2(thigh[0], -thigh[2])))
        reach = leg.ankle - leg.hip
        leg_angle.append(np.degrees(np.arctan2(reach[0], -reach[2])))
    assert max(flex) > 40 and min(flex) < 12                 # bent in the swing, nearly straight in stance
    assert max(np.abs(leg_angle)) < 25.5                     # no lunge: the legs spread +-22.5 degrees
    assert max(hip) < 36 and min(hip) > -25                  # thigh flexion peaks late in the swing
    legs, _ = gait.legs(None, a, 0.05)
    assert all(abs(leg.knee[0]) < 0.01 for leg in legs)      # standing: straight legs


def test_arms_swing_opposite_the_legs():
    a = np.radians(22.0)
    for phi in (0.0, 0.2, 0.6):
        legs, _ = gait.legs(phi, a, 0.05)
        for side, leg in zip((1.0, -1.0), legs, strict=True):
            arm = gait.arm_angle(phi, a, side)
            assert arm * leg.ankle[0] <= 0
    assert abs(gait.arm_angle(0.0, a, 1.0)) > np.radians(12)


def test_standing_people_stand():
    m = catalog.build("person", np.random.default_rng(3), height=H)
    assert not any(k.startswith("gait/") for k in m.anchors)
    assert m.vertices[:, 2].max() == pytest.approx(H)


def test_hair_and_headwear_vary():
    hair, hats = set(), set()
    for seed in range(40):
        m = catalog.build("person", np.random.default_rng(seed), height=H)
        high = m.vertices[m.faces].mean(1)[:, 2] > 0.8 * H
        f = (m.face_material == material_table().id("hair")) & high
        v = m.vertices[np.unique(m.faces[f])]
        hair.add((int(f.sum()), round(float(v[:, 2].min()) / H, 2), round(float(v[:, 0].min()) / H, 2)))
        hats.add(int(((m.face_material == material_table().id("shoes")) & high).sum()))
    assert len(hair) >= 4 and len(hats) >= 2                 # several hair cuts; caps among the heads
