"""``urbangen convert IN OUT --labels unified11 [--sequences 00,01]``.

Rewrites a SemanticKITTI-layout dataset (ours or anyone's) into the unified 11 classes of
seed 000: copies velodyne/*.bin, poses.txt, calib.txt and times.txt, rewrites every .label
(unified id in the low 16 bits, instance kept) and writes OUT/unified11.yaml (label config
in the layout of semantic-kitti.yaml) and OUT/conversion.json. Nothing is written on error.
The config's split lists every sequence in OUT; the converted ones go under --split, else
under their split in IN/semantic-kitti.yaml, else valid (what semantic-kitti-api evaluates
without -s).
"""

from __future__ import annotations

import os

from generator.commands.options import path, sequence_list
from generator.commands.preflight import input_dir, output_dir
from generator.formats.label_config import SPLITS
from generator.formats.relabel import TARGETS, convert_dataset
from generator.formats.semantickitti import semantickitti_root
from generator.jobs.plan import check_free_space


def register(sub) -> None:
    p = sub.add_parser("convert", help="relabel a SemanticKITTI-layout dataset into the unified 11 classes",
                       description=__doc__.split("\n\n")[1])
    p.add_argument("input", type=path, help="SemanticKITTI root (holds sequences/NN) or a dataset folder "
                                                "(lidar/sequences/NN)")
    p.add_argument("output", type=path, help="output dataset root")
    p.add_argument("--labels", required=True, choices=tuple(TARGETS), help="target label set")
    p.add_argument("--sequences", type=sequence_list, default=None,
                   help="comma-separated sequence numbers (default: all with labels)")
    p.add_argument("--split", default=None, choices=SPLITS,
                   help="split of the converted sequences in the written config: train, valid or test "
                        "(default: their split in IN/semantic-kitti.yaml, else valid)")
    p.set_defaults(func=run)


def run(args) -> int:
    input_dir(args.input, what="dataset folder")
    args.input = semantickitti_root(args.input)  # a dataset folder's lidar/ or a SemanticKITTI root
    output_dir(args.output, "OUT")
    check_free_space(args.output, _input_bytes(args.input, args.sequences), "a copy of the scans and labels",
                     flag="OUT")
    summary = convert_dataset(args.input, args.output, args.labels, args.sequences, split=args.split)
    print(f"converted {summary['scans']} scans of sequences {', '.join(summary['sequences'])} to {args.labels} "
          f"-> {args.output} ({summary['config']})")
    return 0


def _input_bytes(root, sequences: list[str] | None) -> int:
    """Bytes of the scans and labels a conversion copies (what it writes, give or take the text files)."""
    total = 0
    base = root / "sequences"
    try:
        names = sequences if sequences is not None else (
            [p.name for p in base.iterdir() if p.name.isdigit()] if base.is_dir() else [])
        for name in names:
            for sub in ("velodyne", "labels"):
                folder = base / name / sub
                if folder.is_dir():
                    total += sum(e.stat().st_size for e in os.scandir(folder) if e.is_file())
    except OSError:  # an estimate; the reader names the file that is wrong
        pass
    return total
