"""``urbangen export nuscenes DIR OUT``: a dataset's LiDAR sequences as a nuScenes v1.0 dataroot.

Written under ``OUT`` (nuScenes' own layout, what ``NuScenes(version, dataroot=OUT)`` and the
converters of MMDetection3D / OpenPCDet read)::

    OUT/v1.0-urbangen/{category,attribute,visibility,instance,sensor,calibrated_sensor,ego_pose,log,
                       scene,sample,sample_data,sample_annotation,map}.json
    OUT/v1.0-urbangen/splits.json              the scenes of each split (the devkit's custom splits)
    OUT/samples/LIDAR_TOP/<log>__LIDAR_TOP__<timestamp>.pcd.bin   key-frame sweeps (2 Hz)
    OUT/sweeps/LIDAR_TOP/...                   the sweeps between them (10 Hz in all)
    OUT/samples/CAM_FRONT/..., CAM_FRONT_STEREO/...   the sequence's stereo pair (image_2, image_3)
    OUT/maps/<token>.png                       per scene: where the LiDAR saw road, parking, sidewalk (and
                                               the ground under the ego's path), 0.1 m per pixel

Every sequence ``lidar/sequences/NN`` is a scene (its own log and map); the tables follow
:mod:`generator.formats.nuscenes`. Points are de-skewed to the sweep start (urbangen scans keep
each column's firing frame; nuScenes' sweeps are ego-motion compensated), boxes are the box records
of :mod:`generator.detection` (each at the instant the LiDAR saw it, so a moving object's box sits on
its points) for the key-frame sweeps, with ``num_lidar_pts`` counted in that sweep. Splits: each
scene goes to ``urbangen_<split>`` with its sequence's split in ``lidar/semantic-kitti.yaml``
(``valid`` -> ``urbangen_val``) or the one ``--split`` names; ``urbangen_all`` lists every scene.
"""

from __future__ import annotations

import json
import logging
import os
import shutil
from pathlib import Path

import numpy as np
from scipy import ndimage
from scipy.spatial.transform import Rotation, Slerp

from generator.atomic import staging
from generator.errors import UserError
from generator.formats import nuscenes as nu
from generator.formats import semantickitti as sk
from generator.formats.label_config import read_split
from generator.formats.point_sidecars import RINGS_DIR, TIMES_DIR, read_sidecar
from generator.geometry.transforms import mount
from generator.imaging import meta_fields as md
from generator.labels.nuscenes import nuscenes_labels
from generator.safeload import printable

log = logging.getLogger(__name__)

VERSION = "v1.0-urbangen"
#: urbangen stereo cameras -> nuScenes channel.
CAMERA_CHANNELS = {2: "CAM_FRONT", 3: "CAM_FRONT_STEREO"}
#: SemanticKITTI raw ids the map's semantic prior holds: road, parking, sidewalk, lane-marking.
MAP_IDS = (40, 44, 48, 60)
MAP_RES_M = 0.1          #: nuScenes' map mask resolution
MAP_CELL_M = 0.2         #: points are binned and closed on this grid, then upsampled
CLOSE_CELLS = 13         #: gaps up to ~2.6 m between hit cells (rings 40 m out) are closed
#: The ego drives on the road: the ground within this radius of it, which its own LiDAR cannot see (an
#: HDL-64E's lowest beam meets the ground 3.7 m out), joins the prior.
EGO_GROUND_M = 3.0
#: Visibility of a box no camera image of its sample shows: nuScenes bins the share visible in all of a
#: sample's images, so a box outside them is in the lowest bin (0-40 %).
NOT_SEEN = "1"
SPLIT_NAMES = {"train": "urbangen_train", "valid": "urbangen_val", "val": "urbangen_val", "test": "urbangen_test"}


def sequences_of(root: Path) -> list[str]:
    """The sequences of ``root/lidar/sequences`` that hold a ``lidar_meta.json``."""
    base = Path(root) / "lidar" / "sequences"
    names = sorted(p.name for p in base.glob("[0-9][0-9]") if (p / "lidar_meta.json").is_file()) \
        if base.is_dir() else []
    if not names:
        raise UserError(f"{base}: no LiDAR sequences (sequences/NN with lidar_meta.json) to export")
    return names


def interp_pose(ts: np.ndarray, poses: np.ndarray, t: float) -> np.ndarray:
    """(4, 4) pose at offset ``t`` between knots ``ts`` (translation linear, rotation slerp; clamped)."""
    t = float(np.clip(t, ts[0], ts[-1]))
    if len(ts) == 1:
        return np.array(poses[0], np.float64)
    out = np.eye(4)
    out[:3, :3] = Slerp(ts, Rotation.from_matrix(poses[:, :3, :3]))(t).as_matrix()
    out[:3, 3] = [np.interp(t, ts, poses[:, i, 3]) for i in range(3)]
    return out


