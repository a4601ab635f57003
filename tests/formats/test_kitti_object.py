"""KITTI label lines: round trip, the 15/16 fields, and one-line refusals naming line and field."""

from __future__ import annotations

import pytest

from generator.errors import SpecError
from generator.formats.kitti_object import KittiObject, calib_text, dont_care, parse_labels, write_labels


def test_lines_round_trip():
    objs = [KittiObject("Car", 0.12, 1, -1.57, (10.0, 20.5, 110.25, 90.0), (1.5, 1.8, 4.2), (2.0, 1.6, 15.5), 0.3),
            dont_care((0.0, 0.0, 5.0, 5.0))]
    text = write_labels(objs)
    assert [len(line.split()) for line in text.splitlines()] == [15, 15]
    again = parse_labels(text, "x.txt")
    assert again[0].type == "Car" and again[0].bbox == (10.0, 20.5, 110.25, 90.0)
    assert again[0].location == (2.0, 1.6, 15.5)
    assert again[1].type == "DontCare" and again[1].location == (-1000.0, -1000.0, -1000.0)
    scored = KittiObject(*objs[0].__dict__.values())
    assert len(KittiObject(**{**scored.__dict__, "score": 0.5}).line().split()) == 16


@pytest.mark.parametrize("line, where", [
    ("Car 0 0 0 1 2 3", "line 1"),                                   # truncated
    ("Bus 0 0 0 1 2 3 4 1 1 1 0 0 0 0", "line 1: type"),              # unknown type
    ("Car 0 0 0 1 2 3 4 1 1 1 0 inf 0 0", "line 1: y"),               # not finite
    ("Car 0 0 0 1 2 3 4 0 1 1 0 0 0 0", "line 1: h w l"),             # zero size
    ("Car 0 7 0 1 2 3 4 1 1 1 0 0 0 0", "line 1: occluded"),
])
def test_bad_lines_name_the_line_and_field(line, where):
    with pytest.raises(SpecError, match=f"lab.txt: {where}"):
        parse_labels(line + "\n", "lab.txt")


def test_predictions_need_a_score():
    with pytest.raises(SpecError, match="16 fields"):
        parse_labels("Car 0 0 0 1 2 3 4 1 1 1 0 0 0 0\n", "p.txt", predictions=True)


def test_calib_has_the_seven_kitti_lines_in_order():
    import numpy as np

    text = calib_text({f"P{i}": np.zeros((3, 4)) for i in range(4)}, np.eye(3), np.eye(4), np.eye(4))
    assert [ln.split(":")[0] for ln in text.splitlines()] == ["P0", "P1", "P2", "P3", "R0_rect", "Tr_velo_to_cam",
                                                              "Tr_imu_to_velo"]
    assert [len(ln.split()) - 1 for ln in text.splitlines()] == [12, 12, 12, 12, 9, 12, 12]
