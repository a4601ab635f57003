"""Intensity models and the profile fit: sampled moments, [0, 1], physical monotonicity, fit == Welford."""

from __future__ import annotations

import json

import numpy as np
import pytest
import yaml
from scipy import stats

import generator.cli as cli
from generator.errors import SpecError, UserError
from generator.formats import semantickitti as sk
from generator.labels import class_table
from generator.lidar.scan import POINT_DTYPE
from generator.materials import material_table
from generator.remission import class_profiles
from generator.remission import models as intensity
from generator.remission.fit import ClassMoments, fit_dataset
from generator.remission.models import intensity_fn_for_spec, intensity_model

SEM_DTYPE = np.dtype([("range", "<f4"), ("cos_incidence", "<f4"), ("semantic", "<u2")])


@pytest.fixture(autouse=True)
def only_ours(monkeypatch):
    monkeypatch.setattr(cli, "COMMANDS", ["intensity", "lidar"])


def semantic_points(raw: np.ndarray, r=15.0, cos=0.5) -> np.ndarray:
    p = np.zeros(len(raw), SEM_DTYPE)
    p["semantic"], p["range"], p["cos_incidence"] = raw, r, cos
    return p


def censored_moments(mean: float, std: float) -> tuple[float, float]:
    """Mean and std of clip(N(mean, std), 0, 1), by quadrature."""
    if std == 0:
        v = min(max(mean, 0.0), 1.0)
        return v, 0.0
    y = np.linspace(0, 1, 200001)
    pdf = stats.norm.pdf(y, mean, std)
    hi = stats.norm.sf(1, mean, std)  # mass clipped to 1; the mass clipped to 0 adds nothing to the moments
    m1 = np.trapz(y * pdf, y) + hi
    m2 = np.trapz(y * y * pdf, y) + hi
    return m1, float(np.sqrt(m2 - m1 * m1))


def test_table3_profile_is_shipped_and_complete():
    prof = class_profiles.resolve_profile(None)
    assert prof.name == "semantickitti_table3"
    assert set(prof.unified) == set(class_table().unified_names.values())
    assert prof.unified["traffic-sign"] == class_profiles.ClassStats(0.499, 0.367, None)
    assert prof.unified["road"].mean == 0.303 and prof.unified["road"].std == 0.087


def test_class_normal_samples_have_profile_moments_and_stay_in_unit_interval():
    prof = class_profiles.resolve_profile(None)
    table = class_table()
    fn = intensity.class_normal(prof)
    n = 200_000
    rng = np.random.default_rng(7)
    for u, name in table.unified_names.items():
        raw = table.unified_to_sk_map[u]
        x = fn(semantic_points(np.full(n, raw, np.uint16)), rng)
        assert x.dtype == np.float32 and x.min() >= 0.0 and x.max() <= 1.0, name
        st = prof.unified[name]
        m, s = censored_moments(st.mean, st.std)
        # 6 standard errors of the mean and of the standard deviation
        assert abs(x.mean() - m) < 6 * s / np.sqrt(n), (name, x.mean(), m)
        assert abs(x.std() - s) < 6 * s / np.sqrt(2 * n), (name, x.std(), s)
        if stats.norm.cdf(0, st.mean, st.std) + stats.norm.sf(1, st.mean, st.std) < 1e-4:  # clipping negligible
            assert abs(x.mean() - st.mean) < 6 * st.std / np.sqrt(n)
            assert abs(x.std() - st.std) < 6 * st.std / np.sqrt(2 * n)


def test_native_points_use_raw_then_unified_class():
    table = class_table()
    prof = class_profiles.resolve_profile(None)
    fn = intensity.class_normal(prof)
    n = 100_000
    for native in ("car", "truck", "traffic_light", "tree_trunk", "crosswalk", "parking"):
        pts = np.zeros(n, POINT_DTYPE)
        pts["class"] = table.id(native)
        x = fn(pts, np.random.default_rng(1))
        st = prof.unified[table.unified_names[int(table.to_unified[table.id(native)])]]
        m, s = censored_moments(st.mean, st.std)
        assert abs(x.mean() - m) < 6 * s / np.sqrt(n), native


