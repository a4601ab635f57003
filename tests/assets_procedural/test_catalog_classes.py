"""The assets of the issue-13 classes: two-wheelers and riders, buses and trams, utility vehicles,
walls, other-ground pieces and street objects.

Every new class is carried by some asset and maps in every label set; every asset is a valid
mesh that rests on its ground, centred on its footprint, +x forward, reproducible, with real
sizes; a bicycle has two wheels a LiDAR sees through (cast with the project's Embree caster);
riders sit on their vehicles without sinking into them.
"""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from trimesh.ray.ray_pyembree import RayMeshIntersector

from assets_procedural import catalog
from assets_procedural.riders import ridden
from generator.geometry import Mesh, face_normals
from generator.labels import class_table
from generator.lidar.caster import EmbreeCaster
from generator.materials import material_table

T = class_table()
NEW_CLASSES = ("bicycle", "motorcycle", "bus", "on_rails", "other_vehicle", "bicyclist", "motorcyclist", "wall",
               "other_ground", "street_object", "rail_track", "shelter")
NEW_KINDS = tuple(k for k in catalog.KINDS[11:] if not k.startswith("ridden_"))  # ridden_*: see test_ridden_pair

#: (id, kind, params): every new kind at least once, and the variants that change the geometry
CASES = [
    *[(f"bicycle-{s}", "bicycle", dict(style=s)) for s in ("city", "sport", "mtb")],
    ("bicycle-leaning", "bicycle", dict(lean_deg=8.0)),
    *[(f"motorcycle-{s}", "motorcycle", dict(style=s)) for s in ("naked", "sport", "scooter")],
    *[(f"bicyclist-{s}", "bicyclist", dict(style=s)) for s in ("city", "sport", "mtb")],
    *[(f"motorcyclist-{s}", "motorcyclist", dict(style=s)) for s in ("naked", "sport", "scooter")],
    ("bus", "bus", dict()),
    ("bus-3-doors", "bus", dict(length=12.0, doors=3)),
    ("tram-3", "tram", dict(sections=3)),
    ("tram-5-curve", "tram", dict(sections=5, bend_deg=8.0)),
    ("rail_track", "rail_track", dict(length=6.0)),
    ("tram_rails", "tram_rails", dict(length=6.0)),
    *[(f"trailer-{s}", "trailer", dict(style=s)) for s in ("open", "box")],
    ("box_van", "box_van", dict()),
    *[(f"excavator-{b}", "construction_vehicle", dict(boom=b)) for b in ("raised", "lowered")],
    *[(f"wall-{s}", "wall", dict(length=7.0, style=s)) for s in ("garden", "retaining", "noise")],
    *[(f"island-{s}", "traffic_island", dict(shape=s)) for s in ("teardrop", "stadium")],
    ("median_strip", "median_strip", dict(length=12.0)),
    ("driveway_apron", "driveway_apron", dict()),
    ("verge_crossing", "verge_crossing", dict()),
    ("gravel_patch", "gravel_patch", dict()),
    ("bench", "bench", dict()),
    ("bench-backless", "bench", dict(backrest=False)),
    *[(f"bin-{s}", "bin", dict(style=s)) for s in ("post", "wheelie")],
    *[(f"bollard-{s}", "bollard", dict(style=s)) for s in ("metal", "concrete")],
    *[(f"bike_rack-{s}", "bike_rack", dict(style=s)) for s in ("hoops", "grid")],
    ("bus_shelter", "bus_shelter", dict()),
    *[(f"hydrant-{s}", "hydrant", dict(style=s)) for s in ("pillar", "us")],
    ("advertising_column", "advertising_column", dict()),
]
IDS = [c[0] for c in CASES]
RIDDEN = {"bicyclist": "bicycle", "motorcyclist": "motorcycle"}

