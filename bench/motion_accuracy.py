"""How exact the motion ground truth of a generated dataset is, measured on its own files.

    python bench/motion_accuracy.py DATASET [--sequence 00]

For every stream (images/ frames, the KITTI stream's image_2): the share of pixels whose forward flow
is known / visible; warping the next image's class and instance maps along the flow, the share that
lands on the same label (visible pixels off label boundaries in both images; with and without the
hull-proxy classes, whose labels are hulls the flow sees through); the forward-backward round trip
(bilinear, on visible pixels whose landing cell lies on one surface: one class and instance, visible,
no depth step over 2 % + 5 cm). Disparity: the largest
difference from f b / Z of the depth pass, the share visible in the right image. Scene flow: per
moving actor and sweep the median distance of its moved points to its next-sweep points beside the
point spacing there (the nearest neighbour, along a ring, and the 4th, the pitch between rings: a
moved point lands anywhere on the surface, between rings too), and the static points' object flow
(must be exactly 0); apart for pairs of scans without and with LiDAR rain (range noise of ~0.2 m at
10 m moves both the points and their neighbours).
"""

from __future__ import annotations

import argparse
import itertools
import json
import sys
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from generator.dataset import Dataset  # noqa: E402
from generator.fusion.projection import boundary_mask  # noqa: E402
from generator.imaging.exr import read_exr  # noqa: E402
from generator.labels import class_table  # noqa: E402
from generator.world import rig  # noqa: E402

HULL = np.array([r.proxy == "hull" for r in class_table().rows])


def _landing(uv):
    h, w = uv.shape[:2]
    uc, vc = np.meshgrid(np.arange(w) + 0.5, np.arange(h) + 0.5)
    x, y = uc + uv[..., 0], vc + uv[..., 1]
    return np.clip(np.floor(y).astype(int), 0, h - 1), np.clip(np.floor(x).astype(int), 0, w - 1), x - 0.5, y - 0.5


