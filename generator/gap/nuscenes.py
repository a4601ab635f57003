"""A nuScenes root as a ``gap`` dataset: the key-frame LIDAR_TOP sweeps, their lidarseg labels and boxes.

Read (the nuScenes v1.0 layout, real or ``urbangen export nuscenes``)::

    ROOT/v1.0-<version>/{sensor,calibrated_sensor,sample,sample_data,scene}.json   always
    ROOT/v1.0-<version>/{category,lidarseg}.json + ROOT/lidarseg/v1.0-*/<token>_lidarseg.bin   labels, if any
    ROOT/v1.0-<version>/{sample_annotation,ego_pose,instance,category}.json         boxes, if any
    ROOT/samples/LIDAR_TOP/*.pcd.bin                                               (n, 5) float32

Only those tables are loaded (never the camera tables' images or the map), and ``sample_data`` is cut to
the LIDAR_TOP key frames as soon as it is read. The version is the one ``v1.0-*`` folder with a
``sample_data.json`` (``--nuscenes-version`` names one when there are several). Scans are every key-frame
sample of every scene, scenes by name, samples in timestamp order (``--every`` thins them per scene);
``ScanData.sequence`` is the scene name, ``index`` the sample's place in it.

A point is ``x, y, z, intensity, ring``: x, y, z are turned from nuScenes' LIDAR_TOP frame (x right,
y forward) into urbangen's LiDAR frame (x forward, y left; :data:`generator.formats.nuscenes.R_LIDAR_NUSCENES`)
so azimuths and columns are counted as for a KITTI scan; intensity 0-255 becomes remission / 255; the ring
column is nuScenes' (0 = lowest beam), handed over as urbangen's ring (0 = highest) -- nothing derived.
A nuScenes sweep holds every firing (32 x ~1084 points): a beam without a return, or one that meets the
ego vehicle's roof, is a point by the sensor. Points within 1 m of it in x and in y are dropped, as the
devkit's ``LidarPointCloud.remove_close(1.0)`` drops them, so they count as lost rays.
Labels: lidarseg indices (category.json ``index``) -> SemanticKITTI learning classes through
``generator/labels/nuscenes_lidarseg.yaml``. Boxes: sample annotations (global frame) moved into the
sensor frame with the sweep's ego_pose and calibrated_sensor, points counted with the devkit's
``points_in_box``.

The sensor is said by the data: a root whose rings fit in 32 is nuScenes' HDL-32E at 20 Hz (preset
``hdl32e_20hz``); up to 64 rings (urbangen's own HDL-64E export), ``hdl64e``.
"""

from __future__ import annotations

import json
import threading
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from generator.errors import UserError
from generator.formats.nuscenes import R_LIDAR_NUSCENES
from generator.gap.objects import ObjectCounts
from generator.gap.scan import ScanData
from generator.labels.nuscenes_lidarseg import lidarseg_mapping
from generator.safeload import printable, read_array

CHANNEL = "LIDAR_TOP"
#: points within this of the sensor in x and in y are no returns of the scene (the devkit's remove_close)
EGO_RADIUS_M = 1.0
NEEDED = ("sensor", "calibrated_sensor", "sample", "sample_data", "scene")


def is_nuscenes_root(root: Path) -> bool:
    """Whether ``root`` looks like a nuScenes dataroot (a ``v1.0-*`` folder or ``samples/LIDAR_TOP``)."""
    return any(p.is_dir() for p in root.glob("v1.0-*")) or (root / "samples" / CHANNEL).is_dir()