#: kind -> (lo, hi) bounds of (length x, width y, height z), metres, over many seeds
SIZES = {
    "bicycle": ((1.5, 0.35, 0.9), (2.0, 0.85, 1.3)),
    "motorcycle": ((1.7, 0.6, 1.0), (2.3, 1.0, 1.5)),
    "bicyclist": ((1.5, 0.5, 1.4), (2.0, 0.95, 2.1)),
    "motorcyclist": ((1.7, 0.6, 1.45), (2.3, 1.0, 1.95)),
    "bus": ((10.0, 2.45, 2.9), (13.0, 3.1, 3.45)),
    "tram": ((19.0, 2.25, 3.3), (36.0, 2.8, 5.3)),
    "trailer": ((2.5, 1.4, 0.7), (4.5, 2.2, 2.5)),
    "box_van": ((5.8, 2.0, 2.9), (7.5, 2.6, 3.5)),
    "construction_vehicle": ((5.0, 2.4, 2.8), (10.0, 6.0, 5.6)),
    "bench": ((0.4, 1.0, 0.4), (0.8, 3.0, 1.0)),
    "bin": ((0.3, 0.3, 0.85), (0.95, 0.7, 1.2)),
    "bollard": ((0.1, 0.1, 0.5), (0.45, 0.45, 1.0)),
    "bike_rack": ((0.5, 0.5, 0.3), (1.0, 10.0, 0.95)),
    "bus_shelter": ((1.4, 2.5, 2.3), (2.2, 8.5, 2.9)),
    "hydrant": ((0.2, 0.2, 0.5), (0.5, 0.5, 1.2)),
    "advertising_column": ((1.1, 1.1, 2.5), (1.7, 1.7, 4.5)),
    "traffic_island": ((2.0, 1.0, 0.1), (20.0, 4.0, 0.16)),
    "driveway_apron": ((0.5, 2.5, 0.1), (3.0, 9.6, 0.16)),
    "verge_crossing": ((3.0, 2.0, 0.02), (4.5, 3.0, 0.03)),
    "gravel_patch": ((1.0, 0.7, 0.03), (25.0, 20.0, 0.05)),
}

#: kind -> most triangles one asset may have (prototypes are instanced; keep them cheap)
BUDGET = {"bicycle": 2000, "motorcycle": 2200, "bicyclist": 4300, "motorcyclist": 4500, "bus": 1200, "tram": 2100,
          "rail_track": 800, "tram_rails": 100, "trailer": 800, "box_van": 900, "construction_vehicle": 600,
          "wall": 600, "traffic_island": 200, "median_strip": 200, "driveway_apron": 20, "verge_crossing": 12,
          "gravel_patch": 100,
          "bench": 400, "bin": 250, "bollard": 200, "bike_rack": 1200, "bus_shelter": 400, "hydrant": 400,
          "advertising_column": 400}


def build(kind: str, seed: int, **params) -> Mesh:
    return catalog.build(kind, np.random.default_rng(seed), **params)


def extent(m: Mesh) -> np.ndarray:
    lo, hi = m.bounds()
    return hi - lo


def of_material(m: Mesh, *names: str) -> np.ndarray:
    return np.isin(m.face_material, [material_table().id(n) for n in names])


def of_class(m: Mesh, name: str) -> np.ndarray:
    return m.face_class == T.id(name)


def tri_areas(m: Mesh) -> np.ndarray:
    t = m.vertices[m.faces]
    return 0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1)


# -- the label table ---------------------------------------------------------------------------------

def test_every_new_kind_is_in_a_case_and_the_catalog():
    assert set(NEW_KINDS) == {c[1] for c in CASES}
    assert set(catalog.MAIN_CLASS) == set(catalog.KINDS)


def test_every_new_class_is_carried_by_some_asset():
    carried = set()
    for _, kind, params in CASES:
        carried |= {T.names[c] for c in np.unique(build(kind, 1, **params).face_class)}
    assert set(NEW_CLASSES) <= carried, set(NEW_CLASSES) - carried


