"""What ``fuse --image-labels`` writes besides the label tree: Markdown, the two maps as PLY and pictures."""

from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw

from generator.atomic import atomic_path, write_bytes
from generator.formats.cityscapes import LABELS
from generator.fusion.prediction_score import HEADLINE, variant_key
from generator.fusion.semantic_map import _font, top_down_image
from generator.labels import class_table
from generator.labels.class_sets import ClassSet

DISAGREE, AGREE = (255, 40, 40), (120, 120, 120)


def palette(target: ClassSet) -> np.ndarray:
    """(size, 3) uint8 RGB per id of ``target``: the colour of its first base member (Cityscapes or native)."""
    base = class_table().colors if target.base == "native" else np.array([LABELS[i][3] for i in range(34)], np.uint8)
    out = np.zeros((target.size, 3), np.uint8)
    for cid in target.names:
        m = np.flatnonzero(target.from_base == cid)
        if len(m):
            out[cid] = base[m[0]]
    return out


def _pct(x) -> str:
    return "–" if x is None else f"{100 * x:.2f}"


def markdown(report: dict) -> str:
    """Markdown of a ``fuse --image-labels`` report."""
    s, cov = report["settings"], report["coverage"]
    hv = variant_key(HEADLINE)
    lines = [
        "# A model's image labels fused onto the LiDAR (seed 001)", "",
        f"Dataset `{s['dataset']}`, sequence {s['sequence']}; predictions `{s['predictions']}` "
        f"(label set {s['label_set']}); {len(report['views'])} images matched on {len(report['scans'])} scans.",
        f"* Projection and occlusion test as `urbangen fuse` (tolerance max({s['abs_tol_m']} m, "
        f"{100 * s['rel_tol']:g} % of distance); de-skew {s['deskew']}); a point seen by several images takes the "
        "majority label.",
        f"* Labelled points: {cov['labelled_occlusion_on']} of {cov['points']} "
        f"({_pct(cov['share_on'])} %) with the occlusion test, {cov['labelled_occlusion_off']} without.",
        f"* Scores: semantic-kitti-api conventions (confusion [prediction, truth], the set's void classes ignored "
        f"as truth only, mIoU over every scored class with absent ones as 0; the mean over present classes beside "
        f"it). Headline variant: {hv}.", "",
        "| label set | points mIoU % | points mIoU present % | accuracy % | map mIoU % | map mIoU present % |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    for name, per in report["points"].items():
        r = per[hv]
        m = report["map"] if name == s["map_set"] else None
        lines.append(f"| {name} | {_pct(r['miou'])} | {_pct(r['miou_present'])} | {_pct(r['accuracy'])} | "
                     f"{_pct(m['miou']) if m else '–'} | {_pct(m['miou_present']) if m else '–'} |")
    ms = s["map_set"]
    pts, mp = report["points"][ms][hv], report["map"]
    lines += ["", f"## Per class, {ms} ({hv}; map: {mp['voxels']} voxels of {s['voxel_m']} m)", "",
              "| class | truth points | points IoU % | truth voxels | map IoU % |", "|---|---:|---:|---:|---:|"]
    for cls in sorted(set(pts["iou"]) | set(mp["iou"])):
        lines.append(f"| {cls} | {pts['truth'].get(cls, 0)} | {_pct(pts['iou'].get(cls))} | "
                     f"{mp['truth'].get(cls, 0)} | {_pct(mp['iou'].get(cls))} |")
    return "\n".join(lines) + "\n"


def write_label_ply(path, xyz: np.ndarray, label: np.ndarray, count: np.ndarray, colors: np.ndarray,
                    comment: str) -> None:
    """Binary PLY of a voxel map: x, y, z (map frame, m), points per voxel, label id, its RGB."""
    dt = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("count", "<u4"), ("label", "<u2"),
                   ("red", "u1"), ("green", "u1"), ("blue", "u1")])
    v = np.empty(len(xyz), dt)
    v["x"], v["y"], v["z"] = xyz[:, 0], xyz[:, 1], xyz[:, 2]
    v["count"] = np.minimum(count, np.iinfo(np.uint32).max)
    v["label"] = label
    v["red"], v["green"], v["blue"] = colors[label].T
    types = {"<f4": "float", "<u4": "uint", "<u2": "ushort", "|u1": "uchar"}
    header = ["ply", "format binary_little_endian 1.0", f"comment {comment}", f"element vertex {len(v)}"]
    header += [f"property {types[dt[n].str]} {n}" for n in dt.names] + ["end_header"]
    write_bytes(path, ("\n".join(header) + "\n").encode("ascii") + v.tobytes())


def side_by_side(xyz: np.ndarray, pred: np.ndarray, truth: np.ndarray, target: ClassSet, trajectory: np.ndarray,
                 title: str) -> Image.Image:
    """Predicted map, ground-truth map and where they disagree, stacked, drawn from above at one scale."""
    colors, names = palette(target), target.class_names()
    lo, hi = xyz[:, :2].min(0) - 2.0, xyz[:, :2].max(0) + 2.0
    pa = top_down_image(xyz, pred, trajectory, colors=colors, names=names, bounds=(lo, hi),
                        title=f"predicted ({target.name})")
    pb = top_down_image(xyz, truth, trajectory, colors=colors, names=names, bounds=(lo, hi),
                        title="LiDAR ground truth")
    diff = np.array([AGREE, DISAGREE], np.uint8)
    wrong = (pred != truth).astype(np.int64)
    pc = top_down_image(xyz, wrong, trajectory, colors=diff, names=["agrees", "differs"], bounds=(lo, hi),
                        title="prediction vs truth")
    panels = (pa, pb, pc)
    out = Image.new("RGB", (max(p.width for p in panels), sum(p.height + 6 for p in panels) + 24), (24, 24, 24))
    for i, p in enumerate(panels):
        out.paste(p, (0, 24 + sum(q.height + 6 for q in panels[:i])))
    ImageDraw.Draw(out).text((8, 4), title, fill=(240, 240, 240), font=_font(14))
    return out


def save_png(path, image: Image.Image) -> None:
    with atomic_path(path) as tmp:
        image.save(tmp, format="PNG")
