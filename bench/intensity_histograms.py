"""Per-class intensity histograms of a generated default-town sequence under two intensity models.

    python bench/intensity_histograms.py --dataset DIR [--frames 5]
                                         [--models class_normal,physical] [--out PNG]

If the dataset lacks them, the sequences are generated first, one per model, with the CLI:
``urbangen lidar scenes/default_town.json --out DATASET --frames 5 --sequence 0i --intensity MODEL``.
Then, per SemanticKITTI class present, the remission histograms (40 bins on [0, 1], each
normalised to its class) of every model are drawn in one panel, with Table III's normal
density (the class_normal target, before clipping) as a black curve; a table of count,
mean, std and the share of exact 0 / 1 values per class and model is printed.
"""

from __future__ import annotations

import argparse
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw, ImageFont

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from generator.formats import semantickitti as sk  # noqa: E402
from generator.labels import class_table  # noqa: E402
from generator.remission.class_profiles import resolve_profile  # noqa: E402

COLORS = [(31, 119, 180), (255, 127, 14), (44, 160, 44), (214, 39, 40)]
BINS = 40


def generate(dataset: Path, models: list[str], frames: int, spec: Path) -> None:
    for i, model in enumerate(models):
        if (dataset / "lidar" / "sequences" / f"{i:02d}" / "poses.txt").is_file():
            continue
        cmd = [sys.executable, "-m", "generator.cli", "-q", "lidar", str(spec), "--out", str(dataset), "--frames",
               str(frames), "--sequence", f"{i:02d}", "--intensity", model, "--no-bev"]
        print(" ".join(cmd[2:]), flush=True)
        subprocess.run(cmd, check=True, cwd=ROOT)


def collect(dataset: Path, sequence: str) -> dict[int, np.ndarray]:
    """Remission per SemanticKITTI raw id over every scan of a sequence."""
    parts: dict[int, list[np.ndarray]] = {}
    for rec in sk.Sequence(dataset / "lidar", sequence):
        for raw in np.unique(rec.semantic):
            parts.setdefault(int(raw), []).append(rec.points[rec.semantic == raw, 3])
    return {k: np.concatenate(v) for k, v in parts.items()}


def draw(per_model: dict[str, dict[int, np.ndarray]], classes: list[int], out: Path) -> None:
    table = class_table()
    prof = resolve_profile(None)
    cols = 4
    rows = math.ceil(len(classes) / cols)
    pw, ph, pad, top = 330, 210, 36, 56
    img = Image.new("RGB", (cols * pw, top + rows * ph), "white")
    d = ImageDraw.Draw(img)
    font = ImageFont.load_default()
    x = 10
    d.text((10, 8), "urbangen: remission per SemanticKITTI class, default town, 5 scans "
           "(bars: share of the class's points per bin)", fill="black", font=font)
    for i, name in enumerate(per_model):
        d.rectangle([x, 30, x + 14, 42], fill=COLORS[i])
        d.text((x + 20, 30), name, fill="black", font=font)
        x += 20 + 8 * len(name) + 30
    d.line([x, 36, x + 20, 36], fill="black", width=2)
    d.text((x + 26, 30), "Table III normal density (class_normal target, before clipping to [0, 1])", fill="black",
           font=font)
    edges = np.linspace(0, 1, BINS + 1)
    for j, raw in enumerate(classes):
        ox, oy = (j % cols) * pw, top + (j // cols) * ph
        x0, y0, x1, y1 = ox + pad, oy + 22, ox + pw - 10, oy + ph - 26
        hists = {
            m: np.histogram(v.get(raw, np.zeros(0)), edges)[0] / max(len(v.get(raw, [])), 1)
            for m, v in per_model.items()
        }
        uni = table.unified_names[int(table.sk_to_unified[raw])]
        st = prof.unified[uni]
        pdf = (
            np.exp(-0.5 * ((edges[:-1] + 0.5 / BINS - st.mean) / st.std) ** 2)
            / (st.std * math.sqrt(2 * math.pi))
            / BINS
        )
        ymax = max(max(h.max() for h in hists.values()), pdf.max(), 1e-9) * 1.1
        d.rectangle([x0, y0, x1, y1], outline=(160, 160, 160))
        n = {m: len(v.get(raw, [])) for m, v in per_model.items()}
        d.text((x0, oy + 6), f"{raw} {table.sk_labels[raw]} -> {uni}  n={max(n.values()):,}", fill="black", font=font)
        bw = (x1 - x0) / BINS
        for i, h in enumerate(hists.values()):
            for b, v in enumerate(h):
                if v <= 0:
                    continue
                bx = x0 + b * bw + i * bw / len(hists)
                d.rectangle([bx, y1 - (y1 - y0) * v / ymax, bx + bw / len(hists) - 1, y1], fill=COLORS[i])
        pts = [(x0 + (b + 0.5) * bw, y1 - (y1 - y0) * p / ymax) for b, p in enumerate(pdf)]
        d.line(pts, fill="black", width=2)
        for t in (0.0, 0.5, 1.0):
            tx = x0 + t * (x1 - x0)
            d.line([tx, y1, tx, y1 + 4], fill="black")
            d.text((tx - 8, y1 + 6), f"{t:.1f}", fill="black", font=font)
        d.text((ox + 2, y0), f"{ymax:.2f}", fill=(90, 90, 90), font=font)
    out.parent.mkdir(parents=True, exist_ok=True)
    img.save(out)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--dataset", type=Path, required=True, help="scratch folder for the sequences it casts")
    ap.add_argument("--spec", type=Path, default=ROOT / "scenes" / "default_town.json")
    ap.add_argument("--frames", type=int, default=5)
    ap.add_argument("--models", default="class_normal,physical")
    ap.add_argument("--out", type=Path, default=None, help="PNG (default DATASET/intensity_histograms.png)")
    ap.add_argument("--min-points", type=int, default=200, help="leave out classes with fewer points")
    args = ap.parse_args()
    models = args.models.split(",")
    generate(args.dataset, models, args.frames, args.spec)
    per_model = {m: collect(args.dataset, f"{i:02d}") for i, m in enumerate(models)}
    table = class_table()
    classes = sorted(
        k
        for k in set().union(*per_model.values())
        if max(len(v.get(k, [])) for v in per_model.values()) >= args.min_points
    )
    print(f"{'class':<16}{'model':<14}{'points':>10}{'mean':>8}{'std':>8}{'=0':>8}{'=1':>8}")
    for raw in classes:
        for m, v in per_model.items():
            x = v.get(raw, np.zeros(0))
            print(f"{table.sk_labels[raw]:<16}{m:<14}{len(x):>10,}{x.mean():>8.3f}{x.std():>8.3f}"
                  f"{(x == 0).mean():>8.1%}{(x == 1).mean():>8.1%}")
    out = args.out or args.dataset / "intensity_histograms.png"
    draw(per_model, classes, out)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