@pytest.mark.parametrize("name", NEW_CLASSES)
def test_every_new_class_maps_in_every_label_set(name):
    i = T.id(name)
    assert i >= 20, "new classes are appended; ids 0..19 keep their meaning"
    raw = int(T.to_semantickitti[i])
    assert raw in T.sk_labels and raw != 0 and T.lidar_returns[i]
    assert raw in T.sk_to_unified_map
    assert T.unified_names[int(T.to_unified[i])] in T.unified_names.values()
    cs = int(T.to_cityscapes[i])
    assert 1 <= cs <= 33
    # Cityscapes gives instance ids to exactly its ids 24..33 (person .. bicycle); SemanticKITTI to
    # its vehicle (10..20) and human (30..32) raw ids: the thing flag agrees with both
    assert T[i].thing == (24 <= cs <= 33) == (10 <= raw <= 32)
    assert int(T.to_semantickitti[T.from_semantickitti(raw)]) == raw


def test_new_classes_round_trip_through_label_files_and_masks(tmp_path):
    from generator.formats.semantickitti import read_labels, write_labels
    from generator.imaging.exr import mask_channels

    native = np.array([T.id(n) for n in NEW_CLASSES], np.uint8)
    raw = T.to_semantickitti[native].astype(np.uint32)
    inst = np.where([T[n].thing for n in NEW_CLASSES], np.arange(1, len(native) + 1), 0).astype(np.uint32)
    write_labels(tmp_path / "x.label", raw, inst)
    sem, ins = read_labels(tmp_path / "x.label")
    assert np.array_equal(sem, raw) and np.array_equal(ins, inst)
    masks = mask_channels(native.reshape(1, -1))
    for k, name in enumerate(NEW_CLASSES):
        ch = next(c for c in masks if c.endswith(f".{name}") or f".{name}." in c)
        assert masks[ch][0, k] == 1 and masks[ch].sum() == 1, name


# -- every asset: valid, on the ground, centred, reproducible ----------------------------------------

@pytest.mark.parametrize("case", CASES, ids=IDS)
def test_mesh_is_valid_rests_on_the_ground_and_is_centred(case):
    _, kind, params = case
    m = build(kind, 7, **params)
    assert m.n_faces > 0
    assert m.vertices.dtype == np.float64 and m.faces.dtype == np.int64
    assert m.face_class.dtype == np.uint8 and m.face_material.dtype == np.uint16
    assert np.isfinite(m.vertices).all() and m.faces.min() >= 0 and m.faces.max() < len(m.vertices)
    assert m.face_class.max() < len(T) and m.face_material.max() < len(material_table())
    assert (m.face_class != T.id("unlabeled")).all() and (m.face_material != material_table().id("default")).all()
    assert abs(m.vertices[:, 2].min()) < 1e-9, "rests on its ground"
    lo, hi = m.bounds()
    centre = (lo[:2] + hi[:2]) / 2
    if kind in ("bicyclist", "motorcyclist"):
        # the frame is the vehicle's; the rider's elbows may stick out a little more on one side
        vehicle = m.select(m.face_class == T.id(RIDDEN[kind]))
        vlo, vhi = vehicle.bounds()
        assert np.allclose((vlo[:2] + vhi[:2]) / 2, 0.0, atol=1e-9)
        assert np.allclose(centre, 0.0, atol=0.1)
    else:
        assert np.allclose(centre, 0.0, atol=1e-9), "origin at the footprint centre"
    assert tri_areas(m).min() > 1e-7, "degenerate (zero-area) triangle"
    for name, pts in m.anchors.items():
        assert pts.ndim == 2 and pts.shape[1] == 3 and np.isfinite(pts).all() and (pts[:, 2] >= 0).all(), name
    assert of_class(m, catalog.MAIN_CLASS[kind]).any()
    assert m.n_faces <= BUDGET[kind], f"{m.n_faces} triangles"


