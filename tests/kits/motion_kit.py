"""Helpers for the motion tests: small worlds with moving actors, and images ray-cast from them.

A ray-cast image shoots one ray per pixel centre at the static town and at every actor posed at
the image time (the nearer hit wins), which is what Blender's real pass does without label
proxies or supersampling: depth, class and instance of the same surface.
"""

from __future__ import annotations

import numpy as np

from generator import geometry as M
from generator.imaging.paths import image_path
from generator.labels import class_table
from generator.lidar.caster import EmbreeCaster
from generator.motion.optical_flow import View
from generator.world import rig
from generator.world.actors import Actor, Track, TrackTrajectory, World

SKY = class_table().id("sky")
DT = 0.05
#: A box car: 4.2 x 1.8 x 1.5 m, local origin on the ground under its centre.
CAR_SIZE, CAR_CENTER = (4.2, 1.8, 1.5), (0.0, 0.0, 0.75)


def car_mesh() -> M.Mesh:
    return M.box(CAR_SIZE, "car", "default", center=CAR_CENTER)


def track(f, t1: float = 4.0, t0: float = 0.0) -> Track:
    """A track sampled every :data:`DT` from ``f(t) -> (x, y)``, heading along the motion (0 when still)."""
    t = np.arange(t0, t1 + DT / 2, DT)
    xy = np.array([f(v) for v in t], np.float64)
    d = np.gradient(xy, DT, axis=0)
    yaw = np.where(np.linalg.norm(d, axis=1) > 1e-9, np.arctan2(d[:, 1], d[:, 0]), 0.0)
    return Track(t0, DT, np.c_[xy, np.zeros(len(t))], np.unwrap(yaw))


def car(uid: int, instance_id: int, tr: Track) -> Actor:
    return Actor(uid, f"actor_car_{uid:04d}", "car", "car", instance_id, "car", CAR_SIZE, CAR_CENTER, tr)


def world(scene, actors: list[Actor], ego: Track, duration: float = 4.0) -> World:
    """A world of ``scene``, box cars ``actors`` and the ego driving ``ego``."""
    dist = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(ego.xyz[:, :2], axis=0), axis=1))]
    return World(scene, actors, {"car": car_mesh()}, {}, TrackTrajectory(ego, dist), duration)


class Caster:
    """Ray-casts images of a world: the static town's BVH once, the posed actors per call."""

    def __init__(self, world: World):
        self.world = world
        self.static = EmbreeCaster.from_scene(world.scene)

    def view(self, T_world_camera: np.ndarray, K: np.ndarray, width: int, height: int, t: float):
        """(View, class_id (H, W) uint8) of a camera at ``t``."""
        d = rig.pixel_rays(K, width, height).reshape(-1, 3) @ T_world_camera[:3, :3].T
        o = np.repeat(T_world_camera[None, :3, 3], len(d), 0)
        d32 = d.astype(np.float32)
        dist, prim = self.static.intersect(o, d32, 1e4)
        sc = self.world.scene
        cls = np.where(prim >= 0, sc.face_class[np.maximum(prim, 0)], SKY).astype(np.uint8)
        inst = np.where(prim >= 0, sc.face_instance[np.maximum(prim, 0)], 0).astype(np.uint32)
        depth = np.where(prim >= 0, dist, np.inf)
        for a, T in zip(self.world.actors, self.world.T_world_actor(t), strict=True):
            mesh = self.world.prototypes[a.prototype]
            caster = EmbreeCaster(M.apply(T, mesh.vertices).astype(np.float32), mesh.faces.astype(np.uint32))
            da, pa = caster.intersect(o, d32, 1e4)
            nearer = (pa >= 0) & (da < depth)
            depth[nearer] = da[nearer]
            cls[nearer] = mesh.face_class[pa[nearer]]
            inst[nearer] = a.instance_id
        shape = (height, width)
        view = View(depth.reshape(shape).astype(np.float32), inst.reshape(shape), K, T_world_camera, t)
        return view, cls.reshape(shape)


