"""The agreement report as Markdown and a PNG (points over the labels, confusion matrix)."""

from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from generator.fusion.agreement import BOUNDARIES, HEADLINE, OCCLUSION, VARIANTS, FusedFrame, variant_key
from generator.labels import class_table

AGREE, DISAGREE, OCCLUDED, EXCLUDED = (40, 220, 60), (255, 40, 40), (60, 120, 255), (255, 210, 0)


def _pct(x) -> str:
    return "–" if x is None else f"{100 * x:.2f}"


def markdown(report: dict) -> str:
    """Markdown text of an :meth:`Agreement.to_dict` report."""
    s = report["settings"]
    hl = report["headline"]
    lines = [
        "# Camera–LiDAR label agreement",
        "",
        f"Dataset `{s['dataset']}`, sequence {s['sequence']}, frames {', '.join(map(str, report['frames']))}.",
        "",
        f"* Projection: seed 001 Eq. 1, `d [u v 1]^T = K T X` with `T = inv(T_world_camera) @ T_world_lidar` "
        f"(per-frame camera jitter included); de-skew: **{s['deskew']}**.",
        f"* Occlusion test: visible when `|distance - depth| <= max({s['abs_tol_m']} m, {100 * s['rel_tol']:g} % of "
        "distance)`, depth = rendered distance to the real geometry at the pixel centre or extrapolated (planar, "
        "in inverse depth) to the point's sub-pixel position.",
        f"* LiDAR classes: {s['lidar_classes']}.",
        f"* Points: {report['points']} in the scans, {report['in_view']} in front of the camera and inside the "
        f"image, {report['visible']} pass the occlusion test.",
        "",
        f"**Agreement, non-proxy classes away from 1-px mask boundaries, occlusion test on: "
        f"{_pct(hl['agreement_native'])} % (native), {_pct(hl['agreement_unified11'])} % (unified 11).**",
        "",
        "## Agreement per variant",
        "",
        "Agreement = share of counted points whose mask class equals their ray-cast class.",
        "",
        "| occlusion | proxies | boundaries | points | agreement native % | mIoU native % "
        "| agreement unified11 % | mIoU unified11 % |",
        "|---|---|---|---:|---:|---:|---:|---:|",
    ]
    nat, uni = (report["label_sets"][k]["variants"] for k in ("native", "unified11"))
    for v in VARIANTS:
        a, b = nat[variant_key(v)], uni[variant_key(v)]
        lines.append(f"| {v[0]} | {v[1]} | {v[2]} | {a['points']} | {_pct(a['agreement'])} | {_pct(a['miou'])} | "
                     f"{_pct(b['agreement'])} | {_pct(b['miou'])} |")
    hull = {class_table().names[i] for i in np.flatnonzero(class_table().hull_classes)}
    for name in ("native", "unified11"):
        lines += _class_table(report["label_sets"][name], name, hull if name == "native" else set())
    lines += _confusion_md(report["label_sets"]["native"], ("on", "included", "included"))
    lines += _worst_pairs(report["label_sets"]["native"], HEADLINE)
    return "\n".join(lines) + "\n"


def _class_table(ls: dict, name: str, hull: set[str]) -> list[str]:
    cols = [(o, "included", b) for b in BOUNDARIES for o in OCCLUSION]
    out = ["", f"## Per-class IoU % ({name}; proxies included)", "",
           "| class | LiDAR points in view | " + " | ".join(f"occl. {o}, bnd. {b}" for o, _, b in cols) + " |",
           "|---|---:|" + "---:|" * len(cols)]
    base = ls["variants"][variant_key(("off", "included", "included"))]
    for cname in ls["classes"]:
        n = base["lidar_points"].get(cname, 0)
        if not n and not any(cname in ls["variants"][variant_key(c)]["iou"] for c in cols):
            continue
        tag = f"{cname} (hull proxy)" if cname in hull else cname
        cells = [_pct(ls["variants"][variant_key(c)]["iou"].get(cname)) for c in cols]
        out.append(f"| {tag} | {n} | " + " | ".join(cells) + " |")
    return out


