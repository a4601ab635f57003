"""Cast a whole SemanticKITTI sequence along a route: scans, labels, poses, calib, previews.

A 10 Hz stream: sweep ``j`` starts at ``t_j = j * SWEEP_PERIOD_S`` (0.1 s) along the ego's drive
through the world in time (:func:`generator.traffic.build.build_world`: the static town and the
moving actors, each column of a sweep seeing them where they are at its firing time); files under
``out/sequences/NN/`` (see :mod:`generator.formats.semantickitti`) plus ``bev/NNNNNN.png``
(bird's-eye view), optionally ``range/NNNNNN.npy`` (range image, rings x columns float32,
0 = no return) and ``ply/NNNNNN.ply``; ``lidar_meta.json`` says how the data was made (sensor,
conventions, remission placeholder, point counts); the dataset's ``semantic-kitti.yaml`` label config sits in
``out/``. Side files for fusion: ``point_times/`` and ``native_labels/`` per scan
(:mod:`generator.formats.point_sidecars`), the scene flow of every scan but the last
(``scene_flow/``, :mod:`generator.formats.scene_flow`, :mod:`generator.jobs.scan_flow`) and, in ``lidar_meta.json``,
``sweep_poses_world`` (the LiDAR world poses during each sweep, :meth:`generator.world.rig.Rig.sweep_record`).

With the physical sensor (:mod:`generator.lidar.returns`) in dual mode, ``velodyne/`` and ``labels/``
(and every side file above) keep one point per beam, its strongest return, exactly the points of
strongest mode; the second returns go to ``second_return/velodyne/NNNNNN.bin`` and
``second_return/labels/NNNNNN.label`` (the same formats, so any KITTI reader reads them) with
``second_return/first_index/NNNNNN.bin`` (uint32 per second return: the row of its beam's strongest
return in ``velodyne/NNNNNN.bin``; 0xFFFFFFFF if the post-processing dropped that one).

Write order: calib first, then scans; ``poses.txt``, ``times.txt`` and the metadata last,
so a sequence with ``poses.txt`` is complete. Re-running into the same folder overwrites
(each file atomically) and removes frames beyond the new frame count.
"""

from __future__ import annotations

import dataclasses
import json
import logging
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generator import __version__
from generator.atomic import atomic_path, inside, write_json
from generator.errors import UserError
from generator.formats import kitti_calib
from generator.formats import semantickitti as sk
from generator.formats.label_config import count_raw_ids, merge_counts, write_label_config
from generator.formats.ply import write_ply
from generator.formats.point_sidecars import write_point_sidecars
from generator.formats.scene_flow import DESCRIPTION as SCENE_FLOW
from generator.jobs.lidar_returns import SECOND_DIR, return_model, sweep_alpha, write_second_returns
from generator.jobs.scan_flow import ScanFlowWriter, remove_last
from generator.labels import class_table
from generator.labels.sets import semantickitti_labels
from generator.lidar.returns import frame_key
from generator.lidar.scan import Scanner
from generator.lidar.sensors import Sensor, sensor_for_spec
from generator.previews.bev import write_bev
from generator.progress import progress as progress_bar
from generator.remission.models import IntensityFn, intensity_fn_for_spec
from generator.scan_effects.pipeline import process_scan, processing_for_spec
from generator.spec.towns import angle_record, town_record
from generator.world.actors import MOVING_THRESHOLD_MPS
from generator.world.census import prototype_census
from generator.world.rig import SWEEP_PERIOD_S, Rig

log = logging.getLogger(__name__)

META_NAME = "lidar_meta.json"
LABEL_CONFIG_NAME = "semantic-kitti.yaml"

MOTION_CONVENTION = (
    "Column c of a sweep is fired at t_k + c/(steps*rotation_hz) from the sensor pose at that instant "
    "(motion skew on) or at t_k (off); points keep the raw sensor-frame coordinates of their firing "
    "instant and the scan is filed under the LiDAR pose at the sweep start t_k, as KITTI does (not de-skewed)."
)


@dataclass(frozen=True)
class SequenceOptions:
    """How to write a sequence.

    Attributes
    ----------
    frames : int
        Number of consecutive 10 Hz sweeps (sweep j starts at ``j * SWEEP_PERIOD_S``).
    sequence : str
        Folder name ``NN``.
    threads : int or None
        Casting threads (None = all cores).
    range_image, ply, bev : bool
        Extra outputs per scan.
    resolution : (int, int)
        Camera width, height for ``calib.txt`` (from the render config).
    render_config : str
        Name of that render config (recorded in the metadata).
    route : int
        Route index of the scene (traffic drives route 0; another route is a frozen drive).
    image_frames : tuple of (int, int)
        ``(image frame k, sweep j)`` pairs of a ``generate`` run, recorded in the metadata.
    weather : bool
        LiDAR weather when ``spec.lidar.weather.enabled`` is null (auto): ``generate`` sets
        True (its images carry the weather), the ``lidar`` command leaves it False.
    dataset_label_config : bool
        Rewrite ``out``'s label config (content summed over every sequence) after the sequence;
        ``generate`` writes it once at the end instead (towns are cast at the same time).
    """

    frames: int
    sequence: str = "00"
    threads: int | None = None
    range_image: bool = False
    ply: bool = False
    bev: bool = True
    resolution: tuple[int, int] = (640, 360)
    render_config: str = "preview"
    route: int = 0
    weather: bool = False
    image_frames: tuple = ()
    dataset_label_config: bool = True


