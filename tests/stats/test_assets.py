"""Distinct meshes per kind over a dataset's sequences (generator/stats/assets.py)."""

from __future__ import annotations

import json

import pytest

from generator.errors import UserError
from generator.stats import assets, section_modules


def _seq(root, name: str, census) -> None:
    d = root / "lidar" / "sequences" / name
    d.mkdir(parents=True)
    (d / "lidar_meta.json").write_text(json.dumps({"format": "SemanticKITTI", "prototypes": census}))


def test_meshes_are_united_over_sequences_and_objects_summed(tmp_path):
    _seq(tmp_path, "00", {"car": {"objects": 5, "meshes": ["a", "b"]}, "person": {"objects": 2, "meshes": ["p"]}})
    _seq(tmp_path, "01", {"car": {"objects": 3, "meshes": ["b", "c"]}, "bench": {"objects": 1, "meshes": ["z"]}})
    data = assets.load(tmp_path)
    assert {k: len(v) for k, v in data.meshes.items()} == {"car": 3, "person": 1, "bench": 1}
    assert data.objects == {"car": 8, "person": 2, "bench": 1}
    table = assets.section(data).tables[0]
    assert table.rows[:2] == [["car", 3, 8], ["person", 1, 2]]             # issue 29's kinds first
    assert assets in section_modules()


def test_a_dataset_without_a_census_has_no_section(tmp_path):
    assert assets.load(tmp_path) is None
    _seq(tmp_path, "00", None)
    assert assets.load(tmp_path) is None


@pytest.mark.parametrize("census", [[1, 2], {"car": {"objects": "5", "meshes": []}}, {"car": {"objects": 1}}])
def test_a_malformed_census_is_one_line_naming_the_file(tmp_path, census):
    _seq(tmp_path, "00", census)
    with pytest.raises(UserError, match=r"lidar_meta.json: prototypes") as e:
        assets.load(tmp_path)
    assert "\n" not in str(e.value)
