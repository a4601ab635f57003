"""A new town every N frames (``town.redraw_every_frames``) and the prototype cache that makes it cheap."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from assets_procedural import catalog
from assets_procedural.proto_cache import CACHE, PrototypeCache
from generator.errors import SpecError, UserError
from generator.jobs.plan import make_plan
from generator.jobs.towns import local_frame, town_runs
from generator.layout import build_scene
from generator.rng import stream
from generator.spec import load_spec, parse_spec
from generator.spec.towns import library_seed, spec_for_record, town_of, town_record, town_spec
from generator.world.rig import Rig
from kits.cli_run import run_cli
from kits.proto_store import bypassed

#: spec_hash of the shipped specs before the option existed (main at 37f56ea): a spec that does not
#: set it must keep its hash, or every dataset made before would refuse to resume
#: The shipped specs' hashes without the option. Re-pinned when the skies work added weather fields with
#: defaults (times_of_day, dusk sun, cloud cover): those change what a spec renders, so its hash moves.
#: Re-pinned again when labels.openlabel_min_points went from 10 to 1 (issue 26: every object that
#: appears in the cloud gets a box, as seed 002): the boxes a spec writes change.
OLD_HASHES = {"default_town.json": "99bbde658e1e7ca03f20787e63eee70a627b5d74e59e2866a860b564a844ba71",
              "test_town.json": "41cc6e6caace9360cdb7708d1d220b103ca8a752eabe18117c79d07960a0d105"}


def _doc(root, name="test_town.json", **town) -> dict:
    doc = json.loads((root / "scenes" / name).read_text())
    doc.setdefault("town", {}).update(town)
    return doc


@pytest.fixture(scope="module")
def redraw(root):
    return parse_spec(_doc(root, redraw_every_frames=2), "redraw.json")


@pytest.mark.parametrize("name", sorted(OLD_HASHES))
def test_option_off_keeps_the_spec_hash(root, name):
    assert load_spec(root / "scenes" / name).spec_hash == OLD_HASHES[name]
    assert parse_spec(_doc(root, name, redraw_every_frames=None), name).spec_hash == OLD_HASHES[name]
    assert parse_spec(_doc(root, name, redraw_every_frames=5), name).spec_hash != OLD_HASHES[name]


def test_towns_differ_and_are_reproducible(redraw, root):
    plain = load_spec(root / "scenes" / "test_town.json")
    t0, t1 = town_spec(redraw, 0), town_spec(redraw, 1)
    assert t0.seed != t1.seed and plain.seed not in (t0.seed, t1.seed)
    assert max(t0.seed, t1.seed) < 2 ** 53  # exact in every JSON reader
    assert t0.spec_hash == t1.spec_hash == redraw.spec_hash and t1.asset_seed == redraw.seed
    d0, d1 = build_scene(t0).digest(), build_scene(t1).digest()
    assert d0 != d1 != build_scene(plain).digest()
    CACHE.clear()  # not the cache's memory: a fresh build from the seed gives the same town
    with bypassed():  # nor the prototypes another test worker built (kits.proto_store)
        assert build_scene(town_spec(redraw, 1)).digest() == d1
    # each town draws its own asset library (assets.redraw_every_towns = 1): no car mesh of town 0 in town 1
    cars = [{m.vertices.tobytes() for k, m in build_scene(t).prototypes.items() if k.startswith("car_v")}
            for t in (t0, t1)]
    assert cars[0] and cars[1] and not cars[0] & cars[1]


def _with_assets(spec, every):
    return dataclasses.replace(spec, assets=dataclasses.replace(spec.assets, redraw_every_towns=every))


def test_towns_share_a_library_for_redraw_every_towns_and_all_of_it_when_null(redraw):
    seeds = [library_seed(town_spec(redraw, i)) for i in range(4)]
    assert len(set(seeds)) == 4 and redraw.seed not in seeds              # default: a fresh library per town
    pairs = [library_seed(town_spec(_with_assets(redraw, 2), i)) for i in range(4)]
    assert pairs[0] == pairs[1] != pairs[2] == pairs[3] and pairs[0] == seeds[0]
    assert {library_seed(town_spec(_with_assets(redraw, None), i)) for i in range(4)} == {redraw.seed}
    assert library_seed(redraw) == redraw.seed                              # the one town of a plain run


def test_towns_of_one_library_share_its_car_meshes(redraw):
    every2 = _with_assets(redraw, 2)
    cars = [{k: m for k, m in build_scene(town_spec(every2, i)).prototypes.items() if k.startswith("car_v")}
            for i in (0, 1)]
    shared = set(cars[0]) & set(cars[1])
    assert shared and all(cars[0][k] is cars[1][k] for k in shared)       # the very meshes (prototype cache)


def test_frames_go_to_towns_and_a_sequence_never_spans_two(redraw):
    plan = make_plan(7, sequence="03")
    runs = town_runs(redraw, plan)
    assert [r.index for r in runs] == [0, 1, 2, 3]
    assert [r.plan.sequence for r in runs] == ["03", "04", "05", "06"]
    assert [list(r.plan.frames) for r in runs] == [[0, 1], [2, 3], [4, 5], [6]]
    for r in runs:
        assert {town_of(redraw, k) for k in r.plan.frames} == {r.index}
        assert r.spec.seed == town_spec(redraw, r.index).seed and r.local_frames[0] == 0
    assert sum(len(r.plan.frames) for r in runs) == 7


def test_option_off_is_one_town_as_before(root):
    spec = load_spec(root / "scenes" / "test_town.json")
    (run,) = town_runs(spec, make_plan(5, sequence="07"))
    assert run.index is None and run.spec is spec and run.first == 0 and run.plan == make_plan(5, sequence="07")
    assert town_record(spec) is None


def test_sequences_go_past_99_as_semantic_kitti_api_names_them(redraw):
    """Sequence 100 is folder "100" ('{0:02d}'.format(100) in semantic-kitti-api); numbers stop at six digits."""
    assert [r.plan.sequence for r in town_runs(redraw, make_plan(5, sequence="98"))] == ["98", "99", "100"]
    with pytest.raises(UserError, match=r"^--frames: .*sequences 999998\.\.1000000; sequence numbers stop at 999999"):
        town_runs(redraw, make_plan(5, sequence="999998"))


def test_each_town_drives_from_its_start(redraw):
    t1 = town_spec(redraw, 1)
    scene = build_scene(t1)
    rig = Rig.from_spec(t1, scene)
    f = local_frame(rig, 3, first=2)
    ref = rig.frame(1)
    assert f.index == 3 and f.t == ref.t and np.array_equal(f.T_world_ego, ref.T_world_ego)
    # the camera jitter is drawn by frame number: what the OpenLABEL boxes read back for image 3
    assert f.camera_jitter == rig.camera_jitter(3)
    assert np.array_equal(f.T_ego_camera, rig.T_ego_camera(rig.camera_jitter(3)))
    same = local_frame(rig, 3, first=0)
    assert same.index == 3 and same.t == rig.frame(3).t and same.camera_jitter == rig.camera_jitter(3)


def test_spec_for_record_picks_the_town(redraw):
    rec = {"seed": town_spec(redraw, 2).seed, "town": town_record(town_spec(redraw, 2))}
    assert spec_for_record(redraw, rec, "m.json").seed == rec["seed"]
    assert spec_for_record(redraw, {"seed": redraw.seed}, "m.json") is redraw
    with pytest.raises(UserError, match=r"^m\.json: made from town 2 of another seed"):
        spec_for_record(redraw, {**rec, "town": {**rec["town"], "seed": 1}}, "m.json")
    with pytest.raises(UserError, match=r"^m\.json: town\.index: must be an integer >= 0"):
        spec_for_record(redraw, {"town": {"index": "2"}}, "m.json")


@pytest.mark.parametrize("value, reason", [
    (0, "must be an integer or null in [1, 100000], got 0"),
    (-3, "must be an integer or null in [1, 100000], got -3"),
    (2.5, "must be an integer or null in [1, 100000], got 2.5"),
    ("10", 'must be an integer or null in [1, 100000], got "10"'),
    (True, "must be an integer or null in [1, 100000], got true"),
    (10 ** 6, "must be an integer or null in [1, 100000], got 1000000"),
])
def test_bad_redraw_value_is_one_line(root, value, reason):
    with pytest.raises(SpecError) as e:
        parse_spec(_doc(root, redraw_every_frames=value), "s.json")
    assert str(e.value) == f"s.json: town.redraw_every_frames: {reason}"


@pytest.mark.parametrize("value", [0, 2.5, "x", [3], {"n": 1}])
def test_generate_refuses_a_bad_redraw_field_and_writes_nothing(tmp_path, capsys, root, value):
    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps(_doc(root, redraw_every_frames=value)))
    out = tmp_path / "out"
    rc, err = run_cli(capsys, ["generate", str(spec), "--config", "test", "--out", str(out), "--frames", "2"],
                      tmp_path, out)
    assert rc == 2 and err.startswith(f"urbangen generate: {spec}: town.redraw_every_frames: must be "), err
    assert not out.exists()


# -- the prototype cache ------------------------------------------------------------------------------------------

def test_cache_is_exact(root):
    spec = load_spec(root / "scenes" / "test_town.json")
    CACHE.clear()
    CACHE.enabled = False
    try:
        plain = build_scene(spec).digest()
    finally:
        CACHE.enabled = True
    with bypassed():  # cold: built into the emptied cache, not read from another test worker's (kits.proto_store)
        cold = build_scene(spec).digest()
    hits = CACHE.hits
    warm = build_scene(spec).digest()
    assert plain == cold == warm and CACHE.hits > hits


def test_a_hit_leaves_the_generator_where_the_build_did():
    cache = PrototypeCache()
    draws = []
    for _ in range(2):
        g = stream(7, "assets", "tree", 0)
        mesh = cache.build("tree", g, {"height": 6.0}, catalog.BUILDERS["tree"])
        draws.append(g.random(3))
    assert cache.hits == 1 and cache.misses == 1 and np.array_equal(draws[0], draws[1])
    g = stream(7, "assets", "tree", 0)
    fresh = catalog.BUILDERS["tree"](g, height=6.0)
    assert np.array_equal(fresh.vertices, mesh.vertices) and np.array_equal(g.random(3), draws[0])
    # another parameter or another stream is another mesh
    other = cache.build("tree", stream(7, "assets", "tree", 0), {"height": 6.5}, catalog.BUILDERS["tree"])
    assert cache.misses == 2 and other is not mesh
    with pytest.raises(ValueError):  # shared: nobody may change it in place
        mesh.vertices[0, 0] = 1.0


def test_cache_stays_within_its_bound():
    cache = PrototypeCache(max_bytes=200_000)
    for i in range(30):
        cache.build("bush", stream(1, "assets", "bush", i), {"size": 1.2}, catalog.BUILDERS["bush"])
    assert cache.nbytes <= 200_000 and 0 < len(cache) < 30


def test_unhashable_parameters_bypass_the_cache():
    cache = PrototypeCache()
    calls = []

    def builder(rng, thing):
        calls.append(thing)
        return catalog.BUILDERS["bollard"](rng)

    for _ in range(2):
        cache.build("bollard", stream(1, "x"), {"thing": object()}, builder)
    assert len(calls) == 2 and cache.bypassed == 2 and len(cache) == 0


def test_generate_refuses_towns_past_the_last_sequence_number_and_writes_nothing(tmp_path, capsys, root):
    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps(_doc(root, redraw_every_frames=1)))
    out = tmp_path / "out"
    rc, err = run_cli(capsys, ["generate", str(spec), "--config", "test", "--out", str(out), "--frames", "3",
                               "--sequence", "999998"], tmp_path, out)
    assert rc == 2 and err.startswith("urbangen generate: --frames: frames up to 2 with town.redraw_every_frames = 1 "
                                      "make towns up to 2, LiDAR sequences 999998..1000000"), err
    assert not out.exists()
