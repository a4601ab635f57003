"""``generate`` writes the motion ground truth of what it rendered (Blender, test preset, a town with traffic).

The rendered passes, not ray casts: label maps warp onto each other along the flow, disparity is
f b / Z of the depth pass, KITTI PNGs decode to the floats, scans carry scene flow, metadata the ego's
and the actors' motion.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from generator.cli import main
from generator.dataset import Dataset
from generator.formats.kitti_flow import read_disparity_png, read_flow_png
from generator.fusion.projection import boundary_mask
from generator.imaging.paths import find_image
from generator.labels import class_table
from generator.world import rig

pytestmark = [pytest.mark.blender, pytest.mark.slow]
HULL = np.array([r.proxy == "hull" for r in class_table().rows])


@pytest.fixture(scope="module")
def dataset(tmp_path_factory, root):
    tmp = tmp_path_factory.mktemp("genmotion")
    doc = json.loads((root / "scenes" / "test_town.json").read_text())
    doc["traffic"] = {"cars_per_km": 40, "pedestrians_per_100m": 2.0}
    spec = tmp / "town.json"
    spec.write_text(json.dumps(doc))
    out = tmp / "ds"
    assert main(["-q", "generate", str(spec), "--config", "test", "--out", str(out), "--frames", "2",
                 "--variants", "day:clear"]) == 0
    return Dataset(out)


def _warp(labels_b, uv):
    h, w = labels_b.shape
    uc, vc = np.meshgrid(np.arange(w) + 0.5, np.arange(h) + 0.5)
    col = np.clip(np.floor(uc + uv[..., 0]).astype(int), 0, w - 1)
    row = np.clip(np.floor(vc + uv[..., 1]).astype(int), 0, h - 1)
    return row, col


def _labels(ds, j, cam):
    from generator.imaging.exr import read_exr

    img = read_exr(ds.root / f"lidar/sequences/00/passes_{cam}/{j:06d}.exr")
    return img.class_id, img.instance, img.depth


def test_rendered_labels_warp_along_the_stereo_streams_flow(dataset):
    """image_2 of one pair, warped from the next pair's labels (1 s later): the same class and instance on
    >= 99.5 % of visible pixels off label boundaries (hull-proxy classes left out: their labels are hulls,
    the depth and the flow are of what shows through them)."""
    sweeps = sorted(int(p.stem) for p in (dataset.root / "lidar/sequences/00/passes_2").glob("*.exr"))
    assert len(sweeps) >= 2
    j0, j1 = sweeps[:2]
    f = dataset.stereo_flow(j0, 2)
    assert f.to["forward"] == f"image_2/{j1:06d}"
    cls_a, inst_a, _ = _labels(dataset, j0, 2)
    cls_b, inst_b, _ = _labels(dataset, j1, 2)
    row, col = _warp(cls_b, f.forward)
    keep = f.valid("forward", visible=True) & ~boundary_mask(cls_a) & ~boundary_mask(inst_a)
    keep &= ~(boundary_mask(cls_b) | boundary_mask(inst_b))[row, col] & ~HULL[cls_a] & ~HULL[cls_b[row, col]]
    assert keep.sum() > 300
    assert (cls_b[row, col] == cls_a)[keep].mean() >= 0.995
    assert (inst_b[row, col] == inst_a)[keep].mean() >= 0.995


def test_disparity_is_f_b_over_z_of_the_rendered_depth(dataset):
    j = sorted(int(p.stem) for p in (dataset.root / "lidar/sequences/00/passes_2").glob("*.exr"))[0]
    _, _, depth = _labels(dataset, j, 2)
    meta = json.loads((dataset.root / f"lidar/sequences/00/passes_2/{j:06d}.json").read_text())
    K = np.array(meta["K"])
    h, w = depth.shape
    known = np.isfinite(depth)
    Z = depth.astype(np.float64) * rig.pixel_rays(K, w, h)[..., 2]
    d = dataset.disparity(j)
    np.testing.assert_array_equal(d.d[known], (K[0, 0] * 0.54 / Z[known]).astype(np.float32))
    png, ok = read_disparity_png(dataset.root / f"lidar/sequences/00/disp_occ_0/{j:06d}.png")
    assert np.abs(png - d.d)[ok].max() <= 1 / 512 + 1e-6 and ok.sum() >= 0.99 * (known & (d.d < 255.99)).sum()


def test_every_stream_and_scan_has_its_motion_files(dataset):
    root = dataset.root
    f = dataset.image_flow("000000_day_clear")
    uv, ok = read_flow_png(root / "flow/flow_occ/000000.png")
    assert f.forward is not None and np.abs(uv - f.forward)[ok].max() <= 1 / 128 + 1e-6
    assert dataset.image_flow("000001_day_clear").backward is not None
    scans = dataset.scan_indices()
    assert dataset.scene_flow(scans[0]) is not None and dataset.scene_flow(scans[-1]) is None
    meta = json.loads(find_image(root, "000001_day_clear", ".json").read_text())
    ego = meta["motion"]["ego"]
    assert ego["speed_mps"] > 0.5 and set(ego["camera"]) == {"velocity_mps", "angular_velocity_rad_s"}
    assert all("velocity_camera_mps" in a for a in meta["motion"]["actors"])
