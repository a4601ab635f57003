"""``urbangen lidar``: a small sequence end to end, and one-line exit-2 errors that write nothing."""

from __future__ import annotations

import json

import numpy as np
import pytest

import generator.cli as cli
from generator.formats import semantickitti as sk

pytest.importorskip("generator.layout.assemble")


@pytest.fixture(autouse=True)
def only_lidar(monkeypatch):
    # other sub-commands are being written in parallel; test this one on its own
    monkeypatch.setattr(cli, "COMMANDS", ["lidar"])


def test_lidar_command_writes_a_sequence(root, tmp_path, capsys):
    out = tmp_path / "ds"
    rc = cli.main(["-q", "lidar", str(root / "scenes" / "test_town.json"), "--out", str(out), "--frames", "2",
                   "--sequence", "7", "--range-image", "--threads", "2"])
    assert rc == 0
    seq = out / "lidar" / "sequences" / "07"
    for name in ("calib.txt", "poses.txt", "times.txt", "lidar_meta.json"):
        assert (seq / name).is_file(), name
    for k in range(2):
        for sub, ext in (("velodyne", "bin"), ("labels", "label"), ("bev", "png"), ("range", "npy")):
            assert (seq / sub / f"{k:06d}.{ext}").is_file()
        rng_img = np.load(seq / "range" / f"{k:06d}.npy")
        assert rng_img.shape == (64, 2083)
        assert np.count_nonzero(rng_img) == len(sk.read_scan(seq / "velodyne" / f"{k:06d}.bin"))
    meta = json.loads((seq / "lidar_meta.json").read_text())
    assert meta["remission"]["model"] == "class_normal" and not meta["remission"].get("placeholder")
    assert (out / "lidar" / "semantic-kitti.yaml").is_file()
    assert "wrote 2 scans" in capsys.readouterr().out


@pytest.mark.parametrize("extra, message", [
    (["--frames", "0"], "--frames: must be an integer in 1..1000000, got '0'"),
    (["--sequence", "abc"], "--sequence: must be a sequence number 00..999999, got 'abc'"),
    (["--sequence", "1234567"], "--sequence: must be a sequence number 00..999999, got '1234567'"),
    (["--threads", "0"], "--threads: must be an integer in 1..256, got '0'"),
    (["--render-config", "nope"], "nope.yaml: file not found"),
])
def test_bad_options_one_line_exit_2_nothing_written(root, tmp_path, capsys, extra, message):
    out = tmp_path / "ds"
    rc = cli.main(["lidar", str(root / "scenes" / "test_town.json"), "--out", str(out), *extra])
    err = capsys.readouterr().err
    assert rc == 2 and message in err and err.count("\n") == 1, err
    assert not out.exists()


def test_bad_sensor_file_in_spec(tmp_path, capsys):
    (tmp_path / "bad_sensor.yaml").write_text("name: b\nrotation_hz: 10\nazimuth_steps: 10\nrange_m: [1, 2]\n"
                                              "uniform: {beams: 0, elevation_deg: [-1, 1]}\n")
    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps({"name": "t", "seed": 1, "sensors": {"lidar": {"sensor_file": "bad_sensor.yaml"}}}))
    out = tmp_path / "ds"
    rc = cli.main(["lidar", str(spec), "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 2 and "bad_sensor.yaml: uniform.beams: must be an integer in [1, 256], got 0" in err
    assert err.count("\n") == 1 and not out.exists()


def test_a_lidar_dataset_folder_is_what_the_other_commands_read(root, tmp_path, monkeypatch):
    """``lidar --out D`` is a dataset folder as ``generate`` writes one: ``openlabel SPEC D`` boxes it, and the
    SemanticKITTI readers take D as well as its SemanticKITTI root ``D/lidar``."""
    monkeypatch.setattr(cli, "COMMANDS", ["lidar", "openlabel", "convert", "intensity"])
    spec, ds = str(root / "scenes" / "test_town.json"), tmp_path / "ds"
    assert cli.main(["-q", "lidar", spec, "--out", str(ds), "--frames", "1", "--no-bev", "--threads", "2"]) == 0
    assert cli.main(["-q", "openlabel", spec, str(ds)]) == 0
    assert (ds / "openlabel" / "00.json").is_file()
    for i, given in enumerate((ds, ds / "lidar")):
        out = tmp_path / f"unified{i}"
        assert cli.main(["-q", "convert", str(given), str(out), "--labels", "unified11"]) == 0
        assert (out / "sequences" / "00" / "labels" / "000000.label").is_file()
        assert cli.main(["-q", "intensity", "fit", str(given), "-o", str(tmp_path / f"p{i}.yaml")]) == 0
    assert (tmp_path / "p0.yaml").read_bytes() == (tmp_path / "p1.yaml").read_bytes()