def _confusion_md(ls: dict, v: tuple[str, str, str]) -> list[str]:
    c = np.array(ls["variants"][variant_key(v)]["confusion_lidar_image"], np.int64)
    used = np.flatnonzero((c.sum(0) + c.sum(1)) > 0)
    names = ls["classes"]
    out = ["", f"## Confusion, native ({variant_key(v)})", "",
           "Rows: ray-cast LiDAR class; columns: mask class at the point's pixel.", "",
           "| LiDAR \\ image | " + " | ".join(names[j] for j in used) + " |", "|---|" + "---:|" * len(used)]
    for i in used:
        out.append(f"| {names[i]} | " + " | ".join(str(int(c[i, j])) for j in used) + " |")
    return out


def _worst_pairs(ls: dict, v: tuple[str, str, str], k: int = 12) -> list[str]:
    c = np.array(ls["variants"][variant_key(v)]["confusion_lidar_image"], np.int64)
    off = c.copy()
    np.fill_diagonal(off, 0)
    order = np.argsort(off, axis=None)[::-1][:k]
    names = ls["classes"]
    out = ["", f"## Remaining disagreements ({variant_key(v)})", ""]
    pairs = [(int(off.flat[i]), names[i // len(c)], names[i % len(c)]) for i in order if off.flat[i] > 0]
    if not pairs:
        return out + ["None."]
    out += ["| LiDAR class | image class | points |", "|---|---|---:|"]
    out += [f"| {a} | {b} | {n} |" for n, a, b in pairs]
    return out


def _font(size: int) -> ImageFont.ImageFont:
    try:
        return ImageFont.load_default(size=size)
    except TypeError:  # pragma: no cover - old Pillow
        return ImageFont.load_default()


def overlay_panel(class_id: np.ndarray, fused: FusedFrame, occlusion: bool, width: int = 640) -> Image.Image:
    """The mask (class colours, dimmed) with the projected points coloured by agreement.

    Green: image class = LiDAR class; red: different; blue: rejected by the occlusion test
    (only with ``occlusion``); yellow: left out of the headline figure (hull-proxy class or
    1-px boundary).
    """
    h, w = class_id.shape
    s = max(1, int(round(width / w)))
    bg = (class_table().colors[class_id].astype(np.float32) * 0.45).astype(np.uint8)
    img = Image.fromarray(np.repeat(np.repeat(bg, s, 0), s, 1), "RGB")
    draw = ImageDraw.Draw(img)
    hull = class_table().hull_classes
    p = fused.proj
    excluded = hull[fused.lidar_class] | hull[fused.image_class] | fused.boundary
    agree = fused.image_class == fused.lidar_class
    colour = np.where(agree[:, None], np.array(AGREE), np.array(DISAGREE))
    colour = np.where(excluded[:, None], np.array(EXCLUDED), colour)
    if occlusion:
        colour = np.where(fused.visible[:, None], colour, np.array(OCCLUDED))
    order = np.argsort(p.distance)[::-1]  # far first, near drawn on top
    r = max(1, s // 6)
    for i in order[:: max(1, len(order) // 60000)]:
        x, y = p.u[i] * s, p.v[i] * s
        draw.rectangle((x - r, y - r, x + r, y + r), fill=tuple(int(v) for v in colour[i]))
    n_dis = int((~agree & ~excluded & (fused.visible if occlusion else True)).sum())
    title = f"frame {fused.index}: occlusion test {'ON' if occlusion else 'OFF'} - {n_dis} disagreeing (red)"
    draw.rectangle((0, 0, img.width, 18), fill=(0, 0, 0))
    draw.text((4, 2), title, fill=(255, 255, 255), font=_font(13))
    return img


def confusion_panel(report: dict, label_set: str = "unified11",
                    variant: tuple[str, str, str] = ("off", "included", "included"), cell: int = 26) -> Image.Image:
    """Row-normalised confusion heatmap ``[LiDAR class, image class]`` with counts."""
    ls = report["label_sets"][label_set]
    c = np.array(ls["variants"][variant_key(variant)]["confusion_lidar_image"], np.float64)
    used = np.flatnonzero((c.sum(0) + c.sum(1)) > 0)
    c = c[np.ix_(used, used)]
    names = [ls["classes"][i] for i in used]
    norm = c / np.maximum(c.sum(1, keepdims=True), 1)
    left, top = 130, 150
    n = len(used)
    img = Image.new("RGB", (left + n * cell + 20, top + n * cell + 40), (255, 255, 255))
    d = ImageDraw.Draw(img)
    f = _font(11)
    d.text((4, 4), f"confusion {label_set}, {variant_key(variant)}", fill=(0, 0, 0), font=_font(13))
    d.text((4, 22), "rows: LiDAR class, columns: mask class; shade = row share", fill=(60, 60, 60), font=f)
    for j, name in enumerate(names):
        txt = Image.new("RGB", (top - 45, 14), (255, 255, 255))
        ImageDraw.Draw(txt).text((0, 0), name, fill=(0, 0, 0), font=f)
        img.paste(txt.rotate(90, expand=True), (left + j * cell + 6, 42))
    for i, name in enumerate(names):
        d.text((4, top + i * cell + 7), name, fill=(0, 0, 0), font=f)
        for j in range(n):
            v = norm[i, j]
            shade = tuple(int(255 - v * (255 - t)) for t in ((20, 120, 40) if i == j else (200, 30, 30)))
            x0, y0 = left + j * cell, top + i * cell
            d.rectangle((x0, y0, x0 + cell - 1, y0 + cell - 1), fill=shade, outline=(220, 220, 220))
            if c[i, j]:
                d.text((x0 + 2, y0 + 8), _short(c[i, j]), fill=(0, 0, 0) if v < 0.6 else (255, 255, 255), font=_font(9))
    return img


def _short(v: float) -> str:
    for div, unit in ((1e6, "M"), (1e3, "k")):
        if v >= div:
            return f"{v / div:.0f}{unit}" if v >= 10 * div else f"{v / div:.1f}{unit}"
    return f"{int(v)}"


def report_png(report: dict, class_id: np.ndarray, fused: FusedFrame) -> Image.Image:
    """Both overlays (occlusion off / on) above the confusion matrices (native, unified 11)."""
    panels = [overlay_panel(class_id, fused, False), overlay_panel(class_id, fused, True)]
    conf = [confusion_panel(report, "native", ("off", "included", "included")),
            confusion_panel(report, "native", ("on", "included", "included"))]
    legend_h = 22
    w = max(sum(p.width for p in panels), sum(c.width for c in conf)) + 10
    h = max(p.height for p in panels) + legend_h + max(c.height for c in conf)
    out = Image.new("RGB", (w, h), (255, 255, 255))
    x = 0
    for p in panels:
        out.paste(p, (x, 0))
        x += p.width + 10
    y = max(p.height for p in panels)
    d = ImageDraw.Draw(out)
    x = 4
    for colour, text in ((AGREE, "agree"), (DISAGREE, "disagree"), (OCCLUDED, "occluded (rejected)"),
                         (EXCLUDED, "hull-proxy class or 1-px boundary (not in the headline)")):
        d.rectangle((x, y + 5, x + 12, y + 17), fill=colour)
        d.text((x + 16, y + 4), text, fill=(0, 0, 0), font=_font(12))
        x += 30 + 8 * len(text)
    x = 0
    for c in conf:
        out.paste(c, (x, y + legend_h))
        x += c.width + 10
    return out
