"""One LiDAR sweep: sensor rays + sensor motion -> labelled points.

Motion convention (KITTI-like, NOT de-skewed)
---------------------------------------------
A sweep of frame ``k`` starts at ``t_k`` (:meth:`generator.world.rig.Rig.frame`) and lasts one
rotation. With motion skew on, column ``c`` is fired at ``t_k + c / (steps * rotation_hz)``
from the sensor pose at that instant, and its points keep the raw coordinates the sensor
measures: the emission point plus range times beam direction, in the sensor frame AT
FIRING TIME. The whole sweep is then filed under the pose at the sweep START
(``T_world_sensor`` of column 0, which is what ``poses.txt`` records), exactly as KITTI
stores its scans: a static wall seen late in the sweep appears shifted by the ego motion
since ``t_k`` (up to speed x 0.1 s at 10 Hz). Each point's ``time`` field gives its
firing offset, so a consumer can de-skew. With motion skew off every column is fired
from the pose at ``t_k`` and ``time`` is 0.

Point record (:data:`POINT_DTYPE`, one structured row per return; no-return rays and
rays blocked nearer than the sensor's minimum range are not points):

=============== ======= ==========================================================
field           dtype   meaning
=============== ======= ==========================================================
x, y, z         float32 sensor frame at firing time, metres (x fwd, y left, z up)
range           float32 distance from the laser's emission point along the beam, metres
                        (what the device measures; differs from |xyz| by the offsets)
azimuth         float32 beam azimuth, radians CCW from +x, in [-pi, pi)
time            float32 firing offset after the sweep start, seconds (0 with skew off)
cos_incidence   float32 |dot(beam direction, face normal)|
ring            uint8   beam row by elevation, 0 = highest
column          uint16  firing column, 0 .. azimuth_steps - 1
laser           uint8   device laser id
class           uint8   native class id (``scene.face_class``)
instance        uint16  instance id (``scene.face_instance``, 0 for stuff)
material        uint16  material id (``scene.face_material``)
=============== ======= ==========================================================

Points are ordered by column (firing time), then ring.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from generator.lidar.caster import RayCaster, make_caster
from generator.lidar.sensors import Sensor

POINT_DTYPE = np.dtype([
    ("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("range", "<f4"), ("azimuth", "<f4"), ("time", "<f4"),
    ("cos_incidence", "<f4"), ("ring", "u1"), ("column", "<u2"), ("laser", "u1"), ("class", "u1"),
    ("instance", "<u2"), ("material", "<u2"),
])


@dataclass
class Scan:
    """The points of one sweep.

    Attributes
    ----------
    points : (n,) POINT_DTYPE
    T_world_sensor : (4, 4) float64
        Sensor pose at the sweep start (the pose the points are filed under).
    n_rays : int
        Rays fired (``rings * columns``).
    rings, columns : int
        Range-image shape.
    """

    points: np.ndarray
    T_world_sensor: np.ndarray
    n_rays: int
    rings: int
    columns: int

    @property
    def xyz(self) -> np.ndarray:
        """(n, 3) float32 sensor-frame coordinates."""
        p = self.points
        return np.stack([p["x"], p["y"], p["z"]], -1)

    def range_image(self) -> np.ndarray:
        """(rings, columns) float32 range per beam and firing column, metres; 0 where no return.

        Row = ring (0 = highest beam), column = firing column (not an azimuth bin): a laser's
        ``rot_correction`` (up to about +-10 deg on the HDL-64E) shifts its beam sideways, so
        an edge looks sheared across rows, as in the device's raw packet order.
        """
        img = np.zeros((self.rings, self.columns), np.float32)
        img[self.points["ring"], self.points["column"]] = self.points["range"]
        return img


class Scanner:
    """Casts a sensor's sweeps against one scene, reusing the BVH for every frame.

    Parameters
    ----------
    scene : generator.world.scene.SceneModel
        Cast against ``scene.vertices`` / ``scene.faces`` (real geometry, not label proxies).
    sensor : Sensor
    threads : int, optional
        Worker threads (default: ``os.cpu_count()``).
    caster : RayCaster, optional
        A prebuilt caster over the same scene (default: Embree over ``scene``).
    chunks_per_thread : int
        Work items per thread (small items balance load across threads).

    Notes
    -----
    Per sweep, each chunk of firing columns is rotated into the world in float32 relative
    to the caster's re-centring point (the float64 pose translation minus the centre is
    taken first, so nothing large is ever rounded), cast, and turned into point fields by
    1-D gathers; the structured array is assembled once at the end. Every step releases
    the GIL, so chunks run in parallel threads.
    """

    def __init__(self, scene, sensor: Sensor, threads: int | None = None, caster: RayCaster | None = None,
                 chunks_per_thread: int = 4):
        self.sensor = sensor
        self.threads = max(1, int(threads or os.cpu_count() or 1))
        self.caster = caster if caster is not None else make_caster(scene)
        self._face_class = np.asarray(scene.face_class, np.uint8)
        self._face_instance = np.asarray(scene.face_instance, np.uint16)
        self._face_material = np.asarray(scene.face_material, np.uint16)
        normals = np.asarray(self.caster.face_normals, np.float32)
        self._normal = [np.ascontiguousarray(normals[:, i]) for i in range(3)]
        origins, dirs, azimuth = sensor.local_rays()
        steps, n_l = azimuth.shape
        self._o32 = origins.astype(np.float32)  # (steps, L, 3), ring order
        self._d32 = dirs.astype(np.float32)
        flat_o, flat_d = origins.reshape(-1, 3), dirs.reshape(-1, 3)
        self._o = [flat_o[:, i].astype(np.float32) for i in range(3)]  # per-ray components, for 1-D gathers
        self._d = [flat_d[:, i].astype(np.float32) for i in range(3)]
        order = sensor.by_ring
        self._ray_fields = {
            "azimuth": azimuth.astype(np.float32).reshape(-1),
            "time": np.repeat(sensor.column_time().astype(np.float32), n_l),
            "ring": np.tile(sensor.ring[order].astype(np.uint8), steps),
            "column": np.repeat(np.arange(steps, dtype=np.uint16), n_l),
            "laser": np.tile(sensor.laser_id[order].astype(np.uint8), steps),
        }
        n_chunks = min(steps, self.threads * max(1, chunks_per_thread))
        edges = np.linspace(0, steps, n_chunks + 1).round().astype(int)
        self._chunks = [slice(a, b) for a, b in zip(edges[:-1], edges[1:]) if b > a]
        self._pool = ThreadPoolExecutor(self.threads, thread_name_prefix="lidar") if self.threads > 1 else None

    def close(self) -> None:
        """Stop the worker threads."""
        if self._pool is not None:
            self._pool.shutdown()
            self._pool = None

    def __enter__(self) -> "Scanner":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def scan(self, T_world_sensor: np.ndarray) -> Scan:
        """Cast one sweep.

        Parameters
        ----------
        T_world_sensor : (4, 4) or (steps, 4, 4) float64
            One pose for the whole sweep (motion skew off) or one pose per firing column
            (motion skew on; column 0 is the sweep start), world frame.

        Returns
        -------
        Scan
        """
        poses = np.asarray(T_world_sensor, np.float64)
        skew = poses.ndim == 3
        if skew and len(poses) != self.sensor.azimuth_steps:
            raise ValueError(f"need one pose per column ({self.sensor.azimuth_steps}), got {len(poses)}")
        rot_t = np.ascontiguousarray(np.swapaxes(poses[..., :3, :3], -1, -2), np.float32)
        trans = (poses[..., :3, 3] - self.caster.center).astype(np.float32)  # float64 difference first
        work = [(c, rot_t, trans, skew) for c in self._chunks]
        if self._pool is not None:
            parts = list(self._pool.map(self._cast_chunk, *zip(*work)))
        else:
            parts = [self._cast_chunk(*w) for w in work]
        # byte-level concatenation: numpy's structured concatenate is ~20x slower than memcpy
        points = np.concatenate([p.view(np.uint8) for p in parts]).view(POINT_DTYPE)
        return Scan(points, poses[0] if skew else poses, self.sensor.rays_per_sweep, self.sensor.n_lasers,
                    self.sensor.azimuth_steps)

    def sweep(self, rig, t0: float, motion_skew: bool = True) -> Scan:
        """Cast the sweep starting at ``t0`` seconds from ``rig``'s LiDAR.

        Parameters
        ----------
        rig : generator.world.rig.Rig
            A rig with a trajectory.
        motion_skew : bool
            Fire each column from the pose of its own instant (a real spinning sensor), or
            every column from the pose at ``t0``.
        """
        return self.scan(rig.sweep_poses(t0, self.sensor.column_time() if motion_skew else None))

    def _cast_chunk(self, cols: slice, rot_t: np.ndarray, trans: np.ndarray, skew: bool) -> np.ndarray:
        o_loc, d_loc = self._o32[cols], self._d32[cols]  # (k, L, 3) float32
        if skew:
            d_w = np.matmul(d_loc, rot_t[cols])
            o_w = np.matmul(o_loc, rot_t[cols])
            o_w += trans[cols, None, :]
        else:
            d_w = d_loc @ rot_t
            o_w = o_loc @ rot_t
            o_w += trans
        d_w, o_w = d_w.reshape(-1, 3), o_w.reshape(-1, 3)
        dist, prim = self.caster.intersect_local(o_w, d_w, self.sensor.max_range_m)
        hit = np.flatnonzero((prim >= 0) & (dist >= self.sensor.min_range_m))
        take = np.take  # 1-D gathers; np.take is about twice as fast as fancy indexing here
        face = take(prim, hit)
        r = take(dist, hit)
        ray = hit + cols.start * self.sensor.n_lasers
        out = np.empty(len(hit), POINT_DTYPE)  # filled here, in the worker thread
        out["range"] = r
        for i, name in enumerate("xyz"):
            out[name] = take(self._o[i], ray) + r * take(self._d[i], ray)
        cos = take(d_w[:, 0], hit) * take(self._normal[0], face)
        cos += take(d_w[:, 1], hit) * take(self._normal[1], face)
        cos += take(d_w[:, 2], hit) * take(self._normal[2], face)
        out["cos_incidence"] = np.abs(cos)
        for name, values in self._ray_fields.items():
            if skew or name != "time":
                out[name] = take(values, ray)
        if not skew:
            out["time"] = 0.0
        out["class"] = take(self._face_class, face)
        out["instance"] = take(self._face_instance, face)
        out["material"] = take(self._face_material, face)
        return out
