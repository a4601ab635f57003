"""Sweeps through moving actors: every column sees an actor where its track puts it at that column's time.

The reference for "exact" is an independent float64 ray/box slab test at each column's firing
time (sensor pose and actor pose of that instant); the scanner must agree ray for ray.
"""

from __future__ import annotations

import numpy as np
import pytest

from generator.formats import semantickitti as sk
from generator.geometry import box, icosphere, rect
from generator.jobs.lidar_returns import return_model
from generator.labels import class_table
from generator.labels.sets import semantickitti_labels
from generator.lidar.caster import EmbreeCaster
from generator.lidar.scan import POINT_DTYPE, Scanner
from generator.lidar.sensors import load_preset, with_returns
from generator.lidar.tracks import TrackBank
from generator.materials import material_table
from generator.world import rig
from generator.world.actors import MOVING_THRESHOLD_MPS, Actor, Track, World
from kits.scene_kit import scene_of
from kits.surface_kit import on_surface

H = 1.73  # KITTI mount height
DT = 0.05
CAR = (4.0, 1.8, 1.5)  # length, width, height of the box car, metres


@pytest.fixture(scope="module")
def hdl64e():
    return load_preset("hdl64e")


@pytest.fixture(scope="module")
def ground():
    return scene_of([("ground", rect(-300, -300, 300, 300, 0.0, "road", "asphalt"), 0)])


def box_car(size=CAR, cls="car"):
    """A box prototype in an actor's local frame: x forward, origin on the ground under its centre."""
    return box(size, cls, "car_paint", center=(0.0, 0.0, size[2] / 2))


def track(p0, velocity, yaw, yaw_rate=0.0, accel=(0.0, 0.0), seconds=2.0) -> Track:
    t = np.arange(round(seconds / DT) + 1) * DT
    v, a = np.array([*velocity, 0.0]), np.array([*accel, 0.0])
    return Track(0.0, DT, np.asarray(p0, float) + t[:, None] * v + 0.5 * t[:, None] ** 2 * a, yaw + yaw_rate * t)


def world_of(scene, movers, prototypes) -> World:
    """``movers``: (prototype key, instance id, Track)."""
    actors = [Actor(i, f"actor_{i:04d}", "car", "car", inst, key, CAR, (0.0, 0.0, CAR[2] / 2), tr)
              for i, (key, inst, tr) in enumerate(movers)]
    return World(scene, actors, prototypes, {}, None, 2.0)


def column_poses(sensor, t0=0.0, speed=0.0, yaw_rate=0.0, mount=(0, 0, 0)) -> np.ndarray:
    """(steps, 4, 4) LiDAR poses of an ego driving along +x (turning at ``yaw_rate``) during one sweep."""
    t = t0 + sensor.column_time()
    ego = [rig.pose(speed * ti, 0.0, 0.0, yaw=yaw_rate * ti) for ti in t]
    return np.stack(ego) @ rig.mount((0, 0, H), mount)


def same_bytes(a: np.ndarray, b: np.ndarray) -> bool:
    """Byte equality of two point arrays (a bool, so a failure does not diff megabytes)."""
    return a.dtype == b.dtype and a.tobytes() == b.tobytes()


def slab(o, d, size, center):
    """Entry distance of rays into an axis-aligned box (inf on a miss) and the slab slack (tmax - tmin)."""
    h = np.asarray(size) / 2
    with np.errstate(divide="ignore", invalid="ignore"):
        t1, t2 = (center - h - o) / d, (center + h - o) / d
    tmin = np.nanmax(np.minimum(t1, t2), axis=1)
    tmax = np.nanmin(np.maximum(t1, t2), axis=1)
    return np.where((tmax >= tmin) & (tmax > 0), tmin, np.inf), tmax - tmin


