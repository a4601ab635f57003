"""nuScenes v1.0 tables of urbangen sequences: records in, JSON-able tables out (no file reading).

One urbangen LiDAR sequence is one nuScenes ``scene`` with its own ``log`` and ``map``. Its 10 Hz
sweeps are ``sample_data`` of the ``LIDAR_TOP`` channel, every :data:`KEY_EVERY`-th one (2 Hz, as
nuScenes) a key frame with a ``sample`` and the ``sample_annotation`` of its boxes; the sweeps between
key frames are linked by ``prev``/``next`` so "10 sweeps" accumulation
(:meth:`nuscenes.utils.data_classes.LidarPointCloud.from_file_multisweep`) finds them, and each
points at its nearest sample (``sample_token``), as nuScenes does.

Frames and units (nuScenes' own conventions, see its devkit and schema):

* ``global``: the urbangen world frame shifted so that the scene's map lies in x, y >= 0 (the map
  PNG's lower-left corner is the global origin, as :class:`nuscenes.utils.map_mask.MapMask` reads it);
  metres, z up. ``ego_pose`` is the ego (x forward, y left, z up; origin on the ground below the
  LiDAR) in ``global`` at the sample_data's timestamp.
* ``LIDAR_TOP``: x right, y forward, z up (nuScenes' Velodyne mount), i.e. urbangen's LiDAR frame
  (x forward, y left) turned by -90 degrees about z: :data:`R_LIDAR_NUSCENES`. Its
  ``calibrated_sensor`` holds the mount in the ego frame (for an unturned mount the rotation is the
  quaternion (0.7071, 0, 0, -0.7071), nuScenes' value).
* rotations are quaternions ``[w, x, y, z]``; box sizes ``[width, length, height]`` metres;
  timestamps integer microseconds.
* ``.pcd.bin``: float32 little-endian rows ``(x, y, z, intensity, ring)`` in ``LIDAR_TOP`` at the
  sample_data's timestamp (ego motion compensated, as nuScenes' sweeps are); intensity on nuScenes'
  0-255 scale (urbangen remission x 255); ring = beam row counted from the lowest beam (0) up, the
  Velodyne driver's order.

Tokens are 32 hex digits derived from names (:func:`token`), so the same dataset gives the same tables.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

from generator.labels.nuscenes import nuscenes_labels

#: Every KEY_EVERY-th 10 Hz sweep is a key frame (2 Hz samples, as nuScenes).
KEY_EVERY = 5
LIDAR_CHANNEL = "LIDAR_TOP"
#: Columns of a nuScenes LiDAR file.
PCD_COLUMNS = ("x", "y", "z", "intensity", "ring")
#: nuScenes LIDAR_TOP axes (columns: its x right, y forward, z up) written in urbangen's LiDAR frame.
R_LIDAR_NUSCENES = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
#: The tables of a nuScenes version folder, in the devkit's order.
TABLES = ("category", "attribute", "visibility", "instance", "sensor", "calibrated_sensor", "ego_pose", "log",
          "scene", "sample", "sample_data", "sample_annotation", "map")
#: The first sample of a dataset: 2020-01-01T00:00:00Z, microseconds (scene k starts k hours later).
EPOCH_US = 1_577_836_800_000_000
SCENE_SPACING_US = 3_600_000_000


def token(*parts) -> str:
    """A 32-hex-digit token named by ``parts`` (the same parts, the same token)."""
    return hashlib.md5("/".join(str(p) for p in ("urbangen", *parts)).encode()).hexdigest()


def quaternion(R: np.ndarray) -> list[float]:
    """``[w, x, y, z]`` of a (3, 3) rotation (w >= 0)."""
    x, y, z, w = Rotation.from_matrix(np.asarray(R, np.float64)).as_quat()
    q = np.array([w, x, y, z])
    return [float(v) for v in (q if w >= 0 else -q)]


def pose_record(T: np.ndarray) -> dict:
    """``translation`` and ``rotation`` of a (4, 4) pose, nuScenes style."""
    T = np.asarray(T, np.float64)
    return {"translation": [float(v) for v in T[:3, 3]], "rotation": quaternion(T[:3, :3])}


def pcd_rows(xyz_lidar: np.ndarray, remission: np.ndarray, ring: np.ndarray, n_rings: int) -> np.ndarray:
    """(n, 5) float32 ``.pcd.bin`` rows from urbangen LiDAR-frame points.

    Parameters
    ----------
    xyz_lidar : (n, 3) float
        urbangen LiDAR frame (x forward, y left, z up), metres.
    remission : (n,) float in [0, 1]
    ring : (n,) int
        urbangen beam rows (0 = highest beam).
    n_rings : int
        Beams of the sensor.
    """
    out = np.empty((len(xyz_lidar), 5), "<f4")
    out[:, :3] = np.asarray(xyz_lidar, np.float64) @ R_LIDAR_NUSCENES
    out[:, 3] = np.clip(np.asarray(remission, np.float64), 0.0, 1.0) * 255.0
    out[:, 4] = (n_rings - 1) - np.asarray(ring, np.int64)
    return out


@dataclass
class Sweep:
    """One LiDAR sweep of a scene.

    Attributes
    ----------
    index : int
        Sweep number in the sequence.
    timestamp : int
        Microseconds.
    T_global_ego : (4, 4) float64
        Ego pose at ``timestamp``.
    filename : str
        The ``.pcd.bin`` path relative to the dataroot.
    """

    index: int
    timestamp: int
    T_global_ego: np.ndarray
    filename: str

    @property
    def key(self) -> bool:
        return self.index % KEY_EVERY == 0


@dataclass
class CameraImage:
    """One camera image of a scene (its sweep a key frame or not).

    ``T_ego_camera``: the optical camera (x right, y down, z forward) in the ego frame; ``K`` (3, 3).
    """

    channel: str
    sweep: int
    timestamp: int
    T_global_ego: np.ndarray
    T_ego_camera: np.ndarray
    K: np.ndarray
    width: int
    height: int
    filename: str


@dataclass
class Annotation:
    """One box of a key-frame sweep, in ``global``.

    ``size`` is (length, width, height) as urbangen stores it; ``yaw`` about global +z.
    """

    sweep: int
    track_id: int
    category: str
    attribute: str
    center: np.ndarray
    size: np.ndarray
    yaw: float
    num_lidar_pts: int
    visibility: str = "1"


@dataclass
class SceneInput:
    """Everything one scene's records are made of."""

    name: str
    description: str
    location: str
    lidar_T_ego_sensor: np.ndarray
    sweeps: list[Sweep]
    annotations: list[Annotation]
    cameras: list[CameraImage] = field(default_factory=list)
    map_filename: str = ""
    date: str = "2020-01-01"