def rings_from_elevation(xyz: np.ndarray, sensor) -> np.ndarray:
    """(n,) beam rows of points in their firing frame, for datasets without ``point_rings``: the laser
    whose elevation (from its emission height) is nearest to the point's."""
    r = np.hypot(xyz[:, 0], xyz[:, 1])
    el = np.arctan2(xyz[:, 2:3] - sensor.vert_offset[None, :], r[:, None])       # (n, lasers)
    laser = np.argmin(np.abs(el - sensor.elevation[None, :]), axis=1)
    return np.asarray(sensor.ring, np.int64)[laser]


class MapRaster:
    """The semantic prior of one scene: road, parking and sidewalk cells the LiDAR hit, in ``global``."""

    def __init__(self, size_m: np.ndarray):
        self.shape = tuple(int(v) for v in np.ceil(np.asarray(size_m) / MAP_CELL_M)[::-1])   # (rows=y, cols=x)
        self.hits = np.zeros(self.shape, bool)

    def add_disk(self, xy_global: np.ndarray, radius_m: float) -> None:
        """Mark the cells within ``radius_m`` of a point (the ground the ego stands on, which its LiDAR cannot see)."""
        r = int(np.ceil(radius_m / MAP_CELL_M))
        off = np.stack(np.meshgrid(np.arange(-r, r + 1), np.arange(-r, r + 1)), -1).reshape(-1, 2) * MAP_CELL_M
        self.add(np.asarray(xy_global, np.float64)[:2] + off[np.hypot(off[:, 0], off[:, 1]) <= radius_m])

    def add(self, xy_global: np.ndarray) -> None:
        ij = np.floor(xy_global / MAP_CELL_M).astype(np.int64)
        ok = (ij[:, 0] >= 0) & (ij[:, 1] >= 0) & (ij[:, 0] < self.shape[1]) & (ij[:, 1] < self.shape[0])
        self.hits[ij[ok, 1], ij[ok, 0]] = True

    def png(self) -> np.ndarray:
        """(H, W) uint8 at :data:`MAP_RES_M`, 255 = prior, row 0 the top (largest y), as MapMask reads it."""
        m = ndimage.binary_closing(self.hits, np.ones((CLOSE_CELLS, CLOSE_CELLS), bool))   # far rings are sparse
        k = int(round(MAP_CELL_M / MAP_RES_M))
        return np.repeat(np.repeat(m[::-1], k, 0), k, 1).astype(np.uint8) * 255


