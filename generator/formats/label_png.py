"""Label-map PNGs from outside (a segmentation model's predictions): read and checked, one line per problem.

A label map is a single-channel PNG whose pixel values are class ids: 8-bit grey (``L``, what
cityscapesScripts' ``labelIds`` and most models write), 8-bit palette (``P``: the index is the id, as
PASCAL-style writers store it) or 16-bit grey (``I;16``, ``I``). Colour images (``RGB``, ``RGBA``), grey
with alpha (``LA``) and 1-bit images are not label maps and are refused, as cityscapesScripts refuses
"multiple channels". Every problem is one :class:`~generator.errors.SpecError` naming the file and the
field: ``mode``, ``size``, ``format`` or ``ids``.
"""

from __future__ import annotations

import io
import warnings
from pathlib import Path

import numpy as np
from PIL import Image

from generator.errors import SpecError
from generator.safeload import MiB, printable, read_bytes

#: PIL modes read as label maps (the array holds the ids).
LABEL_MODES = ("L", "P", "I;16", "I;16L", "I;16B", "I")
#: Largest label PNG read, bytes, and the most pixels it may hold (a 4K frame is 8.3 M).
MAX_PNG_BYTES = 256 * MiB
MAX_PIXELS = 64_000_000


def read_label_png(path: str | Path, shape: tuple[int, int] | None = None) -> np.ndarray:
    """(H, W) int64 class ids of a label PNG.

    Parameters
    ----------
    path : path-like
    shape : (H, W), optional
        The size the map must have (the image it labels).

    Raises
    ------
    SpecError
        ``<file>: format: ...`` not a PNG; ``<file>: mode: ...`` not single-channel; ``<file>: size:
        ...`` another size than ``shape``.
    """
    src = str(path)
    data = read_bytes(path, max_bytes=MAX_PNG_BYTES)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", Image.DecompressionBombWarning)
            img = Image.open(io.BytesIO(data))
            if img.format != "PNG":
                raise SpecError(src, "format", f"is {img.format or 'not an image'}, expected a PNG label map")
            w, h = img.size
            if w * h > MAX_PIXELS:
                raise SpecError(src, "size", f"{w} x {h} pixels, more than the {MAX_PIXELS} a label map may have")
            if img.mode not in LABEL_MODES:
                raise SpecError(src, "mode", f"is {printable(img.mode, 10)} ({len(img.getbands())} channel(s)); a "
                                "label map is one channel of class ids (8-bit L or P, 16-bit I;16)")
            if shape is not None and (h, w) != tuple(shape):
                raise SpecError(src, "size", f"{w} x {h} pixels, but the image it labels is {shape[1]} x {shape[0]}")
            arr = np.asarray(img)
    except SpecError:
        raise
    except (OSError, ValueError, SyntaxError, Image.DecompressionBombError, Image.DecompressionBombWarning) as e:
        raise SpecError(src, "format", f"not a readable PNG ({type(e).__name__})") from None
    if arr.ndim != 2:
        raise SpecError(src, "mode", "must be a single-channel label map")
    return arr.astype(np.int64, copy=False)


def check_ids(ids: np.ndarray, known: np.ndarray, source: str | Path, label_set: str) -> None:
    """Refuse pixel values that are no class of the label set.

    Parameters
    ----------
    ids : (H, W) integer
    known : (65536,) bool
        Which values are class ids (:attr:`generator.labels.class_sets.ClassSet.known`).

    Raises
    ------
    SpecError
        ``<file>: ids: values [..] are not classes of <label set>``.
    """
    values = np.unique(ids)
    bad = values[(values < 0) | (values >= len(known))]
    inside = values[(values >= 0) & (values < len(known))]
    bad = np.concatenate([bad, inside[~known[inside]]])
    if bad.size:
        shown = ", ".join(str(int(v)) for v in bad[:8]) + (", ..." if bad.size > 8 else "")
        raise SpecError(str(source), "ids", f"values [{shown}] are not classes of the label set {label_set}")
