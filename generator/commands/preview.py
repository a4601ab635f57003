"""``urbangen preview DIR [--frames 0,3]``: contact sheets per frame.

``DIR/preview/NNNNNN.png``: RGB | colourised masks | LiDAR bird's-eye view by class;
``DIR/preview/NNNNNN_variants.png``: every weather x time-of-day variant of the frame.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np
from PIL import Image

from generator.atomic import atomic_path, staging
from generator.commands.options import integer_list, path
from generator.commands.preflight import input_dir, output_dir
from generator.errors import UserError
from generator.fusion.movers import is_moving_label
from generator.imaging import meta_fields as md
from generator.imaging.exr import read_exr
from generator.imaging.paths import image_files, images_root
from generator.jobs.plan import MAX_FRAME_INDEX
from generator.labels import class_table
from generator.previews.contact_sheet import variants_sheet
from generator.previews.preview import camera_model_of, colorize, display_rgb, side_by_side

PREFERRED = ("day_clear", "night_clear")
MIN_HEIGHT = 360


def _height(panel: np.ndarray, h: int, smooth: bool) -> np.ndarray:
    if panel.shape[0] == h:
        return panel
    w = int(round(panel.shape[1] * h / panel.shape[0]))
    return np.asarray(Image.fromarray(panel).resize((w, h), Image.BILINEAR if smooth else Image.NEAREST))


def register(sub) -> None:
    p = sub.add_parser("preview", help="contact sheets per frame: RGB | masks | LiDAR bird's-eye; all variants",
                       description=__doc__.split("\n\n")[1].strip())
    p.add_argument("dataset", type=path, help="dataset folder")
    p.add_argument("--frames", type=integer_list(0, MAX_FRAME_INDEX), default=None,
                   help="comma-separated frame numbers (default: all)")
    p.set_defaults(func=run)


def _frames(root: Path) -> dict[int, list[Path]]:
    out: dict[int, list[Path]] = {}
    for p in image_files(root, "*.exr"):
        m = re.match(r"^(\d{6})_", p.name)
        if m:
            out.setdefault(int(m.group(1)), []).append(p)
    return out


def _sequences(root: Path) -> list[tuple[Path, dict[int, int]]]:
    """Each LiDAR sequence folder of ``root`` with its image frame -> sweep pairs (read once per run)."""
    from generator.formats.semantickitti import list_sequences

    lidar = root / "lidar"
    if not (lidar / "sequences").is_dir():
        return []
    out = []
    for name in list_sequences(lidar):
        seq = lidar / "sequences" / name
        meta = seq / "lidar_meta.json"
        out.append((seq, md.image_sweeps(md.load_metadata(meta), str(meta)) if os.path.lexists(meta) else {}))
    return out


def _bev(sequences: list[tuple[Path, dict[int, int]]], frame: int, size: int) -> np.ndarray | None:
    from generator.formats.point_sidecars import NATIVE_DIR, read_sidecar
    from generator.formats.semantickitti import read_labels, read_scan
    from generator.previews.bev import bev_image

    for seq, sweeps in sequences:
        j = sweeps.get(frame, frame)  # the sweep the image was exposed with (a 10 Hz stream)
        scan = seq / "velodyne" / f"{j:06d}.bin"
        if not scan.exists():
            continue
        pts = read_scan(scan)
        native = read_sidecar(seq, NATIVE_DIR, j, len(pts))
        label = seq / "labels" / f"{j:06d}.label"
        sem = read_labels(label)[0] if os.path.lexists(label) else np.zeros(len(pts), np.uint16)
        if len(sem) != len(pts):
            raise UserError(f"{label}: {len(sem)} labels but the scan has {len(pts)} points")
        if native is None:
            t = class_table()
            native = np.array([t.from_semantickitti(int(r)) if r in t.sk_labels else 0 for r in sem], np.uint8)
        img = bev_image(pts[:, :3], native, extent_m=80.0, res_m=0.1, legend=False, title=f"scan {j:06d}",
                        moving=is_moving_label(sem))
        img = img.resize((size * img.width // img.height, size), Image.NEAREST)
        return np.asarray(img.convert("RGB"))
    return None


def run(args) -> int:
    root: Path = input_dir(args.dataset, what="dataset folder")
    if not images_root(root).is_dir():
        raise UserError(f"{root}: no images/ folder (is it a dataset from urbangen generate?)")
    frames = _frames(root)
    if args.frames is not None:
        missing = [k for k in args.frames if k not in frames]
        if missing:
            raise UserError(f"--frames: no images of frame(s) {', '.join(map(str, missing[:10]))}"
                            f"{' ...' if len(missing) > 10 else ''} in {images_root(root)}")
        frames = {k: frames[k] for k in args.frames}
    if not frames:
        raise UserError(f"{images_root(root)}: no images")
    out = output_dir(root / "preview", "")
    # Every sheet is made in a stage and moved into preview/ at the end: a bad EXR in the
    # last frame leaves no sheets of the first ones behind.
    sequences = _sequences(root)
    with staging(out, "preview") as stage:
        for k, paths in frames.items():
            _sheets(root, sequences, k, paths, stage)
        for p in sorted(stage.iterdir()):
            os.replace(p, out / p.name)
    print(f"wrote {len(frames)} preview sheet(s) into {out}")
    return 0


def _sheets(root: Path, sequences: list, k: int, paths: list[Path], out: Path) -> None:
    """The contact sheet of frame ``k`` (and its variants sheet) into ``out``."""
    pick = next((p for pref in PREFERRED for p in paths if p.stem.endswith(pref)), paths[0])
    img = read_exr(pick)
    h = max(img.class_id.shape[0], MIN_HEIGHT)
    panels = [_height(display_rgb(img.rgb, camera_model_of(pick)), h, True), _height(colorize(img.class_id), h, False)]
    bev = _bev(sequences, k, h)
    if bev is not None:
        panels.append(bev)
    with atomic_path(out / f"{k:06d}.png", suffix=".png") as tmp:
        Image.fromarray(side_by_side(panels)).save(tmp, format="PNG")
    if len(paths) > 1:
        variants_sheet(pick.parent, k, out / f"{k:06d}_variants.png", scale=1.0 if img.rgb.shape[1] <= 320 else 0.5)