class SceneExport:
    """One sequence of a dataset as a nuScenes scene (files written into ``stage``)."""

    def __init__(self, root: Path, name: str, spec, stage: Path, index: int):
        from generator.jobs.sequence_boxes import sequence_boxes

        self.root, self.name, self.stage = Path(root), name, Path(stage)
        self.seq = sk.Sequence(self.root / "lidar", name)
        self.meta_src = str(self.seq.dir / "lidar_meta.json")
        self.meta = md.load_metadata(self.seq.dir / "lidar_meta.json")
        self.knots = md.sweep_poses(self.meta, self.meta_src)
        if len(self.knots) != len(self.seq.frames) or self.seq.frames != list(range(len(self.seq.frames))):
            raise UserError(f"{self.meta_src}: sweep_poses_world: needs one entry per scan 000000..; "
                            "re-make the sequence with this urbangen")
        self.T_ego_lidar = mount(md.matrix(self.meta, "mount.lidar_xyz_m", (3,), self.meta_src),
                                 md.matrix(self.meta, "mount.lidar_rpy_deg", (3,), self.meta_src))
        self.boxes = sequence_boxes(self.root, name, spec, [j for j in self.seq.frames if j % nu.KEY_EVERY == 0])
        self.town = md.field(self.meta, "scene.name", self.meta_src)
        if not isinstance(self.town, str) or not self.town.replace("_", "").replace("-", "").isalnum():
            raise UserError(f"{self.meta_src}: scene.name: must be a scene name (letters, digits, _ and -)")
        self.scene_name = f"{self.town}-{name}"
        self.t0_us = nu.EPOCH_US + index * nu.SCENE_SPACING_US
        self.log_name = f"urbangen-{self.scene_name}"
        reach = float(md.matrix(self.meta, "sensor.range_m", (2,), self.meta_src)[1])
        xy = np.array([k[1][0][:2, 3] for k in self.knots])
        lo = np.floor((xy.min(0) - reach - 10.0) / 10.0) * 10.0
        self.shift = np.eye(4)
        self.shift[:2, 3] = -lo                       # world -> global: the map's corner is the origin
        self.map = MapRaster(xy.max(0) + reach + 10.0 - lo)
        self._sensor = None

    def timestamp(self, t: float) -> int:
        return int(self.t0_us + round(float(t) * 1e6))

    def T_world_ego(self, j: int, offset: float = 0.0) -> np.ndarray:
        ts, poses = self.knots[j]
        return interp_pose(ts, poses, offset) @ np.linalg.inv(self.T_ego_lidar)

    def _rings(self, j: int, xyz: np.ndarray) -> np.ndarray:
        rings = read_sidecar(self.seq.dir, RINGS_DIR, j, len(xyz))
        if rings is not None:
            return rings.astype(np.int64)
        if self._sensor is None:
            from generator.lidar.sensors import load_preset

            preset = md.field(self.meta, "sensor.name", self.meta_src)
            try:
                self._sensor = load_preset(str(preset))
            except UserError:
                raise UserError(f"{self.seq.dir / RINGS_DIR}: missing, and the sensor {printable(str(preset), 40)} "
                                "is no preset to take the rings from; re-make the sequence") from None
            log.warning("%s: no %s/; rings taken from each point's elevation", self.seq.dir, RINGS_DIR)
        return rings_from_elevation(xyz, self._sensor)

    def sweep(self, j: int) -> nu.Sweep:
        """Write sweep ``j``'s ``.pcd.bin`` (de-skewed, nuScenes frame) and add it to the map."""
        from generator.fusion.projection import deskew

        pts, sem, _ = self.seq.read_labelled(j)
        times = read_sidecar(self.seq.dir, TIMES_DIR, j, len(pts))
        ts, poses = self.knots[j]
        xyz = pts[:, :3].astype(np.float64)
        rings = self._rings(j, xyz)
        if times is not None:
            xyz = deskew(xyz, times, ts, poses)
        n_rings = int(md.integer(self.meta, "sensor.lasers", self.meta_src, 1, 256))
        t = float(self.seq.times[j])
        folder = "samples" if j % nu.KEY_EVERY == 0 else "sweeps"
        rel = f"{folder}/{nu.LIDAR_CHANNEL}/{self.log_name}__{nu.LIDAR_CHANNEL}__{self.timestamp(t)}.pcd.bin"
        dest = self.stage / rel
        dest.parent.mkdir(parents=True, exist_ok=True)
        dest.write_bytes(nu.pcd_rows(xyz, pts[:, 3], rings, n_rings).tobytes())
        T_global_lidar = self.shift @ poses[0]
        ground = np.isin(sem, MAP_IDS)
        self.map.add(xyz[ground] @ T_global_lidar[:3, :3].T[:, :2] + T_global_lidar[:2, 3])
        T_global_ego = self.shift @ self.T_world_ego(j)
        self.map.add_disk(T_global_ego[:2, 3], EGO_GROUND_M)
        return nu.Sweep(j, self.timestamp(t), T_global_ego, rel)

    def cameras(self) -> list[nu.CameraImage]:
        """The stereo pair's images (``image_2``/``image_3`` with their ``passes_N`` JSON), copied over."""
        out = []
        for cam, channel in CAMERA_CHANNELS.items():
            for png in sorted((self.seq.dir / f"image_{cam}").glob("[0-9]*.png")):
                meta_path = self.seq.dir / f"passes_{cam}" / f"{png.stem}.json"
                if not meta_path.is_file():
                    continue
                m = md.load_metadata(meta_path)
                src = str(meta_path)
                j = md.integer(m, "scan", src, 0, len(self.seq.frames) - 1)
                t = float(md.matrix(m, "time_s", (), src))
                T_world_cam = md.matrix(m, "T_world_camera", (4, 4), src)
                K = md.matrix(m, "K", (3, 3), src)
                w, h = md.integer(m, "width", src, 1, md.MAX_IMAGE_SIDE), md.integer(m, "height", src, 1,
                                                                                     md.MAX_IMAGE_SIDE)
                T_world_ego = self.T_world_ego(j, t - float(self.seq.times[j]))
                rel = f"{'samples' if j % nu.KEY_EVERY == 0 else 'sweeps'}/{channel}/" \
                      f"{self.log_name}__{channel}__{self.timestamp(t)}.png"
                (self.stage / rel).parent.mkdir(parents=True, exist_ok=True)
                shutil.copyfile(png, self.stage / rel)
                out.append(nu.CameraImage(channel, j, self.timestamp(t), self.shift @ T_world_ego,
                                          np.linalg.inv(T_world_ego) @ T_world_cam, K, w, h, rel))
        return out

    def annotations(self) -> list[nu.Annotation]:
        """The key frames' box records in ``global``."""
        labels = nuscenes_labels()
        out = []
        for j, recs in sorted(self.boxes.records.items()):
            seen = self.boxes.visibility.get(j, {})
            for r in recs:
                c = self.shift[:3, :3] @ r.center + self.shift[:3, 3]
                out.append(nu.Annotation(j, r.track_id, labels.category(r.cls, r.kind), r.attribute, c, r.size,
                                         float(r.yaw), r.num_lidar_pts, seen.get(r.track_id, NOT_SEEN)))
        return out

    def scene_input(self, sweeps: list[nu.Sweep], cameras: list[nu.CameraImage]) -> nu.SceneInput:
        town = md.field(self.meta, "scene.town.index", self.meta_src, default=None)
        seed = md.field(self.meta, "scene.seed", self.meta_src, default=None)
        desc = (f"urbangen {self.town}, sequence {self.name}" + (f", town {town}" if town is not None else "")
                + f", seed {seed}: {len(sweeps)} LiDAR sweeps at 10 Hz; boxes {self.boxes.source}")
        map_rel = f"maps/{nu.token(self.scene_name, 'map')}.png"
        from PIL import Image

        (self.stage / "maps").mkdir(parents=True, exist_ok=True)
        Image.fromarray(self.map.png()).save(self.stage / map_rel)
        return nu.SceneInput(self.scene_name, desc, self.town, self.T_ego_lidar, sweeps, self.annotations(),
                             cameras, map_rel)