def reference_actor_hits(sensor, poses, tr: Track, t0, size=CAR):
    """Float64 ray/box distances of every ray at its column's time, and the ground distance."""
    o_l, d_l, _ = sensor.local_rays()
    T_a = tr.pose(t0 + sensor.column_time())
    T_as = np.linalg.inv(T_a) @ poses  # sensor -> actor frame, per column
    o = np.einsum("kij,klj->kli", T_as[:, :3, :3], o_l) + T_as[:, None, :3, 3]
    d = np.einsum("kij,klj->kli", T_as[:, :3, :3], d_l)
    t_box, slack = slab(o.reshape(-1, 3), d.reshape(-1, 3), size, np.array([0.0, 0.0, size[2] / 2]))
    ow = np.einsum("kij,klj->kli", poses[:, :3, :3], o_l) + poses[:, None, :3, 3]
    dw = np.einsum("kij,klj->kli", poses[:, :3, :3], d_l)
    with np.errstate(divide="ignore", invalid="ignore"):
        t_ground = np.where(dw[..., 2] < 0, -ow[..., 2] / dw[..., 2], np.inf).reshape(-1)
    return t_box, slack, t_ground


def points_in_actor_frame(p, poses, tr: Track, t0, sensor):
    """Actor points -> the actor's local frame at each point's own firing time."""
    xyz = np.stack([p["x"], p["y"], p["z"], np.ones(len(p))], -1).astype(np.float64)
    world = np.einsum("kij,kj->ki", poses[p["column"]], xyz)
    T_a = tr.pose(t0 + sensor.column_time()[p["column"]])
    return np.einsum("kji,kj->ki", T_a[:, :3, :3], world[:, :3] - T_a[:, :3, 3])


def test_a_passing_car_is_smeared_exactly_as_each_column_saw_it(hdl64e, ground):
    """A car crossing in front of a moving sensor at 12 m/s: every ray agrees with the float64 reference."""
    s, v, t0 = hdl64e, 12.0, 0.35
    tr = track((11.0, -v * (t0 + 0.05), 0.0), (0.0, v), np.pi / 2)  # in front (azimuth 0) mid-sweep
    world = world_of(ground, [("car", 42, tr)], {"car": box_car()})
    poses = column_poses(s, t0, speed=8.0)
    with Scanner(ground, s, threads=2, world=world) as sc:
        p = sc.scan(poses, t0=t0).points
    on_car = p["instance"] == 42
    car = p[on_car]
    assert len(car) > 1000
    assert np.all(car["class"] == class_table().id("car")) and np.all(
        car["material"] == material_table().id("car_paint")
    )
    assert np.all(car["moving"] == 1) and not p["moving"][~on_car].any()
    # every hit, moved into the car's frame at its own firing time, lies on the box surface
    local = points_in_actor_frame(car, poses, tr, t0, s)
    h, c = np.array(CAR) / 2, np.array([0.0, 0.0, CAR[2] / 2])
    assert np.abs(np.max(np.abs(local - c) - h, axis=1)).max() < 1e-3
    # ... and it would not at the sweep start: the smear is v * (column time), up to 12 m/s * 0.06 s here
    frozen = Track(0.0, DT, tr.position(t0), tr.heading(t0))
    at_start = points_in_actor_frame(car, poses, frozen, t0, s)
    assert np.abs(np.max(np.abs(at_start - c) - h, axis=1)).max() > 0.3
    # the cosine is against the box face hit, turned with the car
    axis = np.argmin(np.abs(np.abs(local - c) - h), axis=1)
    _, d_l, _ = s.local_rays()
    T_as = np.linalg.inv(tr.pose(t0 + s.column_time()[car["column"]])) @ poses[car["column"]]
    d_local = np.einsum("kij,kj->ki", T_as[:, :3, :3], d_l[car["column"], car["ring"]])
    np.testing.assert_allclose(car["cos_incidence"], np.abs(d_local[np.arange(len(car)), axis]), atol=1e-5)
    # ray for ray against the reference: the same rays end on the car, at the same ranges
    t_box, slack, t_ground = reference_actor_hits(s, poses, tr, t0)
    expect = (t_box < t_ground) & (t_box <= s.max_range_m)
    got = np.zeros(len(expect), bool)
    ray = car["column"].astype(np.int64) * s.n_lasers + car["ring"]
    got[ray] = True
    assert np.all(np.abs(slack[got != expect]) < 1e-3)  # only rays grazing an edge may differ
    assert (got != expect).sum() <= 4
    both = got & expect
    r_got = np.full(len(expect), np.nan, np.float32)
    r_got[ray] = car["range"]
    np.testing.assert_allclose(r_got[both], t_box[both], atol=1e-3)


