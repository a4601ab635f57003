"""KITTI flow and disparity PNGs decode with KITTI's own formulas to the float maps they were made from."""

from __future__ import annotations

import numpy as np
import OpenImageIO as oiio

from generator.formats.kitti_flow import read_disparity_png, read_flow_png, write_disparity_png, write_flow_png


def _raw(path) -> np.ndarray:
    """The PNG's 16-bit samples as an independent decoder (OpenImageIO / libpng) reads them."""
    buf = oiio.ImageBuf(str(path))
    return buf.get_pixels(oiio.UINT16).astype(np.float64)


def test_flow_png_decodes_with_the_kitti_formula(tmp_path, rng):
    uv = rng.normal(0, 80, (48, 64, 2)).astype(np.float32)
    uv[0, :3] = [[600.0, 0.0], [-511.9, 3.0], [0.0, -520.0]]  # beyond 16 bits: written invalid
    valid = rng.random((48, 64)) > 0.3
    write_flow_png(tmp_path / "f.png", uv, valid)
    raw = _raw(tmp_path / "f.png")
    u, v, bit = (raw[..., 0] - 2**15) / 64.0, (raw[..., 1] - 2**15) / 64.0, raw[..., 2] > 0
    representable = np.all(np.abs(uv) < 511.99, axis=-1)
    np.testing.assert_array_equal(bit, valid & representable)
    assert np.abs(u - uv[..., 0])[bit].max() <= 1 / 128 + 1e-6
    assert np.abs(v - uv[..., 1])[bit].max() <= 1 / 128 + 1e-6
    assert (raw[~bit] == 0).all()
    ours, ok = read_flow_png(tmp_path / "f.png")
    np.testing.assert_array_equal(ok, bit)
    np.testing.assert_allclose(ours[ok], np.stack([u, v], -1)[ok], atol=1e-6)


def test_disparity_png_decodes_with_the_kitti_formula(tmp_path, rng):
    d = rng.uniform(0, 300, (30, 40)).astype(np.float32)
    valid = rng.random((30, 40)) > 0.2
    write_disparity_png(tmp_path / "d.png", d, valid)
    raw = _raw(tmp_path / "d.png")[..., 0]
    ok = raw > 0
    np.testing.assert_array_equal(ok, valid & (d * 256 <= 65535.5) & (np.rint(d * 256) > 0))
    assert np.abs(raw / 256.0 - d)[ok].max() <= 1 / 512 + 1e-6
    ours, ours_ok = read_disparity_png(tmp_path / "d.png")
    np.testing.assert_array_equal(ours_ok, ok)
    np.testing.assert_allclose(ours[ok], raw[ok] / 256.0)