def pair_stats(a, b, fw, fw_flags, bw, bw_flags) -> dict:
    """Warp agreement and round trip of one forward flow (``a``, ``b``: LabelledImages)."""
    vis = (fw_flags & 2) > 0
    row, col, x, y = _landing(fw)
    edge_b = boundary_mask(b.class_id) | boundary_mask(b.instance)
    keep = vis & ~boundary_mask(a.class_id) & ~boundary_mask(a.instance) & ~edge_b[row, col]
    no_hull = keep & ~HULL[a.class_id] & ~HULL[b.class_id[row, col]]
    out = {"known": float(((fw_flags & 1) > 0).mean()), "visible": float(vis.mean()),
           "warp_pixels": int(no_hull.sum()),
           "class_agree": float((b.class_id[row, col] == a.class_id)[no_hull].mean()) if no_hull.any() else None,
           "instance_agree": float((b.instance[row, col] == a.instance)[no_hull].mean()) if no_hull.any() else None,
           "class_agree_with_hulls": float((b.class_id[row, col] == a.class_id)[keep].mean()) if keep.any() else None}
    if bw is not None:
        h, w = vis.shape
        x0, y0 = np.floor(x).astype(int), np.floor(y).astype(int)
        ok = keep & (x0 >= 0) & (y0 >= 0) & (x0 < w - 1) & (y0 < h - 1)
        x0, y0 = np.clip(x0, 0, w - 2), np.clip(y0, 0, h - 2)
        corners = [(y0 + dy, x0 + dx) for dy in (0, 1) for dx in (0, 1)]
        depths = np.stack([b.depth[r, c] for r, c in corners])
        with np.errstate(invalid="ignore"):  # sky: inf - inf
            smooth = (depths.max(0) - depths.min(0)) <= 0.02 * depths.min(0) + 0.05  # no depth edge in the cell
        ok &= smooth
        for r, c in corners:
            ok &= ((bw_flags[r, c] & 2) > 0) & (b.instance[r, c] == a.instance) & (b.class_id[r, c] == a.class_id)
        fx, fy = x - x0, y - y0
        wts = [(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy]
        back = sum(wt[..., None] * bw[r, c] for wt, (r, c) in zip(wts, corners, strict=True))
        err = np.linalg.norm(fw + back, axis=-1)[ok]
        if err.size:
            out.update(round_trip_pixels=int(err.size), round_trip_median_px=float(np.median(err)),
                       round_trip_p99_px=float(np.percentile(err, 99)), round_trip_max_px=float(err.max()),
                       round_trip_within_half_px=float((err <= 0.5).mean()))
    return out


def images_stream(ds: Dataset) -> list[dict]:
    frames = sorted({int(n[:6]) for n in ds.image_names()})
    names = {int(n[:6]): n for n in ds.image_names() if n.endswith("day_clear")}
    out = []
    for k0, k1 in itertools.pairwise(frames):
        if k0 not in names or k1 not in names:
            continue
        f0, f1 = ds.image_flow(names[k0]), ds.image_flow(names[k1])
        if f0 is None or f0.forward is None:
            continue
        a, b = (read_exr(ds.image_files(names[k])[0]) for k in (k0, k1))
        out.append({"pair": f"{k0:06d}->{k1:06d}", **pair_stats(a, b, f0.forward, f0.forward_flags, f1.backward,
                                                                 f1.backward_flags)})
    return out


def stereo_stream(ds: Dataset) -> list[dict]:
    seq = ds.root / "lidar" / "sequences" / ds.sequence
    sweeps = sorted(int(p.stem) for p in (seq / "passes_2").glob("*.exr"))
    out = []
    for j0, j1 in itertools.pairwise(sweeps):
        f0, f1 = ds.stereo_flow(j0, 2), ds.stereo_flow(j1, 2)
        if f0 is None:
            continue
        a, b = (read_exr(seq / "passes_2" / f"{j:06d}.exr") for j in (j0, j1))
        out.append({"pair": f"image_2/{j0:06d}->{j1:06d}", **pair_stats(a, b, f0.forward, f0.forward_flags,
                                                                         f1.backward, f1.backward_flags)})
    return out


def disparity(ds: Dataset) -> list[dict]:
    seq = ds.root / "lidar" / "sequences" / ds.sequence
    out = []
    for p in sorted((seq / "passes_2").glob("*.exr")):
        d = ds.disparity(int(p.stem))
        if d is None:
            continue
        meta = json.loads(p.with_suffix(".json").read_text())
        depth = read_exr(p).depth
        K = np.array(meta["K"])
        T2, T3 = np.array(meta["T_world_camera"]), np.array(json.loads((seq / "passes_3" / p.with_suffix(".json").name)
                                                                      .read_text())["T_world_camera"])
        b = (np.linalg.inv(T2) @ T3)[0, 3]
        known = np.isfinite(depth)
        Z = depth.astype(np.float64) * rig.pixel_rays(K, depth.shape[1], depth.shape[0])[..., 2]
        err = np.abs(d.d[known] - K[0, 0] * b / Z[known])
        out.append({"image": p.stem, "max_abs_error_px": float(err.max()), "known": float(d.valid().mean()),
                    "visible_in_right": float(d.valid(visible=True).mean())})
    return out


def _noisy(ds: Dataset) -> set[int]:
    """Scans whose LiDAR weather adds range noise (rain: sigma ~0.2 m at 10 m), by the sequence's record."""
    meta = json.loads((ds.root / "lidar" / "sequences" / ds.sequence / "lidar_meta.json").read_text())
    return {s["frame"] for s in meta.get("scans", []) if (s.get("weather") or {}).get("range_noise_sigma_m_at_10m")}


def scene_flow(ds: Dataset, quiet: bool) -> dict:
    """Landing statistics over consecutive scans without range noise (``quiet``) or with it."""
    scans, noisy = ds.scan_indices(), _noisy(ds)
    dists, spacings, pitches, static_max, flags = [], [], [], 0.0, np.zeros(3, np.int64)
    for j in scans[:-1]:
        if quiet == bool({j, j + 1} & noisy):
            continue
        got = ds.scene_flow(j)
        if got is None:
            continue
        ego, flag = got
        obj, _ = ds.scene_flow(j, ego_motion=False)
        s0, s1 = ds.scan(j), ds.scan(j + 1)
        flags += np.bincount(flag, minlength=3)
        moving = np.linalg.norm(obj, axis=1) > 0
        static_max = max(static_max, float(np.abs(obj[~moving]).max(initial=0.0)))
        for iid in np.unique(s0.instance[moving]):
            a, b = (s0.instance == iid) & moving, s1.instance == iid
            if a.sum() < 30 or b.sum() < 30 or np.linalg.norm(obj[a], axis=1).mean() < 0.05:
                continue
            tree = cKDTree(s1.xyz[b])
            dists.append(float(np.median(tree.query(s0.xyz[a] + ego[a])[0])))
            nn = tree.query(s1.xyz[b], k=5)[0]
            spacings.append(float(np.median(nn[:, 1])))  # the nearest neighbour: along the ring
            pitches.append(float(np.median(nn[:, 4])))  # the 4th: the next ring up or down (the grid's coarse pitch)
    d, s, g = np.array(dists), np.array(spacings), np.array(pitches)
    return {"actor_sweeps": len(d), "median_landing_m": float(np.median(d)) if len(d) else None,
            "median_spacing_m": float(np.median(s)) if len(s) else None,
            "median_ring_pitch_m": float(np.median(g)) if len(g) else None,
            "landing_within_spacing": float((d <= s).mean()) if len(d) else None,
            "landing_within_ring_pitch": float((d <= g).mean()) if len(d) else None,
            "static_object_flow_max_m": static_max, "flags_seen_hidden_gone": (flags / flags.sum()).round(4).tolist()}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("dataset", type=Path)
    p.add_argument("--sequence", default="00")
    args = p.parse_args()
    ds = Dataset(args.dataset, args.sequence)
    report = {"images": images_stream(ds), "image_2": stereo_stream(ds), "disparity": disparity(ds),
              "scene_flow_scans_without_range_noise": scene_flow(ds, True),
              "scene_flow_scans_with_rain_range_noise": scene_flow(ds, False)}
    print(json.dumps(report, indent=1))


if __name__ == "__main__":
    main()