@pytest.mark.parametrize("case", CASES, ids=IDS)
def test_same_seed_same_bytes_other_seed_other_mesh(case):
    _, kind, params = case
    a, b, c = build(kind, 11, **params), build(kind, 11, **params), build(kind, 12, **params)
    for name in ("vertices", "faces", "face_class", "face_material"):
        assert getattr(a, name).tobytes() == getattr(b, name).tobytes(), name
    assert a.anchors.keys() == b.anchors.keys()
    assert a.vertices.shape != c.vertices.shape or not np.array_equal(a.vertices, c.vertices)


@pytest.mark.parametrize("case", CASES, ids=IDS)
def test_faces_seen_from_outside_are_front_faces(case):
    _, kind, params = case
    m = build(kind, 3, **params)
    rng = np.random.default_rng(0)
    d = rng.normal(size=(3000, 3))
    d[:, 2] = -np.abs(d[:, 2])
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    lo, hi = m.bounds()
    origins = lo + rng.random((3000, 3)) * (hi - lo) - d * (np.linalg.norm(hi - lo) + 1.0)
    tri, ray = RayMeshIntersector(m.to_trimesh()).intersects_id(origins, d, multiple_hits=False)[:2]
    back = np.einsum("ij,ij->i", face_normals(m)[tri], d[ray]) > 0
    assert len(tri) > 50
    # open tube ends (spokes, hoops, limbs) and proud glass at grazing angles show a back face, rarely
    assert back.mean() <= 0.01, back.mean()


@pytest.mark.parametrize("kind", sorted(SIZES))
def test_sizes_are_plausible(kind):
    lo, hi = (np.array(v) for v in SIZES[kind])
    for seed in range(8):
        params = {"bend_deg": 0.0} if kind == "tram" else {}
        e = extent(build(kind, seed, **params))
        assert (e >= lo).all() and (e <= hi).all(), (seed, e)


def test_bus_is_a_12_m_bus_and_trams_are_long_and_articulated():
    for seed in range(6):
        b = build("bus", seed)
        assert 10.0 <= extent(b)[0] <= 13.0
        assert (b.anchors["headlight"][:, 0] > 0).all() and (b.anchors["taillight"][:, 0] < 0).all()
        glass = face_normals(b)[of_material(b, "car_glass")]
        assert (glass[:, 1] < -0.99).sum() > (glass[:, 1] > 0.99).sum(), "doors on the right (-y) add glass"
        rubber = b.vertices[np.unique(b.faces[of_material(b, "rubber")])]
        on_ground = rubber[rubber[:, 2] < 1e-6]
        assert len(np.unique(np.round(on_ground[:, :2], 1), axis=0)) >= 6, "single front, twin rear tyres"
    for n in (3, 5):
        t = build("tram", 0, sections=n, pantograph_height=1.2)
        assert (19.0 if n == 3 else 28.0) <= extent(t)[0] <= (26.0 if n == 3 else 36.0)
        assert (t.anchors["headlight"][:, 0] > 0).all() and (t.anchors["taillight"][:, 0] < 0).all()
        bellows = t.select(of_material(t, "rubber"))
        assert bellows.n_faces and extent(t)[2] > 4.4, "pantograph raised above a 3.4 m roof"
    low = build("tram", 0, sections=3, pantograph_height=0.35)
    assert extent(low)[2] < 4.0


