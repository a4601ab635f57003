"""``urbangen export coco DIR OUT [--split NAME]``.

See :mod:`generator.exports.coco`.
"""

from __future__ import annotations

from generator.commands.preflight import input_dir, output_dir
from generator.errors import UserError
from generator.jobs.plan import check_free_space


def run(args) -> int:
    from generator.exports.coco import DEFAULT_SPLIT, export_coco, image_sources

    root = input_dir(args.dataset, what="dataset folder")
    output_dir(args.out, "OUT")
    if args.out.resolve() == root.resolve():
        raise UserError(f"{args.out}: output must differ from the dataset folder")
    split = args.split or DEFAULT_SPLIT
    sources = image_sources(root)
    # an 8-bit PNG, a panoptic PNG and the RLE masks: well under half the size of a dataset EXR (the
    # stereo passes are measured; images/ is counted at the size of the largest of them, or 8 MB)
    stereo = [w[0].stat().st_size for _, k, w in sources if k == "stereo"]
    per_image = max(stereo, default=8_000_000)
    need = sum(stereo) + per_image * sum(1 for _, k, _ in sources if k == "images")
    check_free_space(args.out, need // 2, f"{len(sources)} images", flag="OUT")
    summary = export_coco(root, args.out, split)
    print(f"exported {summary['images']} images to {args.out} as COCO {split}: {summary['annotations']} instance "
          f"annotations, {summary['segments']} panoptic segments")
    return 0
