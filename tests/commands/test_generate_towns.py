"""`urbangen generate` with ``town.redraw_every_frames`` end to end (Blender, test preset, tiny).

Three frames at a new town every two frames: town 0 shows frames 0-1 (sequence 00), town 1
frame 2 (sequence 01). The dataset must validate, every image and scan must say which town
it shows, the workers must have rendered the town the LiDAR scanned (fusion agrees), and the
dataset reader must not pair an image with another town's scan.
"""

from __future__ import annotations

import json

import pytest

from generator.cli import main
from generator.dataset import Dataset
from generator.imaging.paths import image_files, image_path
from generator.layout import build_scene
from generator.spec import load_spec
from generator.spec.towns import town_spec

pytestmark = [pytest.mark.blender, pytest.mark.slow]


@pytest.fixture(scope="module")
def towns(tmp_path_factory, root):
    work = tmp_path_factory.mktemp("towns")
    doc = json.loads((root / "scenes" / "test_town.json").read_text())
    doc["town"]["redraw_every_frames"] = 2
    spec = work / "towns.json"
    spec.write_text(json.dumps(doc))
    out = work / "out"
    argv = ["-q", "generate", str(spec), "--config", "test", "--out", str(out), "--frames", "3",
            "--variants", "day:clear", "--workers", "1"]
    assert main(argv) == 0
    return load_spec(spec), out, argv


def test_redrawn_dataset_validates(towns, capsys):
    _, out, _ = towns
    capsys.readouterr()
    assert main(["validate", str(out)]) == 0
    assert "valid: 3 images" in capsys.readouterr().out
    assert sorted(p.name for p in (out / "lidar" / "sequences").iterdir()) == ["00", "01"]
    assert sorted(p.name for p in (out / "openlabel").glob("*.json")) == ["00.json", "01.json"]


def test_every_file_names_its_town_and_sequences_hold_one_town(towns):
    spec, out, _ = towns
    digests = {}
    for seq, town, frames in (("00", 0, [0, 1]), ("01", 1, [2])):
        meta = json.loads((out / "lidar" / "sequences" / seq / "lidar_meta.json").read_text())
        t = town_spec(spec, town)
        assert meta["scene"]["town"] == {"index": town, "seed": t.seed, "base_seed": spec.seed, "every_frames": 2}
        assert sorted(k for k, _ in meta["image_frames"]) == frames  # a sequence never spans two towns
        assert meta["scene"]["scene_digest"] == build_scene(t).digest()  # scanned the town its seed draws
        digests[seq] = meta["scene"]["scene_digest"]
        assert min(j for _, j in meta["image_frames"]) == 0  # every town drives from its own start
        for k in frames:
            img = json.loads(image_path(out, f"{k:06d}_day_clear", ".json").read_text())
            assert img["town"]["index"] == town and img["seed"] == t.seed
    assert digests["00"] != digests["01"]


def test_workers_rendered_the_scanned_town(towns, capsys):
    _, out, _ = towns
    assert main(["-q", "fuse", str(out), "--sequence", "01"]) == 0
    report = json.loads((out / "fusion" / "agreement.json").read_text())
    assert report["frames"] == [2]
    assert report["headline"]["agreement_native"] > 0.97


def test_reader_pairs_images_with_their_towns_scans(towns):
    _, out, _ = towns
    ds = Dataset(out, "01")
    f2, f0 = ds.frame(2), ds.frame(0)
    assert f2.scan is not None and f2.sweep == 0
    assert f0.scan is None and f0.sweep is None and f0.images  # town 0's image, not in sequence 01


def test_rerun_resumes_with_nothing_left(towns, capsys):
    _, out, argv = towns
    before = {p: p.stat().st_mtime_ns for p in image_files(out, "*.exr")}
    capsys.readouterr()
    assert main(argv[1:]) == 0
    assert "nothing left to render" in capsys.readouterr().out
    assert {p: p.stat().st_mtime_ns for p in image_files(out, "*.exr")} == before
