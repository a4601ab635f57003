"""``gap``'s pictures: one line chart per metric, every dataset a line, drawn with Pillow.

Like :mod:`generator.stats.chart` (no plotting library: Pillow is a dependency already). Numeric x axes
are linear; categorical ones (classes) get a tick per category with the name written upwards. Missing
values (None) break a line.
"""

from __future__ import annotations

import math

from PIL import Image, ImageDraw, ImageFont

#: Line colours, in dataset order (colour-blind-safe Okabe-Ito).
COLORS = [(0, 114, 178), (213, 94, 0), (0, 158, 115), (204, 121, 167), (230, 159, 0), (86, 180, 233)]
W, H = 900, 520
LEFT, RIGHT, TOP, BOTTOM = 80, 20, 60, 70


def _font(size: int) -> ImageFont.ImageFont:
    try:
        return ImageFont.load_default(size=size)
    except TypeError:  # pragma: no cover - old Pillow
        return ImageFont.load_default()


def _ticks(lo: float, hi: float, n: int = 6) -> list[float]:
    if hi <= lo:
        hi = lo + 1.0
    raw = (hi - lo) / n
    mag = 10 ** math.floor(math.log10(raw))
    step = next(m * mag for m in (1, 2, 2.5, 5, 10) if m * mag >= raw)
    first = math.ceil(lo / step) * step
    return [first + i * step for i in range(int((hi - first) / step + 1e-9) + 1)]


def _fmt(v: float) -> str:
    return f"{v:.3g}" if abs(v) < 1e4 else f"{v:.2e}"


def line_chart(x: list, series: dict[str, list], title: str, xlabel: str, ylabel: str, subtitle: str = "",
               bottom: int = BOTTOM) -> Image.Image:
    """A line chart of ``series`` (name -> y values, None = no value) over ``x`` (numbers or names)."""
    categorical = any(isinstance(v, str) for v in x)
    bottom = max(bottom, 150) if categorical else bottom
    img = Image.new("RGB", (W, H + bottom - BOTTOM), "white")
    d = ImageDraw.Draw(img)
    x0, x1, y0, y1 = LEFT, W - RIGHT, TOP, H + bottom - BOTTOM - bottom  # plot box
    xs = list(range(len(x))) if categorical else [float(v) for v in x]
    ys = [v for s in series.values() for v in s if v is not None]
    ylo, yhi = (min(ys), max(ys)) if ys else (0.0, 1.0)
    ylo = min(ylo, 0.0)
    yhi = yhi + 0.05 * (yhi - ylo) if yhi > ylo else ylo + 1.0
    xlo, xhi = (min(xs), max(xs)) if xs else (0.0, 1.0)
    xhi = xhi if xhi > xlo else xlo + 1.0

    def px(v: float) -> float:
        return x0 + (v - xlo) / (xhi - xlo) * (x1 - x0)

    def py(v: float) -> float:
        return y1 - (v - ylo) / (yhi - ylo) * (y1 - y0)

    d.rectangle((x0, y0, x1, y1), outline=(0, 0, 0))
    f = _font(12)
    for t in _ticks(ylo, yhi):
        d.line((x0 - 4, py(t), x1, py(t)), fill=(225, 225, 225))
        d.text((x0 - 8, py(t)), _fmt(t), fill=(0, 0, 0), font=f, anchor="rm")
    if categorical:
        for i, name in enumerate(x):
            d.line((px(i), y1, px(i), y1 + 4), fill=(0, 0, 0))
            label = Image.new("RGBA", (130, 16), (255, 255, 255, 0))
            ImageDraw.Draw(label).text((128, 8), str(name), fill=(0, 0, 0), font=f, anchor="rm")
            rot = label.rotate(60, expand=True)
            img.paste(rot, (int(px(i)) - rot.width + 4, y1 + 6), rot)
    else:
        for t in _ticks(xlo, xhi, 8):
            d.line((px(t), y1, px(t), y1 + 4), fill=(0, 0, 0))
            d.text((px(t), y1 + 8), _fmt(t), fill=(0, 0, 0), font=f, anchor="mt")
    for k, (name, ys_) in enumerate(series.items()):
        color = COLORS[k % len(COLORS)]
        if categorical:  # no line between categories: a marker each
            for xv, yv in zip(xs, ys_, strict=True):
                if yv is not None:
                    d.ellipse((px(xv) - 4, py(yv) - 4, px(xv) + 4, py(yv) + 4), outline=color, width=2)
        run: list[tuple[float, float]] = []
        for xv, yv in ([] if categorical else list(zip(xs, ys_, strict=True))) + [(None, None)]:
            if yv is None:
                if len(run) > 1:
                    d.line(run, fill=color, width=2)
                elif len(run) == 1:
                    d.ellipse((run[0][0] - 2, run[0][1] - 2, run[0][0] + 2, run[0][1] + 2), fill=color)
                run = []
            else:
                run.append((px(xv), py(yv)))
        d.rectangle((x0 + 10, y0 + 8 + 18 * k, x0 + 24, y0 + 20 + 18 * k), fill=color)
        d.text((x0 + 30, y0 + 6 + 18 * k), name, fill=(0, 0, 0), font=f)
    d.text((W // 2, 8), title, fill=(0, 0, 0), font=_font(16), anchor="mt")
    if subtitle:
        d.text((W // 2, 30), subtitle, fill=(60, 60, 60), font=f, anchor="mt")
    d.text(((x0 + x1) // 2, img.height - 8), xlabel, fill=(0, 0, 0), font=f, anchor="mb")
    ylab = Image.new("RGBA", (y1 - y0, 16), (255, 255, 255, 0))
    ImageDraw.Draw(ylab).text(((y1 - y0) // 2, 8), ylabel, fill=(0, 0, 0), font=f, anchor="mm")
    rot = ylab.rotate(90, expand=True)
    img.paste(rot, (6, y0), rot)
    return img


def grid(images: list[Image.Image], columns: int = 3) -> Image.Image:
    """Charts tiled ``columns`` wide (each cell as large as the largest chart)."""
    w, h = max(i.width for i in images), max(i.height for i in images)
    rows = math.ceil(len(images) / columns)
    out = Image.new("RGB", (w * columns, h * rows), "white")
    for k, im in enumerate(images):
        out.paste(im, ((k % columns) * w, (k // columns) * h))
    return out
