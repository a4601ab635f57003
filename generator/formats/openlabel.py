"""ASAM OpenLABEL 1.0 annotation files of a LiDAR sequence (seed 002 Sec. 3.1).

One JSON file per sequence, validated against the OpenLABEL 1.0.0 JSON schema shipped in
``generator/formats/schemas/`` before it is written (an invalid document is never written).

Coordinate systems (parent -> children):

* ``odom`` (``scene_cs``, root): the vehicle frame at the first frame of the sequence
  ("the ego vehicle's initial position", seed 002). Its pose in the urbangen world frame is
  ``metadata.urbangen.T_world_odom``.
* ``vehicle-iso8855`` (``local_cs``): x forward, y left, z up, origin on the ground below
  the LiDAR; ``pose_wrt_parent`` is the identity (frame 0) and every frame carries its own
  ego transform.
* ``lidar`` and ``camera`` (``sensor_cs``, children of the vehicle): the nominal mounts.
  The camera frame is optical (x right, y down, z forward); its per-frame random
  yaw/pitch/roll is given per frame.

Matrix conventions follow the OpenLABEL schema and its reference library (VCD/SCL): every
``matrix4x4`` is row-major and maps column points ``X_dst = M X_src``; a coordinate
system's ``pose_wrt_parent`` maps child points into the parent (it is the child's pose in
the parent). Per frame ``frame_properties.transforms`` holds

* ``vehicle-iso8855_to_odom`` (src ``vehicle-iso8855``, dst ``odom``): the ego pose at the
  frame time, i.e. vehicle points -> odom;
* ``camera_to_vehicle-iso8855``: the camera pose of that frame (jitter included).

Objects: every boxed thing (:mod:`generator.detection`: vehicles, riders, people of every thing
class, parked and moving); key = its track id, the instance id (the high 16 bits of the ``.label``
files) of the object naming the box, ``type`` = its box class (``generator/labels/detection.yaml``).
A ridden two-wheeler is one object holding vehicle and rider, typed by the rider's class
(``bicyclist``/``motorcyclist``), its points those of both instance ids. Static town objects and
actors (:mod:`generator.world.actors`) share the key space in disjoint ranges: actors' instance ids
follow every static one, and an actor keeps its id for the whole sequence.

Per frame each object present has one cuboid in ``vehicle-iso8855`` at the frame time (the sweep
start): ``(x, y, z, qx, qy, qz, qw, sx, sy, sz)`` with size = length (along the heading), width,
height in metres; ``num`` ``lidar_points`` = points of its instance ids in the frame's scan;
``text`` ``attribute`` = its nuScenes attribute (``vehicle.moving|stopped|parked``, ``cycle.with_rider|without_rider``,
``pedestrian.moving|standing``); and its motion at the same
instant (:mod:`generator.formats.openlabel_motion`): ``vec`` ``velocity`` (m/s) and
``acceleration`` (m/s^2) of the cuboid centre over ground, expressed in ``odom``; ``num``
``speed`` and ``acceleration_magnitude``; ``boolean`` ``moving``. Objects with fewer points
than the threshold (``spec.labels.openlabel_min_points``) are left out of that frame.

Timestamps: ``frame_properties.timestamp`` and, per stream of the frame,
``stream_properties.sync.timestamp`` = the sweep start in seconds on the sequence's timeline
(``times.txt``); the camera stream appears in a frame only when an image was exposed then.

Motion skew: the ``.bin`` scans keep the coordinates of each column's firing instant (KITTI
convention), so on a moving ego a raw scan drawn in the frame's vehicle frame is shifted by
up to speed x 0.1 s (0.8 m at 8 m/s) against its cuboids. De-skewed with ``point_times/``
and ``lidar_meta.json`` ``sweep_poses_world`` (:func:`generator.fusion.projection.deskew`)
every point of an object lies inside its cuboid (``tests/test_openlabel.py``).
"""

from __future__ import annotations

import functools
import json
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from generator import __version__
from generator.atomic import write_text
from generator.formats import openlabel_motion as om
from generator.world import rig

SCHEMA_PATH = Path(__file__).resolve().parent / "schemas" / "openlabel_json_schema-v1.0.0.json"
ODOM, VEHICLE, LIDAR, CAMERA = "odom", "vehicle-iso8855", "lidar", "camera"
POINTS_NAME = "lidar_points"
CUBOID_NAME = "box3d"
ATTRIBUTE_NAME = "attribute"


@functools.cache
def load_schema() -> dict:
    """The OpenLABEL 1.0.0 JSON schema (package data)."""
    return json.loads(SCHEMA_PATH.read_text(encoding="utf-8"))


def openlabel_errors(doc: dict):
    """The ``jsonschema`` errors of ``doc`` against the OpenLABEL 1.0.0 schema (an iterator)."""
    import jsonschema

    schema = load_schema()
    return jsonschema.validators.validator_for(schema)(schema).iter_errors(doc)


