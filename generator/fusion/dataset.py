"""A dataset folder read frame by frame for fusion: image labels + depth + camera, and the scan.

Layout (see the dataset layout of the project): ``DIR/images/NNNNNN_<tod>_<weather>.{exr,json}``
and ``DIR/lidar/sequences/NN/``. Every image variant of a frame shares masks, depth and camera
pose, so one variant per frame is read (``day_clear`` when present, else the first by name).
"""

from __future__ import annotations

import logging
import os
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generator.errors import SpecError, UserError
from generator.formats import semantickitti as sk
from generator.formats.point_sidecars import NATIVE_DIR, TIMES_DIR, read_sidecar
from generator.imaging import meta_fields as md
from generator.imaging.exr import read_exr
from generator.imaging.paths import frame_images as frame_images_of
from generator.imaging.paths import images_root
from generator.labels import class_table
from generator.world import rig

log = logging.getLogger(__name__)

META_NAME = "lidar_meta.json"


@dataclass
class FusionFrame:
    """One frame's image labels and scan.

    Attributes
    ----------
    index : int
    image_name : str
    class_id : (H, W) uint8
        Mask class per pixel (label proxies included).
    depth : (H, W) float32
        Distance along each pixel-centre ray to the real geometry, metres; inf = sky.
    K : (3, 3) float64
    T_world_camera : (4, 4) float64
        Optical camera frame -> world, at the exposure (sweep start).
    xyz : (n, 3) float32
        Scan points, LiDAR frame at each point's firing instant, metres.
    semantic, instance : (n,) uint16
        SemanticKITTI raw id and instance id of each point.
    native : (n,) uint8
        Native class per point (the side file; without it, the canonical native class of
        the raw id, which cannot tell road_marking from crosswalk etc.).
    native_exact : bool
        Whether ``native`` came from the side file.
    times : (n,) float32 or None
        Firing offsets, seconds (None when the sequence has no side file).
    T_world_lidar_start : (4, 4) float64
        LiDAR pose at the sweep start (when the image is exposed), world frame.
    sweep_times : (k,) float64
        Offsets after the sweep start of the known LiDAR poses, seconds (``[0.0]`` when only
        the start is known).
    sweep_poses : (k, 4, 4) float64
        LiDAR world poses at ``sweep_times`` (see :meth:`generator.world.rig.Rig.sweep_record`).
    pose : (4, 4) float64
        LiDAR pose in the first LiDAR frame (``poses.txt`` / SemanticKITTI convention).
    t_sweep : float or None
        Sweep start on the world timeline, seconds (``times.txt``; the image time).
    """

    index: int
    image_name: str
    class_id: np.ndarray
    depth: np.ndarray
    K: np.ndarray
    T_world_camera: np.ndarray
    xyz: np.ndarray
    semantic: np.ndarray
    instance: np.ndarray
    native: np.ndarray
    native_exact: bool
    times: np.ndarray | None
    T_world_lidar_start: np.ndarray
    sweep_times: np.ndarray
    sweep_poses: np.ndarray
    pose: np.ndarray
    t_sweep: float | None = None


def native_from_raw(raw: np.ndarray) -> np.ndarray:
    """(n,) uint8 canonical native class of SemanticKITTI raw ids (many-to-one: lossy; unknown -> 0)."""
    t = class_table()
    lut = np.zeros(1 << 16, np.uint8)
    for sk_id in {int(v) for v in t.to_semantickitti} | {int(v) for v in t.to_semantickitti_moving}:
        lut[sk_id] = t.from_semantickitti(sk_id)  # moving-* (252-259) read back as their static class
    return lut[np.asarray(raw, np.int64)]


def frame_variants(root: Path) -> dict[int, list[Path]]:
    """Frame index -> metadata JSON of every image variant of the frame (weather x time), sorted by name."""
    folder = images_root(root)
    if not folder.is_dir():
        raise UserError(f"{folder}: missing (render images first: urbangen render SPEC --out {root})")
    return frame_images_of(root)


def frame_images(root: Path) -> dict[int, Path]:
    """Frame index -> metadata JSON of one image variant per frame (``day_clear`` preferred)."""
    out: dict[int, Path] = {}
    for k, paths in frame_variants(root).items():
        clear = [p for p in paths if p.stem.endswith("_day_clear")]
        out[k] = clear[0] if clear else paths[0]
    return out