def _link(records: list[dict]) -> None:
    for a, b in zip(records, records[1:], strict=False):
        a["next"], b["prev"] = b["token"], a["token"]


def _nearest_key(index: int, keys: list[int]) -> int:
    """The key sweep nearest to sweep ``index`` (the earlier one on a tie)."""
    k = np.asarray(keys)
    return int(k[np.argmin(np.abs(k - index) * 2 + (k > index))])


class TableBuilder:
    """Accumulates the nuScenes tables of one or more scenes (:meth:`add_scene`, then :meth:`tables`)."""

    def __init__(self):
        labels = nuscenes_labels()
        self.t = {name: [] for name in TABLES}
        self.t["category"] = [{"token": token("category", c), "name": c, "description": d}
                              for c, d in labels.categories.items()]
        self.t["attribute"] = [{"token": token("attribute", a), "name": a, "description": d}
                               for a, d in labels.attributes.items()]
        self.t["visibility"] = [dict(v) for v in labels.visibility]
        self._sensors: dict[str, str] = {}
        self._calibrations: set[str] = set()

    def _sensor(self, channel: str, modality: str) -> str:
        if channel not in self._sensors:
            self._sensors[channel] = token("sensor", channel)
            self.t["sensor"].append({"token": self._sensors[channel], "channel": channel, "modality": modality})
        return self._sensors[channel]

    def _calibrated(self, scene: str, channel: str, modality: str, T_ego_sensor: np.ndarray,
                    K: np.ndarray | None = None, key: str = "") -> str:
        tok = token(scene, "calibrated_sensor", channel, key)
        if tok not in self._calibrations:
            self._calibrations.add(tok)
            self.t["calibrated_sensor"].append({
                "token": tok, "sensor_token": self._sensor(channel, modality), **pose_record(T_ego_sensor),
                "camera_intrinsic": [] if K is None else np.asarray(K, np.float64).tolist()})
        return tok

    def add_scene(self, s: SceneInput) -> str:
        """Add one scene's log, map, samples, sample_data, ego poses, instances and annotations; its token."""
        scene_tok, log_tok = token(s.name, "scene"), token(s.name, "log")
        self.t["log"].append({"token": log_tok, "logfile": f"urbangen-{s.name}", "vehicle": "urbangen-ego",
                              "date_captured": s.date, "location": s.location})
        if s.map_filename:
            self.t["map"].append({"token": token(s.name, "map"), "log_tokens": [log_tok],
                                  "category": "semantic_prior", "filename": s.map_filename})
        keys = [w.index for w in s.sweeps if w.key]
        if not keys:
            raise ValueError(f"scene {s.name}: no key-frame sweep (sweep 0, {KEY_EVERY}, ...)")
        sample_of = {j: token(s.name, "sample", j) for j in keys}
        by_index = {w.index: w for w in s.sweeps}
        samples = [{"token": sample_of[j], "timestamp": by_index[j].timestamp, "prev": "", "next": "",
                    "scene_token": scene_tok} for j in keys]
        _link(samples)
        self.t["sample"] += samples
        lidar_cs = self._calibrated(s.name, LIDAR_CHANNEL, "lidar", self._lidar_mount(s.lidar_T_ego_sensor))
        data = []
        for w in s.sweeps:
            tok = token(s.name, "sample_data", LIDAR_CHANNEL, w.index)
            self.t["ego_pose"].append({"token": tok, "timestamp": w.timestamp, **pose_record(w.T_global_ego)})
            data.append({"token": tok, "sample_token": sample_of[_nearest_key(w.index, keys)], "ego_pose_token": tok,
                         "calibrated_sensor_token": lidar_cs, "timestamp": w.timestamp, "fileformat": "pcd",
                         "is_key_frame": w.key, "height": 0, "width": 0, "filename": w.filename,
                         "prev": "", "next": ""})
        _link(data)
        self.t["sample_data"] += data
        self._cameras(s, sample_of, keys)
        self._annotations(s, sample_of)
        self.t["scene"].append({"token": scene_tok, "log_token": log_tok, "nbr_samples": len(samples),
                                "first_sample_token": samples[0]["token"], "last_sample_token": samples[-1]["token"],
                                "name": s.name, "description": s.description})
        return scene_tok

    @staticmethod
    def _lidar_mount(T_ego_lidar: np.ndarray) -> np.ndarray:
        """LIDAR_TOP in the ego frame: the urbangen mount turned into nuScenes' sensor axes."""
        T = np.array(T_ego_lidar, np.float64)
        T[:3, :3] = T[:3, :3] @ R_LIDAR_NUSCENES
        return T

    def _cameras(self, s: SceneInput, sample_of: dict[int, str], keys: list[int]) -> None:
        for channel in sorted({c.channel for c in s.cameras}):
            images = sorted((c for c in s.cameras if c.channel == channel), key=lambda c: c.timestamp)
            first = images[0].T_ego_camera
            fixed = all(np.allclose(c.T_ego_camera, first, atol=1e-6) and np.allclose(c.K, images[0].K)
                        for c in images)
            data = []
            for c in images:
                cs = self._calibrated(s.name, channel, "camera", c.T_ego_camera, c.K, "" if fixed else str(c.sweep))
                tok = token(s.name, "sample_data", channel, c.sweep)
                self.t["ego_pose"].append({"token": tok, "timestamp": c.timestamp, **pose_record(c.T_global_ego)})
                key = c.sweep in sample_of
                data.append({"token": tok, "sample_token": sample_of[c.sweep] if key else
                             sample_of[_nearest_key(c.sweep, keys)], "ego_pose_token": tok,
                             "calibrated_sensor_token": cs, "timestamp": c.timestamp,
                             "fileformat": c.filename.rsplit(".", 1)[-1], "is_key_frame": key, "height": c.height,
                             "width": c.width, "filename": c.filename, "prev": "", "next": ""})
            _link(data)
            self.t["sample_data"] += data

    def _annotations(self, s: SceneInput, sample_of: dict[int, str]) -> None:
        labels = nuscenes_labels()
        cat_tok = {c["name"]: c["token"] for c in self.t["category"]}
        attr_tok = {a["name"]: a["token"] for a in self.t["attribute"]}
        tracks: dict[int, list[Annotation]] = {}
        for a in sorted(s.annotations, key=lambda a: (a.track_id, a.sweep)):
            if a.sweep not in sample_of:
                raise ValueError(f"scene {s.name}: an annotation of sweep {a.sweep}, which is no key frame")
            if a.category not in labels.categories or (a.attribute and a.attribute not in attr_tok):
                raise ValueError(f"scene {s.name}: unknown category {a.category!r} or attribute {a.attribute!r}")
            tracks.setdefault(a.track_id, []).append(a)
        for tid, anns in tracks.items():
            inst = token(s.name, "instance", tid)
            recs = []
            for a in anns:
                R = Rotation.from_euler("z", a.yaw).as_matrix()
                L, W, H = (float(v) for v in a.size)
                recs.append({"token": token(s.name, "sample_annotation", tid, a.sweep),
                             "sample_token": sample_of[a.sweep], "instance_token": inst,
                             "visibility_token": a.visibility,
                             "attribute_tokens": [attr_tok[a.attribute]] if a.attribute else [],
                             "translation": [float(v) for v in a.center], "size": [W, L, H],
                             "rotation": quaternion(R), "prev": "", "next": "",
                             "num_lidar_pts": int(a.num_lidar_pts), "num_radar_pts": 0})
            _link(recs)
            self.t["sample_annotation"] += recs
            categories = {a.category for a in anns}
            if len(categories) != 1:
                raise ValueError(f"scene {s.name}: track {tid} changes category {sorted(categories)}")
            self.t["instance"].append({"token": inst, "category_token": cat_tok[anns[0].category],
                                       "nbr_annotations": len(recs), "first_annotation_token": recs[0]["token"],
                                       "last_annotation_token": recs[-1]["token"]})

    def tables(self) -> dict[str, list[dict]]:
        """Every table of :data:`TABLES` (a ``map`` record needs a scene with a map)."""
        return self.t