def _check_route(scene, spec, n: int, route: int) -> None:
    if n < 1:
        raise UserError(f"--frames must be >= 1, got {n}")
    if route >= len(scene.paths):
        raise UserError(f"{spec.source}: the scene has no route {route}")


def check_frames(scene, spec, n: int, route: int = 0) -> None:
    """Refuse more image frames than fit on an open route (a loop wraps)."""
    _check_route(scene, spec, n, route)
    fits = Rig.from_spec(spec, scene, route).max_frames()
    if not scene.paths[route].closed and n > fits:
        raise UserError(f"{spec.source}: route {route} fits {fits} frames at "
                        f"paths.spacing_m = {spec.paths.spacing_m}, asked for {n}")


def check_sweeps(scene, spec, n: int, route: int = 0) -> None:
    """Refuse more 10 Hz sweeps than the ego can drive on an open route (a loop wraps)."""
    _check_route(scene, spec, n, route)
    path = scene.paths[route]
    seconds = path.length() / spec.paths.speed_mps
    if not path.closed and (n - 1) * SWEEP_PERIOD_S > seconds:
        raise UserError(f"{spec.source}: route {route} takes {seconds:.1f} s at paths.speed_mps = "
                        f"{spec.paths.speed_mps}: room for {int(seconds / SWEEP_PERIOD_S) + 1} sweeps, asked for {n}")


def world_for(spec, scene, sweeps: int, distance_m: float = 0.0):
    """The world (:func:`generator.traffic.build.build_world`) covering ``sweeps`` 10 Hz sweeps."""
    from generator.traffic.build import build_world

    return build_world(spec, scene, sweeps * SWEEP_PERIOD_S + 0.2, distance_m)


