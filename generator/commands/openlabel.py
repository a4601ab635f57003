"""``urbangen openlabel SPEC DIR [--sequence NN] [--classes car person ...] [--min-points N]``.

Writes ``DIR/openlabel/NN.json`` (ASAM OpenLABEL 1.0, validated against its schema) and the box
file ``DIR/boxes/NN.npz`` (box records per sweep, visibility per image; 10 Hz streams) for the
LiDAR sequence ``DIR/lidar/sequences/NN`` cast from SPEC: coordinate systems (odom,
vehicle-iso8855, lidar, camera), camera and LiDAR streams, the ego transform per frame, and
per frame a cuboid in the vehicle frame with the LiDAR point count of every object of the
chosen classes that has at least ``--min-points`` points (default
``spec.labels.openlabel_min_points``). The file is written once the whole document is built
and valid; an existing file is replaced only when urbangen made it from the same spec (new
classes or threshold), never one made from another spec or by something else.
"""

from __future__ import annotations

import logging
import os
from pathlib import Path

from generator.commands.options import Integer, path, sequence_id, text_path
from generator.commands.preflight import input_dir, output_file
from generator.errors import UserError
from generator.labels.detection import detection_classes
from generator.safeload import MAX_METADATA_BYTES, load_json

log = logging.getLogger(__name__)

#: Largest --min-points (more points than a scan holds leaves every object out).
MAX_MIN_POINTS = 10_000_000


def register(sub) -> None:
    p = sub.add_parser("openlabel", help="OpenLABEL 1.0 cuboids with LiDAR point counts for a sequence",
                       description=__doc__.split("\n\n")[1])
    p.add_argument("spec", type=text_path, help="scene spec JSON the sequence was cast from")
    p.add_argument("dataset", type=path, help="dataset folder (reads lidar/sequences/NN, writes openlabel/NN.json)")
    p.add_argument("--sequence", type=sequence_id, default="00", help="sequence, 00..999999 (default 00)")
    boxes = list(detection_classes().boxes)
    p.add_argument("--classes", nargs="+", default=boxes,
                   help=f"box classes (generator/labels/detection.yaml; default all: {' '.join(boxes)})")
    p.add_argument("--min-points", type=Integer(0, MAX_MIN_POINTS), default=None,
                   help="leave out objects with fewer LiDAR points in a frame, 0..10000000 "
                        "(default: spec labels.openlabel_min_points)")
    p.set_defaults(func=run)


def check_replaceable(target: Path, spec) -> None:
    """Refuse to replace ``target`` unless it is an OpenLABEL file urbangen made from ``spec``.

    A file of the same spec is rewritten (other classes, another threshold); one from another
    spec, from another tool, or that cannot be read is the user's to keep.
    """
    if not os.path.lexists(target):
        return
    output_file(target, "")
    try:
        doc = load_json(target, max_bytes=4 * MAX_METADATA_BYTES, max_nodes=50_000_000)
        made = doc["openlabel"]["metadata"]["urbangen"]["spec_hash"]
    except (UserError, KeyError, TypeError):
        raise UserError(f"{target}: exists and is not an OpenLABEL file urbangen made; not replaced "
                        "(move it away first)") from None
    if made != spec.spec_hash:
        raise UserError(f"{target}: made from another spec (spec_hash {str(made)[:12]}, not {spec.spec_hash[:12]} "
                        f"of {spec.source}); not replaced (move it away first)")


def run(args) -> int:
    from generator.formats.openlabel import object_counts
    from generator.jobs.box_labels import write_sequence_boxes
    from generator.jobs.boxes import open_sequence, write_sequence_openlabel
    from generator.spec import load_spec

    spec = load_spec(args.spec)
    boxes = detection_classes().boxes
    bad = [c for c in args.classes if c not in boxes]
    if bad:
        raise UserError(f"--classes: {', '.join(bad[:5])} not a box class; choose from {', '.join(boxes)}")
    min_points = spec.labels.openlabel_min_points if args.min_points is None else args.min_points
    root = input_dir(args.dataset, what="dataset folder")
    check_replaceable(root / "openlabel" / f"{args.sequence}.json", spec)
    sw = open_sequence(spec, root, args.sequence)   # scene and world rebuilt once for both files
    out, doc = write_sequence_openlabel(spec, root, args.sequence, list(dict.fromkeys(args.classes)), min_points,
                                        scene=sw.scene, world=sw.world)
    per = object_counts(doc)
    print(f"wrote {out}: {len(doc['openlabel']['frames'])} frames, " + ", ".join(
        f"{c}: {v['objects']} objects / {v['cuboids']} cuboids" for c, v in per.items()) + f" (>= {min_points} points)")
    if sw.stream:
        path, stats = write_sequence_boxes(spec, root, args.sequence, scene=sw.scene, world=sw.world,
                                           min_points=min_points)
        print(f"wrote {path}: {stats['records']} box records, {stats['images']} images with visibility")
    return 0
