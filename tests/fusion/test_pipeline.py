"""Camera-LiDAR fusion: Eq. 1 projection, de-skew, occlusion test, agreement, semantic map."""

from __future__ import annotations

import json

import numpy as np
import pytest

from generator import geometry as M
from generator.cli import main
from generator.fusion import projection as P
from generator.fusion.agreement import HEADLINE, Agreement, FusedFrame, variant_key
from generator.fusion.semantic_map import VoxelMap, top_down_image
from generator.labels import class_table
from generator.lidar.caster import EmbreeCaster
from generator.world import rig
from kits.fusion_kit import raycast_image, write_raycast_images
from kits.scene_kit import fence_scene, make_scene
from kits.sensor_kit import ideal

T = class_table()
CAR, BUILDING, ROAD, FENCE = T.id("car"), T.id("building"), T.id("road"), T.id("fence")


# -- Eq. 1 ------------------------------------------------------------------------------------------
def test_known_point_projects_to_its_pixel():
    # hfov 90 deg, 100 x 50 px: f = 50 px, principal point (50, 25)
    K = rig.intrinsics(90.0, 100, 50)
    assert K[0, 0] == pytest.approx(50.0) and (K[0, 2], K[1, 2]) == (50.0, 25.0)
    # camera 0.27 m ahead of the LiDAR and 0.08 m below it, both level and facing +x (the KITTI rig)
    T_world_camera = rig.camera_extrinsics((0.27, 0.0, 1.65), (0, 0, 0))
    T_world_lidar = rig.mount((0.0, 0.0, 1.73), (0, 0, 0))
    T_cam_lidar = P.camera_from_lidar(T_world_camera, T_world_lidar)
    lidar_pts = np.array([
        [10.27, 0.0, -0.08],   # on the optical axis, 10 m ahead: principal point
        [10.27, 2.0, -0.08],   # 2 m left at z = 10: u = 50 + 50 * (-2 / 10) = 40
        [5.27, 0.0, -1.08],    # 1 m below the camera at z = 5: v = 25 + 50 * (1 / 5) = 35
    ])
    proj = P.project(P.transform(T_cam_lidar, lidar_pts), K, 100, 50)
    assert proj.index.tolist() == [0, 1, 2]
    assert np.allclose(proj.u, [50.0, 40.0, 50.0]) and np.allclose(proj.v, [25.0, 25.0, 35.0])
    assert proj.col.tolist() == [50, 40, 50] and proj.row.tolist() == [25, 25, 35]
    assert np.allclose(proj.z, [10.0, 10.0, 5.0])
    assert proj.distance[1] == pytest.approx(np.hypot(10.0, 2.0))


def test_points_behind_the_camera_or_outside_the_image_are_dropped():
    K = rig.intrinsics(90.0, 100, 50)
    cam = np.array([[0.0, 0.0, -5.0], [0.0, 0.0, 0.05], [20.0, 0.0, 10.0], [0.0, 6.0, 10.0], [1.0, 1.0, 10.0]])
    proj = P.project(cam, K, 100, 50)
    assert proj.index.tolist() == [4]


# -- occlusion ----------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def occluder_view():
    """A car-sized box 6 m ahead of a building wall at 12 m, seen by a level camera at 1.5 m."""
    ground = M.rect(-50, -50, 50, 50, 0.0, "road", "asphalt")
    wall = M.box((1.0, 30.0, 10.0), "building", "facade_brick", center=(0, 0, 5.0))
    car = M.box((1.0, 2.0, 1.5), "car", "car_paint", center=(0, 0, 0.75))
    scene = make_scene([("ground", ground, np.eye(4), 0), ("wall", wall, M.pose(12.5, 0, 0), 1),
                        ("car", car, M.pose(6.0, 0, 0), 2)])
    T_world_camera = rig.camera_extrinsics((0.0, 0.0, 1.5), (0, 0, 0))
    K = rig.intrinsics(90.0, 200, 100)
    cls, _, depth = raycast_image(EmbreeCaster.from_scene(scene), scene, T_world_camera, K, 200, 100)
    return T_world_camera, K, cls, depth


