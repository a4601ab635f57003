"""``urbangen validate DIR``: check every file of a dataset; list every problem; exit 1 if any."""

from __future__ import annotations

import sys
from pathlib import Path

from generator.commands.options import path
from generator.commands.preflight import input_dir
from generator.errors import UserError
from generator.jobs.validate import validate_dataset

EXIT_INVALID = 1


def register(sub) -> None:
    p = sub.add_parser("validate", help="check a dataset: EXR channels and masks, metadata, scans, labels, OpenLABEL",
                       description=__doc__.split(":", 1)[1].strip())
    p.add_argument("dataset", type=path, help="dataset folder (from urbangen generate)")
    p.set_defaults(func=run)


def run(args) -> int:
    root: Path = input_dir(args.dataset, what="dataset folder")
    problems, counts = validate_dataset(root)
    if not any(counts.values()):
        raise UserError(f"{root}: nothing to validate (no images/*.exr, lidar/sequences or openlabel/*.json)")
    for line in problems:
        print(line, file=sys.stderr)
    summary = (f"{counts['images']} images, {counts['scans']} scans, {counts['openlabel']} OpenLABEL files, "
               f"{counts['box files']} box files")
    if problems:
        print(f"urbangen validate: {len(problems)} problem(s) in {summary}", file=sys.stderr)
        return EXIT_INVALID
    print(f"valid: {summary}")
    return 0