def write_sequence(scene, spec, out: str | Path, options: SequenceOptions, sensor: Sensor | None = None,
                   intensity_fn: IntensityFn | None = None, progress: bool = True, world=None) -> dict:
    """Cast and write one sequence; returns the metadata written to ``lidar_meta.json``.

    Parameters
    ----------
    scene : generator.world.scene.SceneModel
    spec : generator.spec.SceneSpec
    out : path-like
        Dataset root (``out/sequences/NN`` is created).
    sensor : Sensor, optional
        Default: :func:`generator.lidar.sensors.sensor_for_spec`.
    intensity_fn : IntensityFn, optional
        Default: the spec's ``lidar.intensity_model``.

    Every scan goes through :func:`generator.scan_effects.pipeline.process_scan` (intensity ->
    domain gap -> LiDAR weather) before anything is written; ``lidar_meta.json`` records
    the chain's parameters (``processing``) and what it did to each scan (``scans``).
    """
    sensor = sensor_for_spec(spec) if sensor is None else sensor
    intensity_fn = intensity_fn_for_spec(spec) if intensity_fn is None else intensity_fn
    processing = processing_for_spec(spec, sensor, options.weather, intensity_fn)
    returns = return_model(sensor, spec.seed)
    check_sweeps(scene, spec, options.frames, options.route)
    name = sk.sequence_name(options.sequence)
    seq = inside(out, "sequences", name)
    if options.route != 0:  # traffic drives route 0's ego; another route is a frozen drive
        world = None
        rig = Rig.from_spec(spec, scene, options.route)
    else:
        world = world_for(spec, scene, options.frames) if world is None else world
        rig = Rig.from_world(spec, world)
    times = np.array([Rig.sweep_time(j) for j in range(options.frames)])
    calib = kitti_calib.kitti_calib(rig, *options.resolution)
    tr = kitti_calib.homogeneous(calib["Tr"])
    kitti_calib.write_calib(seq / "calib.txt", calib)
    skew = spec.sensors.lidar.motion_skew
    starts, n_points, counts, records = [], [], {}, []
    sweeps = []  # LiDAR world poses during each sweep (fusion de-skews with them)
    actors = world.actors if world is not None else []
    flows = ScanFlowWriter(seq, rig, world, sensor, skew)  # scene_flow/ of each sweep, once the next is cast
    with Scanner(scene, sensor, threads=options.threads, world=world, returns=returns) as scanner, flows:
        direct = getattr(scanner.caster, "native", None)  # which backend this scanner's caster casts through

        def submit(j: int):  # sweep j starts on the scanner's threads
            physical = {} if returns is None else {"alpha_per_m": sweep_alpha(spec, processing, j),
                                                   "noise_key": frame_key(spec.seed, j)}
            return scanner.submit_sweep(rig, times[j], skew, **physical)

        scans = scanner.stream(options.frames, submit)  # the next sweep is cast while this one is written
        for j in progress_bar(range(options.frames), desc=f"lidar {name}", unit="scan", enabled=progress):
            scan = next(scans)
            pts = scan.points
            if returns is not None and returns.params.mode == "dual":
                second = pts[pts["echo"] == 1]
                pts = pts[pts["echo"] == 0]
            pts, remission, record = process_scan(pts, processing, spec, j)
            if returns is not None and returns.params.mode == "dual":
                second, rem2, record["second_return"] = process_scan(second, processing, spec, j, SECOND_DIR)
                write_second_returns(seq, f"{j:06d}", pts, second, rem2, sensor.n_lasers)
            scan = dataclasses.replace(scan, points=pts)  # xyz, range image and side files follow the processed points
            records.append(record)
            stem = f"{j:06d}"
            semantic = semantickitti_labels(pts["class"], pts["moving"])  # moving-* ids on movers
            sk.write_scan(seq / "velodyne" / f"{stem}.bin", scan.xyz, remission)
            sk.write_labels(seq / "labels" / f"{stem}.label", semantic, pts["instance"])
            write_point_sidecars(seq, stem, pts["time"], pts["class"], pts["ring"])  # de-skew times, classes, rings
            flows.add(j, times[j], pts)
            if options.bev:
                write_bev(seq / "bev" / f"{stem}.png", scan.xyz, pts["class"], title=f"{spec.name} {name}/{stem}",
                          moving=pts["moving"])
            if options.range_image:
                with atomic_path(seq / "range" / f"{stem}.npy") as tmp:
                    np.save(tmp, scan.range_image())
            if options.ply:
                write_ply(seq / "ply" / f"{stem}.ply", scan.xyz, remission, semantic, pts["instance"],
                          class_table().colors[pts["class"]])
            starts.append(rig.T_world_lidar(times[j])[0])
            sweeps.append(rig.sweep_record(times[j], sensor.period_s))
            n_points.append(int(len(pts)))
            counts = merge_counts(counts, count_raw_ids(semantic))
    _remove_stale(seq, options.frames)
    remove_last(seq, options.frames)  # the last sweep has no scene flow
    sk.write_poses(seq / "poses.txt", kitti_calib.camera_poses(np.array(starts), tr))
    sk.write_times(seq / "times.txt", times)
    meta = _metadata(scene, spec, sensor, options, intensity_fn, n_points, counts, direct)
    meta["sweep_period_s"] = SWEEP_PERIOD_S
    meta["traffic"] = {"actors": len(actors), "moving_threshold_mps": MOVING_THRESHOLD_MPS,
                       "duration_s": float(world.duration_s) if actors else 0.0,
                       "digest": world.digest(times) if actors else None,
                       "moving_ids": "SemanticKITTI 252-259 for points on an actor moving faster than the "
                                     "threshold at its firing time; instance ids stay the same all sequence"}
    meta["prototypes"] = prototype_census(scene, world)   # distinct meshes per kind (urbangen stats)
    if options.image_frames:
        meta["image_frames"] = [list(p) for p in options.image_frames]
    meta["processing"], meta["scans"] = processing.describe(), records
    if returns is not None:
        meta["returns"] = returns.describe()
    meta["sweep_poses_world"] = {"period_s": sensor.period_s, "frames": sweeps}
    meta["scene_flow"] = {**SCENE_FLOW, "dt_s": SWEEP_PERIOD_S}
    write_json(seq / META_NAME, meta)
    if options.dataset_label_config:
        write_dataset_label_config(out)
    return meta


def _remove_stale(seq: Path, n: int) -> None:
    for sub, ext in (("velodyne", ".bin"), ("labels", ".label"), ("bev", ".png"), ("range", ".npy"), ("ply", ".ply"),
                     ("point_times", ".bin"), ("native_labels", ".bin"), ("point_rings", ".bin"),
                     (f"{SECOND_DIR}/velodyne", ".bin"), (f"{SECOND_DIR}/labels", ".label"),
                     (f"{SECOND_DIR}/first_index", ".bin")):
        for p in sorted((seq / sub).glob(f"*{ext}")):
            if p.stem.isdigit() and int(p.stem) >= n:
                log.warning("removing %s left by an earlier, longer run", p)
                p.unlink()