def test_point_behind_a_wall_is_rejected_by_the_occlusion_test(occluder_view):
    T_world_camera, K, cls, depth = occluder_view
    world = np.array([
        [12.0, 0.0, 0.75],   # on the wall, hidden behind the car (the ray crosses x = 6 at z = 1.125, |y| = 0)
        [12.0, 3.0, 0.75],   # on the wall beside the car: seen
        [5.5, 0.3, 1.0],     # on the car's front face: seen
    ])
    proj = P.project(P.transform(rig.invert(T_world_camera), world), K, 200, 100)
    assert proj.index.tolist() == [0, 1, 2]
    vis = P.visible(proj, depth, K)
    assert vis.tolist() == [False, True, True]
    # without the test (seed 001) the hidden wall point would take the car's label
    assert cls[proj.row, proj.col].tolist() == [CAR, BUILDING, CAR]


def test_subpixel_prediction_follows_slanted_ground():
    # the road 20 m ahead seen by a camera 1.5 m up: depth changes by metres per pixel
    T_world_camera = rig.camera_extrinsics((0.0, 0.0, 1.5), (0, 0, 0))
    K = rig.intrinsics(90.0, 96, 64)
    scene = make_scene([("ground", M.rect(-100, -100, 100, 100, 0.0, "road", "asphalt"), np.eye(4), 0)])
    _, _, depth = raycast_image(EmbreeCaster.from_scene(scene), scene, T_world_camera, K, 96, 64)
    # a road point near the lower edge of its pixel, about 20 m ahead (v = 32 + 48 * 1.5 / 20 = 35.6)
    ray = np.linalg.solve(K, [48.3, 35.95, 1.0])
    point = ray * (1.5 / ray[1])  # on the road plane y_cam = 1.5 (optical y points down)
    proj = P.project(point[None], K, 96, 64)
    d_centre = depth[proj.row[0], proj.col[0]]
    assert abs(proj.distance[0] - d_centre) > max(P.ABS_TOL_M,
                                                  P.REL_TOL * proj.distance[0])  # beyond the plain tolerance
    assert P.visible(proj, depth, K).tolist() == [True]
    assert P.visible(proj, depth, K, subpixel=False).tolist() == [False]


def test_subpixel_prediction_does_not_reach_across_a_depth_edge():
    # pixel (0, 1) sees a surface at 10 m, its right neighbour a background at 30 m
    K = rig.intrinsics(90.0, 4, 2)
    depth = np.array([[10.0, 10.0, 30.0, 30.0], [10.0, 10.0, 30.0, 30.0]], np.float32)
    u, v = 1.9, 0.5  # right part of pixel (0, 1), towards the background
    ray = np.linalg.solve(K, [u, v, 1.0])
    ray /= np.linalg.norm(ray)
    pts = np.stack([ray * 10.0, ray * 30.0, ray * 15.0])
    proj = P.project(pts, K, 4, 2)
    assert proj.col.tolist() == [1, 1, 1]
    # on the near surface: seen; on the background or halfway: hidden behind the edge
    assert P.visible(proj, depth, K).tolist() == [True, False, False]


def test_boundary_mask_marks_pixels_next_to_another_class():
    c = np.zeros((5, 6), np.uint8)
    c[2, 3] = 1
    b = P.boundary_mask(c)
    expect = np.zeros((5, 6), bool)
    expect[1:4, 2:5] = True
    assert np.array_equal(b, expect)
    assert not P.boundary_mask(np.full((4, 4), 7, np.uint8)).any()


