"""16-bit PNG files (grey or RGB), as KITTI's flow and disparity maps are stored.

Pillow writes no 16-bit RGB PNG and reads one as 8 bits, so this module writes and reads them
itself, following the PNG specification (ISO/IEC 15948): ``IHDR``, ``IDAT`` (zlib), ``IEND``;
16-bit samples big-endian. The writer uses the "Up" filter on every row (flow and disparity
change slowly from row to row, so the high bytes of the differences are mostly 0 and compress
well); the reader undoes any of the five filters, so it also reads what libpng or OpenCV wrote.
Interlaced files and palettes are refused (KITTI uses neither).
"""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

import numpy as np
from numba import njit

from generator import safeload
from generator.atomic import write_bytes
from generator.errors import UserError
from generator.safeload import printable

SIGNATURE = b"\x89PNG\r\n\x1a\n"
#: Largest PNG read, bytes (a 1920x1080 flow map is ~5 MiB at worst).
MAX_PNG_BYTES = 256 * 2**20
MAX_PIXELS = 50_000_000
_CHANNELS = {0: 1, 2: 3}  # PNG colour type -> samples per pixel (grey, RGB)


def _chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)


def encode(array: np.ndarray, level: int = 6) -> bytes:
    """The bytes of a 16-bit PNG of ``array``: (H, W) grey or (H, W, 3) RGB, uint16."""
    a = np.asarray(array)
    if a.dtype != np.uint16 or a.ndim not in (2, 3) or (a.ndim == 3 and a.shape[2] != 3):
        raise ValueError(f"need (H, W) or (H, W, 3) uint16, got {a.shape} {a.dtype}")
    h, w = a.shape[:2]
    rows = np.ascontiguousarray(a.astype(">u2")).view(np.uint8).reshape(h, -1)
    up = rows.copy()
    up[1:] -= rows[:-1]  # filter 2 ("Up"): byte minus the byte above, modulo 256
    raw = np.empty((h, up.shape[1] + 1), np.uint8)
    raw[:, 0] = 2
    raw[:, 1:] = up
    colour = 2 if a.ndim == 3 else 0
    ihdr = struct.pack(">IIBBBBB", w, h, 16, colour, 0, 0, 0)
    idat = zlib.compress(raw.tobytes(), level)
    return SIGNATURE + _chunk(b"IHDR", ihdr) + _chunk(b"IDAT", idat) + _chunk(b"IEND", b"")


def write_png16(path: str | Path, array: np.ndarray) -> None:
    """Write ``array`` (see :func:`encode`) as a 16-bit PNG at ``path`` (atomically)."""
    write_bytes(path, encode(array))


@njit(cache=True, boundscheck=False)
def _unfilter(data, h, stride, bpp, out):  # pragma: no cover - compiled
    """Undo the PNG row filters of ``data`` (h rows of 1 + stride bytes) into ``out`` (h, stride); False if bad."""
    for y in range(h):
        f = data[y * (stride + 1)]
        src = y * (stride + 1) + 1
        for x in range(stride):
            raw = np.int32(data[src + x])
            a = np.int32(out[y, x - bpp]) if x >= bpp else 0
            b = np.int32(out[y - 1, x]) if y > 0 else 0
            c = np.int32(out[y - 1, x - bpp]) if (x >= bpp and y > 0) else 0
            if f == 0:
                v = raw
            elif f == 1:
                v = raw + a
            elif f == 2:
                v = raw + b
            elif f == 3:
                v = raw + (a + b) // 2
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                v = raw + (a if (pa <= pb and pa <= pc) else (b if pb <= pc else c))
            else:
                return False
            out[y, x] = v & 0xFF
    return True


def decode(data: bytes, source: str = "PNG") -> np.ndarray:
    """(H, W) or (H, W, 3) uint16 samples of a 16-bit grey or RGB PNG (8-bit files are widened).

    Raises
    ------
    UserError
        Not a PNG, truncated, corrupt (CRC, zlib), interlaced, palette or alpha, or too large; one line.
    """
    where = printable(source)
    if not data.startswith(SIGNATURE):
        raise UserError(f"{where}: not a PNG file")
    pos, ihdr, idat = len(SIGNATURE), None, []
    while True:
        if pos + 8 > len(data):
            raise UserError(f"{where}: truncated PNG (no IEND chunk)")
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        crc = data[pos + 8 + n:pos + 12 + n]
        if len(body) != n or len(crc) != 4 or struct.unpack(">I", crc)[0] != zlib.crc32(kind + body) & 0xFFFFFFFF:
            raise UserError(f"{where}: corrupt PNG (chunk {printable(kind.decode('latin-1'), 8)} truncated or bad CRC)")
        pos += 12 + n
        if kind == b"IHDR":
            ihdr = struct.unpack(">IIBBBBB", body) if n == 13 else None
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            break
    if ihdr is None:
        raise UserError(f"{where}: PNG without a valid IHDR chunk")
    w, h, depth, colour, _, _, interlace = ihdr
    if colour not in _CHANNELS or depth not in (8, 16) or interlace != 0:
        raise UserError(f"{where}: a {depth}-bit PNG of colour type {colour}{' (interlaced)' if interlace else ''}; "
                        "only non-interlaced 8- or 16-bit grey or RGB PNGs are read")
    if not (0 < w and 0 < h and w * h <= MAX_PIXELS):
        raise UserError(f"{where}: PNG of {w}x{h} pixels; at most {MAX_PIXELS} pixels are read")
    ch, bps = _CHANNELS[colour], depth // 8
    stride = w * ch * bps
    try:
        raw = zlib.decompress(b"".join(idat), bufsize=h * (stride + 1))
    except zlib.error:
        raise UserError(f"{where}: corrupt PNG (image data does not decompress)") from None
    if len(raw) != h * (stride + 1):
        raise UserError(f"{where}: corrupt PNG (image data of the wrong size)")
    out = np.zeros((h, stride), np.uint8)
    if not _unfilter(np.frombuffer(raw, np.uint8), h, stride, ch * bps, out):
        raise UserError(f"{where}: corrupt PNG (unknown row filter)")
    px = out.view(">u2" if bps == 2 else np.uint8).astype(np.uint16)
    return px.reshape(h, w, ch) if ch == 3 else px.reshape(h, w)


def read_png16(path: str | Path) -> np.ndarray:
    """:func:`decode` of the file at ``path``, read through :mod:`generator.safeload`."""
    return decode(safeload.read_bytes(path, max_bytes=MAX_PNG_BYTES), str(path))
