"""The per-sequence box file ``DIR/boxes/NN.npz``: every 3D box of every sweep, visibility per image.

One compressed numpy archive per LiDAR sequence, columnar (one row per record), read with
``numpy.load(path)`` alone (no pickles) or :func:`read_box_file`. Strings are fixed-width unicode.

==========================  ============  ====================================================
array                       shape, dtype  content
==========================  ============  ====================================================
``format_version``          () int32      1
``info``                    () str        JSON: scene, seed, spec_hash, sequence, min_points,
                                          the conventions below in words
``track_id``                (N,) int32    tracks: one row per boxed thing of the sequence
``track_instance_ids``      (N, P) int32  its instance ids, 0-padded (vehicle and rider)
``track_class``             (N,) str      box class (``generator/labels/detection.yaml``)
``track_kind``, ``track_name``  (N,) str  asset kind, object/actor name
``track_static``            (N,) bool     part of the static town
``sweep_index``, ``sweep_t0``  (S,)       the sweeps of the sequence and their start (s)
``sweep``                   (R,) int32    box records: sweep index
``track``                   (R,) int32    row in the track arrays
``t``                       (R,) float64  instant the box describes (s; the LiDAR's observation time)
``center``, ``size``        (R, 3) f8     world frame, metres; size = length, width, height
``yaw``                     (R,) float64  heading of the length axis about world +z, radians
``velocity``, ``acceleration``  (R, 3) f8  of the centre over ground, world frame, m/s, m/s^2
``moving``                  (R,) bool     faster than 0.3 m/s
``attribute``               (R,) str      nuScenes attribute
``num_lidar_pts``           (R,) int32    points of the track's instance ids in the sweep's labels
``T_world_lidar``           (R, 4, 4) f8  LiDAR pose at ``t`` (the raw points' frame)
``image_name``              (I,) str      ``images/NNNNNN`` (every weather variant of that frame:
                                          they share one label pass), ``image_2/NNNNNN``, ``image_3/...``
``image_sweep``             (I,) int32    sweep exposed with (-1: none)
``image_t``                 (I,) float64  exposure instant (s)
``image_T_world_camera``    (I, 4, 4) f8  optical camera pose in the world
``image_T_world_lidar``     (I, 4, 4) f8  LiDAR pose at the exposure instant
``image_K``                 (I, 3, 3) f8  intrinsics; ``image_size`` (I, 2) int32 width, height
``ib_image``, ``ib_track``  (B,) int32    image boxes: row in the image and track arrays
``ib_center``, ``ib_size``, ``ib_yaw``, ``ib_velocity``, ``ib_acceleration``, ``ib_moving``, ``ib_attribute``
                                          the 3D box at the exposure instant (world frame)
``ib_num_lidar_pts``        (B,) int32    points in the paired sweep's labels (-1: no sweep)
``ib_bbox_amodal``, ``ib_bbox_visible``  (B, 4) f8  (x0, y0, x1, y1) pixels
``ib_pixels_amodal``, ``ib_pixels_visible``  (B,) int32
``ib_truncation``, ``ib_visibility``  (B,) f8
``ib_occlusion``, ``ib_difficulty``  (B,) int8   KITTI occlusion level, difficulty (-1 none)
``ib_nuscenes_visibility``  (B,) str      "1".."4"
==========================  ============  ====================================================
"""

from __future__ import annotations

import io
import json
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from generator.atomic import atomic_path
from generator.detection.records import BoxRecord
from generator.detection.visibility import ImageBox
from generator.errors import SpecError
from generator.safeload import MAX_ARRAY_BYTES, read_bytes

FORMAT_VERSION = 1


@dataclass(frozen=True)
class ImageEntry:
    """One image (or every weather variant of one seed-003 frame) and the boxes it shows.

    Attributes
    ----------
    name : str
        ``images/NNNNNN``, ``image_2/NNNNNN`` or ``image_3/NNNNNN``.
    sweep : int or None
        The sweep it was exposed with.
    t : float
        Exposure instant, seconds.
    T_world_camera : (4, 4) float64
    K : (3, 3) float64
    width, height : int
    boxes : list of (BoxRecord, ImageBox)
        The 3D box at ``t`` (``sweep`` = the image's sweep, ``num_lidar_pts`` that sweep's count) and
        its visibility.
    T_world_lidar : (4, 4) float64
        The LiDAR pose at ``t``.
    """

    name: str
    sweep: int | None
    t: float
    T_world_camera: np.ndarray
    K: np.ndarray
    width: int
    height: int
    boxes: list
    T_world_lidar: np.ndarray = field(default_factory=lambda: np.eye(4))