def test_raw_entry_takes_precedence_over_unified():
    prof = class_profiles.parse_profile({"unified": {"unlabeled": {"mean": 0.1, "std": 0.0}, "road": {"mean": 0.3,
                                                                                                      "std": 0.0}},
                                    "semantickitti": {60: {"mean": 0.9, "std": 0.0}}}, "p.yaml")
    x = intensity.class_normal(prof)(semantic_points(np.array([40, 60, 48, 10], np.uint16)), np.random.default_rng(0))
    # 40 road -> unified road, 60 raw entry, 48 sidewalk and 10 car fall back to unlabeled
    assert np.allclose(x, [0.3, 0.9, 0.1, 0.1])
    u = intensity.class_normal(prof, label_space="unified11")(semantic_points(np.array([3, 0], np.uint16)),
                                                              np.random.default_rng(0))
    assert np.allclose(u, [0.3, 0.1])  # unified ids index the unified entries directly


@pytest.mark.parametrize("doc, message", [
    ({"unified": {"roads": {"mean": 0.3, "std": 0.1}}}, "unified.roads: unknown class"),
    ({"unified": {"road": {"mean": 0.3, "std": -0.1}}}, "std >= 0"),
    ({"unified": {"road": {"mean": 0.3}}}, "mapping with mean and std"),
    ({"semantickitti": {"forty": {"mean": 0.3, "std": 0.1}}}, "raw ids"),
    ({}, "no 'unified' or 'semantickitti'"),
])
def test_bad_profiles_name_the_file(tmp_path, doc, message):
    p = tmp_path / "bad.yaml"
    p.write_text(yaml.safe_dump(doc))
    with pytest.raises(UserError, match="bad.yaml") as e:
        class_profiles.load_profile(p)
    assert message in str(e.value)


def test_missing_class_without_unlabeled_entry_is_refused():
    prof = class_profiles.parse_profile({"unified": {"road": {"mean": 0.3, "std": 0.1}}}, "p.yaml")
    with pytest.raises(UserError, match="no .unlabeled. or .pooled. entry"):
        intensity.class_normal(prof)


def test_received_power_matches_the_documented_formula():
    mats = material_table()
    pts = np.zeros(4, POINT_DTYPE)
    pts["material"] = [mats.id("facade_plaster"), mats.id("facade_plaster"), mats.id("sign_face"), mats.id("asphalt")]
    pts["range"] = [10.0, 20.0, 10.0, 5.0]
    pts["cos_incidence"] = [1.0, 0.5, 1.0, 0.2]
    p = intensity.received_power(pts)
    cfg = intensity.reflectivity_config()["physical"]
    assert p[0] == pytest.approx(0.55)                       # rho at R0, normal incidence
    assert p[1] == pytest.approx(0.55 * 0.5 / 4)             # cos and inverse square
    assert p[2] == pytest.approx(0.9 * (1 + cfg["retro_gain"]))  # retroreflective boost at normal incidence
    assert p[3] == pytest.approx(0.08 * 0.2 * 4)
    assert intensity.received_power(pts, 0.05)[1] == pytest.approx(p[1] * np.exp(-2 * 0.05 * 20))


def test_physical_is_monotone_in_range_and_incidence_and_in_unit_interval():
    fn = intensity.physical()
    mats = material_table()
    n = 20_000
    pts = np.zeros(n, POINT_DTYPE)
    pts["material"] = mats.id("facade_concrete")
    means = []
    for r in (5.0, 10.0, 20.0, 40.0):
        pts["range"], pts["cos_incidence"] = r, 1.0
        means.append(fn(pts, np.random.default_rng(0)).mean())
    assert np.all(np.diff(means) < 0)
    by_cos = []
    for c in (0.1, 0.5, 1.0):
        pts["range"], pts["cos_incidence"] = 10.0, c
        by_cos.append(fn(pts, np.random.default_rng(0)).mean())
    assert np.all(np.diff(by_cos) > 0)
    pts["range"], pts["cos_incidence"] = np.random.default_rng(1).uniform(0.9, 120,
                                                                          n), np.random.default_rng(2).uniform(0, 1, n)
    pts["material"] = np.random.default_rng(3).integers(0, len(mats), n)
    x = fn(pts, np.random.default_rng(0))
    assert x.dtype == np.float32 and x.min() >= 0 and x.max() <= 1
    # a retroreflective sign at 40 m, facing the sensor, outshines a facade at 10 m
    sign, wall = np.zeros(1, POINT_DTYPE), np.zeros(1, POINT_DTYPE)
    sign["material"], sign["range"], sign["cos_incidence"] = mats.id("sign_face"), 40.0, 1.0
    wall["material"], wall["range"], wall["cos_incidence"] = mats.id("facade_concrete"), 10.0, 1.0
    assert intensity.received_power(sign)[0] > intensity.received_power(wall)[0]


