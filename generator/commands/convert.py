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

from pathlib import Path

from generator.commands.intensity import parse_sequences
from generator.errors import UserError
from generator.formats.label_config import SPLITS
from generator.formats.relabel import TARGETS, convert_dataset


def register(sub) -> None:
    p = sub.add_parser("convert", help="relabel a SemanticKITTI-layout dataset into the unified 11 classes",
                       description=__doc__.split("\n\n")[1])
    p.add_argument("input", type=Path, help="dataset root (holds sequences/NN)")
    p.add_argument("output", type=Path, help="output dataset root")
    p.add_argument("--labels", required=True, choices=tuple(TARGETS), help="target label set")
    p.add_argument("--sequences", default=None, help="comma-separated sequence numbers (default: all with labels)")
    p.add_argument("--split", default=None, choices=SPLITS,
                   help="split of the converted sequences in the written config: train, valid or test "
                        "(default: their split in IN/semantic-kitti.yaml, else valid)")
    p.set_defaults(func=run)


def run(args) -> int:
    if not args.input.is_dir():
        raise UserError(f"{args.input}: dataset folder not found")
    summary = convert_dataset(args.input, args.output, args.labels, parse_sequences(args.sequences),
                               split=args.split)
    print(f"converted {summary['scans']} scans of sequences {', '.join(summary['sequences'])} to {args.labels} "
          f"-> {args.output} ({summary['config']})")
    return 0
