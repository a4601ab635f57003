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

import contextlib
import ctypes
import io
import os
import re
import sys
import threading
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import OpenEXR

from generator import __version__, safeload
from generator.atomic import atomic_path
from generator.errors import UserError
from generator.labels import class_table
from generator.safeload import printable

DEPTH_DEFINITION = (
    "distance along the pixel ray from the camera centre to the rendered real geometry, metres; inf = sky"
)
#: Largest EXR file, image and channel count read (a 1920x1080 dataset image is ~10 MiB, ~40 channels).
MAX_EXR_BYTES = safeload.MAX_ARRAY_BYTES
MAX_PIXELS = 50_000_000
MAX_CHANNELS = 1024
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


_quiet = threading.Lock()
_quiet_state = {"depth": 0, "saved": []}


def _c_flush() -> None:
    try:
        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError, TypeError):  # no C library handle on this platform
        pass


@contextlib.contextmanager
def _c_output_silenced():
    """Send fds 1 and 2 to /dev/null while OpenEXR's C core runs.

    On a corrupt file the library prints its own lines ("EXR_ERR_BAD_CHUNK_LEADER ...",
    "Warning: Exception raised reading pixel data") straight to the process's stdout and
    stderr, bypassing Python; the reader turns the failure into one UserError instead.
    C stdio buffers are flushed before the fds are restored so nothing leaks out later.
    Threads reading EXRs at once share one redirection (the first in saves the fds, the
    last out restores them); other output of the process during a read is dropped.
    """
    with _quiet:
        if _quiet_state["depth"] == 0:
            for stream in (sys.stdout, sys.stderr):
                try:
                    stream.flush()
                except (AttributeError, OSError, ValueError):
                    pass
            _c_flush()
            try:
                devnull = os.open(os.devnull, os.O_WRONLY)
            except OSError:
                devnull = None
            saved = []
            if devnull is not None:
                for fd in (1, 2):
                    try:
                        saved.append((fd, os.dup(fd)))
                        os.dup2(devnull, fd)
                    except OSError:
                        pass
                os.close(devnull)
            _quiet_state["saved"] = saved
        _quiet_state["depth"] += 1
    try:
        yield
    finally:
        with _quiet:
            _quiet_state["depth"] -= 1
            if _quiet_state["depth"] == 0:
                _c_flush()
                for fd, copy in _quiet_state["saved"]:
                    os.dup2(copy, fd)
                    os.close(copy)
                _quiet_state["saved"] = []


def _open(data: bytes, path, header_only: bool):
    try:
        with _c_output_silenced(), OpenEXR.File(io.BytesIO(data), separate_channels=True,
                                                 header_only=header_only) as f:
            header = dict(f.header())
            channels = {} if header_only else {k: v.pixels for k, v in f.channels().items()}
    except Exception:  # noqa: BLE001 - OpenEXR raises bare RuntimeError/ValueError/Exception on bad files
        raise UserError(f"{printable(path)}: cannot read as EXR (truncated, corrupt or not an EXR file)") from None
    return header, channels


def _class_names(hdr: dict, path) -> list[str]:
    """The header's class list, every name known to the current class table, none twice."""
    table = class_table()
    names = str(hdr.get("urbangen.classes", ",".join(table.names))).split(",")
    where = f"{printable(path)}: urbangen.classes"
    for n in names:
        if n not in table.names:
            shown = repr(n) if re.fullmatch(r"[a-z0-9_]{1,40}", n) else "(not a class name)"
            raise UserError(f"{where}: class {shown} is not in the class table (generator/labels/classes.yaml); "
                            "was the file written by another version of urbangen?")
    if len(set(names)) != len(names):
        raise UserError(f"{where}: a class is listed twice")
    return names


def _read_checked(path: str | Path) -> tuple[bytes, dict, int, int]:
    """(file bytes, header, width, height) of an EXR whose size and channel count are within the limits
    (:data:`MAX_EXR_BYTES`, :data:`MAX_PIXELS`, :data:`MAX_CHANNELS`); one-line UserError otherwise."""
    data = safeload.read_bytes(path, max_bytes=MAX_EXR_BYTES)
    hdr, _ = _open(data, path, header_only=True)
    try:
        lo, hi = (np.asarray(v, np.int64) for v in hdr["dataWindow"])
        w, h = (int(v) + 1 for v in hi - lo)
        n_channels = len(hdr["channels"])
    except (KeyError, TypeError, ValueError):
        raise UserError(f"{printable(path)}: EXR header without a data window or channel list") from None
    if not (0 < w and 0 < h and w * h <= MAX_PIXELS) or n_channels > MAX_CHANNELS:
        raise UserError(f"{printable(path)}: EXR of {w}x{h} pixels and {n_channels} channels; at most "
                        f"{MAX_PIXELS} pixels and {MAX_CHANNELS} channels are read")
    return data, hdr, w, h


