"""``urbangen gap SYNTH REAL [MORE ...] --out REPORT [--names A,B] [--reference NAME] [--pairwise]``.

Seed 002 §3.2 as measurements: how two (or more) LiDAR datasets differ -- rays lost per ring and per
range, points per range, ring regularity, intensity overall and per class, points per object against
distance, class mix -- each as one curve per dataset and a distance per pair (total variation or
Wasserstein-1, named in the report), written to REPORT/gap.json, REPORT/gap.md and one PNG per metric
(REPORT/gap_<metric>.png, all together in REPORT/gap.png). Datasets are SemanticKITTI-layout folders
(root with sequences/NN/velodyne, labels optional; rings and columns derived from the points with the
sensor's calibration, default the HDL-64E S3 table, see generator/gap/rings.py) or nuScenes roots
(v1.0-*/ tables, samples/LIDAR_TOP, lidarseg optional; the key frames, rings as recorded, sensor
hdl32e_20hz for nuScenes' 32 rings). Distances are to the last dataset named (--reference another one,
or --pairwise for every pair).
"""

from __future__ import annotations

import logging
from pathlib import Path

from generator.commands.options import Integer, path
from generator.commands.preflight import input_dir, output_dir
from generator.errors import UserError

log = logging.getLogger(__name__)
OBJECTS = ("auto", "boxes", "instances", "off")


def register(sub) -> None:
    p = sub.add_parser("gap", help="measure how LiDAR datasets differ (seed 002 §3.2): curves and distances",
                       description=__doc__.split("\n\n")[1])
    p.add_argument("datasets", nargs="+", type=path, metavar="DATASET",
                   help="SemanticKITTI-layout folders or nuScenes roots: SYNTH REAL, or more (raw, processed, "
                        "physics, real)")
    p.add_argument("--out", required=True, type=path, help="report folder (gap.json, gap.md, PNGs)")
    p.add_argument("--names", default=None, help="comma-separated names of the datasets (default: folder names)")
    p.add_argument("--reference", default=None, help="dataset the others are compared with (default: the last)")
    p.add_argument("--pairwise", action="store_true", help="compare every pair instead")
    p.add_argument("--sensor", default=None,
                   help="sensor table for the ring fit of every dataset: a preset (hdl64e, hdl32e, hdl32e_20hz, "
                        "vlp16) or a sensor YAML (default: each dataset's own -- hdl64e, the S3 calibration, for "
                        "SemanticKITTI layouts; for nuScenes roots hdl32e_20hz, or hdl64e when it has 64 rings)")
    p.add_argument("--nuscenes-version", default=None, metavar="V",
                   help="the v1.0-* folder of nuScenes roots that hold several (default: the only one)")
    p.add_argument("--every", type=Integer(1, 1000), default=1, help="read every N-th scan (default 1: all)")
    p.add_argument("--objects", default="auto", choices=OBJECTS,
                   help="points per object from boxes (OpenLABEL), instance labels, or off (default auto: boxes "
                        "when every dataset has them, else instances when every dataset has labels)")
    p.add_argument("--azimuth", default=None, metavar="LO:HI",
                   help="compare only rays and points within this azimuth range, degrees (x forward, +y = left is "
                        "+90); with --elevation, a cropped scan such as KITTI's velodyne_reduced: --azimuth=-40:40 "
                        "--elevation=-14:90 (write the = before a negative value; default: all)")
    p.add_argument("--elevation", default=None, metavar="LO:HI",
                   help="compare only beams whose elevation is within this range, degrees, up positive (default: all)")
    p.set_defaults(func=run)


def _names(args) -> list[str]:
    if args.names is None:
        names = [Path(p).absolute().name or str(p) for p in args.datasets]
        return [n if names.count(n) == 1 else f"{n}#{i + 1}" for i, n in enumerate(names)]
    names = [n.strip() for n in args.names.split(",")]
    if len(names) != len(args.datasets) or not all(names) or len(set(names)) != len(names):
        raise UserError(f"--names: give {len(args.datasets)} distinct non-empty names, comma-separated")
    return names


def _roles(n: int) -> list[str]:
    return ["SYNTH"] + [f"DATASET {i + 2}" for i in range(n - 2)] + ["REAL"]


def _sensor(arg: str):
    from generator.lidar.sensors import load_preset, load_sensor, preset_names

    if arg in preset_names():
        return load_preset(arg)
    if not arg.endswith((".yaml", ".yml")):
        raise UserError(f"--sensor: {arg!r} is neither a preset ({', '.join(preset_names())}) nor a .yaml file")
    return load_sensor(arg, arg)


def run(args) -> int:
    from generator.atomic import atomic_path, staging, write_json, write_text
    from generator.gap.measure import measure, objects_mode
    from generator.gap.plots import grid
    from generator.gap.report import pairs_of, summarize
    from generator.gap.sources import open_source
    from generator.gap.text import charts, markdown
    from generator.gap.window import parse_window

    if len(args.datasets) < 2:
        raise UserError("DATASET: name at least two datasets (SYNTH REAL)")
    roles = _roles(len(args.datasets))
    window = parse_window(args.azimuth, args.elevation)
    for p, role in zip(args.datasets, roles, strict=True):
        input_dir(p, role, "dataset folder")
    names = _names(args)
    reference = args.reference or names[-1]
    if reference not in names:
        raise UserError(f"--reference: {reference!r} is none of the names ({', '.join(names)})")
    sources = [open_source(p, role, args.every, args.nuscenes_version)
               for p, role in zip(args.datasets, roles, strict=True)]
    sensors = [_sensor(args.sensor or src.default_sensor()) for src in sources]
    mode = objects_mode(args.objects, sources)
    out = output_dir(args.out, "--out")
    profiles, records = {}, []
    for name, src, sensor in zip(names, sources, sensors, strict=True):
        prof, rec = measure(name, src, sensor, mode, window=window)
        rec["sensor"] = sensor.source
        profiles[name] = prof
        records.append(rec)
    pairs = pairs_of(names, reference, args.pairwise)
    report = {"datasets": records, "reference": None if args.pairwise else reference,
              "pairs": [f"{a} vs {b}" for a, b in pairs], "sensor": sensors[names.index(reference)].source,
              "objects_from": mode, "window": None if window.whole else window.to_dict(),
              "metrics": summarize(profiles, pairs, mode)}
    pictures = charts(report)
    with staging(out, "gap") as stage:
        write_json(stage / "gap.json", report)
        write_text(stage / "gap.md", markdown(report))
        for key, img in pictures.items():
            with atomic_path(stage / f"gap_{key}.png") as tmp:
                img.save(tmp, format="PNG")
        with atomic_path(stage / "gap.png") as tmp:
            grid(list(pictures.values())).save(tmp, format="PNG")
        for p in sorted(stage.iterdir()):
            p.replace(out / p.name)
    print(markdown(report).split("\n## ")[0].rstrip())
    print(f"wrote {out}/gap.json, gap.md, gap.png and {len(pictures)} charts")
    return 0
