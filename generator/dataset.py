"""Read a generated dataset in training code: numpy arrays, no framework.

::

    from generator.dataset import Dataset

    ds = Dataset("dataset")
    for name in ds.image_names():               # "000000_day_fog", ...
        img = ds.image(name)                    # .rgb .class_id .instance .depth .meta
    frame = ds.frame(0)                         # one call: every image variant, the scan, its boxes
    scan = frame.scan                           # .xyz .remission .semantic .instance .pose .time

Frames and sweeps: the LiDAR is a 10 Hz stream and images are exposed at some of its sweeps
(``image_frames`` of ``lidar_meta.json``); image frame ``k`` pairs with sweep ``frame.sweep``,
whose scan and OpenLABEL boxes :meth:`Dataset.frame` returns. :meth:`Dataset.scan` and
:meth:`Dataset.boxes` take sweep indices. A dataset of many towns (``town.redraw_every_frames``)
has one sequence per town: ``Dataset(root, "01")`` pairs town 1's images with its scans, and an
image of another town comes with ``sweep`` None and no scan (its ``meta["town"]`` says which).

Arrays and frames
-----------------
* ``ImageSample.rgb`` (H, W, 3) float32 linear RGB; ``class_id`` (H, W) uint8 native class
  ids (:func:`ImageSample.labels` maps them to ``cityscapes``, ``semantickitti`` learning ids or
  ``unified11``); ``instance`` (H, W) uint32 (0 for stuff); ``depth`` (H, W) float32 metres
  along the ray (inf = sky); ``meta`` the image's metadata JSON (camera pose, intrinsics,
  weather, lighting).
* ``ScanSample.xyz`` (n, 3) float32 LiDAR frame (x forward, y left, z up), metres;
  ``remission`` (n,) float32 in [0, 1]; ``semantic`` (n,) uint16 SemanticKITTI raw ids;
  ``instance`` (n,) uint16; ``native`` (n,) uint8 native classes (urbangen side file, or None);
  ``pose`` (4, 4) float64 LiDAR pose in the first scan's LiDAR frame; ``time`` seconds.
* ``Box`` (:mod:`generator.formats.box_frames`): a 3D box in the frame of the scan it belongs to, the
  LiDAR frame at the instant the LiDAR saw it (read from ``boxes/NN.npz``): ``center`` (3,),
  ``quaternion`` (x, y, z, w), ``size`` (length, width, height) metres, ``yaw``, ``velocity``, ``cls``,
  ``uid`` (track id), ``points`` (``num_lidar_pts``), ``attribute``; ``box.to("ego" | "camera" |
  "world" | "lidar")`` moves it. A dataset without a box file gives its OpenLABEL cuboids instead
  (ego frame at the sweep start, not movable).
* :meth:`Dataset.image_boxes`: every thing an image shows, its box at the exposure instant in the
  camera frame and its visibility (amodal/visible 2D boxes, truncation, occlusion...).

Motion ground truth (:mod:`generator.jobs.motion`, :mod:`generator.formats.scene_flow`)
--------------------------------------------------------------------------------------
* :meth:`Dataset.image_flow` / :meth:`Dataset.stereo_flow`: ``FlowMaps`` with ``forward`` and
  ``backward`` (H, W, 2) float32 pixels (u right, v down; None at a stream's end) and their flags
  (bit 1 known = KITTI ``flow_occ``, 2 visible in the other image = ``flow_noc``, 4 on an actor);
* :meth:`Dataset.disparity`: ``DisparityMap`` ``d`` (H, W) float32 pixels (``f b / Z``) and flags
  (1 ``disp_occ``, 2 ``disp_noc``);
* :meth:`Dataset.scene_flow`: (n, 3) float32 metres in the scan's LiDAR frame per point, with the
  ego's motion (default) or without, and the flag (n,) uint8 (0 seen, 1 hidden, 2 gone at the next scan).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from generator.errors import SpecError, UserError
from generator.formats import semantickitti as sk
from generator.formats.box_file import read_box_file
from generator.formats.box_frames import Box, box_of_record
from generator.formats.point_sidecars import NATIVE_DIR, TIMES_DIR, read_sidecar
from generator.formats.scene_flow import ego_flow, read_scene_flow
from generator.imaging import meta_fields as md
from generator.imaging.exr import read_exr
from generator.imaging.motion_exr import DisparityMap, FlowMaps, read_disparity_exr, read_flow_exr
from generator.imaging.paths import find_image, frame_of, image_files
from generator.labels import class_table
from generator.labels.sets import label_sets
from generator.safeload import printable


@dataclass
class ImageSample:
    """One image of ``images/`` (see the module docstring for shapes)."""

    name: str
    rgb: np.ndarray
    class_id: np.ndarray
    instance: np.ndarray
    depth: np.ndarray
    meta: dict

    def labels(self, label_set: str = "native") -> np.ndarray:
        """(H, W) class map in ``native``, ``cityscapes`` (label ids), ``semantickitti`` (learning ids) or
        ``unified11``."""
        if label_set == "cityscapes":
            return class_table().to_cityscapes[self.class_id]
        sets = label_sets()
        if label_set not in sets:
            others = ", ".join(s for s in sets if s != "native")
            raise UserError(f"label set {label_set!r}: use native, cityscapes, {others}")
        return sets[label_set].from_native[self.class_id]


@dataclass
class ScanSample:
    """One LiDAR scan with labels, pose and time (see the module docstring for shapes)."""

    index: int
    xyz: np.ndarray
    remission: np.ndarray
    semantic: np.ndarray | None
    instance: np.ndarray | None
    native: np.ndarray | None
    pose: np.ndarray | None
    time: float | None


@dataclass
class FrameSample:
    """Everything of image frame ``index``: its image variants, the scan and boxes of ``sweep``."""

    index: int
    sweep: int | None
    images: dict[str, ImageSample] = field(default_factory=dict)
    scan: ScanSample | None = None
    boxes: list[Box] = field(default_factory=list)


class Dataset:
    """A generated dataset folder (``urbangen generate``'s output).

    Parameters
    ----------
    root : path-like
    sequence : str
        The LiDAR sequence whose scans and boxes :meth:`frame` returns (default ``00``).
    """

    def __init__(self, root: str | Path, sequence: str = "00"):
        self.root = Path(root)
        if not self.root.is_dir():
            raise UserError(f"{self.root}: no such dataset folder")
        self.sequence = sk.sequence_name(sequence)
        lidar = self.root / "lidar"
        has_seq = (lidar / "sequences" / self.sequence / "velodyne").is_dir()
        self.seq = sk.Sequence(lidar, self.sequence) if has_seq else None
        self._poses = self.seq.lidar_poses() if self.seq is not None else None
        box_file = self.root / "boxes" / f"{self.sequence}.npz"
        self._box_file = read_box_file(box_file) if box_file.is_file() else None
        self._boxes = {} if self._box_file else self._read_boxes(self.root / "openlabel" / f"{self.sequence}.json")
        meta = self.seq.dir / "lidar_meta.json" if self.seq is not None else None
        #: image frame -> the sweep it was exposed with (identity without ``image_frames``)
        self._sweep_of = md.image_sweeps(md.load_metadata(meta), str(meta)) if meta and meta.exists() else {}

    def sweep_of(self, frame: int) -> int | None:
        """The sweep image frame ``frame`` was exposed with; None for an image of another sequence
        (a re-drawn town's, ``town.redraw_every_frames``: each town is its own sequence)."""
        if self._sweep_of:
            return self._sweep_of.get(frame)
        return frame

    # -- images ------------------------------------------------------------------------------
    def image_names(self, frame: int | None = None) -> list[str]:
        """Image stems (``NNNNNN_<time>_<weather>``), sorted; only those of ``frame`` if given."""
        files = image_files(self.root, "[0-9][0-9][0-9][0-9][0-9][0-9]_*.json", None if frame is None else [frame])
        return sorted({p.stem for p in files})

    def image_files(self, name: str) -> tuple[Path, Path]:
        """(EXR, metadata JSON) of image ``name``, sharded or flat (:mod:`generator.imaging.paths`)."""
        if frame_of(name) is None:
            raise UserError(f"{printable(name, 60)}: not an image name (NNNNNN_<time>_<weather>)")
        return find_image(self.root, name, ".exr"), find_image(self.root, name, ".json")

    def image(self, name: str) -> ImageSample:
        """The image ``name`` with its masks, instances, depth and metadata."""
        exr, meta = self.image_files(name)
        if not os.path.lexists(exr) or not os.path.lexists(meta):
            raise UserError(f"{exr}: no such image (with its .json)")
        img = read_exr(exr)
        return ImageSample(name, img.rgb, img.class_id, img.instance, img.depth, md.load_metadata(meta))

    # -- scans ---------------------------------------------------------------------------------
    def scan_indices(self) -> list[int]:
        return list(self.seq.frames) if self.seq is not None else []

    def scan(self, index: int) -> ScanSample:
        """Scan ``index`` of the sequence with its labels, native classes, pose and time."""
        if self.seq is None:
            raise UserError(f"{self.root / 'lidar'}: no sequence {self.sequence}")
        rec = self.seq.read(index, True, self._poses)
        if rec.semantic is not None:
            sk.check_raw_ids(rec.semantic, self.seq.label_path(index))
        native = read_sidecar(self.seq.dir, NATIVE_DIR, index, len(rec.points))
        return ScanSample(index, rec.points[:, :3], rec.points[:, 3], rec.semantic, rec.instance, native, rec.pose,
                          rec.time)

    def boxes(self, index: int) -> list[Box]:
        """The 3D boxes of sweep ``index`` in its LiDAR frame (empty when the dataset has none)."""
        if self._box_file is not None:
            return [box_of_record(r, self._box_file.info) for r in self._box_file.records(index)]
        return list(self._boxes.get(index, []))

    def image_boxes(self, name: str) -> list[tuple[Box, dict]]:
        """What image ``name`` shows (``NNNNNN_<time>_<weather>``, ``image_2/NNNNNN`` or ``image_3/NNNNNN``):
        per thing its box at the exposure instant in that image's camera frame, and its visibility
        (``bbox_amodal``, ``bbox_visible`` (x0, y0, x1, y1) px, ``truncation``, ``visibility``,
        ``occlusion``, ``difficulty``, ``nuscenes_visibility``, pixel counts). Empty without a box file."""
        entry = self._box_file.image(name) if self._box_file is not None else None
        if entry is None:
            return []
        out = []
        for rec, vis in entry.boxes:
            box = box_of_record(rec, self._box_file.info).to("camera", entry.T_world_camera)
            out.append((box, {k: getattr(vis, k) for k in ("bbox_amodal", "bbox_visible", "pixels_amodal",
                                                              "pixels_visible", "truncation", "visibility", "occlusion",
                                                              "difficulty", "nuscenes_visibility")}))
        return out

    def frame(self, index: int) -> FrameSample:
        """Every image variant of image frame ``index``, with the scan and boxes of its sweep, in one call."""
        j = self.sweep_of(index)
        out = FrameSample(index, j, {n: self.image(n) for n in self.image_names(index)})
        if self.seq is not None and j is not None and j in self.seq.frames:
            out.scan = self.scan(j)
        out.boxes = self.boxes(j) if j is not None else []
        return out

    # -- motion ground truth (generator.jobs.motion, generator.formats.scene_flow) ---------------
    def image_flow(self, name: str) -> FlowMaps | None:
        """Optical flow of image ``name`` of images/ to the next and previous frame of its stream
        (every variant of a frame shares it); None when the dataset has none for that frame."""
        return _maybe(self.root / "flow" / f"{name[:6]}.exr", read_flow_exr)

    def stereo_flow(self, index: int, camera: int = 2) -> FlowMaps | None:
        """Optical flow of ``image_2|3/NNNNNN`` (sweep ``index``) to the next and previous pair of the stream."""
        return _maybe(self._seq_dir() / f"flow_{int(camera)}" / f"{index:06d}.exr", read_flow_exr)

    def disparity(self, index: int) -> DisparityMap | None:
        """Disparity of ``image_2/NNNNNN`` (sweep ``index``): ``d = f b / Z``, with the right view's occlusion."""
        return _maybe(self._seq_dir() / "disp_2" / f"{index:06d}.exr", read_disparity_exr)

    def scene_flow(self, index: int, ego_motion: bool = True) -> tuple[np.ndarray, np.ndarray] | None:
        """Scene flow of scan ``index``: ((n, 3) float32 metres, (n,) uint8 flag 0 seen / 1 hidden / 2 gone).

        ``ego_motion`` True: the flow as the sensor sees it (``xyz + flow`` is where the next scan's raw
        coordinates put each point's surface; the static town moves by the ego's motion); False: the
        surfaces' own motion (0 on the static town). None for the last scan or a dataset without it.
        """
        if self.seq is None:
            return None
        scan = self.scan(index)
        got = read_scene_flow(self.seq.dir, index, len(scan.xyz))
        if got is None or not ego_motion:
            return got
        obj, flag = got
        src = str(self.seq.dir / "lidar_meta.json")
        sweeps = md.sweep_poses(md.load_metadata(self.seq.dir / "lidar_meta.json"), src)
        if index + 1 >= len(sweeps):
            raise UserError(f"{src}: sweep_poses_world: no poses of sweeps {index} and {index + 1}")
        rec = [{"t_s": t, "T_world_lidar": T} for t, T in sweeps[index:index + 2]]
        times = read_sidecar(self.seq.dir, TIMES_DIR, index, len(scan.xyz))
        return ego_flow(scan.xyz, obj, times, rec[0], rec[1]), flag

    def _seq_dir(self) -> Path:
        return self.root / "lidar" / "sequences" / self.sequence

    def __iter__(self):
        """Image frames in order (each with its sweep); every sweep when there are no images."""
        frames = sorted({int(n[:6]) for n in self.image_names()}) or self.scan_indices()
        for k in frames:
            yield self.frame(k)

    @staticmethod
    def _read_boxes(path: Path) -> dict[int, list[Box]]:
        """The cuboids of an OpenLABEL file by frame, every field used type-checked (one-line errors)."""
        if not os.path.lexists(path):
            return {}
        src = str(path)
        doc = md.load_metadata(path)
        objects = _mapping(md.field(doc, "openlabel.objects", src, default={}), src, "openlabel.objects")
        frames = _mapping(md.field(doc, "openlabel.frames", src, default={}), src, "openlabel.frames")
        types = {uid: o.get("type") if isinstance(o, dict) and isinstance(o.get("type"), str) else ""
                 for uid, o in objects.items()}
        out: dict[int, list[Box]] = {}
        for key, f in frames.items():
            where = f"openlabel.frames.{printable(key, 32)}"
            if not (key.isascii() and key.isdigit() and len(key) <= 9):
                raise SpecError(src, where, "frame keys must be frame numbers")
            objs = _mapping(md.field(_mapping(f, src, where), "objects", src, default={}, prefix=where), src,
                            f"{where}.objects")
            for uid, o in objs.items():
                at = f"{where}.objects.{printable(uid, 32)}"
                if not (uid.isascii() and uid.isdigit() and len(uid) <= 9):
                    raise SpecError(src, at, "object keys must be instance ids")
                data = _mapping(md.field(_mapping(o, src, at), "object_data", src, prefix=at), src, f"{at}.object_data")
                cuboids = md.field(data, "cuboid", src, prefix=f"{at}.object_data")
                if not (isinstance(cuboids, list) and cuboids and isinstance(cuboids[0], dict)):
                    raise SpecError(src, f"{at}.object_data.cuboid", "must be a list of cuboid objects")
                v = md.matrix(cuboids[0], "val", (10,), src, prefix=f"{at}.object_data.cuboid[0]")
                nums = data.get("num", [{"val": 0}])
                n = md.integer(nums[0] if isinstance(nums, list) and nums and isinstance(nums[0], dict) else {},
                               "val", src, 0, 2**32)
                out.setdefault(int(key), []).append(Box(int(uid), types.get(uid, ""), v[:3], v[3:7], v[7:10], n))
        return out


def _maybe(path: Path, read):
    return read(path) if os.path.lexists(path) else None


def _mapping(value, source: str, where: str) -> dict:
    if not isinstance(value, dict):
        raise SpecError(source, where, f"must be an object, got {md.kind_of(value)}")
    return value
