"""The default town: a KITTI-like HDL-64E scan (64 rings, ~100k-132k points) with sane labels."""

from __future__ import annotations

import numpy as np
import pytest

from generator.labels import class_table
from generator.lidar.scan import Scanner
from generator.lidar.sensors import sensor_for_spec
from generator.world.rig import Rig

assemble = pytest.importorskip("generator.layout.assemble")


@pytest.fixture(scope="module")
def town_scans(default_spec):
    scene = assemble.build_scene(default_spec)
    sensor = sensor_for_spec(default_spec)
    with Scanner(scene, sensor, threads=2) as sc:
        rig = Rig.from_spec(default_spec, scene)
        scans = [sc.sweep(rig, f.t, default_spec.sensors.lidar.motion_skew) for f in rig.frames(3)]
    return scene, sensor, scans


def test_default_town_scan_is_kitti_like(town_scans):
    scene, sensor, scans = town_scans
    assert sensor.name == "hdl64e"
    for scan in scans:
        p = scan.points
        assert np.unique(p["ring"]).size == 64
        # KITTI scans hold ~100k-130k points; this raw cast (no intensity threshold, no weather) of a
        # town built up on both sides of the road returns up to ~98 % of the 133,312 rays.
        assert 100_000 <= len(p) <= 132_000, len(p)
        # the downward rings see the ground all around: the lowest ring returns in (almost) every column
        assert np.count_nonzero(p["ring"] == 63) >= 0.95 * sensor.azimuth_steps
        # range and time stay within the sweep's limits
        assert p["range"].min() >= sensor.min_range_m and p["range"].max() <= sensor.max_range_m
        assert 0.0 <= p["time"].min() and p["time"].max() < sensor.period_s


def test_default_town_labels(town_scans):
    scene, _, scans = town_scans
    table = class_table()
    thing = np.array([r.thing for r in table.rows])
    p = np.concatenate([s.points for s in scans])
    names = {table.names[c] for c in np.unique(p["class"])}
    assert {"road", "sidewalk", "building", "car"} <= names
    assert "sky" not in names and "unlabeled" not in names
    assert np.all(table.lidar_returns[p["class"]])
    road = p["class"] == table.id("road")
    assert road.mean() > 0.15 and np.all(p["instance"][road] == 0)
    # every thing point carries the instance of the object whose triangle was hit
    cars = p[p["class"] == table.id("car")]
    assert np.all(cars["instance"] > 0)
    inst_of_obj = {o.instance_id for o in scene.objects if o.cls == "car"}
    assert set(np.unique(cars["instance"]).tolist()) <= inst_of_obj
    assert thing[p["class"]].any()