def _tracks(records) -> tuple[dict, dict[int, int]]:
    by_id = {}
    for r in records:
        by_id.setdefault(r.track_id, r)
    ids = sorted(by_id)
    p = max([len(by_id[i].instance_ids) for i in ids], default=1)
    inst = np.zeros((len(ids), p), np.int32)
    for k, i in enumerate(ids):
        inst[k, :len(by_id[i].instance_ids)] = by_id[i].instance_ids
    cols = {"track_id": np.array(ids, np.int32).reshape(-1), "track_instance_ids": inst,
            "track_class": np.array([by_id[i].cls for i in ids], "U").reshape(-1),
            "track_kind": np.array([by_id[i].kind for i in ids], "U").reshape(-1),
            "track_name": np.array([by_id[i].name for i in ids], "U").reshape(-1),
            "track_static": np.array([by_id[i].static for i in ids], bool).reshape(-1)}
    return cols, {i: k for k, i in enumerate(ids)}


def _record_columns(records, row: dict[int, int], prefix: str = "") -> dict:
    n = len(records)

    def arr(f, shape, dtype):
        return np.array([f(r) for r in records], dtype).reshape((n, *shape))

    return {f"{prefix}track": arr(lambda r: row[r.track_id], (), np.int32),
            f"{prefix}center": arr(lambda r: r.center, (3,), np.float64),
            f"{prefix}size": arr(lambda r: r.size, (3,), np.float64),
            f"{prefix}yaw": arr(lambda r: r.yaw, (), np.float64),
            f"{prefix}velocity": arr(lambda r: r.velocity, (3,), np.float64),
            f"{prefix}acceleration": arr(lambda r: r.acceleration, (3,), np.float64),
            f"{prefix}moving": arr(lambda r: r.moving, (), bool),
            f"{prefix}attribute": np.array([r.attribute for r in records], "U").reshape(n),
            f"{prefix}num_lidar_pts": arr(lambda r: r.num_lidar_pts, (), np.int32)}


def write_box_file(path: str | Path, sweeps: dict[int, float], records: list, images: list[ImageEntry],
                   info: dict) -> None:
    """Write the box file of one sequence atomically.

    Parameters
    ----------
    sweeps : dict of int to float
        Sweep index -> start time (s).
    records : list of BoxRecord
        Every sweep's records (:func:`generator.detection.sweep_boxes`).
    images : list of ImageEntry
    info : dict
        JSON-able description (scene, seed, spec hash, sequence, min_points, conventions).
    """
    ib = [(k, r, b) for k, e in enumerate(images) for r, b in e.boxes]
    tracks, row = _tracks(list(records) + [r for _, r, _ in ib])
    n = len(records)
    cols = {"format_version": np.array(FORMAT_VERSION, np.int32), "info": np.array(json.dumps(info, sort_keys=True)),
            **tracks,
            "sweep_index": np.array(sorted(sweeps), np.int32).reshape(-1),
            "sweep_t0": np.array([sweeps[j] for j in sorted(sweeps)], np.float64).reshape(-1),
            "sweep": np.array([r.sweep for r in records], np.int32).reshape(n),
            "t": np.array([r.t for r in records], np.float64).reshape(n),
            **_record_columns(records, row),
            "T_world_lidar": np.array([r.T_world_lidar for r in records], np.float64).reshape(n, 4, 4)}
    m, nb = len(images), len(ib)
    cols.update({
        "image_name": np.array([e.name for e in images], "U").reshape(m),
        "image_sweep": np.array([-1 if e.sweep is None else e.sweep for e in images], np.int32).reshape(m),
        "image_t": np.array([e.t for e in images], np.float64).reshape(m),
        "image_T_world_camera": np.array([e.T_world_camera for e in images], np.float64).reshape(m, 4, 4),
        "image_T_world_lidar": np.array([e.T_world_lidar for e in images], np.float64).reshape(m, 4, 4),
        "image_K": np.array([e.K for e in images], np.float64).reshape(m, 3, 3),
        "image_size": np.array([(e.width, e.height) for e in images], np.int32).reshape(m, 2),
        "ib_image": np.array([k for k, _, _ in ib], np.int32).reshape(nb),
        **_record_columns([r for _, r, _ in ib], row, "ib_"),
        "ib_bbox_amodal": np.array([b.bbox_amodal for _, _, b in ib], np.float64).reshape(nb, 4),
        "ib_bbox_visible": np.array([b.bbox_visible for _, _, b in ib], np.float64).reshape(nb, 4),
        "ib_pixels_amodal": np.array([b.pixels_amodal for _, _, b in ib], np.int32).reshape(nb),
        "ib_pixels_visible": np.array([b.pixels_visible for _, _, b in ib], np.int32).reshape(nb),
        "ib_truncation": np.array([b.truncation for _, _, b in ib], np.float64).reshape(nb),
        "ib_visibility": np.array([b.visibility for _, _, b in ib], np.float64).reshape(nb),
        "ib_occlusion": np.array([b.occlusion for _, _, b in ib], np.int8).reshape(nb),
        "ib_difficulty": np.array([b.difficulty for _, _, b in ib], np.int8).reshape(nb),
        "ib_nuscenes_visibility": np.array([b.nuscenes_visibility for _, _, b in ib], "U1").reshape(nb),
    })
    with atomic_path(path, suffix=".npz") as tmp:
        write_npz(tmp, cols)


