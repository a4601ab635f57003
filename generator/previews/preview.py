"""Preview PNGs: tone-mapped RGB beside the colourised labels (and optional extra panels).

Every 8-bit view of an image's RGB goes through :func:`display_rgb`: the camera's response
curve when the camera model made the image (its metadata has a ``camera_model`` section),
else the fixed-exposure :func:`tonemap` every image had before the model.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from generator.atomic import atomic_path
from generator.labels import class_table
from generator.postfx.camera_crf import crf_8bit

EXPOSURE = 1.6


def tonemap(rgb: np.ndarray, exposure: float = EXPOSURE) -> np.ndarray:
    """(H, W, 3) float linear RGB -> uint8 sRGB with a Reinhard curve at a fixed exposure.

    A fixed exposure keeps night images dark and day images bright, as they were rendered.
    """
    x = np.clip(np.nan_to_num(rgb) * exposure, 0, None)
    x = x / (1.0 + x)
    srgb = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
    return (np.clip(srgb, 0, 1) * 255 + 0.5).astype(np.uint8)


def display_rgb(rgb: np.ndarray, camera_model: dict | None = None) -> np.ndarray:
    """(H, W, 3) linear RGB -> uint8 sRGB as the image's camera shows it.

    Parameters
    ----------
    rgb : (H, W, 3) float
        The EXR RGB (or the array written into it).
    camera_model : dict, optional
        The image metadata's ``camera_model`` section: its response curve maps the (already
        exposed) RGB. None or absent (the model off, or a dataset from before it): :func:`tonemap`.
    """
    if camera_model and camera_model.get("enabled"):
        return crf_8bit(rgb, camera_model["crf"])
    return tonemap(rgb)


def camera_model_of(exr_path: str | Path) -> dict | None:
    """The ``camera_model`` section of the metadata JSON beside an EXR (None without one)."""
    from generator.imaging.meta_fields import load_metadata

    p = Path(exr_path).with_suffix(".json")
    if not os.path.lexists(p):
        return None
    model = load_metadata(p).get("camera_model")  # a FIFO, a folder or bad JSON is one line (SpecError)
    return model if isinstance(model, dict) else None


def colorize(class_id: np.ndarray) -> np.ndarray:
    """(H, W) native class ids -> (H, W, 3) uint8 class colours."""
    return class_table().colors[class_id]


def depth_panel(depth: np.ndarray, far: float = 120.0) -> np.ndarray:
    """(H, W) metres -> (H, W, 3) uint8 grey (near bright, far and sky dark)."""
    d = np.clip(1.0 - np.nan_to_num(depth, posinf=far) / far, 0, 1)
    return np.repeat((d * 255).astype(np.uint8)[..., None], 3, -1)


def side_by_side(panels: list[np.ndarray], gap: int = 4) -> np.ndarray:
    """Concatenate (H, W, 3) uint8 panels horizontally with a white gap."""
    h = panels[0].shape[0]
    sep = np.full((h, gap, 3), 255, np.uint8)
    out = [panels[0]]
    for p in panels[1:]:
        out += [sep, p]
    return np.concatenate(out, 1)


def legend(class_ids: np.ndarray, width: int) -> np.ndarray:
    """A strip naming the classes present, in their colours."""
    table = class_table()
    present = [int(c) for c in np.unique(class_ids)]
    row_h, cols = 14, max(1, width // 120)
    rows = (len(present) + cols - 1) // cols
    img = Image.new("RGB", (width, rows * row_h + 4), (255, 255, 255))
    d = ImageDraw.Draw(img)
    for i, c in enumerate(present):
        x, y = (i % cols) * 120 + 4, (i // cols) * row_h + 2
        d.rectangle([x, y + 2, x + 10, y + 12], fill=tuple(int(v) for v in table.colors[c]), outline=(0, 0, 0))
        d.text((x + 14, y + 1), table.names[c], fill=(0, 0, 0))
    return np.asarray(img)


def write_preview(path: str | Path, rgb: np.ndarray, class_id: np.ndarray, depth: np.ndarray | None = None,
                  camera_model: dict | None = None) -> None:
    """Write RGB | labels (| depth) with a class legend below, atomically, as PNG (RGB: :func:`display_rgb`)."""
    panels = [display_rgb(rgb, camera_model), colorize(class_id)]
    if depth is not None:
        panels.append(depth_panel(depth))
    top = side_by_side(panels)
    img = np.concatenate([top, legend(class_id, top.shape[1])], 0)
    with atomic_path(path, suffix=".png") as tmp:
        Image.fromarray(img).save(tmp, format="PNG", optimize=False)
