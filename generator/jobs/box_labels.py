"""The box file of a sequence, ``DIR/boxes/NN.npz`` (used by ``generate`` and ``urbangen boxes``).

For the sequence ``DIR/lidar/sequences/NN`` and the world it was cast in (:func:`generator.jobs.boxes.open_sequence`):

* every sweep's 3D box records (:func:`generator.detection.sweep_boxes`): every boxed thing with at
  least ``spec.labels.openlabel_min_points`` points in the sweep's labels, at its observation time;
* for every image exposed with one of the sweeps -- the seed-003 frames in ``images/`` (one entry per
  frame: its weather variants share the label pass) and the stereo pair ``image_2``/``image_3`` --
  the 3D box of every thing its footprint touches at the exposure instant and its visibility
  (:func:`generator.detection.visibility.image_boxes`) from the image's own instance pass.

Nothing is rendered: the footprints are the things' triangles rasterised in numpy.
"""

from __future__ import annotations

import logging
import time
from pathlib import Path

import numpy as np

from generator.atomic import inside
from generator.detection import SweepClock, instance_counts, subjects, sweep_boxes
from generator.detection.records import record
from generator.detection.visibility import image_boxes
from generator.errors import SpecError, UserError
from generator.formats.box_file import ImageEntry, write_box_file
from generator.imaging import meta_fields as md
from generator.imaging.exr import read_exr
from generator.imaging.paths import frame_images
from generator.jobs.boxes import SequenceWorld, open_sequence

log = logging.getLogger(__name__)

STEREO = (2, 3)
CONVENTIONS = ("boxes in the world frame (z up, metres); t = the instant a record describes: the LiDAR's "
               "observation time of the box centre (sweep start + firing offset of its column; the sweep start "
               "without motion skew); T_world_lidar = LiDAR pose at t, the frame of the raw points of that "
               "object; image boxes at the exposure instant; 2D boxes (x0, y0, x1, y1) in pixels")


def box_file_path(root: Path, name: str) -> Path:
    """``root/boxes/NN.npz``, refusing a ``boxes`` that is not a folder inside the dataset."""
    try:
        out = inside(root, "boxes", f"{name}.npz")
    except (ValueError, RuntimeError, OSError):  # a link leading out, or a loop
        out = None
    if out is None or out.is_dir() or ((root / "boxes").exists() and not (root / "boxes").is_dir()):
        raise UserError(f"{root / 'boxes'}: must be a folder inside the dataset (not a file or a link leading out)")
    return out


def _supersample(doc: dict, source: str, default: int) -> int:
    k = doc.get("label_supersample", default) if isinstance(doc, dict) else default
    if isinstance(k, bool) or not isinstance(k, int) or not 1 <= k <= 9:
        raise SpecError(source, "label_supersample", "must be an integer 1..9")
    return k


def _image_sources(sw: SequenceWorld, supersample: int) -> list[tuple[str, int | None, Path, Path, int]]:
    """``(name, sweep, metadata, exr, supersample)`` of every image exposed with a sweep of the sequence."""
    out = []
    if sw.stream:
        sweeps = md.image_sweeps(sw.meta, sw.src)
        for k, paths in sorted(frame_images(sw.root).items()):
            if k in sweeps and sweeps[k] in sw.seq.frames:
                meta = md.load_metadata(paths[0])
                exr = md.exr_path(meta, paths[0])
                k_sup = _supersample(md.field(meta, "render", str(paths[0]), default={}), str(paths[0]), supersample)
                out.append((f"images/{k:06d}", sweeps[k], paths[0], exr, k_sup))
    for cam in STEREO:
        folder = sw.seq.dir / f"passes_{cam}"
        for j in sw.seq.frames:
            js, exr = folder / f"{j:06d}.json", folder / f"{j:06d}.exr"
            if js.is_file() and exr.is_file():
                out.append((f"image_{cam}/{j:06d}", j, js, exr, supersample))
    return out