def test_a_library_car_is_hit_on_its_own_surface(hdl64e, ground):
    from generator.layout.placement.prototypes import Library

    mesh = Library(0).variant("car", 0).mesh
    s, t0 = hdl64e, 0.0
    tr = track((-8.0, 6.0, 0.0), (10.0, 0.0), 0.0, yaw_rate=0.4)
    with Scanner(ground, s, threads=2, world=world_of(ground, [("lib_car", 5, tr)], {"lib_car": mesh})) as sc:
        poses = column_poses(s, t0, speed=5.0)
        p = sc.scan(poses, t0=t0).points
    car = p[p["instance"] == 5]
    assert len(car) > 300
    local = points_in_actor_frame(car, poses, tr, t0, s)
    assert on_surface(local, mesh.vertices, mesh.faces, 1e-3).all()


def test_an_actor_behind_a_wall_gives_no_points_and_an_actor_before_one_hides_it(hdl64e):
    s = hdl64e
    walls = scene_of([("ground", rect(-300, -300, 300, 300, 0.0, "road", "asphalt"), 0),
                      ("front_wall", box((0.5, 30.0, 6.0), "building", "facade_brick", center=(6.0, 0.0, 3.0)), 1),
                      ("back_wall", box((0.5, 60.0, 10.0), "building", "facade_brick", center=(-25.0, 0.0, 5.0)), 2)])
    hidden = track((12.0, -3.0, 0.0), (0.0, 10.0), np.pi / 2)  # beyond the front wall
    shown = track((-12.0, 3.0, 0.0), (0.0, -10.0), -np.pi / 2)  # between the sensor and the back wall
    world = world_of(walls, [("car", 10, hidden), ("car", 11, shown)], {"car": box_car()})
    poses = column_poses(s)
    with Scanner(walls, s, threads=2) as plain, Scanner(walls, s, threads=2, world=world) as moving:
        before, after = plain.scan(poses).points, moving.scan(poses, t0=0.0).points
    assert not np.any(after["instance"] == 10)
    car = after[after["instance"] == 11]
    assert len(car) > 500
    # the rays that end on the car ended farther before (on the wall or the ground): the car occludes them

    def key(p):
        return p["column"].astype(np.int64) * s.n_lasers + p["ring"]

    r_before = np.full(s.rays_per_sweep, np.inf)
    r_before[key(before)] = before["range"]
    assert np.all(car["range"] < r_before[key(car)])
    # every other ray is untouched, byte for byte
    rest = after[after["instance"] != 11]
    kept = ~np.isin(key(before), key(car))
    assert same_bytes(before[kept], rest)


def test_a_world_without_actors_gives_the_static_bytes(hdl64e, ground, test_spec):
    from generator.world.actors import frozen_world

    scene = scene_of([("ground", rect(-300, -300, 300, 300, 0.0, "road", "asphalt"), 0),
                      ("car", box((4.0, 2.0, 1.5), "car", "car_paint", center=(6.0, 4.0, 0.75)), 1)])
    caster = EmbreeCaster.from_scene(scene)
    poses = column_poses(hdl64e, speed=10.0)
    with Scanner(scene, hdl64e, threads=2, caster=caster) as a, \
            Scanner(scene, hdl64e, threads=2, caster=caster, world=frozen_world(scene, None)) as b:
        pa, pb = a.scan(poses).points, b.scan(poses, t0=3.0).points
    assert pa.dtype == POINT_DTYPE and same_bytes(pa, pb)
    assert "moving" in POINT_DTYPE.names and not pa["moving"].any()


