"""Fusion: how much motion de-skew matters, and what the occlusion test costs.

Usage::

    python bench/fusion_skew.py SPEC DIR

``DIR/images`` must hold rendered frames of SPEC (``urbangen render SPEC --out DIR``). The
bench casts the LiDAR for those frames twice into temporary folders -- motion skew on (the
default, KITTI-like) and off -- and prints the headline agreement (non-proxy classes, away
from 1-px boundaries, occlusion test on) for

* skew on, de-skewed with ``point_times/`` and the sweep start/end poses (what ``fuse`` does),
* skew on, raw points (what seed 001 did with KITTI),
* skew off (every column fired from the sweep-start pose),

then the time per frame of Eq. 1 alone (baseline) beside Eq. 1 + de-skew + occlusion test.
"""

from __future__ import annotations

import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np


def _headline(root: Path, deskew: bool) -> tuple[float, int]:
    from generator.fusion.agreement import HEADLINE, Agreement, fuse_frame
    from generator.fusion.dataset import FusionDataset

    a = Agreement()
    for frame in FusionDataset(root):
        a.add(fuse_frame(frame, deskew))
    return a.agreement("native", HEADLINE), int(a.conf["native", HEADLINE].sum())


def main(spec_path: str, dataset: str) -> None:
    from generator.fusion import projection as P
    from generator.fusion.dataset import FusionDataset, frame_images
    from generator.jobs.lidar_sequence import SequenceOptions, write_sequence
    from generator.layout.assemble import build_scene
    from generator.spec import load_spec

    images = frame_images(Path(dataset))
    n = max(images) + 1
    raw = json.loads(Path(spec_path).read_text())
    with tempfile.TemporaryDirectory() as tmp:
        rows = []
        for skew in (True, False):
            data = json.loads(json.dumps(raw))
            data.setdefault("sensors", {}).setdefault("lidar", {})["motion_skew"] = skew
            sp = Path(tmp) / f"spec_{skew}.json"
            sp.write_text(json.dumps(data))
            spec = load_spec(sp)
            root = Path(tmp) / f"skew_{skew}"
            root.mkdir()
            (root / "images").symlink_to(Path(dataset, "images").resolve())
            write_sequence(build_scene(spec), spec, root / "lidar", SequenceOptions(frames=n, threads=2, bev=False),
                           progress=False)
            if skew:
                rows.append(("skew on, de-skewed", *_headline(root, True)))
                rows.append(("skew on, raw points", *_headline(root, False)))
                timed_root = root
            else:
                rows.append(("skew off", *_headline(root, True)))
        print(f"{'LiDAR':<22} {'headline agreement %':>21} {'points':>8}")
        for name, agree, pts in rows:
            print(f"{name:<22} {100 * agree:21.3f} {pts:8d}")
        # timing: Eq. 1 alone vs the full per-frame fusion
        frames = [f for f in FusionDataset(timed_root)]
        t0 = time.perf_counter()
        for f in frames:
            T = P.camera_from_lidar(f.T_world_camera, f.T_world_lidar_start)
            P.project(P.transform(T, f.xyz), f.K, f.depth.shape[1], f.depth.shape[0])
        base = (time.perf_counter() - t0) / len(frames)
        from generator.fusion.agreement import fuse_frame

        t0 = time.perf_counter()
        for f in frames:
            fuse_frame(f)
        full = (time.perf_counter() - t0) / len(frames)
        npts = int(np.mean([len(f.xyz) for f in frames]))
        print(
            f"per frame ({npts} points, {frames[0].depth.shape[1]}x{frames[0].depth.shape[0]} px): "
            f"Eq. 1 projection {1000 * base:.1f} ms (baseline), + de-skew, occlusion, boundaries {1000 * full:.1f} ms"
        )


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