def _camera(meta: dict, source: str) -> tuple[float, np.ndarray, np.ndarray]:
    """(exposure time, T_world_camera, K) of a seed-003 image's or a stereo pass's metadata."""
    t = float(md.matrix(meta, "time_s", (), source))
    if isinstance(meta.get("camera"), dict):
        T = md.matrix(meta, "camera.T_world_camera", (4, 4), source)
        K, _, _ = md.intrinsics(meta, source)
    else:
        T, K = md.matrix(meta, "T_world_camera", (4, 4), source), md.matrix(meta, "K", (3, 3), source)
    return t, T, K


def write_sequence_boxes(spec, root: Path, sequence: str = "00", *, scene=None, world=None,
                         min_points: int | None = None, supersample: int | None = None) -> tuple[Path, dict]:
    """Write ``root/boxes/NN.npz`` for ``root/lidar/sequences/NN`` cast from ``spec``.

    Parameters
    ----------
    scene, world : optional
        The scene and world the sequence was cast in, if the caller has them (else rebuilt, checked).
    min_points : int, optional
        Sweep records of things with fewer points are left out (default ``spec.labels.openlabel_min_points``).
    supersample : int, optional
        ``label_supersample`` of the stereo passes (default: the manifest's render config, else 1; the
        seed-003 images carry their own in their metadata).

    Returns
    -------
    (Path, dict)
        The file written and counts (``records``, ``images``, ``image_boxes``, seconds per part).
    """
    root = Path(root)
    t0 = time.perf_counter()
    sw = open_sequence(spec, root, sequence, scene, world)
    out = box_file_path(root, sw.name)
    spec, seq = sw.spec, sw.seq
    min_points = spec.labels.openlabel_min_points if min_points is None else int(min_points)
    if supersample is None:
        manifest = root / "manifest.json"
        doc = md.load_metadata(manifest) if manifest.is_file() else {}
        supersample = _supersample(doc.get("render_config", {}), f"{manifest}: render_config", 1)
    subs = subjects(sw.scene, sw.world)
    skew = md.field(sw.meta, "motion_skew", sw.src, default=False) is True
    if skew:
        from generator.lidar.sensors import sensor_for_spec

        clock = SweepClock.of(sensor_for_spec(spec))
    else:
        clock = None
    counts, records = {}, []
    for j in seq.frames:
        counts[j] = instance_counts(seq.read_labelled(j)[2])
        records += sweep_boxes(subs, j, float(seq.times[j]), sw.lidar_pose, counts[j], clock, min_points)
    t1 = time.perf_counter()
    images = []
    by_id = {s.track_id: s for s in subs}
    for name, j, meta_path, exr, k_sup in _image_sources(sw, supersample):
        meta = md.load_metadata(meta_path)
        t, T_wc, K = _camera(meta, str(meta_path))
        inst = read_exr(exr).instance
        vis = image_boxes(subs, t, T_wc, K, inst, k_sup)
        cnt = counts.get(j, {})
        T_wl = sw.lidar_pose(t)
        pairs = [(record(by_id[b.track_id], j, t, T_wl, sum(cnt.get(i, 0) for i in by_id[b.track_id].instance_ids)), b)
                 for b in vis]
        images.append(ImageEntry(name, j, t, T_wc, K, inst.shape[1], inst.shape[0], pairs, T_wl))
    t2 = time.perf_counter()
    info = {"scene": spec.name, "seed": spec.seed, "spec_hash": spec.spec_hash, "sequence": sw.name,
            "min_points": min_points, "motion_skew": skew, "conventions": CONVENTIONS,
            "T_ego_lidar": np.round(sw.rig.T_ego_lidar, 12).tolist(),
            "T_ego_camera": np.round(sw.rig.T_ego_camera(), 12).tolist(), "baseline_m": sw.rig.baseline_m}
    write_box_file(out, {j: float(seq.times[j]) for j in seq.frames}, records, images, info)
    stats = {"records": len(records), "images": len(images), "image_boxes": sum(len(e.boxes) for e in images),
             "records_s": round(t1 - t0, 3), "visibility_s": round(t2 - t1, 3),
             "total_s": round(time.perf_counter() - t0, 3)}
    log.info("boxes %s: %d records in %d sweeps, %d images (%d boxes), %.1f s", sw.name, len(records),
             len(seq.frames), len(images), stats["image_boxes"], stats["total_s"])
    return out, stats