def test_moving_flag_and_labels_follow_the_speed_at_each_firing_time(hdl64e, ground, tmp_path):
    """A truck pulling away (crossing the threshold while the beam sweeps it), a parked car and a passing car."""
    s, t0 = hdl64e, 0.0
    truck = box((10.0, 2.5, 3.0), "truck", "car_paint", center=(0.0, 0.0, 1.5))
    starting = track((0.0, 6.0, 0.0), (0.0, 0.0), 0.0, accel=(12.0, 0.0), seconds=0.5)
    parked = track((0.0, -6.0, 0.0), (0.0, 0.0), 0.0)
    passing = track((-15.0, -2.0, 0.0), (13.0, 0.0), 0.0)
    world = world_of(ground, [("truck", 1, starting), ("car", 2, parked), ("car", 3, passing)],
                     {"truck": truck, "car": box_car()})
    with Scanner(ground, s, threads=2, world=world) as sc:
        p = sc.sweep(_FixedRig(column_poses(s, t0)), t0).points
    speed = TrackBank([starting]).speed(np.zeros(len(p), int), t0 + s.column_time()[p["column"]])
    on_truck = p["instance"] == 1
    assert on_truck.sum() > 500 and 0 < p["moving"][on_truck].sum() < on_truck.sum()
    np.testing.assert_array_equal(p["moving"][on_truck], speed[on_truck] > MOVING_THRESHOLD_MPS)
    assert not p["moving"][p["instance"] == 2].any() and p["moving"][p["instance"] == 3].all()
    raw = semantickitti_labels(p["class"], p["moving"])
    path = tmp_path / "000000.label"
    sk.write_labels(path, raw, p["instance"])
    sem, inst = sk.read_labels(path)
    assert np.array_equal(inst, p["instance"])
    moving_truck = on_truck & (p["moving"] == 1)
    assert np.all(sem[moving_truck] == 258) and np.all(sem[on_truck & ~moving_truck] == 18)
    assert np.all(sem[p["instance"] == 2] == 10) and np.all(sem[p["instance"] == 3] == 252)
    assert np.all(sem[p["instance"] == 0] == 40)


class _FixedRig:
    """A rig stand-in whose LiDAR poses are given per column."""

    def __init__(self, poses):
        self.poses = poses

    def sweep_poses(self, t0, column_times):
        return self.poses if column_times is not None else self.poses[0]


def test_skew_off_poses_every_actor_at_the_sweep_start(hdl64e, ground):
    s, t0 = hdl64e, 0.4
    tr = track((9.0, -6.0, 0.0), (0.0, 14.0), np.pi / 2)
    with Scanner(ground, s, threads=1, world=world_of(ground, [("car", 4, tr)], {"car": box_car()})) as sc:
        p = sc.sweep(_FixedRig(column_poses(s, t0)), t0, motion_skew=False).points
    car = p[p["instance"] == 4]
    assert len(car) > 200 and np.all(car["time"] == 0)
    pose = column_poses(s, t0)[0]
    xyz = np.stack([car["x"], car["y"], car["z"], np.ones(len(car))], -1) @ pose.T
    T_a = tr.pose(t0)[0]
    local = (xyz[:, :3] - T_a[:3, 3]) @ T_a[:3, :3]
    assert np.abs(np.max(np.abs(local - [0, 0, CAR[2] / 2]) - np.array(CAR) / 2, axis=1)).max() < 1e-3