# -- de-skew ------------------------------------------------------------------------------------------
def test_deskew_with_the_recorded_sweep_poses_is_exact_through_a_turn(test_spec):
    from generator.lidar.scan import Scanner
    from generator.lidar.sensors import sensor_for_spec
    from generator.world.rig import Rig
    from generator.world.scene import Path

    # a straight that turns into an arc (0.1 rad per metre) at s = 10 m: the yaw rate jumps mid-sweep
    s = np.arange(0.0, 40.0, 1.0)
    heading = np.where(s <= 10.0, 0.0, 0.1 * (s - 10.0))
    pts = np.zeros((len(s), 3))
    for i in range(1, len(s)):
        pts[i] = pts[i - 1] + [np.cos(heading[i - 1]), np.sin(heading[i - 1]), 0.0]
    scene = fence_scene()
    scene.paths = [Path("kink", pts - [8.0, 0.0, 0.0], heading, s, False)]
    sensor = sensor_for_spec(test_spec)
    t0 = 9.6 / test_spec.paths.speed_mps  # the sweep covers s = 9.6 .. 10.4
    rig = Rig.from_spec(test_spec, scene)
    poses = rig.sweep_poses(t0, sensor.column_time())  # one pose per column: skew on
    with Scanner(scene, sensor, threads=2) as sc:
        scan = sc.scan(poses)
    p = scan.points
    xyz = scan.xyz.astype(np.float64)
    exact_world = np.einsum("nij,nj->ni", poses[p["column"], :3, :3], xyz) + poses[p["column"], :3, 3]
    rec = rig.sweep_record(t0, sensor.period_s)
    assert len(rec["t_s"]) == 3 and rec["t_s"][1] == pytest.approx(0.4 / test_spec.paths.speed_mps)
    fixed = P.transform(poses[0], P.deskew(xyz, p["time"], rec["t_s"], rec["T_world_lidar"]))
    assert np.abs(fixed - exact_world).max() < 1e-3
    # start and end poses alone miss the kink; raw points carry the whole skew
    ends = [rec["T_world_lidar"][0], rec["T_world_lidar"][-1]]
    two = P.transform(poses[0], P.deskew(xyz, p["time"], [0.0, sensor.period_s], ends))
    assert np.linalg.norm(two - exact_world, axis=1).max() > 0.05
    assert np.linalg.norm(P.transform(poses[0], xyz) - exact_world, axis=1).max() > 0.5


# -- agreement bookkeeping ------------------------------------------------------------------------------
def test_agreement_counts_each_variant_by_hand():
    lidar = np.array([ROAD, ROAD, CAR, BUILDING, BUILDING, FENCE], np.uint8)
    image = np.array([ROAD, CAR, CAR, CAR, FENCE, FENCE], np.uint8)
    visible = np.array([True, True, True, False, True, True])
    boundary = np.array([False, True, False, False, False, False])
    proj = P.Projection(np.arange(6), *(np.zeros(6),) * 2, *(np.zeros(6, np.int64),) * 2, np.ones(6), np.ones(6))
    a = Agreement()
    a.add(FusedFrame(0, np.zeros((10, 3)), proj, visible, boundary, image, lidar))
    assert (a.points, a.in_view, a.visible) == (10, 6, 5)
    c = a.conf["native", ("off", "included", "included")]
    assert c.sum() == 6 and np.trace(c) == 3 and c[BUILDING, CAR] == 1 and c[BUILDING, FENCE] == 1
    # occlusion on drops the hidden building point; proxies excluded drops both fence pixels; boundaries the 2nd
    assert a.agreement("native", ("on", "included", "included")) == pytest.approx(3 / 5)
    assert a.agreement("native", ("off", "excluded", "included")) == pytest.approx(2 / 4)
    assert a.agreement("native", HEADLINE) == pytest.approx(2 / 2)
    rep = a.to_dict({})
    iou = rep["label_sets"]["native"]["variants"][variant_key(("off", "included", "included"))]["iou"]
    # road: TP 1, FN 1 (seen as car), FP 0 -> 1/2; car: TP 1, FP 2 -> 1/3
    assert iou["road"] == pytest.approx(0.5) and iou["car"] == pytest.approx(1 / 3)
    # in unified 11 the same points: road and car keep their ids, the fence pixel stays fence
    assert rep["label_sets"]["unified11"]["classes"][1] == "vehicle"


