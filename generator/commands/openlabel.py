"""``urbangen openlabel SPEC DIR [--sequence NN] [--classes car truck person] [--min-points N]``.

Writes ``DIR/openlabel/NN.json`` (ASAM OpenLABEL 1.0, validated against its schema) for the
LiDAR sequence ``DIR/lidar/sequences/NN`` cast from SPEC: coordinate systems (odom,
vehicle-iso8855, lidar, camera), camera and LiDAR streams, the ego transform per frame, and
per frame a cuboid in the vehicle frame with the LiDAR point count of every object of the
chosen classes that has at least ``--min-points`` points (default
``spec.labels.openlabel_min_points``).
"""

from __future__ import annotations

import logging
from pathlib import Path


from generator.errors import UserError

log = logging.getLogger(__name__)

from generator.jobs.boxes import DEFAULT_CLASSES  # noqa: E402  (re-exported for the parser)


def register(sub) -> None:
    p = sub.add_parser("openlabel", help="OpenLABEL 1.0 cuboids with LiDAR point counts for a sequence",
                       description=__doc__.split("\n\n")[1])
    p.add_argument("spec", help="scene spec JSON the sequence was cast from")
    p.add_argument("dataset", type=Path, help="dataset folder (reads lidar/sequences/NN, writes openlabel/NN.json)")
    p.add_argument("--sequence", default="00", help="sequence (default 00)")
    p.add_argument("--classes", nargs="+", default=list(DEFAULT_CLASSES),
                   help=f"object classes (thing classes of the class table; default {' '.join(DEFAULT_CLASSES)})")
    p.add_argument("--min-points", type=int, default=None,
                   help="leave out objects with fewer LiDAR points in a frame (default: spec labels.openlabel_min_points)")
    p.set_defaults(func=run)


def run(args) -> int:
    from generator.formats.openlabel import object_counts
    from generator.jobs.boxes import write_sequence_openlabel
    from generator.labels import class_table
    from generator.spec import load_spec

    spec = load_spec(args.spec)
    table = class_table()
    bad = [c for c in args.classes if c not in table.names or not table[c].thing]
    if bad:
        things = [r.name for r in table.rows if r.thing]
        raise UserError(f"--classes: {', '.join(bad)} not a thing class; choose from {', '.join(things)}")
    min_points = spec.labels.openlabel_min_points if args.min_points is None else args.min_points
    if min_points < 0:
        raise UserError(f"--min-points: must be >= 0, got {min_points}")
    out, doc = write_sequence_openlabel(spec, args.dataset, args.sequence, args.classes, min_points)
    per = object_counts(doc)
    print(f"wrote {out}: {len(doc['openlabel']['frames'])} frames, " + ", ".join(
        f"{c}: {v['objects']} objects / {v['cuboids']} cuboids" for c, v in per.items()) + f" (>= {min_points} points)")
    return 0