def validate_openlabel(doc: dict) -> list[str]:
    """Problems of ``doc`` against the OpenLABEL 1.0.0 schema (empty when valid). The messages are
    ``jsonschema``'s, which quote values: for documents we write; user files go through
    :func:`openlabel_errors` and a message that names only the field."""
    return [f"{'/'.join(str(p) for p in e.absolute_path) or '(root)'}: {e.message}" for e in openlabel_errors(doc)]


def _m(T: np.ndarray) -> dict:
    return {"matrix4x4": [float(v) for v in np.round(np.asarray(T, np.float64).reshape(-1), 9)]}


def cuboid_val(box, T_frame_world: np.ndarray) -> list[float]:
    """OpenLABEL cuboid ``(x, y, z, qx, qy, qz, qw, sx, sy, sz)`` of an upright world box in a frame.

    Parameters
    ----------
    box : generator.world.scene.OrientedBox
        World frame, metres; size = (length, width, height).
    T_frame_world : (4, 4) float64
        World -> target frame.
    """
    c = T_frame_world[:3, :3] @ np.asarray(box.center, np.float64) + T_frame_world[:3, 3]
    r = T_frame_world[:3, :3] @ Rotation.from_euler("z", box.yaw).as_matrix()
    q = Rotation.from_matrix(r).as_quat()  # (x, y, z, w), scalar last
    if q[3] < 0:
        q = -q
    return [float(v) for v in np.round(np.r_[c, q, np.asarray(box.size, np.float64)], 6)]


def cuboid_contains(val, points: np.ndarray, margin: float = 0.0) -> np.ndarray:
    """(n,) bool: which (n, 3) points (the cuboid's frame) lie in the cuboid ``val`` grown by ``margin``."""
    v = np.asarray(val, np.float64)
    r = Rotation.from_quat(v[3:7]).as_matrix()
    local = (np.asarray(points, np.float64) - v[:3]) @ r
    return np.all(np.abs(local) <= v[7:10] / 2 + margin, axis=1)


def _intervals(frames: list[int]) -> list[dict]:
    out: list[dict] = []
    for k in sorted(frames):
        if out and out[-1]["frame_end"] == k - 1:
            out[-1]["frame_end"] = k
        else:
            out.append({"frame_start": k, "frame_end": k})
    return out


def _candidates(subjects) -> dict[int, tuple]:
    """Track id -> (name, box class, state at t, instance ids, attribute at t) of every boxed subject."""
    def state(s):
        def at(t):
            v, a = s.motion(t)
            return om.Motion(s.box(t), v, a, s.moving(t))
        return at

    return {s.track_id: (s.name, s.cls, state(s), s.instance_ids, s.attribute) for s in subjects}


