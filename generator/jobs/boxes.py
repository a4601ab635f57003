"""OpenLABEL 1.0 boxes of a dataset's LiDAR sequence (used by ``urbangen openlabel`` and ``generate``).

Two layouts of ``lidar_meta.json``:

* a 10 Hz stream (``sweep_period_s`` present): OpenLABEL frame ``j`` = sweep ``j`` at
  ``times.txt[j]``; the ego pose there, the camera transform only for sweeps an image was
  exposed with (``image_frames`` ``[[k, j], ...]``); with ``traffic`` true the world (actors
  included) is rebuilt from the spec -- deterministic from its seed -- over the recorded
  ``duration_s`` (else the sequence's last time plus one sweep) and ``distance_m``;
* the older one-sweep-per-image layout: frame ``k`` = :meth:`generator.world.rig.Rig.frame`.
"""

from __future__ import annotations

import logging
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generator.atomic import inside
from generator.errors import SpecError, UserError
from generator.formats import semantickitti as sk
from generator.formats.openlabel import build_openlabel, write_openlabel
from generator.imaging import meta_fields as md
from generator.imaging.paths import image_files, image_relpath, iter_image_files
from generator.labels.detection import detection_classes
from generator.safeload import printable
from generator.spec.towns import spec_for_record
from generator.world.rig import SWEEP_PERIOD_S, Rig

log = logging.getLogger(__name__)



@dataclass(frozen=True)
class SweepFrame:
    """One OpenLABEL frame of a 10 Hz stream: sweep ``index`` starting at ``t`` seconds.

    Attributes
    ----------
    T_world_ego : (4, 4) float64
        Ego pose at the sweep start.
    T_ego_camera : (4, 4) float64 or None
        Camera (optical) in the ego frame of the image exposed with this sweep, jitter included.
    image : int or None
        That image's frame number.
    """

    index: int
    t: float
    T_world_ego: np.ndarray
    T_ego_camera: np.ndarray | None = None
    image: int | None = None


def _check_times(times, path) -> None:
    """Sweep times are poses asked of the drive: finite seconds within what a drive can be simulated for."""
    from generator.traffic.build import MAX_DRIVE_S

    t = np.asarray(times, np.float64)
    if not (np.isfinite(t).all() and (t >= 0).all() and (t <= MAX_DRIVE_S).all()):
        raise UserError(f"{path}: every time must be finite seconds in [0, {MAX_DRIVE_S:.0f}] (the drive urbangen "
                        "simulates); this file is not one urbangen wrote")


def sequence_world(spec, scene, meta: dict, times: np.ndarray, source: str, world=None):
    """The world a 10 Hz sequence was cast in: actors when ``meta["traffic"]`` is true, else none.

    ``world``: that world if the caller still has it (checked against the recorded digest),
    else it is rebuilt from the spec.
    """
    from generator.traffic.build import MAX_DRIVE_S, build_world
    from generator.world.actors import frozen_world

    traffic = md.field(meta, "traffic", source, default=None)
    if not isinstance(traffic, dict) or not traffic.get("actors"):
        return None
    digest = md.field(meta, "traffic.digest", source, default=None)
    if world is not None and world.actors:
        world.check_digest(digest if isinstance(digest, str) else None, times, source)
        return world
    duration = md.field(meta, "traffic.duration_s", source, default=float(np.max(times)) + SWEEP_PERIOD_S)
    if isinstance(duration, bool) or not isinstance(duration, (int, float)) or not 0 <= duration <= MAX_DRIVE_S + 2:
        raise SpecError(source, "traffic.duration_s", f"must be seconds in [0, {MAX_DRIVE_S:.0f}]")
    # the simulation is causal: a run at least as long gives the same poses over the sequence
    world = build_world(spec, scene, duration, 0.0)
    world.check_digest(digest if isinstance(digest, str) else None, times, source)
    return world if world.actors else frozen_world(scene, world.ego)


def sweep_frames(rig: Rig, meta: dict, frames: list[int], times: np.ndarray, source: str) -> list[SweepFrame]:
    """Per sweep: the ego pose at ``times[j]`` and, for sweeps paired with an image, its camera."""
    image_of = {j: k for k, j in md.image_sweeps(meta, source).items()}
    out = []
    for j in frames:
        k = image_of.get(j)
        cam = rig.T_ego_camera(rig.camera_jitter(k)) if k is not None else None
        out.append(SweepFrame(j, float(times[j]), rig.T_world_ego(float(times[j]))[0], cam, k))
    return out


