"""``lidar_meta.json`` names the backend that cast the sweeps, and both backends write the same scans."""

from __future__ import annotations

import pytest

from generator.jobs.lidar_sequence import SequenceOptions, write_sequence
from generator.lidar import embree_native


@pytest.mark.skipif(not embree_native.available(), reason="needs Embree called directly")
def test_without_the_direct_library_embreex_casts_the_same_bytes_and_the_metadata_says_so(
        test_spec, test_scene, tmp_path, monkeypatch):
    direct = write_sequence(test_scene, test_spec, tmp_path / "direct", SequenceOptions(frames=1, bev=False),
                            progress=False)
    monkeypatch.setattr(embree_native, "available", lambda: False)
    fallback = write_sequence(test_scene, test_spec, tmp_path / "embreex", SequenceOptions(frames=1, bev=False),
                              progress=False)
    assert direct["software"]["ray_casts"] == "Embree called directly"
    assert fallback["software"]["ray_casts"] == "embreex.run"
    for sub in ("velodyne/000000.bin", "labels/000000.label"):
        a = (tmp_path / "direct" / "sequences" / "00" / sub).read_bytes()
        assert a == (tmp_path / "embreex" / "sequences" / "00" / sub).read_bytes(), sub
