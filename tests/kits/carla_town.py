"""A KITTI-CARLA town written in the exact field layout of its PLY frames and pose file."""

from __future__ import annotations

import numpy as np

from generator.world import rig

KC_DTYPE = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("cos_angle_lidar_surface", "<f4"),
                     ("timestamp", "<f4"), ("instance", "<u4"), ("semantic", "<u4")])
PACKETS = 3  # packets per frame in the pose file
DT = 0.01


def write_ply(path, v: np.ndarray, fmt="binary_little_endian", dtype=KC_DTYPE) -> None:
    names = {"<f4": "float", "<u4": "uint", ">f4": "float", ">u4": "uint"}
    header = ["ply", f"format {fmt} 1.0", "comment KITTI-CARLA layout", f"element vertex {len(v)}"]
    header += [f"property {names[dtype[n].str]} {n}" for n in dtype.names] + ["end_header"]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(("\n".join(header) + "\n").encode() + v.astype(dtype).tobytes())


def pose(yaw, x, y):
    return rig.pose(x, y, 0.0, yaw=yaw)


def make_town(root, frames=3, per_tag=40, poses=True, seed=0):
    """Frames with every CARLA tag 0..22; vehicles/pedestrians carry big CARLA object ids."""
    g = np.random.default_rng(seed)
    town = root / "Town01"
    lines = ["# R(0,0) R(0,1) R(0,2) t(0) R(1,0) R(1,1) R(1,2) t(1) R(2,0) R(2,1) R(2,2) t(2) timestamp"]
    pose_list = []
    for p in range(frames * PACKETS + 2):  # two trailing packets of an unfinished sweep
        t = pose(0.1 * p, 2.0 * p + 5.0, 0.5 * p - 1.0)
        pose_list.append(t)
        lines.append(" ".join(f"{x:.12g}" for x in t[:3].reshape(-1)) + f" {0.5 + p * DT:.6f}")
    frames_out = []
    for k in range(frames):
        tags = np.repeat(np.arange(23), per_tag)
        n = len(tags)
        v = np.zeros(n, KC_DTYPE)
        d = g.normal(size=(n, 3))
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        r = g.uniform(3, 60, n)
        v["x"], v["y"], v["z"] = (d * r[:, None]).T
        v["cos_angle_lidar_surface"] = g.uniform(0.05, 1, n)
        v["timestamp"] = 0.5 + (k * PACKETS + g.integers(0, PACKETS, n)) * DT
        v["timestamp"][0] = 0.5 + k * PACKETS * DT  # the sweep's first packet is present
        v["semantic"] = tags
        v["instance"] = np.where(np.isin(tags, [4, 10]), 100_000 + g.integers(0, 4, n), 0)
        write_ply(town / "generated" / "frames" / f"frame_{k:04d}.ply", v)
        frames_out.append(v)
    if poses:
        (town / "generated" / "full_poses_lidar.txt").write_text("\n".join(lines) + "\n")
    return town, frames_out, pose_list