def _split_of(root: Path, name: str, split: str | None) -> str:
    if split is not None:
        return SPLIT_NAMES[split]
    assigned = read_split(Path(root) / "lidar" / "semantic-kitti.yaml")
    for part, seqs in assigned.items():
        if int(name) in seqs:
            return SPLIT_NAMES[part]
    return SPLIT_NAMES["valid"]


def export_nuscenes(root: Path, out: Path, spec=None, split: str | None = None, sequences: list[str] | None = None,
                    progress=None) -> dict:
    """Write the nuScenes dataroot of ``root``'s sequences under ``out`` (all at once or nothing).

    Returns
    -------
    dict
        ``version``, ``scenes`` (names), ``splits`` and table sizes.
    """
    from generator.progress import progress as bar

    progress = progress or bar
    root, out = Path(root), Path(out)
    names = sequences or sequences_of(root)
    if (out / VERSION).exists():
        raise UserError(f"{out / VERSION}: exists; remove it or choose another output folder")
    builder = nu.TableBuilder()
    splits: dict[str, list[str]] = {}
    with staging(out, "nuscenes") as stage:
        for i, name in enumerate(names):
            scene = SceneExport(root, name, spec, stage, i)
            sweeps = [scene.sweep(j) for j in progress(scene.seq.frames, desc=f"nuscenes {name}", unit="sweep")]
            builder.add_scene(scene.scene_input(sweeps, scene.cameras()))
            splits.setdefault(_split_of(root, name, split), []).append(scene.scene_name)
        splits["urbangen_all"] = [s["name"] for s in builder.tables()["scene"]]
        tables = builder.tables()
        (stage / VERSION).mkdir()
        for table, rows in tables.items():
            (stage / VERSION / f"{table}.json").write_text(json.dumps(rows, indent=0), encoding="utf-8")
        (stage / VERSION / "splits.json").write_text(json.dumps(splits, indent=1), encoding="utf-8")
        _move_in(stage, out)
    return {"version": VERSION, "dataroot": str(out), "scenes": splits["urbangen_all"], "splits": splits,
            "tables": {k: len(v) for k, v in tables.items()}}


def _move_in(stage: Path, out: Path) -> None:
    """Move every staged file into ``out``, after checking that none would replace an existing one."""
    files = sorted(p for p in stage.rglob("*") if p.is_file())
    for path in files:
        if os.path.lexists(out / path.relative_to(stage)):
            raise UserError(f"{out / path.relative_to(stage)}: exists; remove it or choose another output folder")
    for path in files:
        target = out / path.relative_to(stage)
        target.parent.mkdir(parents=True, exist_ok=True)
        os.replace(path, target)