def test_forward_is_plus_x():
    for kind in ("motorcycle", "box_van"):
        m = build(kind, 2)
        assert (m.anchors["headlight"][:, 0] > 0.2 * extent(m)[0]).all()
        assert (m.anchors["taillight"][:, 0] < -0.2 * extent(m)[0]).all()
    trailer = build("trailer", 2)
    hitch = trailer.vertices[np.unique(trailer.faces[of_material(trailer, "chrome")])]
    assert hitch[:, 0].max() > 0.45 * extent(trailer)[0], "the drawbar points forward"
    excavator = build("construction_vehicle", 2, slew_deg=0.0)
    bucket = excavator.select(of_material(excavator, "pole_metal"))
    assert bucket.bounds()[1][0] > 0.4 * extent(excavator)[0], "the arm reaches forward"
    bench = build("bench", 2, backrest=True)
    top = bench.vertices[:, 2] > 0.8 * extent(bench)[2]
    assert bench.vertices[top, 0].mean() < 0, "the backrest is behind the sitter, who looks +x"
    shelter = build("bus_shelter", 2)
    back = shelter.vertices[np.unique(shelter.faces[of_material(shelter, "car_glass")])]
    assert np.median(back[:, 0]) < 0, "open toward +x"
    apron = build("driveway_apron", 2)
    top_faces = face_normals(apron)[:, 2] > 0.9
    tv = apron.vertices[np.unique(apron.faces[top_faces])]
    assert tv[tv[:, 0] > 0, 2].max() < tv[tv[:, 0] < 0, 2].min(), "low edge at the road (+x)"


def test_walls_run_along_x_like_fences():
    for style in ("garden", "retaining", "noise"):
        for length in (3.0, 12.0):
            m = build("wall", 4, length=length, height=2.0, style=style)
            lo, hi = m.bounds()
            assert lo[0] == pytest.approx(-length / 2, abs=0.05) and hi[0] == pytest.approx(length / 2, abs=0.05)
            assert 1.95 <= extent(m)[2] <= 2.2 and extent(m)[1] < 0.7
            assert (m.face_class == T.id("wall")).all()
    long, short = build("wall", 0, length=40.0, style="noise"), build("wall", 0, length=10.0, style="noise")
    assert long.n_faces / short.n_faces < 5


def test_ground_pieces_are_flat_and_other_ground():
    for kind in ("traffic_island", "median_strip", "driveway_apron", "verge_crossing", "gravel_patch"):
        for seed in range(6):
            m = build(kind, seed)
            assert (m.face_class == T.id("other_ground")).all()
            assert extent(m)[2] <= 0.18
            n = face_normals(m)
            assert (n[:, 2] > -0.5).all(), "no hidden bottom faces: the piece lies on its ground"
            # seen from above, every ray inside the footprint hits an upward face
            lo, hi = m.bounds()
            gx, gy = np.meshgrid(np.linspace(lo[0], hi[0], 30), np.linspace(lo[1], hi[1], 30))
            o = np.c_[gx.ravel(), gy.ravel(), np.full(gx.size, 5.0)]
            dist, prim = EmbreeCaster(m.vertices, m.faces).intersect(o, np.tile([0.0, 0.0, -1.0], (len(o), 1)), 10.0)
            hit = np.isfinite(dist)
            assert hit.mean() > 0.5 and (n[prim[hit], 2] > 0.9).all()


def test_tram_rails_are_road_and_track_bed_is_rail_track():
    street = build("tram_rails", 0, length=5.0)
    assert (street.face_class == T.id("road")).all() and extent(street)[2] <= 0.007
    bed = build("rail_track", 0, length=5.0)
    assert (bed.face_class == T.id("rail_track")).all()
    top = bed.anchors["rail_top"]
    assert top[:, 2] == pytest.approx(bed.bounds()[1][2], abs=1e-9)
    heads = bed.vertices[bed.vertices[:, 2] > top[0, 2] - 0.01]
    assert np.abs(heads[:, 1]).min() == pytest.approx(1.435 / 2, abs=1e-6), "standard gauge between the heads"


# -- a bicycle is seen through ------------------------------------------------------------------------

def _wheel_centres(m: Mesh) -> np.ndarray:
    """(2, 3) axle centres: the x of each tyre's ground contact, at the tyre radius."""
    rubber = m.vertices[np.unique(m.faces[of_material(m, "rubber")])]
    ground = rubber[rubber[:, 2] < 0.03]
    xs = np.sort(ground[:, 0])
    split = np.argmax(np.diff(xs))
    radius = rubber[np.abs(rubber[:, 0] - xs[: split + 1].mean()) < 0.02, 2].max() / 2
    return np.array([[xs[: split + 1].mean(), 0.0, radius], [xs[split + 1:].mean(), 0.0, radius]])