def street_scene():
    """A road, buildings on both sides, a wall across the end and a parked car (a static thing)."""
    from kits.scene_kit import make_scene

    parts = [
        ("ground", M.rect(-20, -40, 120, 40, 0.0, "road", "asphalt"), np.eye(4), 0),
        ("left", M.box((100.0, 4.0, 12.0), "building", "facade_brick", center=(0, 0, 6.0)), M.pose(50, 14, 0), 0),
        ("right", M.box((100.0, 4.0, 9.0), "building", "facade_brick", center=(0, 0, 4.5)), M.pose(50, -14, 0), 0),
        ("end", M.box((2.0, 30.0, 15.0), "building", "facade_brick", center=(0, 0, 7.5)), M.pose(90, 0, 0), 0),
        ("pole", M.box((0.15, 0.15, 5.0), "pole", "default", center=(0, 0, 2.5)), M.pose(25, -5, 0), 0),
        ("parked", car_mesh(), M.pose(30, 6, 0), 7),
    ]
    return make_scene(parts)


def write_dataset(root, spec, scene, frames: int, stereo_sweeps=(), size=(96, 64), drop_channel: str | None = None):
    """A dataset folder as ``generate`` lays it out, its images ray-cast instead of rendered.

    ``images/NNNNNN_day_clear.{exr,json}`` for frames ``0..frames-1`` and, for ``stereo_sweeps``,
    ``lidar/sequences/00/passes_2|3/NNNNNN.{exr,json}``, posed and timed as ``generate`` poses them
    (:func:`generator.jobs.drive.plan_drive`), plus ``manifest.json``. ``drop_channel`` leaves that
    channel out of every EXR (a dataset from before the pass existed).

    Returns
    -------
    generator.jobs.drive.Drive
    """
    import json

    import OpenEXR

    from generator.imaging.exr import LabelledImage, write_exr
    from generator.jobs import manifest as mf
    from generator.jobs.drive import plan_drive
    from generator.jobs.plan import make_plan
    from generator.jobs.towns import local_frame
    from generator.spec.render import load_render_config

    w, h = size
    K = rig.intrinsics(spec.sensors.camera.hfov_deg, w, h)
    drive = plan_drive(spec, scene, list(range(frames)))
    caster = Caster(drive.world)

    def write(path, T, t):
        view, cls = caster.view(T, K, w, h, t)
        write_exr(path, LabelledImage(np.zeros((h, w, 3), np.float32), cls, view.instance, view.depth))
        if drop_channel is not None:
            with OpenEXR.File(str(path), separate_channels=True) as f:
                header, ch = dict(f.header()), {k: v.pixels for k, v in f.channels().items()}
            del ch[drop_channel]
            with OpenEXR.File(header, ch) as f:
                f.write(str(path))

    for k in range(frames):
        f = local_frame(drive.rig, k)
        name = f"{k:06d}_day_clear"
        image_path(root, name).parent.mkdir(parents=True, exist_ok=True)
        write(image_path(root, name, ".exr"), f.T_world_camera, f.t)
        meta = {"image": name, "frame": k, "time_s": f.t,
                "camera": {"T_world_camera": f.T_world_camera.tolist(), "T_ego_camera": f.T_ego_camera.tolist(),
                           "intrinsics": {"width": w, "height": h, "K": K.tolist()}}}
        image_path(root, name, ".json").write_text(json.dumps(meta))
    seq = root / "lidar" / "sequences" / "00"
    for j in stereo_sweeps:
        t = rig.Rig.sweep_time(j)
        for cam in (2, 3):
            T = drive.rig.T_world_ego(t)[0] @ drive.rig.T_ego_stereo(cam)
            write(seq / f"passes_{cam}" / f"{j:06d}.exr", T, t)
            rec = {"image": f"image_{cam}/{j:06d}.png", "camera": cam, "scan": j, "time_s": t,
                   "T_world_camera": T.tolist(), "K": K.tolist(), "width": w, "height": h}
            (seq / f"passes_{cam}" / f"{j:06d}.json").write_text(json.dumps(rec))
    plan = make_plan(frames, combos=[("day", "clear")])
    (root / mf.NAME).write_text(json.dumps(mf.new_manifest(spec, load_render_config("test"), plan, "local")))
    return drive
