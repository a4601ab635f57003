"""The physical return model on built test scenes: received-power drop, mixed points on edges, dual
returns, glass, and the ideal sensor unchanged."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from generator.geometry import box, polygon, rect
from generator.labels import class_table
from generator.lidar.returns import ReturnModel, ReturnParams, optics_from_materials
from generator.lidar.scan import Scanner
from generator.lidar.sensors import load_preset, with_returns
from generator.world import rig
from kits.lidar_helpers import scene_of

H = 1.73
POSE = rig.mount((0, 0, H), (0, 0, 0))
CLS = class_table()


def model_of(sensor, **params) -> ReturnModel:
    """A physical model of ``sensor`` with ``params`` changed (seed 0)."""
    s = dataclasses.replace(sensor, returns=dataclasses.replace(sensor.returns, model="physical", **params))
    return ReturnModel.build(s, optics_from_materials(), 0)


@pytest.fixture(scope="module")
def hdl64e():
    return load_preset("hdl64e")


def scan(scene, sensor, model=None, threads=2, **kw):
    with Scanner(scene, sensor, threads=threads, returns=model) as sc:
        return sc.scan(POSE, **kw).points


def test_the_hdl64e_preset_is_physical_and_a_spec_can_switch_it(hdl64e):
    assert hdl64e.returns.physical and hdl64e.returns.mode == "strongest"
    assert not with_returns(hdl64e, "ideal").returns.physical
    assert with_returns(hdl64e, "dual").returns.mode == "dual"
    assert ReturnParams().model == "ideal"  # a sensor table without a returns block: first hits, as before


def test_dark_and_grazing_surfaces_lose_more_points(hdl64e):
    """Half the ground bright concrete, half dark asphalt: the physical sensor keeps every near bright
    point, loses more of the dark half, and on both loses more far (grazing) rings than near ones."""
    scene = scene_of([("bright", rect(-150, 0, 150, 150, 0.0, "sidewalk", "facade_plaster"), 0),
                      ("dark", rect(-150, -150, 150, 0, 0.0, "road", "asphalt"), 0)])
    ideal, phys = scan(scene, hdl64e), scan(scene, hdl64e, model_of(hdl64e))
    side = CLS.id("sidewalk"), CLS.id("road")

    def kept(cls, lo, hi):
        a = ideal[(ideal["class"] == cls) & (ideal["range"] >= lo) & (ideal["range"] < hi)]
        b = phys[(phys["class"] == cls) & (phys["range"] >= lo) & (phys["range"] < hi)]
        return len(b) / max(len(a), 1)

    # received power ~ rho cos^0.25 / R^2, and on flat ground cos = h / R: dark asphalt lasts to ~28 m,
    # bright plaster to ~66 m
    assert kept(side[0], 0, 8) > 0.99 and kept(side[1], 0, 8) > 0.99  # near, steep: everything returns
    assert kept(side[1], 32, 60) < 0.05 < 0.95 < kept(side[0], 32, 60)  # farther, more grazing: dark first
    assert kept(side[0], 75, 120) < 0.05                               # and then the bright too
    assert len(phys) < len(ideal)


def wall_edge_scene(back_x: float):
    """A building wall facing the sensor at x = 10 m covering y > 0, a fence-class wall at ``back_x`` behind it."""
    front = box((0.2, 10.0, 6.0), "building", "facade_plaster", center=(10.1, 5.0, 0.0))
    back = box((0.2, 20.0, 6.0), "fence", "facade_plaster", center=(back_x + 0.1, 0.0, 0.0))
    return scene_of([("front", front, 0), ("back", back, 0)])


def test_sub_rays_on_a_wall_edge_give_mixed_points_between_the_two_walls(hdl64e):
    p = scan(wall_edge_scene(10.5), hdl64e, model_of(hdl64e, range_noise_m=0.0))
    walls = p[np.abs(p["y"]) < 2.0]  # the sensor looks along +x: a point's depth is its x
    mixed = walls[walls["mixed"] == 1]
    assert len(mixed) >= 15  # about one ring in three has a beam within a sub-ray's reach (7 mm) of the edge
    xm = mixed["x"]
    # between the surfaces, never beyond the farther one (the emission offsets move x by < 3 cm)
    assert np.all(xm > 10.0 - 0.03) and np.all(xm < 10.5 + 0.03)
    inside = (xm > 10.05) & (xm < 10.45)
    assert inside.sum() >= 0.9 * len(xm)  # really between, not snapped onto one wall
    # the label is the surface that dominates the return: the one the power-weighted range is nearer to
    clear = np.abs(xm - 10.25) > 0.03
    want = np.where(xm < 10.25, CLS.id("building"), CLS.id("fence"))
    assert np.array_equal(mixed["class"][clear], want[clear])
    assert not walls["mixed"][np.abs(walls["y"]) > 0.1].any()  # away from the edge: clean


def test_casting_only_the_differing_sub_rays_keeps_every_beam_and_the_mixed_points_between_the_walls(hdl64e):
    """``edge_subrays: differing`` (the default) against ``all``: the same beams return with the same classes,
    the beams no edge splits are the same points byte for byte (a split beam that is not mixed may differ in
    power), and the mixed points stay between the two walls."""
    scene = wall_edge_scene(10.5)
    some = scan(scene, hdl64e, model_of(hdl64e, range_noise_m=0.0))
    every = scan(scene, hdl64e, model_of(hdl64e, range_noise_m=0.0, edge_subrays="all"))
    assert hdl64e.returns.edge_subrays == "differing"
    key = lambda p: p["ring"].astype(np.int64) * 10_000 + p["column"]  # noqa: E731
    assert np.array_equal(key(some), key(every))
    clean = (some["mixed"] == 0) & (every["mixed"] == 0)
    assert clean.mean() > 0.99 and np.array_equal(some["class"][clean], every["class"][clean])
    assert np.abs(some["range"][clean] - every["range"][clean]).max() < 0.01
    same = some[clean].view(np.void) == every[clean].view(np.void)  # the beams no edge split: the same bytes
    assert same.mean() > 0.95
    for p in (some, every):
        xm = p[(p["mixed"] == 1) & (np.abs(p["y"]) < 2.0)]["x"]
        assert len(xm) >= 15 and np.all(xm > 10.0 - 0.03) and np.all(xm < 10.5 + 0.03)
    assert 0.5 < (some["mixed"] == 1).sum() / (every["mixed"] == 1).sum() < 2.0


def test_dual_returns_are_the_strongest_and_the_last_and_ordered(hdl64e):
    scene = wall_edge_scene(20.0)
    dual = scan(scene, hdl64e, model_of(hdl64e, mode="dual", range_noise_m=0.0))
    strongest = scan(scene, hdl64e, model_of(hdl64e, range_noise_m=0.0))
    first, second = dual[dual["echo"] == 0], dual[dual["echo"] == 1]
    assert len(second) >= 10
    # the first returns of a dual scan are the points of strongest mode, byte for byte
    assert first.tobytes() == strongest.tobytes()
    # every second return pairs with its beam's first, which comes right before it
    at = np.flatnonzero(dual["echo"] == 1)
    prev = dual[at - 1]
    assert np.all(prev["echo"] == 0) and np.array_equal(prev["ring"], second["ring"])
    assert np.array_equal(prev["column"], second["column"])
    # second = the last return when the strongest is not the last; else the second strongest, nearer and weaker
    later = second["range"] > prev["range"]
    assert np.all(second["power"][~later] <= prev["power"][~later])
    assert np.all(prev["power"] >= second["power"]) or later.any()
    assert later.any()
    # the two returns of a split beam are the two walls
    assert set(np.unique(second["class"])) <= {CLS.id("building"), CLS.id("fence")}


def test_truck_windows_are_holes_and_a_free_standing_pane_shows_what_is_behind(hdl64e):
    """A truck's cabin is not modelled (``cabins``): its windows are holes. (A car's is: its windows show
    the cabin, tests/lidar/test_returns_interior.py.)"""
    car = box((2.0, 4.0, 1.5), "truck", "truck_paint", center=(21.0, 0.0, 0.0))
    # a side window leaning in by 30 degrees (no glint for level beams), 1 cm in front of the body
    lean = np.tan(np.radians(30.0)) * 0.5
    window = polygon(np.array([[19.99, -1.5, 0.8], [19.99, 1.5, 0.8], [19.99 + lean, 1.5, 1.3],
                               [19.99 + lean, -1.5, 1.3]]), "truck", "car_glass", (-1.0, 0.0, 0.5))
    pane = polygon(np.array([[6.0, -9.0, 0.2], [6.0, -6.0, 0.2], [6.0, -6.0, 2.2], [6.0, -9.0, 2.2]]),
                   "fence", "car_glass", (-1.0, 0.0, 0.0))
    wall = box((0.2, 20.0, 6.0), "building", "facade_plaster", center=(12.1, -10.0, 0.0))
    scene = scene_of([("car", car, 7), ("window", window, 7), ("pane", pane, 0), ("wall", wall, 0)])
    ideal, phys = scan(scene, hdl64e), scan(scene, hdl64e, model_of(hdl64e, range_noise_m=0.0))

    def in_window(p):
        return (p["x"] < 20.5) & (p["x"] > 19.5) & (np.abs(p["y"]) < 1.4) & (p["z"] > 0.85 - H) & (p["z"] < 1.25 - H)

    assert in_window(ideal).sum() >= 30 and in_window(phys).sum() == 0   # the classic hole
    inside = (phys["x"] > 20.05) & (phys["x"] < 21.95) & (np.abs(phys["y"]) < 1.95) & (phys["z"] < 0.7 - H)
    assert not inside.any()                                               # nothing from inside the car
    # the beams the ideal sensor stops on the pane reach the wall behind it (the pane's return is weaker)
    on_pane = ideal[ideal["class"] == CLS.id("fence")]
    beam = lambda p: p["column"].astype(np.int64) * 64 + p["ring"]  # noqa: E731
    same = phys[np.isin(beam(phys), beam(on_pane))]
    assert len(on_pane) >= 100 and len(same) >= 0.95 * len(on_pane)
    assert np.all(same["class"] == CLS.id("building")) and np.all(same["x"] > 11.9)


def test_a_beam_through_a_vehicle_window_ends_in_the_cabin_even_where_the_body_has_a_seam(hdl64e):
    """A vehicle's window over an opening of its body (a seam between body parts): the beam ends in the
    cabin (``cabins`` in materials.yaml) and never returns from what stands beyond the vehicle; the same
    pane standing free (class fence) shows the wall behind it."""
    wall = box((0.2, 20.0, 6.0), "building", "facade_plaster", center=(14.1, 0.0, 0.0))
    # a body open where its window is: a floor and a roof, nothing between them behind the pane
    floor = box((2.0, 4.0, 0.8), "truck", "truck_paint", center=(9.0, 0.0, 0.0))
    roof = box((2.0, 4.0, 0.3), "truck", "truck_paint", center=(9.0, 0.0, 1.8))

    def scene(cls):
        pane = polygon(np.array([[7.99, -1.8, 0.8], [7.99, 1.8, 0.8], [7.99, 1.8, 1.8], [7.99, -1.8, 1.8]]),
                       cls, "car_glass", (-1.0, 0.0, 0.0))
        inst = 5 if cls == "truck" else 0
        return scene_of([("wall", wall, 0), ("floor", floor, 5), ("roof", roof, 5), ("pane", pane, inst)])

    def beyond(p):  # on the wall, in the shadow of the window
        return (p["x"] > 13.9) & (np.abs(p["y"]) < 2.5) & (p["z"] > 0.3 - H) & (p["z"] < 1.7 - H)

    model = model_of(hdl64e, range_noise_m=0.0)
    cabin, free = scan(scene("truck"), hdl64e, model), scan(scene("fence"), hdl64e, model)
    assert beyond(free).sum() >= 50         # a free-standing pane: the wall behind it shows
    assert not beyond(cabin).any()          # a vehicle's window: the beam ends in the cabin


def test_a_beam_through_a_shop_window_ends_in_the_room_not_on_the_ground_under_the_building(hdl64e):
    """A room without a floor (the scene's buildings stand on the ground) behind a pane: through a
    building's facade glass (``behind: room``) no beam reaches the ground inside; through the same
    pane as free-standing glass, the ground behind it shows."""
    ground = rect(-5, -30, 40, 30, 0.0, "road", "asphalt")
    back = box((0.3, 12.0, 4.0), "building", "facade_plaster", center=(16.15, 0.0, 0.0))
    sides = [box((6.0, 0.3, 4.0), "building", "facade_plaster", center=(13.0, y, 0.0)) for y in (-6.15, 6.15)]
    roof = rect(10.0, -6.3, 16.3, 6.3, 4.0, "building", "roof")
    lintel = box((0.3, 12.0, 1.0), "building", "facade_plaster", center=(9.85, 0.0, 3.0))

    def scene(material):
        pane = polygon(np.array([[10.0, -6.0, 0.0], [10.0, 6.0, 0.0], [10.0, 6.0, 3.0], [10.0, -6.0, 3.0]]),
                       "building", material, (-1.0, 0.0, 0.0))
        parts = [("ground", ground, 0), ("back", back, 3), ("pane", pane, 3), ("lintel", lintel, 3),
                 ("roof", roof, 3)] + [(f"side{i}", m, 3) for i, m in enumerate(sides)]
        return scene_of(parts)

    def inside(p):
        return (p["x"] > 10.05) & (p["x"] < 15.95) & (np.abs(p["y"]) < 5.95) & (p["z"] < 0.3 - H)

    model = model_of(hdl64e, range_noise_m=0.0)
    shop, free = scan(scene("shop_glass"), hdl64e, model), scan(scene("car_glass"), hdl64e, model)
    ideal = scan(scene("shop_glass"), hdl64e)
    assert not inside(ideal).any()          # the ideal sensor stops on the pane
    assert inside(free).sum() >= 50         # a free-standing pane: the floorless room's ground shows
    assert not inside(shop).any()           # facade glass: the room absorbs the beam
    # and the window is mostly a hole, as in real scans: the pane's own diffuse return is too weak at
    # 10 m; only the glint near normal incidence (the beams straight ahead) comes back, from the pane
    beam = lambda p: p["column"].astype(np.int64) * 64 + p["ring"]  # noqa: E731
    on_pane = beam(ideal[(ideal["x"] < 10.05) & (ideal["x"] > 9.95) & (ideal["z"] < 2.9 - H)])
    back = shop[np.isin(beam(shop), on_pane)]
    assert len(on_pane) >= 200 and len(back) <= 0.2 * len(on_pane) and np.all(back["x"] < 10.05)


def test_model_off_is_the_ideal_scanner_byte_for_byte(hdl64e):
    scene = wall_edge_scene(10.5)
    off = model_of(hdl64e)
    off = dataclasses.replace(off, params=dataclasses.replace(off.params, model="ideal"))
    a = scan(scene, hdl64e)
    b = scan(scene, with_returns(hdl64e, "ideal"), off)
    assert a.tobytes() == b.tobytes() and not a["mixed"].any() and not a["echo"].any()


def test_physical_scans_do_not_depend_on_threads_or_chunks_and_noise_is_keyed(hdl64e):
    scene = wall_edge_scene(10.5)
    m = model_of(hdl64e, mode="dual")
    with Scanner(scene, hdl64e, threads=1, returns=m) as one, \
            Scanner(scene, hdl64e, threads=2, returns=m, chunks_per_thread=7) as two:
        a, b = one.scan(POSE, noise_key=5).points, two.scan(POSE, noise_key=5).points
        c = two.scan(POSE, noise_key=6).points
    assert a.tobytes() == b.tobytes()
    assert len(a) == len(c) and not np.array_equal(a["range"], c["range"])
    sigma = np.std((a["range"] - c["range"])[a["mixed"] == 0]) / np.sqrt(2)
    assert 0.012 < sigma < 0.03  # the per-laser noise about the datasheet's 2 cm


def test_points_that_are_not_mixed_agree_with_the_camera(hdl64e, test_spec, test_scene):
    """Project a physical sweep of the test town into a camera image ray-cast at the same instant: the
    points the camera sees (occlusion test) carry the class of their pixel, >= 99.5 % of those not mixed."""
    from generator.fusion.projection import camera_from_lidar, project, transform, visible
    from generator.lidar.caster import EmbreeCaster
    from generator.world.rig import Rig
    from kits.fusion_kit import raycast_image

    r = Rig.from_spec(test_spec, test_scene)
    f = r.frame(0)
    w, h = 640, 360
    K = rig.intrinsics(test_spec.sensors.camera.hfov_deg, w, h)
    caster = EmbreeCaster.from_scene(test_scene)
    cls_img, _, depth = raycast_image(caster, test_scene, f.T_world_camera, K, w, h)
    T_lidar = r.T_world_lidar(np.array([f.t]))[0]
    with Scanner(test_scene, hdl64e, threads=2, caster=caster, returns=model_of(hdl64e)) as sc:
        p = sc.scan(T_lidar).points
    xyz = np.stack([p["x"], p["y"], p["z"]], -1).astype(np.float64)
    proj = project(transform(camera_from_lidar(f.T_world_camera, T_lidar), xyz), K, w, h)
    seen = visible(proj, depth, K)
    idx = proj.index[seen]
    same = p["class"][idx] == cls_img[proj.row[seen], proj.col[seen]]
    clean = p["mixed"][idx] == 0
    assert clean.sum() > 5000 and (~clean).sum() > 20
    assert same[clean].mean() >= 0.995
