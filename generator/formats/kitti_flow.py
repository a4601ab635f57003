"""KITTI's optical-flow and disparity PNGs (the KITTI flow 2015 / stereo 2015 devkit encodings).

=================  ===========================================================================
map                16-bit PNG
=================  ===========================================================================
flow               RGB: ``R = u * 64 + 2^15``, ``G = v * 64 + 2^15``, ``B = 1`` where the flow
                   is valid (``0, 0, 0`` elsewhere); ``u = (R - 2^15) / 64`` pixels, ``v`` alike
disparity          grey: ``d * 256``, 0 = no disparity; ``d = value / 256`` pixels
=================  ===========================================================================

Values are rounded to the nearest code (the devkit truncates; rounding halves the error to
1/128 px and 1/512 px). A flow beyond what 16 bits hold (``|u| or |v| > 511.98`` px) or a
disparity beyond 255.996 px is written invalid rather than clipped, so every valid code decodes
to the true value within half a code; the float arrays beside the PNGs keep them.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from generator.errors import UserError
from generator.formats.png16 import read_png16, write_png16

FLOW_SCALE, FLOW_OFFSET = 64.0, 2.0**15
DISP_SCALE = 256.0


def encode_flow(uv: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """(H, W, 3) uint16 KITTI flow codes of ``uv`` (H, W, 2) pixels where ``valid`` (H, W) bool."""
    code = np.rint(np.asarray(uv, np.float64) * FLOW_SCALE + FLOW_OFFSET)
    ok = np.asarray(valid, bool) & np.all((code >= 0) & (code <= 65535), axis=-1)
    out = np.zeros(uv.shape[:2] + (3,), np.uint16)
    out[ok, :2] = code[ok]
    out[ok, 2] = 1
    return out


def decode_flow(code: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """((H, W, 2) float32 flow in pixels, (H, W) bool valid) of KITTI flow codes (H, W, 3)."""
    c = np.asarray(code)
    valid = c[..., 2] > 0
    uv = np.where(valid[..., None], (c[..., :2].astype(np.float32) - FLOW_OFFSET) / FLOW_SCALE, 0.0)
    return uv.astype(np.float32), valid


def encode_disparity(d: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """(H, W) uint16 KITTI disparity codes of ``d`` (H, W) pixels where ``valid`` (0 elsewhere)."""
    code = np.rint(np.asarray(d, np.float64) * DISP_SCALE)
    ok = np.asarray(valid, bool) & (code > 0) & (code <= 65535)
    return np.where(ok, code, 0).astype(np.uint16)


def decode_disparity(code: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """((H, W) float32 disparity in pixels, (H, W) bool valid) of KITTI disparity codes."""
    c = np.asarray(code)
    return (c.astype(np.float32) / DISP_SCALE), c > 0


def write_flow_png(path: str | Path, uv: np.ndarray, valid: np.ndarray) -> None:
    """Write a KITTI flow PNG (atomically)."""
    write_png16(path, encode_flow(uv, valid))


def read_flow_png(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """((H, W, 2) float32, (H, W) bool) of a KITTI flow PNG."""
    code = read_png16(path)
    if code.ndim != 3:
        raise UserError(f"{path}: a KITTI flow map is an RGB PNG, this one is grey")
    return decode_flow(code)


def write_disparity_png(path: str | Path, d: np.ndarray, valid: np.ndarray) -> None:
    """Write a KITTI disparity PNG (atomically)."""
    write_png16(path, encode_disparity(d, valid))


def read_disparity_png(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """((H, W) float32, (H, W) bool) of a KITTI disparity PNG."""
    code = read_png16(path)
    if code.ndim != 2:
        raise UserError(f"{path}: a KITTI disparity map is a grey PNG, this one is RGB")
    return decode_disparity(code)
