"""Contact sheets: one frame's weather x time-of-day variants in a labelled grid."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from generator.atomic import atomic_path
from generator.imaging.exr import read_exr
from generator.previews.preview import camera_model_of, colorize, display_rgb
from generator.weather import DEFAULT_TIMES, KINDS, TIMES


def _caption(img: np.ndarray, text: str) -> np.ndarray:
    im = Image.fromarray(img)
    d = ImageDraw.Draw(im)
    d.rectangle([0, 0, 8 + 7 * len(text), 16], fill=(0, 0, 0))
    d.text((4, 2), text, fill=(255, 255, 255))
    return np.asarray(im)


def variants_sheet(images_dir: str | Path, frame: int, out_png: str | Path, scale: float = 0.5) -> list[str]:
    """Grid of every variant of ``frame`` found in ``images_dir`` (rows: weather; columns: day, dusk when the
    frame has dusk images, night, labels).

    Returns
    -------
    list of str
        The image names placed on the sheet.
    """
    images_dir = Path(images_dir)
    rows, names, label_tile = [], [], None
    times = [t for t in TIMES if t in DEFAULT_TIMES or any(images_dir.glob(f"{frame:06d}_{t}_*.exr"))]
    for kind in KINDS:
        tiles = []
        for tod in times:
            name = f"{frame:06d}_{tod}_{kind}"
            path = images_dir / f"{name}.exr"
            if not path.exists():
                tiles.append(None)
                continue
            img = read_exr(path)
            if label_tile is None:
                label_tile = _caption(colorize(img.class_id), "labels (shared by all variants)")
            tiles.append(_caption(display_rgb(img.rgb, camera_model_of(path)), f"{tod} / {kind}"))
            names.append(name)
        rows.append(tiles)
    if not names:
        raise FileNotFoundError(f"no images of frame {frame} in {images_dir}")
    h, w = label_tile.shape[:2]
    blank = np.full((h, w, 3), 255, np.uint8)
    grid = [np.concatenate([t if t is not None else blank for t in r] + [label_tile if i == 0 else blank], 1)
            for i, r in enumerate(rows)]
    sheet = Image.fromarray(np.concatenate(grid, 0))
    if scale != 1.0:
        sheet = sheet.resize((int(sheet.width * scale), int(sheet.height * scale)), Image.LANCZOS)
    with atomic_path(out_png, suffix=".png") as tmp:
        sheet.save(tmp, format="PNG")
    return names
