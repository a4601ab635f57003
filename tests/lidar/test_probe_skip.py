"""Which probes need not be cast (:func:`generator.lidar.probe_skip.probes_on_centre`)."""

from __future__ import annotations

import numpy as np
import pytest

from generator.geometry import box
from generator.labels import class_table
from generator.lidar import physical_chunk
from generator.lidar.physical_chunk import SPLIT_STEP_M, SPLIT_STEP_REL
from generator.lidar.returns import ReturnModel, optics_from_materials
from generator.lidar.scan import Scanner
from generator.lidar.sensors import load_preset
from generator.world import rig
from kits.scene_kit import scene_of

POSE = rig.mount((0, 0, 1.73), (0, 0, 0))


@pytest.fixture(scope="module")
def hdl64e():
    return load_preset("hdl64e")


def probes_of(scene, sensor, monkeypatch, pose=POSE) -> tuple[dict, Scanner]:
    """Scan ``scene`` once with the physical model, recording every probe and whether it was left uncast."""
    seen = []
    real = physical_chunk.probes_on_centre

    def spy(pb, pw, edge, side, probes, o_w, d_w, p_o, p_d, dist, face, *rest):
        n = real(pb, pw, edge, side, probes, o_w, d_w, p_o, p_d, dist, face, *rest)
        out = rest[-1]
        seen.append({"p_o": p_o.copy(), "p_d": p_d.copy(), "uncast": out.copy(), "dist": dist[pb].copy(),
                     "face": face[pb].copy(), "xyz": o_w[pb] + dist[pb, None] * d_w[pb]})
        assert n == out.sum()
        return n

    monkeypatch.setattr(physical_chunk, "probes_on_centre", spy)
    sc = Scanner(scene, sensor, threads=1, returns=ReturnModel.build(sensor, optics_from_materials(), 0))
    sc.scan(pose)
    sc.close()
    return {k: np.concatenate([s[k] for s in seen]) for k in seen[0]}, sc


def test_a_probe_left_uncast_would_have_agreed_with_its_centre(hdl64e, test_scene, monkeypatch):
    """On the test town, every probe is cast afterwards anyway: those the test left uncast see their
    centre's surface (same class and instance, within the split step), all but a few that meet a surface
    neither the centre nor the neighbour touches; and the test does leave a good share uncast."""
    p, sc = probes_of(test_scene, hdl64e, monkeypatch, rig.mount((2.0, 1.0, 1.73), (0, 0, 0.3)))
    dist, face = sc.caster.intersect_local(p["p_o"], p["p_d"], hdl64e.max_range_m)
    label = sc.face_lookup.label
    agree = (label[face] == label[p["face"]]) & (np.abs(dist - p["dist"]) <= SPLIT_STEP_M + SPLIT_STEP_REL * p["dist"])
    un = p["uncast"]
    assert len(un) > 5000 and 0.2 < un.mean() < 0.7
    assert agree[un].mean() >= 0.995
    # mostly the very triangle the centre hit; on foliage (leaf skins of hedges, bushes and crowns: many small
    # triangles of one class and instance) a neighbouring leaf
    leafy = class_table().hull_classes[label[p["face"]] >> 16]
    assert np.mean(face[un & ~leafy] == p["face"][un & ~leafy]) >= 0.99
    assert agree[~un].mean() < 0.95  # the cast ones include every probe that splits its beam


def two_walls(back_x: float):
    """A building wall facing the sensor at x = 10 m over 0 < y < 10 and a fence over -10 < y < 0 whose face
    is at ``back_x`` (10: one plane, a class boundary at y = 0; more: a step behind the building's edge)."""
    front = box((0.2, 10.0, 6.0), "building", "facade_plaster", center=(10.1, 5.0, 0.0))
    back = box((0.2, 10.0, 6.0), "fence", "facade_plaster", center=(back_x + 0.1, -5.0, 0.0))
    return scene_of([("front", front, 0), ("back", back, 0)])


def test_a_class_boundary_on_one_plane_is_always_probed_a_step_behind_an_edge_need_not_be(hdl64e, monkeypatch):
    """Building next to fence on one plane: paint or a seam could lie on the boundary, so every probe
    towards it is cast; with the fence 0.5 m behind, a probe from the building that lands on the building
    cannot be hidden by the fence behind it and is left uncast."""
    def near_boundary(back_x):
        p, sc = probes_of(two_walls(back_x), hdl64e, monkeypatch)
        y = p["xyz"][:, 1] + sc.caster.center[1]
        on_front = (np.abs(y) < 1.0) & (p["xyz"][:, 0] + sc.caster.center[0] < 10.05) & (p["face"] >= 0)
        return p["uncast"][on_front]

    flat, step = near_boundary(10.0), near_boundary(10.5)
    assert len(flat) > 20 and not flat.any()
    assert len(step) > 20 and step.mean() > 0.5