class NuScenesSource:
    """The key-frame LiDAR sweeps of a nuScenes root (see the module docstring).

    Parameters
    ----------
    root : path-like
    role : str
        How the command line names it (``SYNTH``, ``REAL``), for messages.
    every : int
        Read every ``every``-th key frame of each scene.
    version : str, optional
        The ``v1.0-*`` folder name (default: the only one with tables).

    Raises
    ------
    UserError
        ``<role>: <file>: <field>: <reason>`` for a missing version, table, field or sweep.
    """

    layout = "nuscenes"
    #: lidarseg has no instance ids (panoptic is not read): objects come from boxes or not at all
    has_instances = False

    def __init__(self, root: str | Path, role: str, every: int = 1, version: str | None = None):
        self.root, self.role, self.every = Path(root), role, every
        self.version_dir = self._version(version)
        t = {name: self._table(name) for name in NEEDED}
        lidar_cs = self._lidar_calibrations(t["sensor"], t["calibrated_sensor"])
        sd = self._src("sample_data")
        sweeps = [r for r in t["sample_data"]
                  if _get(r, "calibrated_sensor_token", sd) in lidar_cs and _get(r, "is_key_frame", sd)]
        del t["sample_data"]
        sa = self._src("sample")
        scene_of = {_get(s, "token", sa): _get(s, "scene_token", sa) for s in t["sample"]}
        names = {_get(s, "token", self._src("scene")): _get(s, "name", self._src("scene")) for s in t["scene"]}
        by_scene: dict[str, list[dict]] = {}
        for r in sweeps:
            scene = scene_of.get(_get(r, "sample_token", self._src("sample_data")))
            if scene is None:
                raise UserError(f"{role}: {self._src('sample_data')}: sample_token: {printable(r['sample_token'])} "
                                "is in no sample")
            by_scene.setdefault(names.get(scene, scene), []).append(r)
        self.frames = {s: sorted(v, key=lambda r: _get(r, "timestamp", self._src("sample_data")))[::every]
                       for s, v in sorted(by_scene.items())}
        if not sum(len(f) for f in self.frames.values()):
            raise UserError(f"{role}: {self._src('sample_data')}: no {CHANNEL} key frame")
        self.calibration = {k: lidar_cs[k] for k in {r["calibrated_sensor_token"] for v in self.frames.values()
                                                       for r in v}}
        self._labels = self._lidarseg()
        self.has_labels = self._labels is not None
        self._boxes, self._lock = None, threading.Lock()
        self.rings = self._ring_count()

    # -- reading -------------------------------------------------------------------------------------------
    def _src(self, table: str) -> str:
        return printable(self.version_dir / f"{table}.json")

    def _version(self, version: str | None) -> Path:
        found = sorted(p for p in self.root.glob("v1.0-*") if (p / "sample_data.json").is_file())
        if version is not None:
            if not (self.root / version).is_dir():
                raise UserError(f"--nuscenes-version: {printable(self.root / version)}: no such folder "
                                f"(found: {', '.join(p.name for p in found) or 'none'})")
            return self.root / version
        if not found:
            raise UserError(f"{self.role}: {printable(self.root)}: no nuScenes version folder with tables "
                            "(v1.0-*/sample_data.json)")
        if len(found) > 1:
            raise UserError(f"--nuscenes-version: {printable(self.root)} holds {', '.join(p.name for p in found)}; "
                            "name one")
        return found[0]

    def _table(self, name: str, required: bool = True) -> list | None:
        path = self.version_dir / f"{name}.json"
        if not path.is_file():
            if not required:
                return None
            raise UserError(f"{self.role}: {self._src(name)}: missing (a nuScenes table this reader needs)")
        try:
            with open(path, encoding="utf-8") as f:
                doc = json.load(f)
        except (OSError, UnicodeDecodeError, ValueError) as e:
            raise UserError(f"{self.role}: {self._src(name)}: not a JSON table ({type(e).__name__})") from None
        if not isinstance(doc, list) or not all(isinstance(r, dict) for r in doc):
            raise UserError(f"{self.role}: {self._src(name)}: (top level): must be a list of records")
        return doc

    def _lidar_calibrations(self, sensors: list, calibrations: list) -> dict[str, dict]:
        lidar = {_get(s, "token", self._src("sensor")) for s in sensors
                 if _get(s, "channel", self._src("sensor")) == CHANNEL}
        if not lidar:
            raise UserError(f"{self.role}: {self._src('sensor')}: channel: no {CHANNEL} sensor")
        return {_get(c, "token", self._src("calibrated_sensor")): c for c in calibrations
                if _get(c, "sensor_token", self._src("calibrated_sensor")) in lidar}

    def _lidarseg(self) -> dict | None:
        records = self._table("lidarseg", required=False)
        if records is None:
            return None
        files = {_get(r, "sample_data_token", self._src("lidarseg")): _get(r, "filename", self._src("lidarseg"))
                 for r in records}
        if not all(r["token"] in files for v in self.frames.values() for r in v):
            raise UserError(f"{self.role}: {self._src('lidarseg')}: sample_data_token: not every {CHANNEL} key frame "
                            "has a lidarseg record")
        mapping = lidarseg_mapping()
        lut = np.zeros(256, np.int64)
        cats = self._table("category", required=False) or []
        indexed = [c for c in cats if "index" in c]
        if indexed:  # the category.json of nuScenes-lidarseg names each index
            for c in indexed:
                name, i = c.get("name"), c["index"]
                if not isinstance(i, int) or not 0 <= i < 256:
                    raise UserError(f"{self.role}: {self._src('category')}: index: {printable(i)} is no 0-255 value")
                if name in mapping.names:
                    lut[i] = mapping.to_learning[mapping.names.index(name)]
        else:
            lut[: len(mapping.to_learning)] = mapping.to_learning
        self._lut = lut
        return files

    def _ring_count(self) -> int:
        first = next(r for v in self.frames.values() for r in v)
        ring = self._points(first)[:, 4]
        top = int(ring.max(initial=0)) + 1
        if top > 64:
            raise UserError(f"{self.role}: {printable(self.root / first['filename'])}: ring: {top} rings, "
                            "more than any preset (hdl32e_20hz: 32, hdl64e: 64)")
        return 32 if top <= 32 else 64

    def _points(self, rec: dict) -> np.ndarray:
        rel = _get(rec, "filename", self._src("sample_data"))
        path = self.root / rel
        if not path.is_file():
            raise UserError(f"{self.role}: {printable(path)}: missing (sample_data {printable(rec['token'])})")
        return read_array(path, "<f4", 20, source=printable(path), field="x, y, z, intensity, ring", finite=True)

    # -- the Source interface ------------------------------------------------------------------------------
    @property
    def n_scans(self) -> int:
        return sum(len(f) for f in self.frames.values())

    @property
    def has_boxes(self) -> bool:
        return all((self.version_dir / f"{t}.json").is_file()
                   for t in ("sample_annotation", "ego_pose", "instance", "category"))

    def boxes(self, sequence: str):
        """A callable ``(index, xyz) -> ObjectCounts`` for the scene (annotations loaded on first use)."""
        with self._lock:
            if self._boxes is None:
                self._boxes = _Boxes(self)
        return lambda index, xyz: self._boxes(self.frames[sequence][index], xyz)

    def sensor_name(self) -> str:
        """The preset of the data's sensor: ``hdl32e_20hz`` (nuScenes) or ``hdl64e`` (urbangen's export)."""
        return "hdl32e_20hz" if self.rings == 32 else "hdl64e"

    def default_sensor(self) -> str:
        """The ring fit's sensor when ``--sensor`` names none: the data's own (:meth:`sensor_name`)."""
        return self.sensor_name()

    def scans(self) -> Iterator[ScanData]:
        """Every key frame read (one in ``every`` per scene), in scene and timestamp order."""
        for scene, recs in self.frames.items():
            for i, rec in enumerate(recs):
                pts = self._points(rec)
                path = printable(self.root / rec["filename"])
                ring = pts[:, 4]
                if ring.size and (ring.min() < 0 or ring.max() >= self.rings or np.any(ring != np.round(ring))):
                    raise UserError(f"{self.role}: {path}: ring: not a whole number 0..{self.rings - 1}")
                learning = None
                if self._labels is not None:
                    learning = self._learning(rec, len(pts))
                # nuScenes writes every firing: a beam without a return and a beam on the ego vehicle's roof sit
                # by the sensor. Those are dropped as the devkit's remove_close(1.0) drops them: no return.
                far = ~((np.abs(pts[:, 0]) < EGO_RADIUS_M) & (np.abs(pts[:, 1]) < EGO_RADIUS_M))
                pts, ring = pts[far], ring[far]
                learning = None if learning is None else learning[far]
                xyz = (pts[:, :3].astype(np.float64) @ R_LIDAR_NUSCENES.T).astype(np.float32)
                yield ScanData(scene, i, xyz, np.clip(pts[:, 3] / 255.0, 0.0, 1.0).astype(np.float32), learning,
                               None, ((self.rings - 1) - ring).astype(np.int16))

    def _learning(self, rec: dict, n: int) -> np.ndarray:
        path = self.root / self._labels[rec["token"]]
        if not path.is_file():
            raise UserError(f"{self.role}: {printable(path)}: missing "
                            f"(lidarseg of sample_data {printable(rec['token'])})")
        raw = read_array(path, "u1", source=printable(path), field="lidarseg")
        if len(raw) != n:
            raise UserError(f"{self.role}: {printable(path)}: lidarseg: {len(raw)} labels for the {n} points of "
                            f"{printable(rec['filename'])}")
        return self._lut[raw]


