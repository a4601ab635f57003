"""``urbangen stats DIR [--out OUT] [--verify]``.

Writes the dataset statistics of DIR into OUT (default DIR): ``stats.md`` with seed 003
Table I (annotated pixels per class, total and average per image) and Table II (images per
weather x time of day), the tables as CSV (``table1_pixels.csv``, ``table2_conditions.csv``)
and a bar chart ``pixels_per_class.png``; the LiDAR class mix; and seed 002 Table 1 (3D box annotations
per class, ``table1_annotations.csv``, from the box files). Reads the per-image metadata only; ``--verify``
also recomputes the pixel counts from the EXR masks and fails (exit 1, nothing written)
when they differ.
"""

from __future__ import annotations

import logging
import os
import sys
from pathlib import Path

from generator.atomic import staging
from generator.commands.options import path
from generator.commands.preflight import input_dir, output_dir
from generator.errors import UserError
from generator.stats import section_modules
from generator.stats.report import write_report

log = logging.getLogger(__name__)
EXIT_MISMATCH = 1


def register(sub) -> None:
    p = sub.add_parser("stats", help="dataset statistics: pixels per class, images per weather x time of day, "
                                     "boxes per class",
                       description=__doc__.split("\n\n")[1])
    p.add_argument("dataset", type=path, help="dataset folder (with images/*.json)")
    p.add_argument("--out", type=path, default=None, help="output folder (default: DIR/stats)")
    p.add_argument("--verify", action="store_true",
                   help="recompute pixel counts from the EXR masks; exit 1 listing the images that differ")
    p.set_defaults(func=run)


def run(args) -> int:
    root: Path = input_dir(args.dataset, what="dataset folder")
    out: Path = output_dir(args.out if args.out is not None else root / "stats", "--out")
    sections, problems = [], []
    for mod in section_modules():
        data = mod.load(root)
        if data is None:
            continue
        if args.verify and hasattr(mod, "verify"):
            problems += mod.verify(data)
        sections.append(mod.section(data))
    if not sections:
        raise UserError(f"{root}: no dataset found (expected images/*.json or LiDAR sequences)")
    if problems:
        for line in problems:
            print(f"urbangen stats: {line}", file=sys.stderr)
        print(f"urbangen stats: --verify: {len(problems)} image(s) disagree with their EXR; nothing written",
              file=sys.stderr)
        return EXIT_MISMATCH
    with staging(out, "stats") as stage:  # every file written in full before any is moved into place
        staged = write_report(stage, root, sections)
        paths = [out / p.name for p in staged]
        for p, dest in zip(staged, paths, strict=False):
            os.replace(p, dest)
    print(f"wrote {', '.join(p.name for p in paths)} into {out}")
    return 0
