"""``urbangen export kitti-object DIR OUT``: the KITTI 3D object layout (:mod:`generator.jobs.kitti_export`).

Every stereo pair of the dataset's LiDAR sequences becomes a KITTI sample: ``training/velodyne``,
``image_2``, ``image_3``, ``label_2`` (15 fields, KITTI type names), ``calib`` (P0-P3, R0_rect,
Tr_velo_to_cam, Tr_imu_to_velo), ``ImageSets/train.txt``, ``val.txt``; what OpenPCDet's and
MMDetection3D's KITTI converters read. Staged and moved in at the end: nothing half-written.
"""

from __future__ import annotations


def run(args) -> int:
    from generator.commands.preflight import input_dir, output_dir
    from generator.errors import UserError
    from generator.jobs.kitti_export import export_kitti_object
    from generator.jobs.plan import check_free_space

    root = input_dir(args.dataset, what="dataset folder")
    output_dir(args.out, "OUT")
    if args.out.resolve() == args.dataset.resolve():
        raise UserError(f"{args.out}: output must differ from the dataset folder")
    seqs = sorted((root / "lidar" / "sequences").glob("[0-9][0-9]/velodyne"))
    need = sum(p.stat().st_size for s in seqs for p in s.glob("*.bin")) // 5   # about one scan in ten is a pair
    check_free_space(args.out, need, "the KITTI export", flag="OUT")
    sequences = list(dict.fromkeys(args.sequences)) if args.sequences else None
    stats = export_kitti_object(root, args.out, sequences, args.min_points, args.val_share)
    print(f"exported {stats['samples']} KITTI samples to {args.out} (train {stats['train']}, val {stats['val']}); "
          "objects: " + ", ".join(f"{k} {v}" for k, v in stats["objects"].items()))
    return 0