def build_openlabel(*, subjects, frames, times, counts, min_points: int, T_ego_lidar: np.ndarray,
                    T_ego_camera_nominal: np.ndarray, K: np.ndarray, width: int, height: int,
                    streams: dict, frame_uris: list[dict], info: dict) -> dict:
    """The OpenLABEL document of one sequence.

    Parameters
    ----------
    subjects : list of generator.detection.Subject
        The boxed things (parked statics and actors; a ridden two-wheeler is one with its rider).
    frames : list
        The sequence's frames (sweeps): each with ``index``, ``T_world_ego`` (4, 4) at the sweep
        start and ``T_ego_camera`` (4, 4, optical camera in the ego frame, jitter included) or
        ``None`` when no image was exposed with that sweep (:class:`generator.world.rig.Frame` fits).
    times : (n_frames,) float
        Sweep starts, seconds on the world timeline (``times.txt``); actors are evaluated there.
    counts : list of dict
        Per frame: instance id -> LiDAR points of that instance in the scan (a subject counts the
        points of all its instance ids).
    min_points : int
        Objects with fewer points in a frame are left out of it.
    T_ego_lidar, T_ego_camera_nominal : (4, 4) float64
        Sensor mounts (camera in the optical frame, without jitter).
    K : (3, 3) float64
        Camera intrinsics; ``width``, ``height`` in pixels.
    streams : dict
        ``{"camera": {"uri", "description"}, "lidar": {"uri", "description", "stream_properties"}}``.
    frame_uris : list of dict
        Per frame ``{"lidar": uri}`` and ``"camera": uri`` when the frame has an image.
    info : dict
        Extra ``metadata.urbangen`` fields (scene, seed, spec hash...).
    """
    T_world_odom = frames[0].T_world_ego
    T_odom_world = rig.invert(T_world_odom)
    doc_frames: dict[str, dict] = {}
    present: dict[int, list[int]] = {}
    cands = _candidates(subjects)
    for f, t, cnt, uris in zip(frames, times, counts, frame_uris, strict=True):
        T_vehicle_world = rig.invert(f.T_world_ego)
        objs = {}
        for uid in sorted(cands):
            n = sum(int(cnt.get(i, 0)) for i in cands[uid][3])
            if n < max(min_points, 1):
                continue
            m = cands[uid][2](float(t))
            objs[str(uid)] = {"object_data": {
                "cuboid": [{"name": CUBOID_NAME, "coordinate_system": VEHICLE,
                            "val": cuboid_val(m.box, T_vehicle_world)}],
                "num": [{"name": POINTS_NAME, "type": "value", "val": n}],
                "text": [{"name": ATTRIBUTE_NAME, "val": cands[uid][4](float(t))}]}}
            for kind, items in om.motion_data(m, T_odom_world[:3, :3], ODOM).items():
                objs[str(uid)]["object_data"].setdefault(kind, []).extend(items)
            present.setdefault(uid, []).append(f.index)
        transforms = {f"{VEHICLE}_to_{ODOM}": {"src": VEHICLE, "dst": ODOM,
                                               "transform_src_to_dst": _m(T_odom_world @ f.T_world_ego)}}
        if getattr(f, "T_ego_camera", None) is not None:
            transforms[f"{CAMERA}_to_{VEHICLE}"] = {"src": CAMERA, "dst": VEHICLE,
                                                    "transform_src_to_dst": _m(f.T_ego_camera)}
        doc_frames[str(f.index)] = {
            "frame_properties": {
                "timestamp": float(t),
                "streams": {key: {"uri": uri, "stream_properties": {"sync": {"timestamp": float(t)}}}
                            for key, uri in uris.items()},
                "transforms": transforms},
            "objects": objs,
        }
    doc_objects = {str(uid): {"name": cands[uid][0], "type": cands[uid][1], "coordinate_system": VEHICLE,
                              "frame_intervals": _intervals(ks)} for uid, ks in sorted(present.items())}
    camera_matrix = np.hstack([np.asarray(K, np.float64), np.zeros((3, 1))])
    ol = {
        "metadata": {
            "schema_version": "1.0.0", "file_version": "1",
            "name": f"{info.get('scene', 'scene')} sequence {info.get('sequence', '00')}",
            "annotator": f"urbangen {__version__} (automatic: boxes from the scene model, counts from the "
                         "ray-cast labels)",
            "comment": ("matrix4x4 row-major, X_dst = M X_src; pose_wrt_parent maps child -> parent; cuboids "
                        "(x,y,z,qx,qy,qz,qw,length,width,height) in vehicle-iso8855 at the frame time (sweep "
                        "start); velocity/acceleration of the cuboid centre over ground at the same instant, in "
                        f"odom (central differences, h = 0.05 s); moving = speed > {om.MOVING_THRESHOLD_MPS} m/s; "
                        f"objects with fewer than {min_points} LiDAR points left out of a frame; attribute = "
                        "nuScenes attribute"),
            "urbangen": {**info, "T_world_odom": [float(v) for v in np.round(T_world_odom.reshape(-1), 9)],
                         "min_points": int(min_points)},
        },
        "coordinate_systems": {
            ODOM: {"type": "scene_cs", "parent": "", "children": [VEHICLE]},
            VEHICLE: {"type": "local_cs", "parent": ODOM, "pose_wrt_parent": _m(np.eye(4)),
                      "children": [LIDAR, CAMERA]},
            LIDAR: {"type": "sensor_cs", "parent": VEHICLE, "pose_wrt_parent": _m(T_ego_lidar), "children": []},
            CAMERA: {"type": "sensor_cs", "parent": VEHICLE, "pose_wrt_parent": _m(T_ego_camera_nominal),
                     "children": []},
        },
        "streams": {
            "camera": {"type": "camera", "uri": streams["camera"]["uri"],
                       "description": streams["camera"]["description"],
                       "stream_properties": {"intrinsics_pinhole": {
                           "width_px": int(width), "height_px": int(height),
                           "camera_matrix": [float(v) for v in camera_matrix.reshape(-1)],
                           "distortion_coeffs": [0.0] * 5}}},
            "lidar": {"type": "lidar", "uri": streams["lidar"]["uri"], "description": streams["lidar"]["description"],
                      "stream_properties": streams["lidar"].get("stream_properties", {})},
        },
        "frame_intervals": _intervals([f.index for f in frames]),
        "frames": doc_frames,
        "objects": doc_objects,
    }
    return {"openlabel": ol}


def write_openlabel(path: str | Path, doc: dict) -> None:
    """Validate ``doc`` against the schema, then write it atomically.

    Raises
    ------
    ValueError
        If the document does not validate (nothing is written).
    """
    problems = validate_openlabel(doc)
    if problems:
        raise ValueError(f"OpenLABEL document does not match the 1.0.0 schema: {problems[0]}"
                         + (f" (and {len(problems) - 1} more)" if len(problems) > 1 else ""))
    write_text(path, json.dumps(doc, indent=1) + "\n")


def object_counts(doc: dict) -> dict[str, dict[str, int]]:
    """Per class: objects in the file and object-frame cuboids (for reports)."""
    ol = doc["openlabel"]
    out: dict[str, dict[str, int]] = {}
    for o in ol.get("objects", {}).values():
        d = out.setdefault(o["type"], {"objects": 0, "cuboids": 0})
        d["objects"] += 1
    for f in ol.get("frames", {}).values():
        for uid in f.get("objects", {}):
            out[ol["objects"][uid]["type"]]["cuboids"] += 1
    return dict(sorted(out.items()))
