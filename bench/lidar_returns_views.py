"""Pictures of the physical LiDAR (generator/lidar/returns.py) to look at, and its return figures.

    python bench/lidar_returns_views.py --out FIGDIR [--spec scenes/default_town.json] [--sweeps 20]

Casts ``--sweeps`` consecutive sweeps of the spec's drive (traffic included) with the ideal sensor and
with the physical one (strongest), prints points per sweep and the share of rays returned for both
(and the mixed share), the mean remission per unified class beside seed 000's Table III, and writes:

* ``corner_mixed.png``: bird's-eye close-up of the building corner with the most mixed points,
  ideal points grey, physical points by class, mixed points red;
* ``range_car_windows.png``: range images (ideal, physical) cropped round the nearest car; pixels
  where the ideal sensor hit vehicle glass outlined in blue: the physical sensor's holes.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from generator.jobs.lidar_returns import return_model  # noqa: E402
from generator.jobs.lidar_sequence import world_for  # noqa: E402
from generator.labels import class_table  # noqa: E402
from generator.layout import build_scene  # noqa: E402
from generator.lidar.returns import frame_key  # noqa: E402
from generator.lidar.scan import Scanner  # noqa: E402
from generator.lidar.sensors import sensor_for_spec, with_returns  # noqa: E402
from generator.materials import material_table  # noqa: E402
from generator.remission.models import intensity_fn_for_spec  # noqa: E402
from generator.scan_effects.pipeline import process_scan, processing_for_spec  # noqa: E402
from generator.spec import load_spec  # noqa: E402
from generator.world.rig import SWEEP_PERIOD_S, Rig  # noqa: E402

TABLE3 = {"unlabeled": 0.148, "vehicle": 0.326, "person": 0.246, "road": 0.303, "sidewalk": 0.302,
          "other-ground": 0.361, "building": 0.295, "fence": 0.296, "vegetation": 0.299, "terrain": 0.342,
          "pole": 0.222, "traffic-sign": 0.499}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--spec", default=str(ROOT / "scenes" / "default_town.json"))
    ap.add_argument("--sweeps", type=int, default=20)
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    spec = load_spec(args.spec)
    scene = build_scene(spec)
    world = world_for(spec, scene, args.sweeps)
    rig = Rig.from_world(spec, world)
    phys_sensor = with_returns(sensor_for_spec(spec), "strongest")
    model = return_model(phys_sensor, spec.seed)
    cls, mats = class_table(), material_table()
    glass = np.flatnonzero(mats.transmittance > 0)
    scans = {"ideal": [], "physical": []}
    with Scanner(scene, phys_sensor, threads=2, world=world) as ideal, \
            Scanner(scene, phys_sensor, threads=2, world=world, returns=model) as phys:
        for j in range(args.sweeps):
            t = j * SWEEP_PERIOD_S
            scans["ideal"].append(ideal.sweep(rig, t))
            scans["physical"].append(phys.sweep(rig, t, noise_key=frame_key(spec.seed, j)))
    rays = phys_sensor.rays_per_sweep
    for k, v in scans.items():
        n = np.array([len(s.points) for s in v])
        mixed = np.mean([s.points["mixed"].mean() for s in v])
        print(f"{k:9s}: {n.mean():,.0f} points per sweep ({n.min():,}-{n.max():,}), {100 * n.mean() / rays:.1f} % of "
              f"{rays:,} rays; mixed {100 * mixed:.2f} %")
    # remission per unified class with the spec's intensity model and the physical sensor's laser gains
    proc = processing_for_spec(spec, phys_sensor, intensity_fn=intensity_fn_for_spec(spec))
    uni = cls.to_unified
    rem, ids = [], []
    for j, s in enumerate(scans["physical"]):
        pts, r, _ = process_scan(s.points, proc, spec, j)
        rem.append(r)
        ids.append(pts["class"])
    rem, ids = np.concatenate(rem), np.concatenate(ids)
    if uni is not None:
        names = cls.unified_names
        print("remission per unified class (physical sensor, laser gains) vs seed 000 Table III:")
        for u, name in sorted(names.items()):
            m = uni[ids] == u
            if m.sum() > 100 and name in TABLE3:
                print(f"  {name:14s} {rem[m].mean():.3f} (std {rem[m].std():.3f})  Table III {TABLE3[name]:.3f}")
    _corner(plt, scans, cls, out / "corner_mixed.png")
    _windows(plt, scans, glass, cls, out / "range_car_windows.png")
    return 0


def _corner(plt, scans, cls, path):
    """The 8 m square round the building corner with the most mixed points."""
    best = None
    for j, s in enumerate(scans["physical"]):
        p = s.points
        m = p[(p["mixed"] == 1) & (p["class"] == cls.id("building"))]
        if len(m) == 0:
            continue
        cell = np.floor(np.stack([m["x"], m["y"]], -1) / 4.0).astype(int)
        keys, count = np.unique(cell, axis=0, return_counts=True)
        i = count.argmax()
        if best is None or count[i] > best[0]:
            best = (count[i], j, (keys[i] + 0.5) * 4.0)
    if best is None:
        return
    _, j, c = best
    fig, ax = plt.subplots(figsize=(8, 8), dpi=120)
    for name, s, style in (("ideal", scans["ideal"][j], {"c": "0.75", "s": 6}),):
        p = s.points
        w = (np.abs(p["x"] - c[0]) < 4) & (np.abs(p["y"] - c[1]) < 4)
        ax.scatter(p["x"][w], p["y"][w], label=f"{name} (first hits)", **style)
    p = scans["physical"][j].points
    w = (np.abs(p["x"] - c[0]) < 4) & (np.abs(p["y"] - c[1]) < 4)
    clean, mixed = w & (p["mixed"] == 0), w & (p["mixed"] == 1)
    ax.scatter(p["x"][clean], p["y"][clean], c=cls.colors[p["class"][clean]] / 255.0, s=6, label="physical, by class")
    ax.scatter(p["x"][mixed], p["y"][mixed], c="red", s=14, label="physical, mixed")
    ax.set_aspect("equal")
    ax.set_xlabel("x (m, sensor frame)")
    ax.set_ylabel("y (m)")
    ax.set_title(f"sweep {j}: mixed points at a building corner ({int(mixed.sum())} mixed in view)")
    ax.legend(loc="upper right", fontsize=8)
    fig.savefig(path, bbox_inches="tight")
    plt.close(fig)
    print(f"wrote {path}")


def _windows(plt, scans, glass, cls, path):
    """Range images round the car 8-25 m away whose glass the ideal sensor hit most."""
    best = None
    for j, s in enumerate(scans["ideal"]):
        p = s.points
        g = p[np.isin(p["material"], glass) & (p["class"] == cls.id("car")) & (p["range"] > 8) & (p["range"] < 25)]
        if len(g) and (best is None or len(g) > best[0]):
            best = (len(g), j, int(np.median(g["column"])))
    if best is None:
        return
    _, j, col = best
    c0, c1 = max(0, col - 60), col + 60
    fig, axes = plt.subplots(2, 1, figsize=(12, 6), dpi=120)
    for ax, name in zip(axes, ("ideal", "physical"), strict=True):
        s = scans[name][j]
        img = s.range_image()[:, c0:c1]
        shown = np.where(img > 0, np.minimum(img, 40.0), np.nan)
        ax.set_facecolor("white")
        ax.imshow(shown, cmap="viridis", aspect="auto", interpolation="nearest", vmin=0, vmax=40)
        ideal = scans["ideal"][j].points
        g = ideal[np.isin(ideal["material"], glass) & (ideal["column"] >= c0) & (ideal["column"] < c1)
                  & (ideal["class"] == cls.id("car"))]
        ax.scatter(g["column"] - c0, g["ring"], s=10, facecolors="none", edgecolors="deepskyblue", linewidths=0.6)
        ax.set_title(f"{name} range image, sweep {j}, columns {c0}-{c1} (white: no return; blue rings: rays the ideal "
                     "sensor ended on car glass; colour: range 0-40 m)", fontsize=9)
        ax.set_ylabel("ring")
    axes[-1].set_xlabel("column")
    fig.savefig(path, bbox_inches="tight")
    plt.close(fig)
    print(f"wrote {path}")


if __name__ == "__main__":
    sys.exit(main())