@pytest.mark.parametrize("style", ["city", "sport", "mtb"])
def test_bicycle_has_two_open_wheels_the_lidar_sees_through(style):
    for seed in range(3):
        m = build("bicycle", seed, style=style)
        caster = EmbreeCaster(m.vertices, m.faces)
        centres = _wheel_centres(m)
        assert 0.9 < centres[1, 0] - centres[0, 0] < 1.3, "wheelbase"
        for c in centres:
            r = c[2]
            # rays across the wheel plane (+y) through the spoked disc, between hub and rim
            g = np.linspace(-r, r, 41)
            gx, gz = np.meshgrid(g, g)
            rho = np.hypot(gx, gz).ravel()
            inside = (rho > 0.06) & (rho < r - 0.06)
            o = np.c_[c[0] + gx.ravel()[inside], np.full(inside.sum(), -3.0), c[2] + gz.ravel()[inside]]
            dist, prim = caster.intersect(o, np.tile([0.0, 1.0, 0.0], (len(o), 1)), 10.0)
            hit = np.isfinite(dist)
            assert 0.5 < 1 - hit.mean(), f"a spoked wheel is mostly open ({hit.mean():.2f} hit)"
            assert hit.any(), "... but the spokes are there"
            # rays aimed at the tyre ring all hit it
            a = np.linspace(0, 2 * np.pi, 24, endpoint=False)
            rt = r - 0.6 * float(np.mean([0.013, 0.02, 0.028]))
            o = np.c_[c[0] + rt * np.cos(a), np.full(24, -3.0), c[2] + rt * np.sin(a)]
            dist, prim = caster.intersect(o, np.tile([0.0, 1.0, 0.0], (24, 1)), 10.0)
            assert np.isfinite(dist).mean() > 0.9
            assert (m.face_material[prim[np.isfinite(dist)]] == material_table().id("rubber")).mean() > 0.8


def _hull_2d(p: np.ndarray) -> np.ndarray:
    """Counter-clockwise convex hull of (n, 2) points (monotone chain)."""
    p = np.unique(p, axis=0)
    def half(pts):
        out = []
        for q in pts:
            while len(out) >= 2 and ((out[-1][0] - out[-2][0]) * (q[1] - out[-2][1])
                                     - (out[-1][1] - out[-2][1]) * (q[0] - out[-2][0])) <= 0:
                out.pop()
            out.append(q)
        return out[:-1]
    return np.array(half(p) + half(p[::-1]))


def _in_convex(poly: np.ndarray, q: np.ndarray) -> np.ndarray:
    e = np.roll(poly, -1, 0) - poly
    rel = q[:, None, :] - poly[None]
    return (e[None, :, 0] * rel[..., 1] - e[None, :, 1] * rel[..., 0] >= 0).all(1)


def test_a_side_scan_of_a_bicycle_hits_a_fraction_of_its_silhouette():
    """A dense side-on scan (2 cm grid, like a near LiDAR) hits well under half of the bike's
    side-view convex hull: tubes and spokes, not a box."""
    for style in ("city", "sport", "mtb"):
        m = build("bicycle", 5, style=style)
        lo, hi = m.bounds()
        gx, gz = np.meshgrid(np.arange(lo[0], hi[0], 0.02), np.arange(0.0, hi[2], 0.02))
        o = np.c_[gx.ravel(), np.full(gx.size, -5.0), gz.ravel()]
        dist, _ = EmbreeCaster(m.vertices, m.faces).intersect(o, np.tile([0.0, 1.0, 0.0], (len(o), 1)), 20.0)
        hit = np.isfinite(dist)
        in_hull = _in_convex(_hull_2d(m.vertices[:, [0, 2]]), np.c_[gx.ravel(), gz.ravel()])
        assert hit.sum() < 0.45 * in_hull.sum(), style


