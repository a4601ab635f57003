"""``urbangen export nuscenes DIR OUT [--split train|val|test] [--spec SPEC]``.

See :mod:`generator.exports.nuscenes`.
"""

from __future__ import annotations

from generator.commands.preflight import input_dir, output_dir
from generator.errors import UserError
from generator.jobs.plan import check_free_space


def run(args) -> int:
    from generator.exports.nuscenes import VERSION, export_nuscenes, sequences_of
    from generator.jobs.sequence_boxes import dataset_spec

    root = input_dir(args.dataset, what="dataset folder")
    output_dir(args.out, "OUT")
    if args.out.resolve() == root.resolve():
        raise UserError(f"{args.out}: output must differ from the dataset folder")
    names = sequences_of(root)
    scans = [p for n in names for p in (root / "lidar" / "sequences" / n / "velodyne").glob("*.bin")]
    # a .pcd.bin row is 20 bytes where a .bin row is 16; images copied as they are
    images = [p for n in names for c in (2, 3) for p in (root / "lidar" / "sequences" / n / f"image_{c}").glob("*.png")]
    need = sum(p.stat().st_size for p in scans) * 5 // 4 + sum(p.stat().st_size for p in images) + 50_000_000
    check_free_space(args.out, need, f"{len(scans)} sweeps, {len(images)} images", flag="OUT")
    from generator.jobs.sequence_boxes import box_file_of

    # the boxes come from each sequence's box file; only a sequence without one needs the spec
    spec = None if all(box_file_of(root, n) for n in names) and args.spec is None else dataset_spec(root, args.spec)
    summary = export_nuscenes(root, args.out, spec, args.split, names)
    n = summary["tables"]
    print(f"exported {len(summary['scenes'])} scene(s) to {args.out} as nuScenes {VERSION}: {n['sample']} samples, "
          f"{n['sample_data']} sample_data, {n['sample_annotation']} annotations of {n['instance']} instances; "
          f"splits {', '.join(f'{k} ({len(v)})' for k, v in summary['splits'].items())}")
    return 0