# -- semantic map ---------------------------------------------------------------------------------------
def test_voxel_map_keeps_the_majority_label_and_the_centroid():
    pts = np.array([[0.05, 0.05, 0.05], [0.15, 0.05, 0.05], [0.10, 0.10, 0.10],  # voxel (0,0,0): 1, 1, 2
                    [1.05, 0.0, 0.0], [1.15, 0.0, 0.0]])                          # voxel (5,0,0): 4, 3 (tie)
    labels = np.array([1, 1, 2, 4, 3])
    one = VoxelMap(0.2)
    one.add(pts, labels)
    xyz, lab, count = one.voxels()
    order = np.argsort(xyz[:, 0])
    assert lab[order].tolist() == [1, 3]  # majority; a tie goes to the lower id
    assert count[order].tolist() == [3, 2]
    assert np.allclose(xyz[order][0], pts[:3].mean(0)) and np.allclose(xyz[order][1], pts[3:].mean(0))
    two = VoxelMap(0.2)
    two.add(pts[:2], labels[:2])
    two.add(pts[2:], labels[2:])
    for a, b in zip(two.voxels(), one.voxels(), strict=False):
        assert np.allclose(a[np.argsort(two.voxels()[0][:, 0])], b[order])
    img = top_down_image(xyz, lab)
    assert img.width > 100 and img.height > 100


# -- the fuse command on a ray-cast dataset (no Blender) ---------------------------------------------------
@pytest.fixture(scope="module")
def raycast_dataset(tmp_path_factory, test_spec):
    from generator.jobs.lidar_sequence import SequenceOptions, write_sequence
    from generator.layout.assemble import build_scene

    root = tmp_path_factory.mktemp("fuse")
    scene = build_scene(test_spec)
    write_raycast_images(root, scene, test_spec, 2)
    write_sequence(scene, test_spec, root / "lidar", SequenceOptions(frames=2, threads=2, bev=False), progress=False)
    assert main(["fuse", str(root)]) == 0
    return root


def test_fuse_writes_report_and_maps(raycast_dataset):
    out = raycast_dataset / "fusion"
    for name in ("agreement.md", "agreement.json", "agreement.png", "semantic_map_lidar.ply", "semantic_map_lidar.png",
                 "semantic_map_camera.ply", "semantic_map_camera.png"):
        assert (out / name).stat().st_size > 100, name
    rep = json.loads((out / "agreement.json").read_text())
    assert rep["frames"] == [0, 1] and rep["visible"] < rep["in_view"] < rep["points"]
    nat = rep["label_sets"]["native"]["variants"]
    on, off = nat[variant_key(("on", "included", "included"))], nat[variant_key(("off", "included", "included"))]
    assert on["agreement"] > off["agreement"] + 0.02  # the occlusion test removes smeared labels
    assert rep["headline"]["agreement_native"] >= 0.995
    assert rep["without_deskew"]["agreement_native"] < rep["headline"]["agreement_native"]
    ply = (out / "semantic_map_lidar.ply").read_bytes()
    assert ply.startswith(b"ply\n") and b"property uchar native" in ply


def test_fuse_refuses_a_folder_without_images(tmp_path, capsys):
    (tmp_path / "lidar").mkdir()
    assert main(["fuse", str(tmp_path)]) == 2
    assert "images" in capsys.readouterr().err


# -- on real renders (Blender) -----------------------------------------------------------------------------
@pytest.fixture(scope="module")
def rendered_dataset(tmp_path_factory, test_spec):
    from generator.jobs.lidar_sequence import SequenceOptions, write_sequence
    from generator.layout.assemble import build_scene

    root = tmp_path_factory.mktemp("rendered")
    assert main(["render", test_spec.source, "--config", "test", "--out", str(root), "--frames", "2"]) == 0
    scene = build_scene(test_spec)
    # the ideal sensor: each point on the surface its camera ray meets (the physical one blurs edges)
    write_sequence(scene, ideal(test_spec), root / "lidar", SequenceOptions(frames=2, threads=2, bev=False),
                   progress=False)
    return root, scene


