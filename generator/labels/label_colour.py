"""The colour code of the label renders: exact integer ids in a float RGB sample.

The label material (:mod:`generator.blender.label_shader`) paints every camera sample with

* R, G -- class id and instance id of the surface the ray stopped at (a real surface, the sky
  or an opaque label proxy);
* B -- ``class + CODE_BASE * instance`` of the first label proxy the ray met, when that proxy
  was the first thing it hit; 0 otherwise.

With emission strength 1, one sample and no bounces Cycles stores these values exactly (float32
holds every integer below 2**24, and ``255 + 256 * 65535 = 2**24 - 1``). The mask label of a
sample is the proxy in B where B > 0, else the surface in R, G; the real surface is R, G on
rays that cross the proxies (pixel centres).
"""

from __future__ import annotations

import numpy as np

#: B = class + CODE_BASE * instance (classes are uint8).
CODE_BASE = 256
#: Largest B: class 255, instance 65535 -- still an exact float32 integer.
MAX_CODE = 255 + CODE_BASE * 65535


def encode(class_id: np.ndarray, instance: np.ndarray) -> np.ndarray:
    """The B value of proxies with these ids, as the shader computes it: (...) float32."""
    return (np.asarray(class_id, np.float32) + np.float32(CODE_BASE) * np.asarray(instance, np.float32))


def decode(rgb: np.ndarray, what: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Split a label render into mask labels and the stopping surface's ids.

    Parameters
    ----------
    rgb : (H, W, C) float32, C >= 3
        The render's combined pass (alpha, if present, is ignored).
    what : str
        Named in the error if a value is not an integer.

    Returns
    -------
    label_class : (H, W) uint8
    label_instance : (H, W) uint16
        The first label proxy where the ray met one first, else the surface it stopped at.
    class_id : (H, W) uint8
    instance : (H, W) uint16
        The surface the ray stopped at (R, G).

    Raises
    ------
    RuntimeError
        If a value is not an integer (labels would be blended) or outside its id range.
    """
    limits = (255, 65535, MAX_CODE)
    ids = []
    for ch, top in enumerate(limits):  # a plane at a time: a paper-size 5x label image is 1.2 GB of float32
        vals = rgb[..., ch]
        ints = np.rint(vals)
        bad = int(np.count_nonzero(np.abs(vals - ints) > 1e-3))
        if bad:
            raise RuntimeError(f"{what}: {bad} pixel values are not integers: labels would be blended")
        if ints.size and (ints.min() < 0 or ints.max() > top):
            raise RuntimeError(f"{what}: ids out of range (class 0..255, instance 0..65535, proxy code 0..{MAX_CODE})")
        ids.append(ints.astype(np.int32))
    cls, inst, code = ids
    met = code > 0
    label_cls = np.where(met, code % CODE_BASE, cls).astype(np.uint8)
    label_inst = np.where(met, code // CODE_BASE, inst).astype(np.uint16)
    return label_cls, label_inst, cls.astype(np.uint8), inst.astype(np.uint16)
