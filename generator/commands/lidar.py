"""``urbangen lidar SPEC --out DIR [--frames N] [--sequence NN] [--threads N] [--range-image]``.

Builds the scene of SPEC and casts the spec's LiDAR (default: the KITTI HDL-64E) along
route 0, one sweep per frame, writing a SemanticKITTI sequence to ``DIR/lidar/sequences/NN/``
(velodyne/*.bin, labels/*.label, poses.txt, calib.txt, times.txt, lidar_meta.json), a
bird's-eye PNG per scan in ``bev/``, and the dataset label config ``DIR/lidar/semantic-kitti.yaml``,
whose split lists every sequence in DIR: --split puts this one under train, valid or test
(default: the split it already has there, else valid, the split semantic-kitti-api evaluates
without -s).

A spec with ``town.redraw_every_frames`` needs ``--town I``: the sequence is then town ``I``'s, drawn
and driven as ``generate`` does (its own seed, from its own start), and ``lidar_meta.json`` records
the town (see :func:`generator.commands.layout.spec_for_town`).
"""

from __future__ import annotations

import logging
import os
from pathlib import Path

from generator.atomic import staging
from generator.commands.intensity import add_processing_args, spec_with_processing_args
from generator.commands.layout import add_town_argument, spec_for_town
from generator.commands.options import Integer, path, sequence_id, text_path
from generator.commands.preflight import output_dir
from generator.formats.label_config import SPLITS
from generator.formats.semantickitti import LIDAR_DIR
from generator.jobs.plan import MAX_FRAMES, check_free_space, scan_bytes
from generator.lidar.sensors import sensor_for_spec
from generator.remission.models import intensity_fn_for_spec
from generator.spec import load_spec
from generator.spec.render import load_render_config

log = logging.getLogger(__name__)


def register(sub) -> None:
    p = sub.add_parser("lidar", help="cast the virtual LiDAR along the route and write a SemanticKITTI sequence",
                       description=__doc__.split("\n\n")[1])
    p.add_argument("spec", type=text_path, help="scene spec JSON (e.g. scenes/default_town.json)")
    p.add_argument("--out", required=True, type=path, help="dataset folder (lidar/sequences/NN/ is written inside, as "
                                                                     "generate does)")
    p.add_argument("--frames", type=Integer(1, MAX_FRAMES), default=10,
                   help=f"number of consecutive 10 Hz sweeps (times.txt steps 0.1 s), 1..{MAX_FRAMES} "
                        "(default 10: one second of driving)")
    p.add_argument("--sequence", type=sequence_id, default="00", help="sequence number, 00..999999 (default 00)")
    p.add_argument("--threads", type=Integer(1, 256), default=None, help="casting threads, 1..256 (default: all cores)")
    p.add_argument(
        "--range-image", action="store_true", help="also save range/NNNNNN.npy (rings x columns, 0 = no return)"
    )
    p.add_argument("--ply", action="store_true", help="also save ply/NNNNNN.ply per scan")
    p.add_argument("--no-bev", action="store_true", help="skip the bird's-eye PNGs")
    p.add_argument("--render-config", type=text_path, default="preview",
                   help="render config (preset or YAML) whose resolution goes into calib.txt (default preview)")
    p.add_argument("--split", default=None, choices=SPLITS,
                   help="split of this sequence in DIR/semantic-kitti.yaml: train, valid or test "
                        "(default: the one it has there, else valid)")
    add_processing_args(p, weather=True)
    add_town_argument(p)
    p.set_defaults(func=run)


def run(args) -> int:
    # Every check on user input comes before anything is built or written.
    # the town last: re-parsing the spec (processing options) would drop its town index and asset seed
    spec = spec_for_town(spec_with_processing_args(load_spec(args.spec), args), args.town)
    cfg = load_render_config(args.render_config)
    sensor = sensor_for_spec(spec)
    intensity_fn = intensity_fn_for_spec(spec)
    name: str = args.sequence
    out: Path = output_dir(output_dir(args.out, "--out") / LIDAR_DIR, "--out")  # DIR/lidar, as generate writes it
    extras = {"range_image": args.range_image, "ply": args.ply, "bev": not args.no_bev}
    check_free_space(out, args.frames * scan_bytes(sensor.rays_per_sweep, **extras), f"{args.frames} scans")

    from generator.jobs.lidar_sequence import (
        SequenceOptions,
        check_sweeps,
        world_for,
        write_dataset_label_config,
        write_sequence,
    )
    from generator.layout.assemble import build_scene

    scene = build_scene(spec)
    check_sweeps(scene, spec, args.frames)
    world = world_for(spec, scene, args.frames)  # traffic problems are refused here, before any write
    opts = SequenceOptions(frames=args.frames, sequence=name, threads=args.threads, range_image=args.range_image,
                           ply=args.ply, bev=not args.no_bev, resolution=(cfg.width, cfg.height),
                           render_config=cfg.name)
    # The sequence is cast into a stage inside DIR and moved into place when complete: a failure
    # (or Ctrl-C) while casting and writing leaves DIR as it was.
    out.mkdir(parents=True, exist_ok=True)
    with staging(out, "lidar") as stage:
        meta = write_sequence(scene, spec, stage, opts, sensor=sensor, intensity_fn=intensity_fn, world=world)
        _move_in(stage / "sequences" / name, out / "sequences" / name, args.frames)
    write_dataset_label_config(out, args.split, [name] if args.split else None)
    pts = meta["points_per_scan"]
    print(f"wrote {len(pts)} scans to {out / 'sequences' / name} ({sensor.name}, "
          f"{min(pts)}-{max(pts)} points per scan, remission: {meta['remission']['model']})")
    return 0


def _move_in(new: Path, dest: Path, frames: int) -> None:
    """Move the finished sequence ``new`` to ``dest``: in one rename when ``dest`` is new, else file by
    file over the older run's files (renames only: no space needed), keeping what this command does not
    write (a generate dataset's stereo pairs) and dropping scans beyond ``frames``, as a rerun always did."""
    from generator.jobs.lidar_sequence import _remove_stale

    dest.parent.mkdir(parents=True, exist_ok=True)
    if not os.path.lexists(dest):
        os.replace(new, dest)
        return
    for folder, _, files in os.walk(new):
        target = dest / Path(folder).relative_to(new)
        target.mkdir(parents=True, exist_ok=True)
        for name in files:
            os.replace(Path(folder) / name, target / name)
    _remove_stale(dest, frames)
