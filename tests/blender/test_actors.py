"""Moving actors in the camera: where the timeline says at the image time, exact labels under
motion blur, and the image metadata's motion record.

The Blender tests render the test town with a few hand-built car actors on straight tracks in
front of the camera of frame 2 (96x54 pixels, 8 samples).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from generator.imaging.paths import image_path
from generator.world.actors import frozen_world
from generator.world.rig import Rig
from kits.actor_world import CARS, FRAME, LATER, RES, car_world


def project(k: np.ndarray, T_world_camera: np.ndarray, points: np.ndarray) -> np.ndarray:
    """(n, 2) pixel coordinates of world points (in front of the camera)."""
    cam = (points - T_world_camera[:3, 3]) @ T_world_camera[:3, :3]
    return (cam @ k.T)[:, :2] / cam[:, 2:3]


# -- without Blender ---------------------------------------------------------------------------


def test_motion_blur_switch_in_the_presets():
    from generator.spec.render import load_render_config

    test, preview, paper = (load_render_config(n) for n in ("test", "preview", "paper"))
    assert not test.motion_blur.enabled and "motion_blur" not in test.to_dict()
    for cfg in (preview, paper):
        assert cfg.motion_blur.enabled and 0.001 <= cfg.motion_blur.shutter_s <= 1 / 60
        assert cfg.to_dict()["motion_blur"] == {"enabled": True, "shutter_s": cfg.motion_blur.shutter_s}


def test_off_keeps_the_config_hash_of_a_config_without_the_switch(tmp_path, root):
    from generator.spec.render import load_render_config

    text = (root / "render_configs" / "test.yaml").read_text()
    (tmp_path / "old.yaml").write_text("\n".join(ln for ln in text.splitlines() if not ln.startswith("motion_blur")))
    (tmp_path / "on.yaml").write_text(text.replace("motion_blur: {enabled: false}", "motion_blur: {enabled: true}"))
    old, on = load_render_config(tmp_path / "old.yaml"), load_render_config(tmp_path / "on.yaml")
    assert old.config_hash == load_render_config("test").config_hash
    assert on.motion_blur.enabled and on.motion_blur.shutter_s == 0.01 and on.config_hash != old.config_hash


def test_bad_shutter_is_one_line_naming_the_field(tmp_path, root):
    from generator.errors import SpecError
    from generator.spec.render import load_render_config

    text = (root / "render_configs" / "test.yaml").read_text()
    (tmp_path / "bad.yaml").write_text(text.replace("motion_blur: {enabled: false}", "motion_blur: {shutter_s: 2}"))
    with pytest.raises(SpecError, match="motion_blur.shutter_s"):
        load_render_config(tmp_path / "bad.yaml")


def test_visible_actors_carry_the_tracks_velocity(test_spec, test_scene):
    from generator.jobs.exposure import visible_actors

    rig = Rig.from_spec(test_spec, test_scene)
    t = rig.frame(FRAME).t
    world = car_world(test_spec, test_scene, rig, t)
    instance = np.zeros((4, 5), np.uint16)
    instance[1, 1:3] = world.actors[1].instance_id  # only the second car is seen
    recs = visible_actors(world, t, instance)
    assert [r["uid"] for r in recs] == [1] and recs[0]["pixels"] == 2
    np.testing.assert_array_equal(recs[0]["velocity_mps"], world.velocities(t)[1])
    assert recs[0]["speed_mps"] == pytest.approx(10.0) and recs[0]["moving"]
    assert recs[0]["class"] == "car" and recs[0]["instance_id"] == world.actors[1].instance_id
    assert visible_actors(frozen_world(test_scene, rig.trajectory), t, instance) == []


def test_metadata_with_motion_matches_the_schema(test_spec, test_scene):
    from generator.imaging.metadata import image_metadata, validate_metadata
    from generator.jobs.exposure import visible_actors
    from generator.spec.render import load_render_config

    rig = Rig.from_spec(test_spec, test_scene)
    frame = rig.frame(FRAME)
    world = car_world(test_spec, test_scene, rig, frame.t)
    instance = np.full((4, 5), world.actors[0].instance_id, np.uint16)
    motion = {"motion_blur": {"enabled": True, "shutter_s": 0.01, "method": "cycles"},
              "actors": visible_actors(world, frame.t, instance)}
    cfg = load_render_config("preview")
    record = image_metadata(image="x", files={"exr": "x.exr"}, frame=frame, k=rig.K(5, 4), width=5, height=4,
                            hfov_deg=90.0, class_id=np.ones((4, 5), np.uint8), time_of_day="day",
                            weather={"kind": "clear"}, lighting={}, spec=test_spec, render_cfg=cfg, device="CPU",
                            timings={}, blender_version=None, motion=motion)
    assert validate_metadata(record) == []
    assert record["time_s"] == frame.t and record["render"]["motion_blur"]["enabled"]
    record["motion"]["actors"][0]["velocity_mps"] = [1.0, 2.0]
    assert validate_metadata(record)


# -- with Blender ------------------------------------------------------------------------------


def _render(spec, scene, rig, world, blur: bool, times, scratch, shutter_s: float = 0.1) -> dict:
    """RGB and labels of frame ``FRAME``'s camera at each of ``times`` (one Renderer, then dropped);
    with blur, also the RGB at the first time from a camera held still over the exposure."""
    from generator.blender.renderer import Renderer
    from generator.jobs.exposure import expose
    from generator.spec.render import MotionBlur, load_render_config
    from generator.weather import Lighting

    cfg = dataclasses.replace(load_render_config("test"), resolution=RES, samples=8,
                              motion_blur=MotionBlur(blur, shutter_s))
    r = Renderer(scene, spec, cfg, scratch, world)
    r.set_conditions(Lighting("day", sun_elevation_deg=45.0, sun_azimuth_deg=200.0))
    frame = rig.frame(FRAME)
    out = {"k": r.k, "motion_blur": r.motion_blur}
    for t in times:
        T = expose(r, rig, t, frame.T_ego_camera)
        labels = r.render_labels()
        rgb, _ = r.render_rgb(seed=1)
        out[t] = {"T": T, "rgb": rgb, "labels": labels}
    if blur:
        T = out[times[0]]["T"]
        r.place_camera(T, np.stack([T, T]))
        out["still_rgb"] = r.render_rgb(seed=1)[0]
    return out


@pytest.fixture(scope="module")
def town(test_spec, test_scene):
    rig = Rig.from_spec(test_spec, test_scene)
    t = rig.frame(FRAME).t
    return rig, t, car_world(test_spec, test_scene, rig, t)


@pytest.fixture(scope="module")
def renders(tmp_path_factory, test_spec, test_scene, town):
    rig, t, world = town
    scratch = tmp_path_factory.mktemp("actors")
    return {
        "off": _render(test_spec, test_scene, rig, world, False, (t, t + LATER), scratch),
        "on": _render(test_spec, test_scene, rig, world, True, (t,), scratch),
    }


def _extent(k, T, world, a, when) -> tuple[np.ndarray, np.ndarray]:
    """Projected (2,) min and max pixel coordinates of actor ``a``'s mesh at ``when``."""
    pose = a.track.pose(when)[0]
    verts = world.prototypes[a.prototype].vertices @ pose[:3, :3].T + pose[:3, 3]
    uv = project(k, T, verts)
    return uv.min(0), uv.max(0)