def read_image_meta(meta_path: Path) -> tuple[dict, np.ndarray, np.ndarray]:
    """(metadata, T_world_camera (4, 4), K (3, 3)) of one image, every field fusion uses checked."""
    meta = md.load_metadata(meta_path)
    T = md.matrix(meta, "camera.T_world_camera", (4, 4), str(meta_path))
    problem = md.rigid_problem(T)
    if problem:
        raise SpecError(str(meta_path), "camera.T_world_camera", problem)
    K, _, _ = md.intrinsics(meta, str(meta_path))
    return meta, T, K


def read_image(meta_path: Path) -> tuple[dict, object]:
    """Metadata dict and :class:`generator.imaging.exr.LabelledImage` of one image."""
    meta, _, _ = read_image_meta(meta_path)
    return meta, read_exr(md.exr_path(meta, meta_path))


class FusionDataset:
    """Images and LiDAR sequence ``seq`` of dataset folder ``root``: image frame ``k`` joined with the
    sweep it was exposed with (``image_frames`` of ``lidar_meta.json``; scan ``k`` without them).

    Parameters
    ----------
    root : path-like
        Dataset folder with ``images/`` and ``lidar/sequences/NN/``.
    sequence : str
        Sequence name (default ``00``).
    images : bool
        Whether images are required (default); with False a folder without ``images/`` reads as
        scans only (:attr:`frames` empty).

    Raises
    ------
    UserError
        Anything the readers refuse, or a sequence without ``poses.txt`` and ``calib.txt``
        (without poses every scan would be stacked at the origin of the map).
    """

    def __init__(self, root: str | Path, sequence: str = "00", images: bool = True):
        self.root = Path(root)
        self.images = frame_images(self.root) if images or images_root(self.root).is_dir() else {}
        self.seq = sk.Sequence(self.root / "lidar", sequence)
        self.meta, self.sweeps = self._lidar_meta()
        #: (n, 4, 4) LiDAR poses in the first LiDAR frame (poses.txt + calib.txt)
        self.poses = self.seq.lidar_poses()
        if self.poses is None:
            missing = [n for n in ("poses.txt", "calib.txt") if not os.path.lexists(self.seq.dir / n)]
            raise UserError(f"{self.seq.dir}: {' and '.join(missing)} missing; fusion places every scan with its "
                            "pose (without them every scan would stack at the origin)")
        #: image frame k -> the scan (sweep) it was exposed with; identity for the one-sweep-per-image layout
        pairs = md.image_sweeps(self.meta, str(self.seq.dir / META_NAME))
        scans = set(self.seq.frames)
        # with image_frames, only the images this sequence was exposed with (another town's images
        # belong to another sequence); without them, the one-sweep-per-image layout
        self.scan_of = {k: pairs[k] for k in self.images if k in pairs} if pairs else {k: k for k in self.images}
        self.frames = [k for k in sorted(self.scan_of) if self.scan_of[k] in scans]
        if not self.frames and images:
            raise UserError(f"{self.root}: no frame has both an image in images/ and its scan in {self.seq.velodyne}")
        self.paired_scans = {self.scan_of[k] for k in self.frames}
        unpaired = len(scans - self.paired_scans)
        if unpaired:
            log.info("%d of %d scans have no image (a 10 Hz stream: images at some sweeps); they go into "
                     "the LiDAR map only", unpaired, len(scans))

    def _lidar_meta(self) -> tuple[dict, list]:
        path = self.seq.dir / META_NAME
        if not os.path.lexists(path):
            return {}, []
        meta = md.load_metadata(path)
        return meta, md.sweep_poses(meta, str(path))

    def _lidar_poses(self, k: int, image_meta: dict | None) -> tuple[np.ndarray, np.ndarray]:
        """(sweep_times (k,), sweep_poses (k, 4, 4)) of scan ``k``."""
        if k < len(self.sweeps):
            return self.sweeps[k]
        source = str(self.seq.dir / META_NAME)
        mount = md.field(self.meta, "mount", source, default=None)
        if image_meta is None and k in self.images:
            image_meta = md.load_metadata(self.images[k])
        if not mount or image_meta is None:
            raise UserError(f"{self.seq.dir / META_NAME}: needs 'sweep_poses_world' (or 'mount' and an image) "
                            f"to place scan {k:06d} of the LiDAR")
        xyz = md.matrix(self.meta, "mount.lidar_xyz_m", (3,), source)
        rpy = md.matrix(self.meta, "mount.lidar_rpy_deg", (3,), source)
        ego = md.matrix(image_meta, "ego.T_world_ego", (4, 4), str(self.images.get(k, "image metadata")))
        problem = md.rigid_problem(ego)
        if problem:
            raise SpecError(str(self.images.get(k, "image metadata")), "ego.T_world_ego", problem)
        start = ego @ rig.mount(xyz, rpy)
        log.warning("%s: no sweep poses for scan %06d; it is projected without de-skew", self.seq.dir, k)
        return np.zeros(1), start[None]

    def __len__(self) -> int:
        return len(self.frames)

    def read_scan(self, k: int, image_meta: dict | None = None) -> dict:
        """The LiDAR part of frame ``k`` (any scan of the sequence): the :class:`FusionFrame`
        fields ``xyz, semantic, instance, native, native_exact, times, T_world_lidar_start,
        sweep_times, sweep_poses, pose, t_sweep``."""
        rec = self.seq.read(k, True, self.poses)
        if rec.semantic is None:
            raise UserError(f"{self.seq.labels_dir}: missing (fusion needs labelled scans)")
        sk.check_raw_ids(rec.semantic, self.seq.label_path(k))
        native = read_sidecar(self.seq.dir, NATIVE_DIR, k, len(rec.points))
        times = read_sidecar(self.seq.dir, TIMES_DIR, k, len(rec.points))
        sweep_times, sweep_poses = self._lidar_poses(k, image_meta)
        return dict(xyz=rec.points[:, :3], semantic=rec.semantic, instance=rec.instance,
                    native=native if native is not None else native_from_raw(rec.semantic),
                    native_exact=native is not None, times=times, T_world_lidar_start=sweep_poses[0],
                    sweep_times=sweep_times, sweep_poses=sweep_poses, pose=rec.pose,
                    t_sweep=(float(self.seq.times[k]) if self.seq.times is not None and k < len(self.seq.times)
                             else None))

    def read(self, k: int) -> FusionFrame:
        """Frame ``k`` (must be in :attr:`frames`)."""
        meta, T, K = read_image_meta(self.images[k])
        img = read_exr(md.exr_path(meta, self.images[k]))
        name = meta.get("image") if isinstance(meta.get("image"), str) else self.images[k].stem
        return FusionFrame(index=k, image_name=name, class_id=img.class_id, depth=img.depth, K=K, T_world_camera=T,
                           **self.read_scan(self.scan_of[k], meta))

    def __iter__(self) -> Iterator[FusionFrame]:
        for k in self.frames:
            yield self.read(k)


def deskewed(scan: dict | FusionFrame, deskew: bool = True, actors=None) -> np.ndarray:
    """(n, 3) float64 points of a scan in the LiDAR frame at the sweep start (raw when
    ``deskew`` is False or the scan has no firing times / only one known pose).

    ``actors`` (instance id -> ``T_world_actor(t)``, :func:`generator.fusion.movers.actor_poses`):
    points of those actors are then also moved by their actor's motion from their firing
    instant to the sweep start (:func:`generator.fusion.movers.deskew_movers`), the image time.
    """
    get = scan.get if isinstance(scan, dict) else lambda key: getattr(scan, key)
    xyz = np.asarray(get("xyz"), np.float64)
    times, ts = get("times"), get("sweep_times")
    if not deskew:
        return xyz
    if times is not None and len(ts) >= 2:
        from generator.fusion.projection import deskew as _deskew

        xyz = _deskew(xyz, times, ts, get("sweep_poses"))
    if actors:
        from generator.fusion.movers import deskew_movers

        t0 = get("t_sweep")
        if t0 is None:
            raise UserError("de-skewing actors needs the sweep start times (times.txt)")
        xyz = deskew_movers(xyz, get("instance"), times, t0, t0, get("T_world_lidar_start"), actors)
    return xyz