def write_dataset_label_config(out: str | Path, split: str | None = None, sequences: list[str] | None = None) -> dict:
    """(Re)write ``out/semantic-kitti.yaml``: ``content`` summed over every sequence, ``split`` merged.

    Parameters
    ----------
    out : path-like
        Dataset root (``out/sequences/NN``).
    split : {"train", "valid", "test"}, optional
        Put ``sequences`` (default: every sequence) under this split; the other sequences keep
        the split the config on disk gives them, new ones go to ``valid``
        (:func:`generator.formats.label_config.merge_split`).
    sequences : list of str, optional
        The sequences ``split`` applies to.
    """
    from generator.formats.label_config import merge_split, read_split

    total: dict[int, int] = {}
    seqs = []
    for name in sk.list_sequences(out):
        meta_path = Path(out) / "sequences" / name / META_NAME
        if meta_path.is_file():
            meta = json.loads(meta_path.read_text(encoding="utf-8"))
            counts = {int(k): int(v) for k, v in meta["raw_id_counts"].items()}
        else:  # a sequence from elsewhere: count its labels
            counts = {}
            for rec in sk.Sequence(out, name):
                if rec.semantic is not None:
                    counts = merge_counts(counts, count_raw_ids(rec.semantic))
        total = merge_counts(total, counts)
        seqs.append(int(name))
    path = Path(out) / LABEL_CONFIG_NAME
    assigned = {} if split is None else {int(s): split for s in (seqs if sequences is None else sequences)}
    return write_label_config(path, total, merge_split(seqs, assigned, read_split(path)))


#: ``lidar_meta.json`` ``software.ray_casts``: the backend of the scanner's caster (None: not an Embree caster)
_RAY_CASTS = {True: "Embree called directly", False: "embreex.run", None: "not Embree"}


def _metadata(scene, spec, sensor: Sensor, options: SequenceOptions, intensity_fn, n_points, counts,
              direct: bool | None) -> dict:
    import embreex

    from generator.lidar import embree_native

    remission = dict(getattr(intensity_fn, "description", {"model": getattr(intensity_fn, "__name__", "custom")}))
    if remission.get("placeholder"):
        remission["note"] = ("placeholder: every point has the same remission until an intensity model "
                             "is selected; do not train on it")
    return {
        "generator": f"urbangen {__version__} lidar",
        "format": "SemanticKITTI",
        "sequence": sk.sequence_name(options.sequence),
        "frames": options.frames,
        "scene": {"name": spec.name, "seed": spec.seed, "spec_hash": spec.spec_hash, "scene_digest": scene.digest(),
                  "route": options.route, "triangles": int(len(scene.faces)),
                  **({"town": town_record(spec)} if spec.town_index is not None else {}), **angle_record(spec)},
        "sensor": {"name": sensor.name, "model": sensor.model, "file": sensor.source, "lasers": sensor.n_lasers,
                   "azimuth_steps": sensor.azimuth_steps, "rotation_hz": sensor.rotation_hz,
                   "range_m": [sensor.min_range_m, sensor.max_range_m],
                   "rings": "ring 0 = highest beam (range-image row 0)",
                   "corrections": "vert/rot/vert_offset/horiz_offset applied as the Velodyne driver does; "
                                  "dist_correction (device range bias) not applied"},
        "mount": {"lidar_xyz_m": list(spec.sensors.lidar.xyz_m), "lidar_rpy_deg": list(spec.sensors.lidar.rpy_deg),
                  "camera_xyz_m": list(spec.sensors.camera.xyz_m), "camera_rpy_deg": list(spec.sensors.camera.rpy_deg),
                  "camera_hfov_deg": spec.sensors.camera.hfov_deg},
        "calib": {"render_config": options.render_config, "resolution": list(options.resolution),
                  "P0..P3": "K [I|0] of the one rig camera (zero baselines)",
                  "Tr": "velodyne -> cam0 from the rig mounts, without per-frame camera jitter"},
        "poses": "poses.txt: cam0 pose of each scan in the first cam0 frame (KITTI); LiDAR pose = inv(Tr) @ pose @ Tr",
        "motion_skew": bool(spec.sensors.lidar.motion_skew),
        "motion_convention": MOTION_CONVENTION,
        "remission": remission,
        "labels": "uint32: SemanticKITTI raw id (low 16 bits) | instance id (high 16 bits)",
        "points_per_scan": n_points,
        "rays_per_scan": sensor.rays_per_sweep,
        "raw_id_counts": {str(k): v for k, v in sorted(counts.items())},
        "software": {"numpy": np.__version__, "embreex": getattr(embreex, "__version__", "unknown"),
                     "embree": embree_native.version() or "through embreex.run",
                     "ray_casts": _RAY_CASTS[direct]},
    }
