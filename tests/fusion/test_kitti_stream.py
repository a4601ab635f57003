"""The KITTI camera stream: image_2/image_3 beside the scans, with calib.txt's true P0-P3 and Tr (Blender)."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from generator.formats import kitti_calib
from generator.fusion.kitti_stream import sequence_agreement
from generator.imaging.exr import read_exr
from generator.jobs.stereo import files_of, stereo_frames
from kits.generated_town import reference_run

pytestmark = pytest.mark.blender


@pytest.fixture(scope="module")
def sequence(tmp_path_factory, root):
    """The stream of the test town's ``generate`` run that tests/commands/test_generate.py makes too (2 frames:
    9 sweeps, a pair at 0), made once per test run (:mod:`kits.generated_town`); read-only."""
    return reference_run(tmp_path_factory, root).path() / "lidar" / "sequences" / "00"


def test_every_tenth_sweep_has_a_stereo_pair(sequence, test_spec):
    sweeps = sorted(int(p.stem) for p in (sequence / "velodyne").glob("*.bin"))
    pairs = stereo_frames(test_spec, sweeps)
    assert pairs == [j for j in sweeps if j % test_spec.sensors.stereo.every == 0] and pairs
    assert not any(p.exists() for j in set(sweeps) - set(pairs) for p in files_of(sequence, j))
    for k in pairs:
        assert all(p.is_file() for p in files_of(sequence, k))
        left, right = (np.asarray(Image.open(sequence / f"image_{c}" / f"{k:06d}.png")) for c in (2, 3))
        assert left.dtype == np.uint8 and left.shape == right.shape and left.shape[2] == 3
        assert not np.array_equal(left, right)  # two viewpoints


def test_p2_tr_projects_scans_onto_their_image_2_labels(sequence):
    """What every KITTI tool does (P2 @ Tr on the raw scan) lands on the right pixels."""
    rep = sequence_agreement(sequence)
    assert rep["counted"] > 5000
    assert rep["agreement"] >= 0.995, rep


def test_calib_is_a_rectified_pair_with_the_spec_baseline(sequence, test_spec):
    calib = kitti_calib.read_calib(sequence / "calib.txt")
    p2, p3 = calib["P2"], calib["P3"]
    assert np.allclose(calib["P0"], p2) and np.allclose(calib["P1"], p3)
    assert np.allclose(p2[:, :3], p3[:, :3]) and np.allclose(p2[:, 3], 0)
    assert -p3[0, 3] / p3[0, 0] == pytest.approx(test_spec.sensors.stereo.baseline_m)


def test_right_image_sees_the_scene_shifted_by_the_baseline(sequence):
    """Depth of image_3 equals image_2's depth re-projected through P3: the pair is really rectified."""
    calib = kitti_calib.read_calib(sequence / "calib.txt")
    left, right = read_exr(sequence / "passes_2" / "000000.exr"), read_exr(sequence / "passes_3" / "000000.exr")
    K = calib["P2"][:, :3]
    h, w = left.depth.shape
    v, u = np.mgrid[0:h, 0:w] + 0.5
    rays = np.stack([(u - K[0, 2]) / K[0, 0], (v - K[1, 2]) / K[1, 1], np.ones_like(u)], -1)
    pts = rays / np.linalg.norm(rays, axis=-1, keepdims=True) * left.depth[..., None]
    ok = np.isfinite(left.depth) & (left.depth < 60)
    x = pts[ok] @ calib["P3"][:, :3].T + calib["P3"][:, 3]
    uu, vv = (x[:, 0] / x[:, 2]).astype(int), (x[:, 1] / x[:, 2]).astype(int)
    inside = (uu >= 0) & (uu < w) & (vv >= 0) & (vv < h)
    same = left.class_id[ok][inside] == right.class_id[vv[inside], uu[inside]]
    assert same.mean() > 0.9