@pytest.mark.parametrize("ideal, tight, ego_speed, ego_turn, actor_speed", [
    (False, False, 15.0, 2.0, 30.0),  # the real sensor, everything moving
    (False, True, 0.0, 0.0, 0.0),  # no slack but the lasers' azimuth corrections and emission offsets
    (True, True, 0.0, 0.0, 30.0),  # no slack but the actors' own motion
    (True, True, 15.0, 2.0, 0.0),  # no slack but the sensor's motion
])
def test_culling_never_changes_a_point(hdl64e, ideal, tight, ego_speed, ego_turn, actor_speed):
    """Many actors near and far, above and below: the windows (per sweep, then per column) give the
    same bytes as casting every ray at every actor. ``ideal``: a sensor without per-laser azimuth
    corrections and emission offsets; ``tight``: actors that fill their bounding boxes (boxes) or
    their bounding spheres (balls); so no other margin can hide a missing one."""
    import dataclasses

    zero = np.zeros(hdl64e.n_lasers)
    sensor = dataclasses.replace(hdl64e, rot_correction=zero, vert_offset=zero, horiz_offset=zero) if ideal else hdl64e
    g = np.random.default_rng(7 + ideal + int(ego_speed) + int(actor_speed))
    scene = scene_of([("ground", rect(-300, -300, 300, 300, 0.0, "road", "asphalt"), 0),
                      ("wall", box((1.0, 40.0, 8.0), "building", "facade_brick", center=(-14.0, 5.0, 4.0)), 1)])
    protos = {"car": box_car(), "truck": box((9.0, 2.5, 3.5), "truck", "car_paint", center=(0, 0, 1.75)),
              "ball": icosphere(0.6, "car", "car_paint", subdivisions=3),
              "slab": box((4.0, 0.4, 1.2), "car", "car_paint", center=(0.7, -0.3, 0.2))}
    kinds = ["car", "ball", "slab"] if tight else ["car", "truck", "ball"]
    poses = column_poses(sensor, 0.3, speed=ego_speed, yaw_rate=ego_turn, mount=(3.0, 4.0, 10.0))
    movers = []
    while len(movers) < 60:
        i = len(movers)
        r, a = g.uniform(3.0, 125.0) if i % 4 else g.uniform(2.0, 12.0), g.uniform(-np.pi, np.pi)
        p0 = (r * np.cos(a) + 5.0, r * np.sin(a), g.uniform(-1.0, 4.0))
        kind = kinds[i % 3]
        tr = track(p0, g.uniform(-actor_speed, actor_speed, 2), g.uniform(-np.pi, np.pi), yaw_rate=g.uniform(-3, 3))
        gap = np.linalg.norm(tr.position(0.3 + hdl64e.column_time()) - poses[:, :3, 3], axis=1).min()
        if gap > np.linalg.norm(protos[kind].vertices, axis=1).max() + 0.5:  # nothing swallows the sensor
            movers.append((kind, 100 + i, tr))
    world = world_of(scene, movers, protos)
    with (
        Scanner(scene, sensor, threads=2, world=world) as culled,
        Scanner(scene, sensor, threads=2, world=world) as every,
    ):
        every.actors.radius = np.full(len(movers), 1e4)  # every window is the whole sweep ...
        every.actors._column_windows = every_beam  # ... every beam of it, nothing is pre-culled
        a, b = culled.scan(poses, t0=0.3).points, every.scan(poses, t0=0.3).points
    assert same_bytes(a, b)
    assert len(np.unique(a["instance"])) > 10


def every_beam(beams, position, *args):
    """Stand-in for :func:`generator.lidar.windows.column_windows` that lets every beam through."""
    m = len(position)
    return {"azimuth": np.zeros(m), "half": np.full(m, 4.0), "ring0": np.zeros(m, int),
            "ring1": np.full(m, len(beams.rot)), "near": np.full(m, -np.inf, np.float32)}


def test_threads_and_repeated_sweeps_give_identical_bytes(hdl64e, ground):
    tr = track((5.0, -8.0, 0.0), (0.0, 11.0), np.pi / 2)
    world = world_of(ground, [("car", 9, tr)], {"car": box_car()})
    poses = column_poses(hdl64e, 0.2, speed=9.0)
    with Scanner(ground, hdl64e, threads=1, world=world) as one, Scanner(ground, hdl64e, threads=2, world=world) as two:
        a, b, c = one.scan(poses, t0=0.2).points, two.scan(poses, t0=0.2).points, two.scan(poses, t0=0.2).points
    assert np.any(a["instance"] == 9) and same_bytes(a, b) and same_bytes(a, c)