@pytest.mark.blender
def test_actors_are_where_their_pose_projects(renders, town):
    """Each actor's mask lies inside the projection of its mesh posed at the image time, and its
    left and top edges (not occluded in this view) are where the projection puts them."""
    _, t, world = town
    r = renders["off"]
    for when in (t, t + LATER):
        inst, T = r[when]["labels"].instance, r[when]["T"]
        for a in world.actors:
            rows, cols = np.nonzero(inst == a.instance_id)
            assert len(rows) >= 15, (a.name, when)
            lo, hi = _extent(r["k"], T, world, a, when)
            assert lo[0] - 1 <= cols.min() and cols.max() <= hi[0] + 1, (a.name, when)
            assert lo[1] - 1 <= rows.min() and rows.max() <= hi[1] + 1, (a.name, when)
            # a pixel is in the mask when its centre (col + 0.5) is inside the silhouette; the left
            # edges are in plain view, and so is the far car's roof
            assert cols.min() + 0.5 == pytest.approx(lo[0], abs=1.5), (a.name, when)
            if a.uid == 0:
                assert rows.min() + 0.5 == pytest.approx(lo[1], abs=1.5), (a.name, when)


@pytest.mark.blender
def test_moving_the_image_time_moves_the_actors(renders, town):
    _, t, world = town
    r = renders["off"]
    crossing = world.actors[1]  # 10 m/s to the left
    seen = [np.nonzero(r[when]["labels"].instance == crossing.instance_id)[1].min() for when in (t, t + LATER)]
    expect = [_extent(r["k"], r[when]["T"], world, crossing, when)[0][0] for when in (t, t + LATER)]
    assert expect[1] - expect[0] < -5
    assert seen[1] - seen[0] == pytest.approx(expect[1] - expect[0], abs=2.0)