def test_physical_without_materials_uses_class_reflectivity():
    road, sign = semantic_points(np.array([40], np.uint16), 10.0, 1.0), semantic_points(np.array([81], np.uint16),
                                                                                        10.0, 1.0)
    assert intensity.received_power(road)[0] == pytest.approx(material_table()["asphalt"].reflectivity)
    assert intensity.received_power(sign)[0] > 10 * intensity.received_power(road)[0]


def test_hybrid_keeps_the_class_mean_at_reference_geometry_and_darkens_grazing_far_points():
    prof = class_profiles.resolve_profile(None)
    fn = intensity.hybrid(prof)
    n = 100_000
    ref = fn(semantic_points(np.full(n, 40, np.uint16), 15.0, 0.5), np.random.default_rng(0))
    assert abs(ref.mean() - 0.303) < 6 * 0.087 / np.sqrt(n)
    far = fn(semantic_points(np.full(n, 40, np.uint16), 60.0, 0.05), np.random.default_rng(0))
    near = fn(semantic_points(np.full(n, 40, np.uint16), 5.0, 1.0), np.random.default_rng(0))
    assert far.mean() < ref.mean() < near.mean() and near.max() <= 1.0


def test_spec_profile_path_is_relative_to_the_spec(tmp_path, test_spec):
    (tmp_path / "prof.yaml").write_text(yaml.safe_dump({"unified": {"unlabeled": {"mean": 0.7, "std": 0.0}}}))
    from generator.spec import load_spec
    spec = tmp_path / "s.json"
    spec.write_text(json.dumps({"name": "t", "seed": 1, "lidar": {"intensity_model": "class_normal",
                                                                  "intensity_profile": "prof.yaml"}}))
    fn = intensity_fn_for_spec(load_spec(spec))
    assert np.allclose(fn(semantic_points(np.array([40, 10], np.uint16)), np.random.default_rng(0)), 0.7)
    spec.write_text(json.dumps({"name": "t", "seed": 1, "lidar": {"intensity_model": "hybrid",
                                                                  "intensity_profile": "nope.yaml"}}))
    with pytest.raises(SpecError, match="lidar.intensity_profile: nope.yaml: intensity profile not found"):
        intensity_fn_for_spec(load_spec(spec))


def test_intensity_model_by_name():
    assert intensity_model("constant", constant_value=0.25)(semantic_points(np.zeros(3, np.uint16)),
                                                            None).tolist() == [0.25] * 3
    with pytest.raises(UserError, match="unknown intensity model"):
        intensity_model("laser")


# -- fit ------------------------------------------------------------------------------------
TRUE = {40: (0.30, 0.05), 60: (0.70, 0.08), 10: (0.45, 0.12), 70: (0.25, 0.06)}


def write_dataset(root, rng, scans=(3, 2), points=40_000) -> None:
    raws = np.array(list(TRUE), np.uint16)
    for s, n_scans in enumerate(scans):
        for i in range(n_scans):
            sem = rng.choice(raws, points)
            rem = np.empty(points)
            for r, (m, sd) in TRUE.items():
                on = sem == r
                rem[on] = rng.normal(m, sd, on.sum())
            xyz = rng.normal(0, 10, (points, 3))
            sk.write_scan(root / "sequences" / f"{s:02d}" / "velodyne" / f"{i:06d}.bin", xyz, rem.astype(np.float32))
            sk.write_labels(root / "sequences" / f"{s:02d}" / "labels" / f"{i:06d}.label", sem,
                            rng.integers(0, 5, points).astype(np.uint16))


