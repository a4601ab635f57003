"""``urbangen lidar SPEC --out DIR [--frames N] [--sequence NN] [--threads N] [--range-image]``.

Builds the scene of SPEC and casts the spec's LiDAR (default: the KITTI HDL-64E) along
route 0, one sweep per frame, writing a SemanticKITTI sequence to ``DIR/sequences/NN/``
(velodyne/*.bin, labels/*.label, poses.txt, calib.txt, times.txt, lidar_meta.json), a
bird's-eye PNG per scan in ``bev/``, and the dataset label config ``DIR/semantic-kitti.yaml``,
whose split lists every sequence in DIR: --split puts this one under train, valid or test
(default: the split it already has there, else valid, the split semantic-kitti-api evaluates
without -s).
"""

from __future__ import annotations

import logging
import os
from pathlib import Path

from generator.commands.intensity import add_processing_args, spec_with_processing_args
from generator.errors import UserError
from generator.formats.label_config import SPLITS
from generator.formats.semantickitti import sequence_name
from generator.remission.models import intensity_fn_for_spec
from generator.lidar.sensors import sensor_for_spec
from generator.spec import load_spec
from generator.spec.render import load_render_config

log = logging.getLogger(__name__)


def register(sub) -> None:
    p = sub.add_parser("lidar", help="cast the virtual LiDAR along the route and write a SemanticKITTI sequence",
                       description=__doc__.split("\n\n")[1])
    p.add_argument("spec", help="scene spec JSON (e.g. scenes/default_town.json)")
    p.add_argument("--out", required=True, type=Path, help="dataset folder (sequences/NN/ is written inside)")
    p.add_argument("--frames", type=int, default=10,
                   help="number of scans (default 10, more than generate's 2 frames: scans are cheap, images are not)")
    p.add_argument("--sequence", default="00", help="sequence number, 00..99 (default 00)")
    p.add_argument("--threads", type=int, default=None, help="casting threads (default: all cores)")
    p.add_argument("--range-image", action="store_true", help="also save range/NNNNNN.npy (rings x columns, 0 = no return)")
    p.add_argument("--ply", action="store_true", help="also save ply/NNNNNN.ply per scan")
    p.add_argument("--no-bev", action="store_true", help="skip the bird's-eye PNGs")
    p.add_argument("--render-config", default="preview",
                   help="render config (preset or YAML) whose resolution goes into calib.txt (default preview)")
    p.add_argument("--split", default=None, choices=SPLITS,
                   help="split of this sequence in DIR/semantic-kitti.yaml: train, valid or test "
                        "(default: the one it has there, else valid)")
    add_processing_args(p, weather=True)
    p.set_defaults(func=run)


def run(args) -> int:
    # Every check on user input comes before anything is built or written.
    spec = spec_with_processing_args(load_spec(args.spec), args)
    cfg = load_render_config(args.render_config)
    sensor = sensor_for_spec(spec)
    intensity_fn = intensity_fn_for_spec(spec)
    name = sequence_name(args.sequence)
    if len(name) > 2:
        raise UserError(f"--sequence: must be 00..99, got {args.sequence!r}")
    if args.frames < 1:
        raise UserError(f"--frames: must be an integer >= 1, got {args.frames}")
    if args.threads is not None and not 1 <= args.threads <= 256:
        raise UserError(f"--threads: must be in 1..256, got {args.threads}")
    out: Path = args.out
    if out.exists() and not out.is_dir():
        raise UserError(f"--out: {out} exists and is not a folder")
    if out.exists() and not os.access(out, os.W_OK):
        raise UserError(f"--out: {out} is not writable")

    from generator.layout.assemble import build_scene
    from generator.jobs.lidar_sequence import SequenceOptions, check_frames, write_dataset_label_config, write_sequence

    scene = build_scene(spec)
    check_frames(scene, spec, args.frames)
    opts = SequenceOptions(frames=args.frames, sequence=name, threads=args.threads, range_image=args.range_image,
                           ply=args.ply, bev=not args.no_bev, resolution=(cfg.width, cfg.height), render_config=cfg.name)
    meta = write_sequence(scene, spec, out, opts, sensor=sensor, intensity_fn=intensity_fn)
    if args.split:
        write_dataset_label_config(out, args.split, [name])
    pts = meta["points_per_scan"]
    print(f"wrote {len(pts)} scans to {out / 'sequences' / name} ({sensor.name}, "
          f"{min(pts)}-{max(pts)} points per scan, remission: {meta['remission']['model']})")
    return 0