def read_exr(path: str | Path) -> LabelledImage:
    """Read a dataset EXR; the class map is rebuilt from the mask channels, matched to the current
    class table BY NAME (the header's ``urbangen.classes`` says which masks the file has).

    The file is read through :mod:`generator.safeload` (a regular file within
    :data:`MAX_EXR_BYTES`); its header is checked (size, channel count) before any pixel is
    decoded.

    Raises
    ------
    UserError
        If the file is not a (complete) EXR, is too large, lists a class the table does not
        know, lacks a channel, has channels of the wrong type or size, or its masks are not a
        partition. One line, never quoting the file.
    """
    data, hdr, w, h = _read_checked(path)
    names = _class_names({k: v for k, v in hdr.items() if isinstance(k, str)}, path)
    _, ch = _open(data, path, header_only=False)
    masks = {n: mask_channel(n) if mask_channel(n) in ch else f"mask.{n}" for n in names}
    missing = [c for c in ["R", "G", "B", "depth.Z", "instance.id"] + list(masks.values()) if c not in ch]
    if missing:
        raise UserError(f"{printable(path)}: missing channel(s) {', '.join(missing)}")
    for c in ["R", "G", "B", "depth.Z", "instance.id"] + list(masks.values()):
        kind = "iu" if c == "instance.id" else "f"
        if np.shape(ch[c]) != (h, w) or ch[c].dtype.kind not in kind:
            raise UserError(f"{printable(path)}: channel {c} must be {'UINT' if kind == 'iu' else 'HALF or FLOAT'} "
                            f"with {w}x{h} samples")
    table = class_table()
    class_id = np.zeros((h, w), np.uint8)
    hits = np.zeros((h, w), np.uint8)
    for n in names:
        m = ch[masks[n]]
        on = m == 1
        if not (on | (m == 0)).all():
            raise UserError(f"{printable(path)}: mask channels are not binary")
        class_id[on] = table.id(n)
        hits += on
    if not (hits == 1).all():
        raise UserError(f"{printable(path)}: masks do not partition the image (each pixel must be in exactly one mask)")
    rgb = np.stack([ch["R"], ch["G"], ch["B"]], -1).astype(np.float32)
    return LabelledImage(rgb, class_id, ch["instance.id"].astype(np.uint32), ch["depth.Z"].astype(np.float32),
                         {k: v for k, v in hdr.items() if isinstance(k, str) and k.startswith("urbangen.")})


def read_channels(path: str | Path, names: list[str]) -> tuple[dict[str, np.ndarray], dict]:
    """Channels ``names`` of any EXR (and its ``urbangen.*`` header), without decoding the label masks'
    class map: what a reader needing only depth and instances (:mod:`generator.motion`) reads.

    Raises
    ------
    UserError
        Not a (complete) EXR, too large, or a channel in ``names`` missing or of another size; one line.
    """
    data, hdr, w, h = _read_checked(path)
    _, ch = _open(data, path, header_only=False)
    missing = [c for c in names if c not in ch]
    if missing:
        raise UserError(f"{printable(path)}: missing channel(s) {', '.join(missing)}")
    for c in names:
        if np.shape(ch[c]) != (h, w):
            raise UserError(f"{printable(path)}: channel {c} must have {w}x{h} samples")
    return {c: ch[c] for c in names}, {k: v for k, v in hdr.items() if isinstance(k, str) and k.startswith("urbangen.")}


def channel_names(path: str | Path) -> list[str]:
    """The channel names of an EXR (its header only is decoded); a bad file is one line."""
    data = safeload.read_bytes(path, max_bytes=MAX_EXR_BYTES)
    hdr, _ = _open(data, path, header_only=True)
    chans = hdr.get("channels")
    try:
        return [c.name if hasattr(c, "name") else str(c) for c in chans]
    except TypeError:
        raise UserError(f"{printable(path)}: EXR header without a channel list") from None
