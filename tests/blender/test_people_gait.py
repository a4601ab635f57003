"""A walker in the camera: two images of one walker show the gait phase meshes of their instants
(the ones the LiDAR and the boxes use), so its silhouette changes with its stride, not only its place.

The test town at the ``test`` preset (labels only), a walker crossing 4.5 m in front of the camera of
frame 2 (held still), seen from the side.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from generator.world.actors import World
from generator.world.rig import Rig
from kits.actor_world import FRAME
from kits.walker_world import straight, walker

RES = (192, 108)


def project(k: np.ndarray, T_world_camera: np.ndarray, points: np.ndarray) -> np.ndarray:
    cam = (points - T_world_camera[:3, 3]) @ T_world_camera[:3, :3]
    return (cam @ k.T)[:, :2] / cam[:, 2:3]


@pytest.fixture(scope="module")
def seen(tmp_path_factory, test_spec, test_scene):
    from generator.blender.renderer import Renderer
    from generator.spec.render import load_render_config
    from generator.weather import Lighting

    rig = Rig.from_spec(test_spec, test_scene)
    frame = rig.frame(FRAME)
    v = 1.4
    protos: dict = {}
    stride = walker(protos, straight((0.0, 0.0, 0.0), (v, 0.0))).gait.stride_m
    cycle = stride / v
    t_wide = np.ceil(frame.t / cycle) * cycle                 # walked whole strides: phase 0, both feet down
    t_narrow = t_wide + cycle / 4                             # a quarter cycle on: feet passing each other
    T = rig.T_world_ego((t_wide + t_narrow) / 2)[0]
    across = T[:3, 1]                                         # walking to the ego's left, across the view
    middle = T[:3, 3] + 4.5 * T[:3, 0]                        # 4.5 m ahead on the road between the two images
    middle[2] = 0.0
    t_mid = (t_wide + t_narrow) / 2
    protos = {}
    a = walker(protos, straight(middle - v * t_mid * across, tuple(v * across[:2]), seconds=t_narrow + 2.0),
               instance_id=4000)
    world = World(test_scene, [a], protos, {}, rig.trajectory, t_narrow + 2.0)
    cfg = dataclasses.replace(load_render_config("test"), resolution=RES, samples=1)
    r = Renderer(test_scene, test_spec, cfg, tmp_path_factory.mktemp("people"), world)
    r.set_conditions(Lighting("day", sun_elevation_deg=45.0, sun_azimuth_deg=200.0))
    out = {"k": r.k, "actor": a, "protos": protos}
    Tc = rig.T_world_ego(t_mid)[0] @ frame.T_ego_camera      # one camera pose: only the walker differs
    for name, t in (("wide", t_wide), ("narrow", t_narrow)):
        r.set_time(t)
        r.place_camera(Tc)
        out[name] = {"t": t, "T": Tc, "mask": r.render_labels().instance == a.instance_id}
    return out


def _projected_width(seen, name) -> float:
    a, rec = seen["actor"], seen[name]
    pose = a.track.pose(rec["t"])[0]
    verts = seen["protos"][a.prototype_at(rec["t"])].vertices @ pose[:3, :3].T + pose[:3, 3]
    uv = project(seen["k"], rec["T"], verts)
    return float(np.ptp(uv[:, 0]))


@pytest.mark.blender
def test_two_frames_of_a_walker_show_different_limb_poses(seen):
    a = seen["actor"]
    assert a.prototype_at(seen["wide"]["t"]) != a.prototype_at(seen["narrow"]["t"])
    widths = {}
    for name in ("wide", "narrow"):
        cols = np.nonzero(seen[name]["mask"])[1]
        assert len(cols) > 60, name
        widths[name] = cols.max() + 1 - cols.min()
        # the mask spans what the phase mesh of that instant projects to (within a pixel each side)
        assert widths[name] == pytest.approx(_projected_width(seen, name), abs=2.0), name
    assert widths["wide"] >= widths["narrow"] + 5            # a stride apart, then feet together
