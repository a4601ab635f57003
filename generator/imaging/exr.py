"""The dataset's multilayer EXR: RGB, one binary mask channel per class, depth, instance.

Channel layout (one scanline part, ZIP compression by default):

===============  ======  ===========================================================
channel          type    content
===============  ======  ===========================================================
``R G B``        HALF    linear scene-referred RGB (the default layer)
``mask.<name>.V``  HALF  1.0 where the pixel's class is ``<name>``, else 0.0; one per
                         native class, in class-table order; exactly one is 1 per pixel
``depth.Z``      FLOAT   distance along the pixel's ray to the real geometry, metres;
                         +inf for sky
``instance.id``  UINT    instance id of the labelled surface (0 for stuff and sky)
===============  ======  ===========================================================

The mask channels are named ``mask.<class>.V`` (layer ``mask``, pass ``<class>``, channel
``V``): Blender's multilayer reader needs one-letter channel tokens and then shows each mask
as its own pass of a ``mask`` layer; OpenEXR and OpenImageIO read the names as they are.
Files with the two-part names ``mask.<class>`` are read too.

Header attributes: ``urbangen.classes`` (comma-separated class names, index = class id),
``urbangen.depth`` (the depth definition), ``urbangen.image`` and ``urbangen.version``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import OpenEXR

from generator import __version__
from generator.atomic import atomic_path
from generator.errors import UserError
from generator.labels import class_table

DEPTH_DEFINITION = "distance along the pixel ray from the camera centre to the rendered real geometry, metres; inf = sky"
CODECS = {"zip": OpenEXR.ZIP_COMPRESSION, "zips": OpenEXR.ZIPS_COMPRESSION, "piz": OpenEXR.PIZ_COMPRESSION,
          "none": OpenEXR.NO_COMPRESSION}


@dataclass
class LabelledImage:
    """One image as stored in the dataset.

    Attributes
    ----------
    rgb : (H, W, 3) float32
        Linear RGB.
    class_id : (H, W) uint8
        Native class per pixel (derived from the masks when read).
    instance : (H, W) uint32
    depth : (H, W) float32
        Metres along the ray; inf for sky.
    header : dict
        The ``urbangen.*`` header attributes.
    """

    rgb: np.ndarray
    class_id: np.ndarray
    instance: np.ndarray
    depth: np.ndarray
    header: dict = field(default_factory=dict)

    def masks(self) -> dict[str, np.ndarray]:
        """(H, W) bool mask per class name."""
        return {name: self.class_id == i for i, name in enumerate(class_table().names)}


def mask_channel(name: str) -> str:
    """EXR channel name of the mask of class ``name``."""
    return f"mask.{name}.V"


def mask_channels(class_id: np.ndarray) -> dict[str, np.ndarray]:
    """``mask.<name>.V`` -> (H, W) float16 binary channel for every native class."""
    return {mask_channel(name): (class_id == i).astype(np.float16) for i, name in enumerate(class_table().names)}


def write_exr(path: str | Path, image: LabelledImage, codec: str = "zip") -> None:
    """Write ``image`` as the dataset EXR at ``path`` (atomically)."""
    names = class_table().names
    if image.class_id.max(initial=0) >= len(names):
        raise ValueError(f"class id {int(image.class_id.max())} outside the class table")
    rgb = np.nan_to_num(image.rgb, nan=0.0, posinf=65504.0).clip(0, 65504).astype(np.float16)
    channels = {"R": rgb[..., 0], "G": rgb[..., 1], "B": rgb[..., 2]}
    channels.update(mask_channels(image.class_id))
    channels["depth.Z"] = image.depth.astype(np.float32)
    channels["instance.id"] = image.instance.astype(np.uint32)
    # The OpenEXR binding reads raw buffers and ignores numpy strides: every channel must be contiguous.
    channels = {k: np.ascontiguousarray(v) for k, v in channels.items()}
    header = {
        "compression": CODECS[codec],
        "type": OpenEXR.scanlineimage,
        "urbangen.classes": ",".join(names),
        "urbangen.depth": DEPTH_DEFINITION,
        "urbangen.version": __version__,
    }
    header.update({k: str(v) for k, v in image.header.items() if k.startswith("urbangen.")})
    with atomic_path(path, suffix=".exr") as tmp:
        with OpenEXR.File(header, channels) as f:
            f.write(str(tmp))


def read_exr(path: str | Path) -> LabelledImage:
    """Read a dataset EXR; the class map is rebuilt from the mask channels.

    Raises
    ------
    UserError
        If the file is not an EXR, lacks a channel, or its masks are not a partition.
    """
    try:
        f = OpenEXR.File(str(path), separate_channels=True)
    except Exception as e:  # OpenEXR raises a bare Exception/RuntimeError on bad files
        raise UserError(f"{path}: cannot read as EXR ({e})") from None
    with f:
        hdr = {k: v for k, v in f.header().items() if isinstance(k, str) and k.startswith("urbangen.")}
        ch = {k: v.pixels for k, v in f.channels().items()}
    names = str(hdr.get("urbangen.classes", ",".join(class_table().names))).split(",")
    masks = {n: mask_channel(n) if mask_channel(n) in ch else f"mask.{n}" for n in names}
    missing = [c for c in ["R", "G", "B", "depth.Z", "instance.id"] + list(masks.values()) if c not in ch]
    if missing:
        raise UserError(f"{path}: missing channel(s) {', '.join(missing)}")
    stack = np.stack([ch[masks[n]] for n in names]).astype(np.float32)
    if not np.isin(stack, (0.0, 1.0)).all():
        raise UserError(f"{path}: mask channels are not binary")
    if not (stack.sum(0) == 1).all():
        raise UserError(f"{path}: masks do not partition the image (each pixel must be in exactly one mask)")
    rgb = np.stack([ch["R"], ch["G"], ch["B"]], -1).astype(np.float32)
    return LabelledImage(rgb, stack.argmax(0).astype(np.uint8), ch["instance.id"].astype(np.uint32),
                         ch["depth.Z"].astype(np.float32), hdr)