@pytest.mark.blender
def test_motion_blur_leaves_labels_exact(renders, town):
    _, t, world = town
    off, on = renders["off"][t], renders["on"][t]
    for name in ("class_id", "instance", "real_class", "real_instance", "depth"):
        np.testing.assert_array_equal(getattr(on["labels"], name), getattr(off["labels"], name), err_msg=name)
    np.testing.assert_array_equal(on["T"], off["T"])
    # Without any actor motion the still camera's blurred image would be the sharp one; the
    # crossing car (10 m/s, ~7 px in the 100 ms exposure) changes it around itself only.
    moving = np.zeros(RES[::-1], bool)
    for a in world.actors:
        moving |= off["labels"].instance == a.instance_id
    near = moving.copy()
    for shift in range(1, 9):
        near |= (np.roll(moving, shift, 1) | np.roll(moving, -shift, 1)
                 | np.roll(moving, shift, 0) | np.roll(moving, -shift, 0))
    diff = np.abs(renders["on"]["still_rgb"] - off["rgb"]).mean(-1)
    crossing = off["labels"].instance == world.actors[1].instance_id
    assert diff[crossing].mean() > 10 * diff[~near].mean(), (diff[crossing].mean(), diff[~near].mean())
    assert (diff[~near] == 0).mean() > 0.8
    # The moving camera (8 m/s forward) blurs the static town too.
    ego = np.abs(on["rgb"] - off["rgb"]).mean(-1)
    assert (ego[~near] > 0).mean() > 0.5 and ego[~near].mean() > 3 * diff[~near].mean()
    assert renders["on"]["motion_blur"] == {"enabled": True, "shutter_s": 0.1, "method": "cycles"}


@pytest.mark.blender
def test_world_without_actors_renders_as_no_world(tmp_path, test_spec, test_scene, town):
    rig, t, _ = town
    plain = _render(test_spec, test_scene, rig, None, False, (t,), tmp_path)[t]
    frozen = _render(test_spec, test_scene, rig, frozen_world(test_scene, rig.trajectory), False, (t,), tmp_path)[t]
    np.testing.assert_array_equal(frozen["rgb"], plain["rgb"])
    for name in ("class_id", "instance", "depth"):
        np.testing.assert_array_equal(getattr(frozen["labels"], name), getattr(plain["labels"], name))


@pytest.mark.blender
def test_written_metadata_records_time_and_visible_actors(tmp_path, test_spec, test_scene, town):
    import json

    from generator.blender.renderer import Renderer
    from generator.jobs.variants import render_frame
    from generator.spec.render import MotionBlur, load_render_config

    rig, t, world = town
    cfg = dataclasses.replace(load_render_config("test"), resolution=RES, samples=1, preview=False,
                              motion_blur=MotionBlur(True, 0.01))
    r = Renderer(test_scene, test_spec, cfg, tmp_path / "scratch", world)
    render_frame(r, test_spec, cfg, rig.frame(FRAME), tmp_path, [("day", "clear")], rig)
    meta = json.loads(image_path(tmp_path, f"{FRAME:06d}_day_clear", ".json").read_text())
    assert meta["time_s"] == t and meta["motion"]["motion_blur"] == {"enabled": True, "shutter_s": 0.01,
                                                                     "method": "cycles"}
    seen = {a["uid"]: a for a in meta["motion"]["actors"]}
    assert sorted(seen) == [0, 1]
    v = world.velocities(t)
    for uid, a in seen.items():
        assert a["velocity_mps"] == pytest.approx(v[uid].tolist(), abs=1e-9)
        assert a["speed_mps"] == pytest.approx(CARS[uid][3]) and a["instance_id"] == world.actors[uid].instance_id
    # (same Blender scene) each car's headlights drive with it: at its anchors, posed at the time set
    r.set_time(t + LATER)
    for a, ob in zip(world.actors, r.actors.objects, strict=False):
        lights = [np.array(x.matrix_world.translation) for x in r.night_lights.objects if x.parent == ob]
        anchors = world.prototypes[a.prototype].anchors["headlight"]
        pose = a.track.pose(t + LATER)[0]
        expect = anchors @ pose[:3, :3].T + pose[:3, 3]
        assert len(lights) == len(anchors)
        np.testing.assert_allclose(sorted(map(tuple, lights)), sorted(map(tuple, expect)), atol=1e-4)
