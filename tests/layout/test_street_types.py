"""Street variety (issue 13): cross-section types, parking occupancy per strip, districts.

The presets that use ``streets`` (kitti_like, city_centre) keep every invariant of the plain
town: nothing but vehicles (and people on crosswalks) on the lanes, nothing within the route
clearance, nothing colliding at street level, everything resting on its ground; the verges and
median islands are raised ground with curbs; districts set what their lots promise. Without
``streets`` nothing changes (the digest pin in test_layout.py).
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from generator.errors import SpecError
from generator.geometry import apply
from generator.geometry.boxes import point_box_distance
from generator.labels import class_table
from generator.layout import build_scene
from generator.layout.lots.districts import DISTRICTS
from generator.layout.lots.lot import make_lots
from generator.layout.network.cross_sections import MEDIAN_W_M, drive_directions
from generator.layout.network.design_vehicle import EGO_HALF_WIDTH_M
from generator.layout.network.draw import make_grid
from generator.layout.network.grid import segment_frame_points
from generator.layout.network.measures import BAY_M
from generator.spec import load_spec, parse_spec
from kits.town_checks import GROUND_KINDS, check_vehicles, no_collisions, rests_on_ground


@pytest.fixture(scope="module")
def kitti(root):
    spec = load_spec(root / "scenes" / "kitti_like.json")
    return spec, make_grid(spec), build_scene(spec)


@pytest.fixture(scope="module")
def centre(root):
    spec = load_spec(root / "scenes" / "city_centre.json")
    return spec, make_grid(spec), build_scene(spec)


def test_without_streets_every_street_is_plain(default_spec):
    grid = make_grid(default_spec)
    assert default_spec.streets is None and grid.sections == ()
    assert "streets" not in default_spec.to_dict()      # the spec hash reads as before the field existed
    assert all(grid.section(s).strips == ("parking", "parking") for s in grid.segments)


def test_kitti_like_streets_have_parking_and_a_verge_and_varied_occupancy(kitti):
    spec, grid, _ = kitti
    assert spec.streets.residential_strips == "parking_and_verge"
    residential = [s for s in grid.sections if s.kind == "residential"]
    assert residential and all(sorted(s.strips) == ["parking", "verge"] for s in residential)
    occ = [s.share(side) for s in grid.sections for side in (-1, 1) if s.strip(side) == "parking"]
    lo, hi = spec.streets.parking_occupancy
    assert min(occ) >= lo and max(occ) <= hi and np.ptp(occ) > 0.5 * (hi - lo)


@pytest.mark.parametrize("seed", [1, 2027, 2028, 2029, 77])
def test_kitti_like_drive_passes_the_same_streets_in_every_town(root, seed):
    """Issue 27: the class mix of one minute of route 0 (the drive a user gets) does not hang on
    which streets drew parking. Route 0's streets take ``drive_types`` in turn from its start, and
    a residential one has its parking strip across the street (on the drive's left) and a verge on
    the drive's own kerb, whatever the seed."""
    spec = load_spec(root / "scenes" / "kitti_like.json")
    spec = dataclasses.replace(spec, seed=seed)
    grid = make_grid(spec)
    drive = drive_directions(grid.segments, spec.town.blocks_x, spec.town.blocks_y)
    assert len(drive) >= 8 and list(drive)[0] == grid.segment_between((0, 0), (1, 0))[0].index
    want = spec.streets.drive_types
    by_index = {s.index: s for s in grid.segments}
    for k, (i, d) in enumerate(drive.items()):
        sec = grid.section(by_index[i])
        assert sec.kind == want[k % len(want)], (k, sec)
        if sec.kind == "residential":            # driven towards +u (d = +1) the ego keeps to side -1
            assert sec.strip(d) == "parking" and sec.strip(-d) == "verge", (k, sec)


def test_kitti_like_parked_cars_line_every_residential_street_of_the_drive(kitti):
    """The preset's own town: the parking strips along the drive hold parked vehicles."""
    spec, grid, scene = kitti
    drive = drive_directions(grid.segments, spec.town.blocks_x, spec.town.blocks_y)
    parked = np.array([o.box.center[:2] for o in scene.objects if o.attrs.get("placement") == "parked"
                       and o.kind in ("car", "truck")])
    for seg in grid.segments:
        span = grid.strip_span(seg)
        if seg.index not in drive or span is None or span[1] - span[0] < 30 or grid.section(seg).kind != "residential":
            continue
        uv = segment_frame_points(seg, parked)
        d = drive[seg.index]
        here = (uv[:, 0] > span[0]) & (uv[:, 0] < span[1]) & (grid.lane_half < uv[:, 1] * d) \
            & (uv[:, 1] * d < grid.road_half)
        bays = (span[1] - span[0]) // BAY_M
        assert here.sum() >= 0.4 * spec.streets.parking_occupancy[0] * bays, (seg, here.sum(), bays)


def test_residential_strips_either_draws_as_before_and_one_of_each_changes_only_strips():
    """The new setting takes the same two draws per residential street: the street kinds and
    occupancies stay, and with its default (``either``) the spec hash reads as before."""
    doc = {"name": "r", "seed": 5, "streets": {"types": {"residential": 2, "boulevard": 1}}}
    either = parse_spec(doc, "r.json")
    both = parse_spec({**doc, "streets": {**doc["streets"], "residential_strips": "either"}}, "r.json")
    one = parse_spec({**doc, "streets": {**doc["streets"], "residential_strips": "parking_and_verge"}}, "r.json")
    assert either.spec_hash == both.spec_hash != one.spec_hash
    a, b = make_grid(either).sections, make_grid(one).sections
    assert [(s.kind, s.occupancy) for s in a] == [(s.kind, s.occupancy) for s in b]
    assert any(sorted(s.strips) != ["parking", "verge"] for s in a if s.kind == "residential")
    assert all(sorted(s.strips) == ["parking", "verge"] for s in b if s.kind == "residential")


@pytest.mark.parametrize("which", ["kitti", "centre"])
def test_parked_vehicles_only_in_parking_strips_at_their_occupancy(which, kitti, centre):
    """Verges and shoulders hold no parked car; a strip's share of taken bays follows its draw,
    so some strips are emptier and some fuller: the ego is not always beside the same row."""
    spec, grid, scene = {"kitti": kitti, "centre": centre}[which]
    check_vehicles(spec, scene)
    parked = [o for o in scene.objects if o.kind in ("car", "truck") and o.attrs.get("placement") == "parked"]
    taken: dict[tuple[int, int], int] = {}
    for o in parked:
        for seg in grid.segments:
            u, v = segment_frame_points(seg, o.box.center[:2])[0]
            if 0 < u < seg.length and grid.lane_half < abs(v) < grid.road_half:
                taken[(seg.index, int(np.sign(v)))] = taken.get((seg.index, int(np.sign(v))), 0) + 1
                assert grid.section(seg).strip(int(np.sign(v))) == "parking", o.name
    shares = []
    for seg in grid.segments:
        span = grid.strip_span(seg)
        if span is None:
            continue
        bays = int((span[1] - span[0] + 1e-6) // 6.0)
        for side in (-1, 1):
            if grid.section(seg).strip(side) == "parking" and bays >= 6:
                shares.append(taken.get((seg.index, side), 0) / bays)
    mid = sum(spec.streets.parking_occupancy) / 2       # strips emptier and fuller than the middle of the range
    assert min(shares) < mid < max(shares) and max(shares) - min(shares) > 0.2, shares


@pytest.mark.parametrize("which", ["kitti", "centre"])
def test_only_vehicles_on_the_lanes_none_near_a_route_none_colliding(which, kitti, centre):
    spec, grid, scene = {"kitti": kitti, "centre": centre}[which]
    placed = [o for o in scene.objects if o.kind not in GROUND_KINDS]
    lanes = grid.drivable_rects()
    on_lanes = ("car", "truck", "bus", "on_rails", "other_vehicle", "ridden_bicycle", "ridden_motorcycle",
                "bicyclist", "motorcyclist", "road")
    for o in placed:
        x, y = o.transform[:2, 3]
        if ((x > lanes[:, 0]) & (x < lanes[:, 2]) & (y > lanes[:, 1]) & (y < lanes[:, 3])).any():
            assert o.cls in on_lanes or o.attrs.get("placement") == "crosswalk", (o.name, o.cls)
    limit = spec.paths.clearance_m + EGO_HALF_WIDTH_M
    things = [o for o in placed if o.kind != "tram_rails"]
    for path in scene.paths:
        near = min(float(point_box_distance(path.points[:, :2], o.box).min()) for o in things)
        assert near >= limit - 1e-6, path.name
    no_collisions(scene)
    rests_on_ground(spec, grid, scene)


def test_verges_and_medians_are_raised_ground_behind_curbs(kitti, centre):
    table = class_table()
    for spec, grid, scene in (kitti, centre):
        raised = grid.raised_rects()
        assert raised
        h = spec.town.curb_height_m
        ground = np.array([o.kind in GROUND_KINDS for o in scene.objects])[scene.face_object]
        tri = scene.vertices[scene.faces[ground]].astype(np.float64)
        c = tri.mean(1)
        fc = scene.face_class[ground]
        for seg, kind, (x0, y0, x1, y1) in raised:
            e = min(0.3, (x1 - x0) / 4, (y1 - y0) / 4)        # clear of the curbs round it
            inside = (c[:, 0] > x0 + e) & (c[:, 0] < x1 - e) & (c[:, 1] > y0 + e) & (c[:, 1] < y1 - e)
            top = inside & np.isclose(tri[:, :, 2], h, atol=1e-4).all(1)
            want = table.id("terrain") if kind == "verge" else table.id("other_ground")
            assert top.any() and (fc[top & (c[:, 2] < h + 1e-3)] == want).all(), (seg.index, kind)
            # nothing of the road surface under or on it
            assert not (inside & np.isin(fc, [table.id("road"), table.id("parking")])).any()
        assert grid.ground_height(np.array([[(r[0] + r[2]) / 2, (r[1] + r[3]) / 2] for *_, r in raised])).min() == h
    medians = [r for _, k, r in centre[1].raised_rects() if k == "median"]
    assert medians and all(min(r[2] - r[0], r[3] - r[1]) == pytest.approx(MEDIAN_W_M) for r in medians)
    # the ego on its lane centre keeps clear of an island; lanes too narrow for that get none
    lane_w = centre[0].town.lane_width_m
    assert lane_w / 2 - EGO_HALF_WIDTH_M - MEDIAN_W_M / 2 >= 0.1 - 1e-9
    for lane_w, island in ((2.75, False), (3.2, True), (3.5, True)):
        spec = parse_spec({"name": "a", "seed": 1, "town": {"lane_width_m": lane_w},
                           "streets": {"types": {"arterial": 1}}}, "a.json")
        assert all(s.median == island for s in make_grid(spec).sections), lane_w


def test_boulevards_have_tree_rows_and_residential_verges_greenery(kitti):
    spec, grid, scene = kitti
    verge = [o for o in scene.objects if o.attrs.get("placement") == "verge"]
    kinds = {o.kind for o in verge}
    assert {"tree", "hedge"} <= kinds   # (verge_hedges = 1: hedges leave no gaps for bushes)
    for o in verge:
        assert grid.ground_height(o.transform[None, :2, 3])[0] == spec.town.curb_height_m, o.name


def test_districts_set_their_lots(kitti):
    """Buildings keep their district's setback (front garden) and height; district lots facing a
    street on a side or the back are lined there too."""
    spec, grid, scene = kitti
    lots = make_lots(spec, grid)
    assert {lot.district for lot in lots} >= {"row_houses", "detached", "light_industry"}
    by_index = {lot.index: lot for lot in lots}
    n = 0
    for o in scene.objects_of("building"):
        d = o.attrs.get("district")
        if not d:
            continue
        lot, dist = by_index[o.attrs["lot"]], DISTRICTS[d]
        front = min(lot.building.center[1] - np.ptp(lot.building.footprint[:, 1]) / 2, 99)
        assert front >= dist.setback_m[0] - 1e-6 and front <= max(dist.setback_m[1], 1.5) + 0.1, (o.name, front)
        low, high = dist.height_m
        assert low - spec.heights.floor_m / 2 - 1e-6 <= lot.building.height <= high + spec.heights.floor_m / 2
        n += 1
    assert n > 30
    assert any(f.across for lot in lots for f in lot.front)


def test_presets_are_reproducible(root, kitti):
    spec, _, scene = kitti
    assert build_scene(load_spec(root / "scenes" / "kitti_like.json")).digest() == scene.digest()


BAD = [
    ({"types": {}},
     "streets.types: must name at least one of arterial, boulevard, one_way, plain, residential, shared, got {}"),
    ({"types": {"plain": 0}}, 'streets.types: needs a weight > 0, got {"plain": 0}'),
    ({"types": {"cul_de_sac": 1}}, "streets.types.cul_de_sac: unknown key"),
    ({"types": {"plain": -1}}, "streets.types.plain: must be a number in [0, 100], got -1"),
    ({"districts": {"dense_centre": 0}}, 'streets.districts: needs a weight > 0, got {"dense_centre": 0}'),
    ({"parking_occupancy": [0.2, 1.5]}, "streets.parking_occupancy: must lie within [0, 1], got [0.2, 1.5]"),
    ({"parking_occupancy": [0.9, 0.1]}, "streets.parking_occupancy: must be a range [low, high] with low <= high"),
    ({"verge_hedges": 2}, "streets.verge_hedges: must be a number in [0, 1], got 2"),
    ({"residential_strips": "both"},
     'streets.residential_strips: must be one of "either", "parking_and_verge", got "both"'),
    ({"drive_types": ["one_way"]}, 'streets.drive_types[0]: must be one of "plain", "residential", "boulevard", '
     '"arterial", "shared", got "one_way"'),
    ("many", 'streets: must be an object or null, got "many"'),
]


@pytest.mark.parametrize("streets,expected", BAD, ids=[b[1].split(",")[0] for b in BAD])
def test_bad_streets_fields_name_file_field_and_reason(streets, expected):
    with pytest.raises(SpecError) as e:
        parse_spec({"name": "x", "seed": 1, "streets": streets}, "scenes/x.json")
    assert str(e.value).startswith("scenes/x.json: " + expected) and "\n" not in str(e.value)


def test_bad_streets_field_through_the_cli_exits_2_writes_nothing(tmp_path, capsys):
    from generator.cli import main

    spec = tmp_path / "bad.json"
    spec.write_text(json.dumps({"name": "x", "seed": 1, "streets": {"parking_occupancy": [0.2, 1.5]}}))
    out = tmp_path / "out"
    assert main(["layout", str(spec), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err == f"urbangen layout: {spec}: streets.parking_occupancy: must lie within [0, 1], got [0.2, 1.5]\n"
    assert not out.exists()


def test_street_geometry_faces_up_and_curbs_face_the_lane(kitti):
    """A verge's lane-side curb has a vertical face at the lane edge (|v| = lane_half)."""
    spec, grid, scene = kitti
    table = class_table()
    seg = next(s for s in grid.segments if "verge" in grid.section(s).strips and grid.strip_span(s))
    side = -1 if grid.section(seg).strip(-1) == "verge" else 1
    obj = next(o for o in scene.objects if o.name == f"street_{seg.index:04d}")
    mesh = scene.prototypes[obj.prototype]
    v = apply(obj.transform, mesh.vertices)
    curb = mesh.faces[mesh.face_class == table.id("curb")]
    uv = segment_frame_points(seg, v[:, :2])
    on_edge = np.isclose(np.abs(uv[curb][:, :, 1]), grid.lane_half, atol=1e-6).all(1)
    assert on_edge.any() and (np.sign(uv[curb][on_edge][:, 0, 1]) == side).any()


def _furnished(seed: int):
    doc = {"name": "furnished", "seed": seed, "town": {"blocks_x": 2, "blocks_y": 2, "block_size_m": 50},
           "density": {"street_objects_per_100m": 12, "bike_racks_per_block": 4}}
    spec = parse_spec(doc, "furnished.json")
    return spec, make_grid(spec), build_scene(spec)


@pytest.mark.parametrize("town", ["kitti", "centre", 1, 2])
def test_what_stands_on_the_pavement_stays_on_it(town, kitti, centre):
    """A thing standing at kerb height keeps its lower 0.9 m over kerb-height ground: no rack,
    bench or column reaches over the kerb into the road (poles' arms and crowns above may)."""
    spec, grid, scene = {"kitti": kitti, "centre": centre}[town] if isinstance(town, str) else _furnished(town)
    names, lows = [], []
    for o in scene.objects:
        if o.instance_id == 0 and o.kind in GROUND_KINDS:
            continue
        m = scene.prototypes[o.prototype]
        v = apply(o.transform, m.vertices)
        z0 = v[:, 2].min()
        if abs(z0 - grid.curb_h) > 0.01:
            continue
        tri = v[m.faces]
        names.append(o.name)
        lows.append(tri[tri[:, :, 2].min(1) < z0 + 0.9].reshape(-1, 3)[:, :2])
    # the ground under every object's low points, all at once
    owner = np.repeat(np.arange(len(lows)), [len(p) for p in lows])
    sunk = grid.ground_height(np.concatenate(lows)) < grid.curb_h - 1e-6 if lows else np.zeros(0, bool)
    bad = [names[k] for k in np.unique(owner[sunk])]
    assert names and not bad