def welford(root, sequences):
    """The published converter's method: one Python update per point."""
    n, mean, m2 = {}, {}, {}
    for s in sequences:
        for rec in sk.Sequence(root, s):
            for key, x in zip(rec.semantic.tolist(), rec.points[:, 3].astype(np.float64).tolist(), strict=False):
                n[key] = n.get(key, 0) + 1
                d = x - mean.get(key, 0.0)
                mean[key] = mean.get(key, 0.0) + d / n[key]
                m2[key] = m2.get(key, 0.0) + d * (x - mean[key])
    return {k: (mean[k], np.sqrt(m2[k] / (n[k] - 1)), n[k]) for k in n}


def test_fit_recovers_known_parameters_and_equals_welford(tmp_path):
    write_dataset(tmp_path, np.random.default_rng(11))
    prof, summary = fit_dataset(tmp_path, ["00", "01"], progress=False)
    assert summary["scans"] == 5 and summary["points"] == 200_000
    ref = welford(tmp_path, ["00", "01"])
    assert set(prof.semantickitti) == set(TRUE)
    for raw, (m, sd) in TRUE.items():
        st = prof.semantickitti[raw]
        assert st.count == ref[raw][2]
        assert abs(st.mean - ref[raw][0]) < 1e-6 and abs(st.std - ref[raw][1]) < 1e-6
        assert abs(st.mean - m) < 6 * sd / np.sqrt(st.count) and abs(st.std - sd) < 6 * sd / np.sqrt(2 * st.count)
    # unified 'road' pools raw road (40) and lane-marking (60): equal to Welford over both
    pooled = [(rec.points[:, 3], rec.semantic) for s in ("00", "01") for rec in sk.Sequence(tmp_path, s)]
    road = np.concatenate([p[np.isin(lab, [40, 60])] for p, lab in pooled]).astype(np.float64)
    assert prof.unified["road"].count == len(road)
    assert abs(prof.unified["road"].mean - road.mean()) < 1e-6
    assert abs(prof.unified["road"].std - road.std(ddof=1)) < 1e-6
    assert set(prof.unified) == {"road", "vehicle", "vegetation"}
    everything = np.concatenate([p for p, _ in pooled]).astype(np.float64)
    assert prof.pooled.count == len(everything) and abs(prof.pooled.mean - everything.mean()) < 1e-6
    assert abs(prof.pooled.std - everything.std(ddof=1)) < 1e-6


def test_chan_merge_equals_one_batch(rng):
    keys = rng.integers(0, 50, 30_000)
    x = rng.normal(0.4, 0.2, 30_000)
    whole = ClassMoments.of(keys, x, 50)
    parts = ClassMoments.empty(50)
    for chunk in np.array_split(np.arange(30_000), 7):
        parts = parts.merge(ClassMoments.of(keys[chunk], x[chunk], 50))
    assert np.array_equal(parts.count, whole.count)
    assert np.allclose(parts.mean, whole.mean, atol=1e-12) and np.allclose(parts.m2, whole.m2, rtol=1e-10)


def test_fit_command_writes_a_profile_class_normal_can_use(tmp_path, capsys):
    write_dataset(tmp_path / "ds", np.random.default_rng(3), scans=(2, 1), points=5000)
    out = tmp_path / "p.yaml"
    assert cli.main(["intensity", "fit", str(tmp_path / "ds"), "--sequences", "00", "-o", str(out)]) == 0
    assert "from 2 scans" in capsys.readouterr().out
    prof = class_profiles.load_profile(out)
    doc = yaml.safe_load(out.read_text())
    assert doc["semantickitti"][40]["name"] == "road" and doc["semantickitti"][40]["count"] > 0
    x = intensity.class_normal(prof)(semantic_points(np.full(50_000, 60, np.uint16)), np.random.default_rng(0))
    assert abs(x.mean() - prof.semantickitti[60].mean) < 0.01


@pytest.mark.parametrize("extra, message", [
    (["--sequences", "07"], "sequence not found"),
    (["--sequences", "x"], "--sequences: must be a sequence number 00..999999, got 'x'"),
    (["--labels", "unified11"], "not unified-11 ids"),
])
def test_fit_command_errors_one_line_nothing_written(tmp_path, capsys, extra, message):
    write_dataset(tmp_path / "ds", np.random.default_rng(3), scans=(1,), points=100)
    out = tmp_path / "p.yaml"
    rc = cli.main(["intensity", "fit", str(tmp_path / "ds"), "-o", str(out), *extra])
    err = capsys.readouterr().err
    assert rc == 2 and message in err and err.count("\n") == 1, err
    assert not out.exists()
