"""Label anti-aliasing: a per-pixel majority vote over a supersampled label image.

A label pass sampled once per pixel (at the pixel centre) aliases thin structures: a 15 cm
lane marking a few pixels wide at 30 m covers a pixel's centre in one frame and misses it in
the next when the camera moves by a few centimetres, so the marking's mask flickers. Rendering
the labels at ``k`` times the resolution (``k`` odd) and voting over each ``k x k`` block gives
each pixel the class that covers most of it: a class covering more than half of a pixel always
wins, so the mask moves smoothly with the geometry, and every pixel still holds one exact
class id (a vote never blends).

Ties are broken towards the class under the pixel centre (the middle sample of an odd ``k``:
exactly the ray a 1x label pass would cast), then towards the first sample in row-major order.
The instance id is voted among the samples of the winning class, the same way, so a pixel's
instance always belongs to its class.
"""

from __future__ import annotations

import numpy as np


def _blocks(a: np.ndarray, k: int) -> np.ndarray:
    """(k H, k W) -> (H, W, k * k): the samples of each output pixel, row-major."""
    kh, kw = a.shape
    return a.reshape(kh // k, k, kw // k, k).transpose(0, 2, 1, 3).reshape(kh // k, kw // k, k * k)


def _vote(values: np.ndarray, eligible: np.ndarray, centre: int) -> np.ndarray:
    """Index (H, W) of the winning sample: most equal eligible samples, centre first on ties."""
    n = values.shape[-1]
    count = np.zeros(values.shape, np.int16)
    for j in range(n):
        count += (values == values[..., j:j + 1]) & eligible[..., j:j + 1]
    score = 2 * count
    score[..., centre] += 1
    score[~eligible] = -1
    return np.argmax(score, axis=-1)


def majority_labels(class_id: np.ndarray, instance: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Reduce a ``k``-times supersampled label image to one class and instance per pixel.

    Parameters
    ----------
    class_id : (k H, k W) uint8
        Class per sample, rendered at ``k`` times the output resolution.
    instance : (k H, k W) uint16
        Instance id per sample.
    k : int
        Odd supersampling factor (1 returns the inputs unchanged).

    Returns
    -------
    class_id : (H, W) uint8
        The class covering most samples of each pixel (ties: the centre sample's class).
    instance : (H, W) uint16
        The most frequent instance among the samples of that class (ties: the centre's, if
        it has the winning class).

    Raises
    ------
    ValueError
        If ``k`` is not a positive odd integer or the shapes are not multiples of ``k``.
    """
    if k < 1 or k % 2 == 0:
        raise ValueError(f"supersampling factor must be a positive odd integer, got {k}")
    if class_id.shape != instance.shape or class_id.shape[0] % k or class_id.shape[1] % k:
        raise ValueError(f"label images {class_id.shape} / {instance.shape} are not {k}x a common resolution")
    if k == 1:
        return class_id, instance
    cls, inst = _blocks(class_id, k), _blocks(instance, k)
    centre = (k * k) // 2
    everywhere = np.ones(cls.shape, bool)
    win = _vote(cls, everywhere, centre)
    out_cls = np.take_along_axis(cls, win[..., None], -1)[..., 0]
    same_class = cls == out_cls[..., None]
    win_inst = _vote(inst, same_class, centre)
    out_inst = np.take_along_axis(inst, win_inst[..., None], -1)[..., 0]
    return np.ascontiguousarray(out_cls), np.ascontiguousarray(out_inst)