class _Boxes:
    """Sample annotations of the key frames, counted in the sensor frame (devkit ``Box``, ``points_in_box``)."""

    def __init__(self, src: NuScenesSource):
        try:  # the boxes are counted with the devkit's own geometry: say so before anything is read
            import nuscenes.utils.data_classes  # noqa: F401
        except ImportError:
            raise UserError('gap: points per object of a nuScenes root need nuscenes-devkit: '
                            'pip install -e ".[detection]" (or --objects off)') from None
        wanted = {r["sample_token"] for v in src.frames.values() for r in v}
        self.anns: dict[str, list] = {}
        for a in src._table("sample_annotation"):
            if a.get("sample_token") in wanted:
                self.anns.setdefault(a["sample_token"], []).append(a)
        poses = {r["ego_pose_token"] for v in src.frames.values() for r in v}
        self.poses = {p["token"]: p for p in src._table("ego_pose") if p.get("token") in poses}
        cats = {c.get("token"): c.get("name") for c in src._table("category")}
        self.cls = {i.get("token"): _box_class(cats.get(i.get("category_token")))
                    for i in src._table("instance")}
        self.src = src

    def __call__(self, rec: dict, xyz: np.ndarray) -> ObjectCounts:
        from nuscenes.utils.data_classes import Box
        from nuscenes.utils.geometry_utils import points_in_box
        from pyquaternion import Quaternion

        anns = self.anns.get(rec["sample_token"], [])
        if not anns:
            return ObjectCounts([], np.zeros(0), np.zeros(0, np.int64))
        pose, cs = self.poses[rec["ego_pose_token"]], self.src.calibration[rec["calibrated_sensor_token"]]
        pts = (np.asarray(xyz, np.float64) @ R_LIDAR_NUSCENES).T  # back to nuScenes' LIDAR_TOP frame, (3, n)
        cls, dist, count = [], [], []
        for a in anns:
            b = Box(a["translation"], a["size"], Quaternion(a["rotation"]))
            b.translate(-np.asarray(pose["translation"]))
            b.rotate(Quaternion(pose["rotation"]).inverse)
            b.translate(-np.asarray(cs["translation"]))
            b.rotate(Quaternion(cs["rotation"]).inverse)
            cls.append(self.cls.get(a.get("instance_token"), "object"))
            dist.append(float(np.linalg.norm(b.center)))
            count.append(int(points_in_box(b, pts).sum()))
        return ObjectCounts(cls, np.array(dist), np.array(count, np.int64))


def _box_class(category: str | None) -> str:
    """``car`` for nuScenes' car category (what points_per_car counts), else the category name."""
    return "car" if category == "vehicle.car" else str(category or "object")


def _get(rec: dict, key: str, source: str):
    try:
        return rec[key]
    except KeyError:
        raise UserError(f"{source}: {key}: missing in a record") from None