def _camera(root: Path, seq, meta: dict, meta_source: str) -> tuple[np.ndarray, int, int, str]:
    """Intrinsics from the first image's metadata, else from calib.txt and the sequence metadata."""
    for p in iter_image_files(root, "[0-9]*_*.json"):
        try:
            K, w, h = md.intrinsics(md.load_metadata(p), str(p))
        except UserError as e:  # another JSON in images/, or a damaged one: the next may do
            log.warning("%s; intrinsics not read from it", e)
            continue
        return K, w, h, f"metadata of {printable(p.name)}"
    if seq.calib is None or "calib" not in meta:
        raise UserError(f"{seq.dir}: no image metadata and no calib.txt/lidar_meta.json to read the camera from")
    res = md.field(meta, "calib.resolution", meta_source)
    if not (isinstance(res, list) and len(res) == 2 and all(
            isinstance(v, int) and not isinstance(v, bool) and 1 <= v <= md.MAX_IMAGE_SIDE for v in res)):
        raise SpecError(meta_source, "calib.resolution", f"must be [width, height] in pixels, 1..{md.MAX_IMAGE_SIDE}")
    w, h = res
    P2 = np.asarray(seq.calib.get("P2", np.zeros(0)), np.float64)
    if P2.shape != (3, 4):
        raise UserError(f"{seq.dir / 'calib.txt'}: P2: needs 12 numbers")
    return P2[:, :3], w, h, "calib.txt P2"


def _sensor(meta: dict, source: str) -> dict:
    """The ``sensor`` fields of ``lidar_meta.json`` the OpenLABEL streams copy, type-checked."""
    out = {}
    for key in ("model", "name"):
        out[key] = md.field(meta, f"sensor.{key}", source)
        if not isinstance(out[key], str):
            raise SpecError(source, f"sensor.{key}", f"must be a string, got {md.kind_of(out[key])}")
    out["lasers"] = md.integer(meta, "sensor.lasers", source, 1, 100_000)
    out["rotation_hz"] = float(md.matrix(meta, "sensor.rotation_hz", (), source))
    out["range_m"] = md.matrix(meta, "sensor.range_m", (2,), source).tolist()
    skew = md.field(meta, "motion_skew", source, default=False)
    if not isinstance(skew, bool):
        raise SpecError(source, "motion_skew", f"must be true or false, got {md.kind_of(skew)}")
    out["motion_skew"] = skew
    return out


def _output(root: Path, name: str) -> Path:
    """``root/openlabel/NN.json``, refusing an ``openlabel`` that is not a folder inside the dataset."""
    folder = root / "openlabel"
    try:
        out = inside(root, "openlabel", f"{name}.json")
    except (ValueError, RuntimeError, OSError):  # a link leading out, or a loop
        out = None
    if out is None or (os.path.lexists(folder) and not folder.is_dir()) or out.is_dir():
        raise UserError(f"{folder}: must be a folder inside the dataset (not a file, FIFO or link leading out)")
    return out


@dataclass
class SequenceWorld:
    """A dataset's LiDAR sequence with the scene, world and rig it was cast in (every box writer's input).

    Attributes
    ----------
    spec : SceneSpec
        The spec of the sequence's town (a re-drawn town's own spec).
    root : Path
        Dataset folder.
    name : str
        Sequence ``NN``.
    seq : generator.formats.semantickitti.Sequence
    meta : dict
        ``lidar_meta.json``; ``src`` its path.
    scene : SceneModel
    world : World or None
        The world in time (None: the older one-sweep-per-image layout).
    rig : Rig
    stream : bool
        A 10 Hz stream (``sweep_period_s`` present).
    """

    spec: object
    root: Path
    name: str
    seq: object
    meta: dict
    src: str
    scene: object
    world: object
    rig: Rig
    stream: bool

    def lidar_pose(self, t: float) -> np.ndarray:
        """(4, 4) ``T_world_lidar`` at ``t`` seconds."""
        return self.rig.T_world_lidar(float(t))[0]


def open_sequence(spec, root: Path, sequence: str = "00", scene=None, world=None) -> SequenceWorld:
    """Open ``root/lidar/sequences/NN`` cast from ``spec`` and rebuild (or check) its world.

    ``scene``, ``world``: the ones the sequence was cast in, if the caller has them (``generate``);
    otherwise they are rebuilt from the spec (the world checked against the recorded digest).

    Raises
    ------
    UserError
        Another spec, no labelled scans, no ``times.txt``, or times outside a drive.
    """
    root = Path(root)
    name = sk.sequence_name(sequence)
    seq = sk.Sequence(root / "lidar", name)
    meta_path = seq.dir / "lidar_meta.json"
    meta = md.load_metadata(meta_path)
    src = str(meta_path)
    if md.field(meta, "scene.spec_hash", src, default=None) != spec.spec_hash:
        raise UserError(f"{meta_path}: cast from another spec (spec_hash differs from {spec.source})")
    spec = spec_for_record(spec, md.field(meta, "scene", src, default=None), src)  # a re-drawn town's own spec
    if not seq.has_labels or not seq.frames:
        raise UserError(f"{seq.dir}: needs scans with labels")
    if seq.times is None:
        raise UserError(f"{seq.dir / 'times.txt'}: missing")
    _check_times(seq.times, seq.dir / "times.txt")
    if scene is None:
        from generator.layout import build_scene

        scene = build_scene(spec)
    route = md.integer(meta, "scene.route", src, 0, max(len(scene.paths) - 1, 0), default=0)
    stream = md.field(meta, "sweep_period_s", src, default=None) is not None
    world = sequence_world(spec, scene, meta, seq.times, src, world) if stream else None
    rig = Rig.from_world(spec, world) if world is not None else Rig.from_spec(spec, scene, route)
    return SequenceWorld(spec, root, name, seq, meta, src, scene, world, rig, stream)