def _depth_edges(depth: np.ndarray, jump_m: float = 0.5) -> np.ndarray:
    """(h, w) bool: pixels whose 8-neighbourhood spans a depth jump of more than ``jump_m`` (or the sky)."""
    d = np.nan_to_num(depth.astype(np.float64), posinf=1e6)
    p = np.pad(d, 1, mode="edge")
    h, w = d.shape
    near = np.stack([p[1 + dy:1 + dy + h, 1 + dx:1 + dx + w] for dy in (-1, 0, 1) for dx in (-1, 0, 1)])
    return near.max(0) - near.min(0) > jump_m


@pytest.mark.blender
def test_rendered_depth_equals_lidar_range_on_shared_rays(rendered_dataset):
    from generator.fusion.dataset import FusionDataset

    root, scene = rendered_dataset
    caster = EmbreeCaster.from_scene(scene)
    for frame in FusionDataset(root):
        h, w = frame.depth.shape
        cls, _, dist = raycast_image(caster, scene, frame.T_world_camera, frame.K, w, h)
        shared = (cls == frame.class_id) & ~P.boundary_mask(frame.class_id) & np.isfinite(frame.depth)
        # a ray through a gap of a porous (hull-labelled) crown or hedge, or past the edge of a building's
        # thin part (balcony rail, awning) in front of its wall: same class, another surface a sub-pixel away
        thin = T.hull_classes[frame.class_id] | (frame.class_id == T.id("building"))
        porous_edge = thin & _depth_edges(frame.depth)
        shared &= ~porous_edge
        assert shared.sum() > 0.3 * h * w  # (facades with balconies have many depth edges at 96 x 64)
        err = np.abs(dist[shared].astype(np.float64) - frame.depth[shared])
        assert np.percentile(err, 99) < 0.003, np.percentile(err, 99)
        # the few larger ones are grazing rays on the road far away (float32 ray directions)
        assert np.all(err < 0.005 + 2e-4 * frame.depth[shared]), err.max()
        # sky where the centre ray meets nothing; on a porous edge Cycles' depth sample (jittered in the pixel)
        # may pass a leaf the centre ray hits, so those pixels are left out, as above
        keep = ~porous_edge
        assert np.array_equal((cls == T.id("sky"))[keep], ~np.isfinite(frame.depth)[keep])


@pytest.mark.blender
def test_rendered_labels_agree_with_lidar_labels(rendered_dataset):
    from generator.fusion.agreement import fuse_frame
    from generator.fusion.dataset import FusionDataset

    root, scene = rendered_dataset
    assert main(["fuse", str(root)]) == 0
    rep = json.loads((root / "fusion" / "agreement.json").read_text())
    assert rep["headline"]["agreement_native"] >= 0.995, rep["headline"]
    # every remaining disagreement is the label pass sampling one ray per pixel centre: the camera ray
    # through the point itself hits the point's class, the ray through the pixel centre the mask's class
    caster = EmbreeCaster.from_scene(scene)
    for frame in FusionDataset(root):
        f = fuse_frame(frame)
        hull = T.hull_classes
        bad = f.visible & ~f.boundary & ~hull[f.lidar_class] & ~hull[f.image_class] & (f.lidar_class != f.image_class)
        idx = np.flatnonzero(bad)
        if not idx.size:
            continue
        Twc = frame.T_world_camera
        world = P.transform(frame.T_world_lidar_start, f.xyz_start[f.proj.index[idx]])
        d = world - Twc[:3, 3]
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        o = np.repeat(Twc[None, :3, 3], len(idx), 0)
        _, prim = caster.intersect(o, d.astype(np.float32), 1e4)
        assert np.array_equal(scene.face_class[prim], f.lidar_class[idx])
        centre = rig.pixel_rays(frame.K, frame.depth.shape[1], frame.depth.shape[0])[f.proj.row[idx], f.proj.col[idx]]
        _, prim_c = caster.intersect(o, (centre @ Twc[:3, :3].T).astype(np.float32), 1e4)
        assert np.array_equal(scene.face_class[prim_c], f.image_class[idx])
