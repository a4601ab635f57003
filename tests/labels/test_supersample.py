"""Label anti-aliasing by majority vote (generator.labels.supersample), without Blender."""

from __future__ import annotations

import numpy as np
import pytest

from generator.labels.supersample import majority_labels

ROAD, MARKING, CAR = 1, 2, 16


def _coverage_image(k: int, width_px: float, offset_px: float, h: int = 4, w: int = 12) -> np.ndarray:
    """A vertical marking ``width_px`` wide starting at ``offset_px``, sampled at k x k per pixel."""
    x = (np.arange(w * k) + 0.5) / k  # sample centres in output-pixel units
    row = np.where((x >= offset_px) & (x < offset_px + width_px), MARKING, ROAD).astype(np.uint8)
    return np.tile(row, (h * k, 1))


def test_labels_stay_exact_class_ids_of_the_samples():
    g = np.random.default_rng(0)
    cls = g.choice(np.array([0, ROAD, MARKING, CAR], np.uint8), size=(30, 45))
    inst = np.where(cls == CAR, g.integers(1, 4, cls.shape), 0).astype(np.uint16)
    out_c, out_i = majority_labels(cls, inst, 3)
    assert out_c.shape == (10, 15) and out_c.dtype == np.uint8 and out_i.dtype == np.uint16
    blocks = cls.reshape(10, 3, 15, 3).transpose(0, 2, 1, 3).reshape(10, 15, 9)
    assert all(out_c[i, j] in blocks[i, j] for i in range(10) for j in range(15))
    # an instance always belongs to the winning class: stuff pixels keep instance 0
    assert (out_i[out_c != CAR] == 0).all()
    assert (out_i[out_c == CAR] > 0).all()


def test_a_class_covering_most_of_a_pixel_wins_even_off_centre():
    cls = np.full((3, 3), ROAD, np.uint8)
    cls[:, :2] = MARKING  # 6 of 9 samples, not the centre column... the centre is (1, 1): marking
    cls[1, 1] = ROAD      # now the centre is road, the marking still covers 5 of 9
    out, _ = majority_labels(cls, np.zeros_like(cls, np.uint16), 3)
    assert out[0, 0] == MARKING


def test_ties_go_to_the_class_at_the_pixel_centre():
    cls = np.array([[ROAD, ROAD, CAR, CAR, MARKING]], np.uint8).repeat(5, 0)  # k=5: 10 road, 10 car, 5 marking
    cls[2, 2] = MARKING  # centre sample, marking: road 10, car 9... make road and car tie instead
    cls[0, 0] = CAR      # road 9, car 10
    cls[0, 1] = MARKING  # road 8, car 10: car wins outright
    out, _ = majority_labels(cls, np.zeros_like(cls, np.uint16), 5)
    assert out[0, 0] == CAR
    tie = np.array([[ROAD, CAR, ROAD], [CAR, CAR, ROAD], [ROAD, CAR, MARKING]], np.uint8)  # 4 road, 4 car, 1 marking
    out, _ = majority_labels(tie, np.zeros_like(tie, np.uint16), 3)
    assert out[0, 0] == CAR  # the centre (1, 1) is car
    tie[1, 1], tie[2, 2] = MARKING, CAR  # centre marking (1), road 4, car 4: first sample in row order
    out, _ = majority_labels(tie, np.zeros_like(tie, np.uint16), 3)
    assert out[0, 0] == ROAD


def test_instance_is_voted_among_the_winning_class():
    cls = np.array([[CAR, CAR, CAR], [CAR, ROAD, ROAD], [ROAD, ROAD, ROAD]], np.uint8)  # car 4, road 5
    inst = np.where(cls == CAR, 7, 0).astype(np.uint16)
    out_c, out_i = majority_labels(cls, inst, 3)
    assert (out_c[0, 0], out_i[0, 0]) == (ROAD, 0)
    cls[1, 1:] = CAR  # car 6: instances 7, 7, 7, 7, 9, 9
    inst = np.where(cls == CAR, 7, 0).astype(np.uint16)
    inst[1, 1:] = 9   # the centre is instance 9 but instance 7 covers more
    out_c, out_i = majority_labels(cls, inst, 3)
    assert (out_c[0, 0], out_i[0, 0]) == (CAR, 7)


def test_k1_is_the_identity_and_bad_factors_are_refused():
    cls = np.arange(12, dtype=np.uint8).reshape(3, 4)
    inst = np.zeros((3, 4), np.uint16)
    out_c, out_i = majority_labels(cls, inst, 1)
    assert np.array_equal(out_c, cls) and np.array_equal(out_i, inst)
    with pytest.raises(ValueError, match="odd"):
        majority_labels(cls, inst, 2)
    with pytest.raises(ValueError, match="3x"):
        majority_labels(np.zeros((4, 6), np.uint8), np.zeros((4, 6), np.uint16), 3)


def _coverage(width_px: float, offset_px: float, w: int = 12) -> np.ndarray:
    """(w,) exact fraction of each pixel covered by the marking."""
    lo = np.clip(offset_px - np.arange(w), 0, 1)
    hi = np.clip(offset_px + width_px - np.arange(w), 0, 1)
    return hi - lo


@pytest.mark.parametrize("width_px", [0.2, 0.3, 0.8, 1.4, 2.5])
def test_label_follows_coverage_as_the_marking_slides(width_px):
    """The property the vote exists for: a marking sliding by 1/20 px per frame is labelled by how
    much of each pixel it covers, not by whether it happens to cover the pixel centre.

    With k = 3, a pixel covered by at least 2/3 is always marked and one covered by less than 1/3
    never is, at every offset. The 1x pass breaks that for markings thinner than 1/3 px (a sliver
    over the pixel centre is marked); for wider ones a straight edge covers more than half of a
    pixel exactly when it covers its centre, so in 1D the two agree there.
    """
    broken_1x = False
    for off in 5.0 + np.arange(20) / 20:
        cov = _coverage(width_px, off)
        for k in (1, 3):
            cls = _coverage_image(k, width_px, off)
            out, _ = majority_labels(cls, np.zeros_like(cls, np.uint16), k)
            marked = (out == MARKING).all(0)
            assert ((out == MARKING) == marked).all()  # rows agree: a vertical marking
            ok = marked[cov >= 2 / 3].all() and not marked[cov < 1 / 3].any()
            if k == 3:
                assert ok, (off, cov, marked)
            else:
                broken_1x |= not ok
    assert broken_1x == (width_px < 1 / 3)


def test_render_config_option_is_validated_and_1_keeps_the_old_hash(tmp_path):
    from generator.errors import SpecError
    from generator.spec.render import load_render_config

    p = tmp_path / "r.yaml"
    base = "name: r\nresolution: [64, 64]\nsamples: 4\n"
    p.write_text(base)
    plain = load_render_config(p)
    assert plain.label_supersample == 1
    p.write_text(base + "label_supersample: 1\n")
    assert load_render_config(p).config_hash == plain.config_hash
    p.write_text(base + "label_supersample: 3\n")
    three = load_render_config(p)
    assert three.label_supersample == 3 and three.config_hash != plain.config_hash
    assert three.to_dict()["label_supersample"] == 3
    p.write_text(base + "label_supersample: 3.0\n")
    assert type(load_render_config(p).label_supersample) is int
    for bad in ("2", "0", "7", "-1", "'3'", "true"):
        p.write_text(base + f"label_supersample: {bad}\n")
        with pytest.raises(SpecError, match=r"r.yaml: label_supersample: "):
            load_render_config(p)
