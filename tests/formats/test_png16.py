"""16-bit PNGs: what we write is what OpenImageIO reads, and we read what libpng writes (any row filter)."""

from __future__ import annotations

import numpy as np
import OpenImageIO as oiio
import pytest

from generator.errors import UserError
from generator.formats.png16 import decode, encode, read_png16, write_png16


@pytest.mark.parametrize("shape", [(37, 53), (20, 31, 3)])
def test_round_trip_and_openimageio_reads_it(tmp_path, rng, shape):
    a = rng.integers(0, 65536, shape).astype(np.uint16)
    a[5:9] = 40000 + np.arange(shape[1])[:, None] if len(shape) == 3 else 40000 + np.arange(shape[1])  # smooth rows
    path = tmp_path / "a.png"
    write_png16(path, a)
    np.testing.assert_array_equal(read_png16(path), a)
    got = oiio.ImageBuf(str(path)).get_pixels(oiio.UINT16)
    np.testing.assert_array_equal(got.reshape(a.shape), a)


def test_reads_what_libpng_writes(tmp_path, rng):
    """OpenImageIO writes through libpng, which picks its own row filters (Sub, Average, Paeth...)."""
    y, x = np.mgrid[0:40, 0:70]
    a = np.stack([x * 900, y * 1500, (x * y * 17) % 65536], -1).astype(np.uint16)
    a[::7] = rng.integers(0, 65536, a[::7].shape)
    path = str(tmp_path / "lib.png")
    out = oiio.ImageOutput.create(path)
    out.open(path, oiio.ImageSpec(70, 40, 3, oiio.UINT16))
    out.write_image(a)
    out.close()
    np.testing.assert_array_equal(read_png16(path), a)


def test_damaged_files_are_one_line_errors(tmp_path):
    data = encode(np.arange(600, dtype=np.uint16).reshape(20, 30))
    bad_crc = bytearray(data)
    bad_crc[40] ^= 0xFF
    for blob, reason in ((data[:50], "truncated"), (bytes(bad_crc), "CRC"), (b"GIF89a", "not a PNG")):
        with pytest.raises(UserError, match=reason) as e:
            decode(blob, "x.png")
        assert "\n" not in str(e.value)


def test_only_uint16_is_written():
    with pytest.raises(ValueError):
        encode(np.zeros((4, 4), np.float32))
