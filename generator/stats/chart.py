"""Horizontal bar charts on a log scale, drawn with Pillow (no plotting library needed).

Pillow is already a dependency; a log-scale bar chart with class colours is a few dozen
lines, whereas matplotlib would add a large dependency (and ~1 s of import time) for it.
"""

from __future__ import annotations

import io
import math

from PIL import Image, ImageDraw, ImageFont


def _font(size: int) -> ImageFont.ImageFont:
    try:
        return ImageFont.load_default(size=size)  # scalable default font (Pillow >= 10.1 with FreeType)
    except TypeError:  # pragma: no cover - old Pillow
        return ImageFont.load_default()


def _fmt(v: float) -> str:
    for div, unit in ((1e12, "T"), (1e9, "G"), (1e6, "M"), (1e3, "k")):
        if v >= div:
            return f"{v / div:.3g}{unit}"
    return f"{v:.3g}"


def log_bar_chart(labels: list[str], values: list[float], colors: list[tuple[int, int, int]], title: str,
                  xlabel: str, width: int = 900) -> bytes:
    """A PNG of horizontal bars, one per label, with a log10 value axis.

    Parameters
    ----------
    labels : list of str
        Bar labels, drawn top to bottom in this order.
    values : list of float
        Non-negative values; zero bars are drawn empty and labelled ``0``.
    colors : list of (3,) int tuples
        RGB fill per bar (bars get a dark outline so black and white classes show).
    title, xlabel : str

    Returns
    -------
    bytes
        The encoded PNG.
    """
    font, small = _font(15), _font(12)
    bar_h, gap, top, bottom = 22, 6, 44, 48
    probe = ImageDraw.Draw(Image.new("RGB", (1, 1)))
    left = 16 + max((probe.textlength(s, font=font) for s in labels), default=0)
    left = int(left) + 8
    right = 70
    height = top + len(labels) * (bar_h + gap) + bottom
    img = Image.new("RGB", (width, height), (255, 255, 255))
    d = ImageDraw.Draw(img)
    d.text((left, 12), title, fill=(0, 0, 0), font=font)
    positive = [v for v in values if v > 0]
    lo = math.floor(math.log10(min(positive)) - 1e-9) if positive else 0  # the smallest bar is never empty
    hi = max(math.ceil(math.log10(max(positive))), lo + 1) if positive else 1
    span = width - left - right

    def x_of(v: float) -> float:
        return left + span * (math.log10(v) - lo) / (hi - lo)

    plot_bottom = top + len(labels) * (bar_h + gap)
    for e in range(lo, hi + 1):  # decade grid and tick labels
        x = x_of(10.0**e)
        d.line([(x, top - 4), (x, plot_bottom)], fill=(215, 215, 215))
        d.text((x, plot_bottom + 4), _fmt(10.0**e), fill=(60, 60, 60), font=small, anchor="ma")
    d.text((left + span / 2, plot_bottom + 24), xlabel, fill=(0, 0, 0), font=small, anchor="ma")
    for i, (label, v, c) in enumerate(zip(labels, values, colors, strict=False)):
        y = top + i * (bar_h + gap)
        d.text((left - 8, y + bar_h / 2), label, fill=(0, 0, 0), font=font, anchor="rm")
        x1 = x_of(v) if v > 0 else left
        d.rectangle([left, y, max(x1, left + 1), y + bar_h], fill=tuple(int(k) for k in c), outline=(40, 40, 40))
        d.text((x1 + 6, y + bar_h / 2), _fmt(v) if v > 0 else "0", fill=(0, 0, 0), font=small, anchor="lm")
    buf = io.BytesIO()
    img.save(buf, format="PNG")
    return buf.getvalue()
