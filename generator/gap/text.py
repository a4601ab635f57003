"""``gap.md`` and the charts of a ``gap`` report."""

from __future__ import annotations

from PIL import Image

from generator.gap.plots import line_chart

Y_LABELS = {"rays_lost_per_ring": "share of rays lost", "rays_lost_per_range": "share of rays lost",
            "points_per_range": "points per scan", "ring_regularity": "median |range - median5|, m",
            "ring_fit_vertical": "share of points", "intensity": "share of points",
            "intensity_per_class": "mean remission", "class_mix": "share of points",
            "points_per_object": "median points per object", "points_per_car": "median points per car"}


def _value(v) -> str:
    return "n/a" if v is None else f"{v:.4g}"


def markdown(report: dict) -> str:
    """The report as Markdown: datasets, then one table row per metric and pair."""
    pairs = report["pairs"]
    lines = ["# LiDAR domain gap (seed 002 §3.2, measured)", ""]
    for d in report["datasets"]:
        lines.append(f"* **{d['name']}** `{d['path']}`: {d['scans']} scans, {d['points_per_scan']:.0f} points per "
                     f"scan of {d['rays_per_scan']} rays; ring fit: {100 * d['ring_fit']['within_1cm_of_cone']:.1f} % "
                     f"of points within 1 cm of their laser's cone, {d['ring_fit']['cell_collisions_per_scan']:.0f} "
                     "points per scan share a cell")
    win = report.get("window")
    crop = ""
    if win:
        (a0, a1), (e0, e1) = win["azimuth_deg"], win["elevation_deg"]
        crop = f" Only rays and points within azimuth {a0:g}..{a1:g}° and elevation {e0:g}..{e1:g}° are compared."
    lines += ["", f"Ring fit with `{report['sensor']}`; points per object from "
              f"{report['objects_from'] or 'nowhere'}." + crop,
              "", "## Distances", "", "| metric | distance | unit | " + " | ".join(pairs) + " |",
              "|---|---|---|" + "---:|" * len(pairs)]
    for key, m in report["metrics"].items():
        if "skipped" in m:
            lines.append(f"| {key} | skipped: {m['skipped']} | | " + " | ".join("" for _ in pairs) + " |")
            continue
        dist = m["distance"]
        lines.append(f"| {key} | {dist['kind']} | {dist['unit']} | "
                     + " | ".join(_value(dist["values"][p]) for p in pairs) + " |")
    lines += ["", "## What each metric is", ""] + [f"* `{k}`: {m['what']}" for k, m in report["metrics"].items()]
    return "\n".join(lines) + "\n"


def charts(report: dict) -> dict[str, Image.Image]:
    """One chart per metric that was measured."""
    out = {}
    for key, m in report["metrics"].items():
        if "skipped" in m:
            continue
        dist = m["distance"]
        sub = f"{dist['kind']} ({dist['unit']}): " + ", ".join(f"{p} = {_value(v)}" for p, v in dist["values"].items())
        out[key] = line_chart(m["x_values"], m["curves"], key.replace("_", " "), m["x"], Y_LABELS.get(key, ""),
                              subtitle=sub[:150])
    return out