def test_bike_rack_and_bench_have_gaps():
    for kind, params, axis, least in (("bike_rack", dict(style="hoops", stands=3), 0, 0.8),
                                      ("bike_rack", dict(style="grid", stands=3), 0, 0.5),
                                      ("bench", dict(backrest=False), 2, 0.1)):
        m = build(kind, 1, **params)
        lo, hi = m.bounds()
        a, b = [i for i in range(3) if i != axis]
        ga, gb = np.meshgrid(np.linspace(lo[a], hi[a], 40)[1:-1], np.linspace(lo[b], hi[b], 40)[1:-1])
        o = np.zeros((ga.size, 3))
        o[:, axis] = hi[axis] + 1.0
        o[:, a], o[:, b] = ga.ravel(), gb.ravel()
        d = np.zeros((len(o), 3))
        d[:, axis] = -1.0
        dist, _ = EmbreeCaster(m.vertices, m.faces).intersect(o, d, 10.0)
        assert (~np.isfinite(dist)).mean() > least, kind


# -- riders sit on their vehicles ---------------------------------------------------------------------

RIDES = [(k, s, seed) for k, styles in (("bicyclist", ("city", "sport", "mtb")), ("motorcyclist", ("naked", "sport",
                                                                                                   "scooter")))
         for s in styles for seed in range(3)]


@pytest.mark.parametrize("kind,style,seed", RIDES)
def test_riders_sit_on_their_vehicle(kind, style, seed):
    rider, vehicle = ridden(kind, np.random.default_rng(seed), style)
    rider_cls, vehicle_cls = kind, "bicycle" if kind == "bicyclist" else "motorcycle"
    assert (rider.face_class == T.id(rider_cls)).all() and (vehicle.face_class == T.id(vehicle_cls)).all()
    # the vehicle is the parked one drawn from the same generator state; the merged kind is both
    parked = build(vehicle_cls, seed, style=style)
    assert np.array_equal(parked.vertices, vehicle.vertices) and np.array_equal(parked.faces, vehicle.faces)
    both = build(kind, seed, style=style)
    assert both.n_faces == rider.n_faces + vehicle.n_faces
    alone = build(kind, seed, style=style, with_vehicle=False)
    assert np.array_equal(alone.vertices, rider.vertices)
    (seat,), grips, rests = vehicle.anchors["saddle"], vehicle.anchors["grips"], vehicle.anchors["footrests"]
    # pelvis on the seat: the rider's lowest point over the seat is the seat top (within 3 cm)
    over = (np.abs(rider.vertices[:, 0] - seat[0]) < 0.1) & (np.abs(rider.vertices[:, 1]) < 0.06)
    assert over.any()
    assert rider.vertices[over, 2].min() == pytest.approx(seat[2], abs=0.03)
    # hands on the grips, feet on the pedals / pegs / floorboard, never on the ground
    tri = rider.vertices[rider.faces]
    assert (surface_distance(grips, tri) < 0.04).all(), "hands on the grips"
    assert (surface_distance(rests, tri) < 0.05).all(), "feet on the pedals / pegs / floorboard"
    assert rider.vertices[:, 2].min() > 0.05
    assert 1.4 < extent(merge_of(rider, vehicle))[2] < 2.1
    # looks the way the vehicle goes: face (or visor) ahead of the back of the head
    top = rider.vertices[:, 2].max()
    head = np.unique(rider.faces[(rider.vertices[rider.faces][:, :, 2] > top - 0.25).all(1)])
    front = np.unique(rider.faces[of_material(rider, "car_glass", "skin") &
                                  (rider.vertices[rider.faces][:, :, 2] > top - 0.25).all(1)])
    assert rider.vertices[front, 0].mean() > rider.vertices[head, 0].mean()
    # no gross interpenetration: few rider vertices inside the vehicle's closed parts, and few
    # vehicle vertices inside the rider's closed parts
    assert _inside_fraction(rider.vertices, vehicle) < 0.03
    assert _inside_fraction(vehicle.vertices, rider) < 0.03