def write_npz(path, arrays: dict[str, np.ndarray]) -> None:
    """A compressed ``.npz`` that ``numpy.load`` reads, byte for byte the same for the same arrays
    (``numpy.savez_compressed`` stamps every member with the time of writing)."""
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        for key in sorted(arrays):
            info = zipfile.ZipInfo(f"{key}.npy", date_time=(1980, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            buf = io.BytesIO()
            np.lib.format.write_array(buf, np.asanyarray(arrays[key]), allow_pickle=False)
            z.writestr(info, buf.getvalue())


#: name -> (dtype kind(s), trailing shape, length key) of every array a box file holds
_SCHEMA = {
    "track_id": ("i", (), "track_id"), "track_instance_ids": ("i", None, "track_id"),
    "track_class": ("U", (), "track_id"), "track_kind": ("U", (), "track_id"), "track_name": ("U", (), "track_id"),
    "track_static": ("b", (), "track_id"),
    "sweep_index": ("i", (), "sweep_index"), "sweep_t0": ("f", (), "sweep_index"),
    "sweep": ("i", (), "sweep"), "t": ("f", (), "sweep"), "T_world_lidar": ("f", (4, 4), "sweep"),
    "image_name": ("U", (), "image_name"), "image_sweep": ("i", (), "image_name"), "image_t": ("f", (), "image_name"),
    "image_T_world_camera": ("f", (4, 4), "image_name"), "image_T_world_lidar": ("f", (4, 4), "image_name"),
    "image_K": ("f", (3, 3), "image_name"),
    "image_size": ("i", (2,), "image_name"),
    "ib_image": ("i", (), "ib_image"), "ib_bbox_amodal": ("f", (4,), "ib_image"),
    "ib_bbox_visible": ("f", (4,), "ib_image"), "ib_pixels_amodal": ("i", (), "ib_image"),
    "ib_pixels_visible": ("i", (), "ib_image"), "ib_truncation": ("f", (), "ib_image"),
    "ib_visibility": ("f", (), "ib_image"), "ib_occlusion": ("i", (), "ib_image"),
    "ib_difficulty": ("i", (), "ib_image"), "ib_nuscenes_visibility": ("U", (), "ib_image"),
}
for _p, _n in (("", "sweep"), ("ib_", "ib_image")):
    _SCHEMA.update({f"{_p}track": ("i", (), _n), f"{_p}center": ("f", (3,), _n), f"{_p}size": ("f", (3,), _n),
                    f"{_p}yaw": ("f", (), _n), f"{_p}velocity": ("f", (3,), _n),
                    f"{_p}acceleration": ("f", (3,), _n), f"{_p}moving": ("b", (), _n),
                    f"{_p}attribute": ("U", (), _n), f"{_p}num_lidar_pts": ("i", (), _n)})


def _load(path: Path) -> dict[str, np.ndarray]:
    src = str(path)
    data = read_bytes(path, max_bytes=MAX_ARRAY_BYTES)
    try:
        with zipfile.ZipFile(io.BytesIO(data)) as z:
            if sum(i.file_size for i in z.infolist()) > MAX_ARRAY_BYTES:
                raise SpecError(src, "", "arrays larger than the reader's limit")
        with np.load(io.BytesIO(data), allow_pickle=False) as z:
            return {k: z[k] for k in z.files}
    except (zipfile.BadZipFile, ValueError, OSError, EOFError, KeyError):
        raise SpecError(src, "", "not a numpy .npz archive urbangen wrote (damaged or truncated)") from None


def _check(a: dict[str, np.ndarray], src: str) -> None:
    for key in ("format_version", "info", *_SCHEMA):
        if key not in a:
            raise SpecError(src, key, "missing")
    if a["format_version"].shape != () or int(a["format_version"]) != FORMAT_VERSION:
        raise SpecError(src, "format_version", f"must be {FORMAT_VERSION}")
    for key, (kind, shape, length) in _SCHEMA.items():
        v = a[key]
        ok = v.dtype.kind in ("iu" if kind == "i" else kind) and v.ndim >= 1
        ok = ok and len(v) == len(a[length]) and (shape is None and v.ndim == 2 or v.shape[1:] == (shape or ()))
        if not ok:
            raise SpecError(src, key, "wrong dtype or shape")
        if kind == "f" and not np.isfinite(v).all():
            raise SpecError(src, key, "must be finite numbers")
    for key, n in (("track", "track_id"), ("ib_track", "track_id"), ("ib_image", "image_name")):
        if len(a[key]) and (a[key].min() < 0 or a[key].max() >= len(a[n])):
            raise SpecError(src, key, f"row numbers outside the {n} table")


def _records(a: dict, rows: np.ndarray, p: str, sweep, t, T) -> list[BoxRecord]:
    out = []
    for k, r in enumerate(rows):
        tr = int(a[f"{p}track"][r])
        inst = tuple(int(i) for i in a["track_instance_ids"][tr] if i > 0)
        out.append(BoxRecord(int(sweep[k]), float(t[k]), int(a["track_id"][tr]), inst, str(a["track_class"][tr]),
                             str(a["track_kind"][tr]), str(a["track_name"][tr]), a[f"{p}center"][r].copy(),
                             a[f"{p}size"][r].copy(), float(a[f"{p}yaw"][r]), a[f"{p}velocity"][r].copy(),
                             a[f"{p}acceleration"][r].copy(), bool(a[f"{p}moving"][r]), str(a[f"{p}attribute"][r]),
                             int(a[f"{p}num_lidar_pts"][r]), np.asarray(T[k], np.float64),
                             bool(a["track_static"][tr])))
    return out


class BoxFile:
    """A box file read back and checked (every array's dtype, shape, finiteness and row references).

    Raises
    ------
    generator.errors.SpecError
        One line naming the file and the array.
    """

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self.arrays = a = _load(self.path)
        _check(a, str(self.path))
        self.info = json.loads(str(a["info"]))
        self.sweeps = {int(j): float(t) for j, t in zip(a["sweep_index"], a["sweep_t0"], strict=True)}
        self._by_sweep: dict[int, np.ndarray] = {}
        order = np.argsort(a["sweep"], kind="stable")
        for j, rows in zip(*np.unique(a["sweep"][order], return_index=True), strict=True):
            self._by_sweep[int(j)] = rows
        self._order = order
        self.image_names = [str(n) for n in a["image_name"]]

    def records(self, sweep: int) -> list[BoxRecord]:
        """The box records of ``sweep`` (empty if it has none)."""
        a = self.arrays
        if sweep not in self._by_sweep:
            return []
        start = self._by_sweep[sweep]
        stop = np.searchsorted(a["sweep"][self._order], sweep, side="right")
        rows = self._order[start:stop]
        return _records(a, rows, "", a["sweep"][rows], a["t"][rows], a["T_world_lidar"][rows])

    def image(self, name: str) -> ImageEntry | None:
        """The entry ``images/NNNNNN`` (any variant's stem ``NNNNNN_<time>_<weather>`` finds its frame),
        ``image_2/NNNNNN`` or ``image_3/NNNNNN``; None when the file has none."""
        a = self.arrays
        key = name if "/" in name else f"images/{name[:6]}"
        if key not in self.image_names:
            return None
        k = self.image_names.index(key)
        rows = np.flatnonzero(a["ib_image"] == k)
        sweep = int(a["image_sweep"][k])
        T_cam = a["image_T_world_camera"][k]
        recs = _records(a, rows, "ib_", np.full(len(rows), sweep), np.full(len(rows), a["image_t"][k]),
                        np.repeat(a["image_T_world_lidar"][k][None], len(rows), 0))
        vis = [ImageBox(r.track_id, a["ib_bbox_amodal"][i].copy(), a["ib_bbox_visible"][i].copy(),
                        int(a["ib_pixels_amodal"][i]), int(a["ib_pixels_visible"][i]), float(a["ib_truncation"][i]),
                        float(a["ib_visibility"][i]), int(a["ib_occlusion"][i]), int(a["ib_difficulty"][i]),
                        str(a["ib_nuscenes_visibility"][i])) for r, i in zip(recs, rows, strict=True)]
        w, h = (int(v) for v in a["image_size"][k])
        return ImageEntry(key, None if sweep < 0 else sweep, float(a["image_t"][k]), T_cam.copy(),
                          a["image_K"][k].copy(), w, h, list(zip(recs, vis, strict=True)),
                          a["image_T_world_lidar"][k].copy())


def read_box_file(path: str | Path) -> BoxFile:
    """:class:`BoxFile` of ``path``."""
    return BoxFile(path)