@pytest.mark.parametrize("mode", ["ideal", "dual"])
def test_sweeps_submitted_ahead_are_the_sweeps_cast_one_at_a_time(hdl64e, ground, mode):
    """A job keeps the next sweeps in flight while it writes one: their chunks share the threads, not their points."""
    sensor = with_returns(hdl64e, mode)
    returns = return_model(sensor, 7)
    tr = track((5.0, -8.0, 0.0), (0.0, 11.0), np.pi / 2)
    world = world_of(ground, [("car", 9, tr)], {"car": box_car()})
    starts = [0.0, 0.1, 0.2, 0.3]
    poses = [column_poses(hdl64e, t, speed=9.0) for t in starts]
    with Scanner(ground, sensor, threads=2, world=world, returns=returns) as sc:
        alone = [sc.scan(p, t0=t, noise_key=k).points for k, (p, t) in enumerate(zip(poses, starts, strict=True))]
        pending = [sc.submit(p, t0=t, noise_key=k) for k, (p, t) in enumerate(zip(poses, starts, strict=True))]
        ahead = [s.result().points for s in pending]
        streamed = [x.points for x in sc.stream(len(starts), lambda k: sc.submit(poses[k], t0=starts[k], noise_key=k))]
    assert all(np.any(a["instance"] == 9) for a in alone)
    assert (returns is None) == (mode == "ideal") and all(not same_bytes(alone[0], a) for a in alone[1:])
    assert all(same_bytes(a, b) for a, b in zip(alone, ahead, strict=True))
    assert all(same_bytes(a, b) for a, b in zip(alone, streamed, strict=True))


def test_a_scanner_with_actors_needs_the_sweep_time(hdl64e, ground):
    world = world_of(ground, [("car", 9, track((5.0, 0.0, 0.0), (1.0, 0.0), 0.0))], {"car": box_car()})
    with Scanner(ground, hdl64e, threads=1, world=world) as sc, pytest.raises(ValueError, match="t0"):
        sc.scan(column_poses(hdl64e))


def test_track_bank_is_bit_identical_to_the_tracks(rng):
    tracks = [track(rng.uniform(-50, 50, 3), rng.uniform(-15, 15, 2), rng.uniform(-3, 3), rng.uniform(-1, 1),
                    rng.uniform(-3, 3, 2), seconds=s) for s in (1.0, 1.0, 2.0, 0.0)]
    tracks.append(Track(0.3, 0.1, rng.uniform(-5, 5, (7, 3)), rng.uniform(-3, 3, 7)))
    bank = TrackBank(tracks)
    actors = rng.integers(0, len(tracks), 500)
    t = rng.uniform(-0.5, 2.5, 500)
    pos, yaw = bank.position_heading(actors, t)
    speed = bank.speed(actors, t)
    for a, tr in enumerate(tracks):
        m = actors == a
        assert np.array_equal(pos[m], tr.position(t[m])) and np.array_equal(yaw[m], tr.heading(t[m]))
        assert np.array_equal(speed[m], tr.speed(t[m]))


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("where", ["plan", "cast"])
def test_a_failing_sweep_raises_instead_of_hanging_and_the_scanner_goes_on(hdl64e, ground, threads, where):
    world = world_of(ground, [("car", 9, track((6.0, -3.0, 0.0), (0.0, 5.0), np.pi / 2))], {"car": box_car()})
    poses = column_poses(hdl64e)
    with Scanner(ground, hdl64e, threads=threads, world=world) as sc:
        good = sc.scan(poses, t0=0.0).points
        real = getattr(sc.actors, where)

        def broken(*args):
            raise ArithmeticError("boom")

        setattr(sc.actors, where, broken)
        with pytest.raises(ArithmeticError, match="boom"):
            sc.scan(poses, t0=0.0)
        setattr(sc.actors, where, real)
        assert same_bytes(sc.scan(poses, t0=0.0).points, good)