def merge_of(a: Mesh, b: Mesh) -> Mesh:
    from generator.geometry import merge

    return merge([a, b])


def surface_distance(points: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """(n,) distance from each point to the nearest of the triangles ``tri`` (m, 3, 3)."""
    out = np.full(len(points), np.inf)
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    ab, ac = b - a, c - a
    n = np.cross(ab, ac)
    n_len = np.linalg.norm(n, axis=1)
    for k, p in enumerate(np.asarray(points, float)):
        # distance to the plane where the projection falls inside, else to the three edges
        ap = p - a
        d_plane = np.einsum("ij,ij->i", ap, n) / n_len
        q = p - d_plane[:, None] * n / n_len[:, None]
        v0, v1, v2 = ab, ac, q - a
        d00, d01, d11 = (v0 * v0).sum(1), (v0 * v1).sum(1), (v1 * v1).sum(1)
        d20, d21 = (v2 * v0).sum(1), (v2 * v1).sum(1)
        den = d00 * d11 - d01 * d01
        v = (d11 * d20 - d01 * d21) / den
        w = (d00 * d21 - d01 * d20) / den
        inside = (v >= 0) & (w >= 0) & (v + w <= 1)
        best = np.abs(d_plane[inside]).min() if inside.any() else np.inf
        for e0, e1 in ((a, b), (b, c), (c, a)):
            e = e1 - e0
            t = np.clip(((p - e0) * e).sum(1) / np.maximum((e * e).sum(1), 1e-300), 0, 1)
            best = min(best, np.linalg.norm(e0 + t[:, None] * e - p, axis=1).min())
        out[k] = best
    return out


def _closed_parts(mesh: Mesh) -> list[trimesh.Trimesh]:
    """The watertight connected pieces of ``mesh`` (its primitives: tubes, boxes, lofts)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    f = mesh.faces
    edges = np.concatenate([f[:, [0, 1]], f[:, [1, 2]]])
    graph = coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(len(mesh.vertices),) * 2)
    _, label = connected_components(graph, directed=False)
    parts = []
    for c in np.unique(label[f[:, 0]]):
        part = trimesh.Trimesh(mesh.vertices, f[label[f[:, 0]] == c], process=True)
        if part.is_watertight and part.volume > 1e-6:
            parts.append(part)
    return parts


def _inside_fraction(points: np.ndarray, mesh: Mesh) -> float:
    """Fraction of ``points`` inside one of ``mesh``'s watertight parts by more than 1 cm."""
    inside = np.zeros(len(points), bool)
    for part in _closed_parts(mesh):
        lo, hi = part.bounds
        cand = np.flatnonzero(((points > lo) & (points < hi)).all(1) & ~inside)
        if not len(cand):
            continue
        c = part.contains(points[cand])
        if c.any():
            deep = surface_distance(points[cand[c]], part.vertices[part.faces]) > 0.01
            inside[cand[c][deep]] = True
    return float(inside.mean())


@pytest.mark.parametrize("kind", ["bicyclist", "motorcyclist"])
def test_ridden_vehicle_is_the_riders_own_vehicle_relabelled(kind):
    """The layout builds rider and vehicle from one stream: the vehicle is the one the rider sits on."""
    vehicle_kind = "ridden_bicycle" if kind == "bicyclist" else "ridden_motorcycle"
    rider = catalog.build(kind, np.random.default_rng(5), with_vehicle=False)
    vehicle = catalog.build(vehicle_kind, np.random.default_rng(5))
    both = catalog.build(kind, np.random.default_rng(5))
    assert {T.names[c] for c in np.unique(vehicle.face_class)} == {vehicle_kind}
    assert {T.names[c] for c in np.unique(rider.face_class)} == {kind}
    assert vehicle.n_faces + rider.n_faces == both.n_faces
    np.testing.assert_allclose(np.vstack([rider.bounds(), vehicle.bounds()]).min(0), both.bounds()[0], atol=1e-9)
