"""The colour code of the label renders (generator.labels.label_colour), without Blender."""

from __future__ import annotations

import numpy as np
import pytest

from generator.labels.label_colour import MAX_CODE, decode, encode


def _render(real_cls, real_inst, proxy_cls, proxy_inst, met):
    """What Cycles stores per sample: float32 RGBA with the ids as the label material emits them."""
    b = np.where(met, encode(proxy_cls, proxy_inst), np.float32(0))
    a = np.ones(real_cls.shape, np.float32)
    return np.stack([real_cls.astype(np.float32), real_inst.astype(np.float32), b, a], -1)


def test_labels_and_real_ids_come_back_exactly_over_the_whole_id_range():
    g = np.random.default_rng(3)
    shape = (40, 60)
    real_cls = g.integers(1, 256, shape).astype(np.uint8)
    real_inst = g.integers(0, 65536, shape).astype(np.uint16)
    proxy_cls = g.integers(1, 256, shape).astype(np.uint8)
    proxy_inst = g.integers(0, 65536, shape).astype(np.uint16)
    proxy_cls[0, 0], proxy_inst[0, 0] = 255, 65535  # the largest code is still an exact float32 integer
    met = g.random(shape) < 0.3
    met[0, 0] = True
    lab_c, lab_i, c, i = decode(_render(real_cls, real_inst, proxy_cls, proxy_inst, met), "test")
    assert lab_c.dtype == c.dtype == np.uint8 and lab_i.dtype == i.dtype == np.uint16
    assert np.array_equal(c, real_cls) and np.array_equal(i, real_inst)
    assert np.array_equal(lab_c, np.where(met, proxy_cls, real_cls))
    assert np.array_equal(lab_i, np.where(met, proxy_inst, real_inst))
    assert encode(255, 65535) == MAX_CODE == 2**24 - 1


def test_blended_or_out_of_range_values_are_refused():
    one = np.ones((2, 2), np.uint8)
    rgb = _render(one, one.astype(np.uint16), one, one.astype(np.uint16), np.zeros((2, 2), bool))
    blended = rgb.copy()
    blended[1, 1, 0] = 1.5  # a filter or a second sample mixed two classes
    with pytest.raises(RuntimeError, match="test: 1 pixel values are not integers"):
        decode(blended, "test")
    for channel, value in ((0, 256.0), (1, 65536.0), (2, float(MAX_CODE + 1)), (2, -1.0)):
        bad = rgb.copy()
        bad[0, 0, channel] = value
        with pytest.raises(RuntimeError, match="out of range"):
            decode(bad, "test")