def write_sequence_openlabel(spec, root: Path, sequence: str = "00", classes=None,
                             min_points: int | None = None, scene=None, world=None) -> tuple[Path, dict]:
    """Write ``root/openlabel/NN.json`` for ``root/lidar/sequences/NN`` cast from ``spec``.

    Parameters
    ----------
    classes : sequence of str, optional
        Box classes (``generator/labels/detection.yaml``) that get cuboids (default: every one).
    min_points : int, optional
        Objects with fewer LiDAR points in a frame are left out (default ``spec.labels.openlabel_min_points``).
    scene : SceneModel, optional
        The spec's scene if already built (it is rebuilt otherwise).
    world : World, optional
        The world the sequence was cast in, if the caller has it (``generate``); it must match the
        digest the sequence recorded. Otherwise it is rebuilt from the spec (:func:`sequence_world`).

    Returns
    -------
    (Path, dict)
        The file written and the OpenLABEL document.
    """
    from generator.detection import instance_counts, subjects

    classes = tuple(detection_classes().boxes) if classes is None else tuple(classes)
    min_points = spec.labels.openlabel_min_points if min_points is None else min_points
    out = _output(Path(root), sk.sequence_name(sequence))  # where it goes is checked before any work
    sw = open_sequence(spec, root, sequence, scene, world)
    spec, seq, meta, src, name = sw.spec, sw.seq, sw.meta, sw.src, sw.name
    sensor = _sensor(meta, src)
    rig, stream = sw.rig, sw.stream
    frames = sweep_frames(rig, meta, seq.frames, seq.times, src) if stream else [rig.frame(k) for k in seq.frames]
    subs = [s for s in subjects(sw.scene, sw.world) if s.cls in classes]
    counts = [instance_counts(seq.read_labelled(k)[2]) for k in seq.frames]
    K, w, h, k_src = _camera(sw.root, seq, meta, src)
    cam = spec.sensors.camera
    streams = {
        "camera": {"uri": "images/", "description": f"rig camera, hfov {cam.hfov_deg} deg, intrinsics from {k_src}"},
        "lidar": {"uri": f"lidar/sequences/{name}/velodyne/",
                  "description": f"{sensor['model']} ({sensor['name']}), {sensor['rotation_hz']} Hz",
                  "stream_properties": {"lasers": sensor["lasers"], "range_m": sensor["range_m"],
                                        "motion_skew": sensor["motion_skew"]}},
    }
    info = {"scene": spec.name, "seed": spec.seed, "spec_hash": spec.spec_hash, "sequence": name,
            "route": md.integer(meta, "scene.route", src, 0, 10**6, default=0), "classes": list(classes)}
    shown = [f.image if stream else f.index for f in frames]
    exr = {int(p.name[:6]): p
           for p in reversed(image_files(sw.root, "[0-9]*_*.exr", [k for k in shown if k is not None]))}
    frame_uris = []
    for f, k in zip(frames, shown, strict=True):
        uris = {} if k is None else {"camera": exr[k].relative_to(sw.root).as_posix() if k in exr
                                     else image_relpath(f"{k:06d}_day_clear")}
        frame_uris.append({**uris, "lidar": f"lidar/sequences/{name}/velodyne/{f.index:06d}.bin"})
    doc = build_openlabel(subjects=subs, frames=frames, times=[seq.times[k] for k in seq.frames], counts=counts,
                          min_points=min_points, T_ego_lidar=rig.T_ego_lidar,
                          T_ego_camera_nominal=rig.T_ego_camera(), K=K, width=w, height=h,
                          streams=streams, frame_uris=frame_uris, info=info)
    try:
        write_openlabel(out, doc)
    except ValueError as e:  # a bug, not a user error: say so loudly
        raise RuntimeError(str(e)) from None
    return out, doc
