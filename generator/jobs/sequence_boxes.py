"""The 3D box records of a dataset's LiDAR sequence, rebuilt from the spec it was cast from.

The exports (nuScenes) and ``urbangen process`` need one :class:`generator.detection.BoxRecord` per
boxed thing per sweep. The world is deterministic from the spec (the seed names every draw), so the
records are rebuilt: the sequence's town (``lidar_meta.json`` ``scene`` record, a re-drawn town's own
spec), its traffic over the recorded duration (checked against the recorded digest, as ``openlabel``
and ``fuse`` do), and ``num_lidar_pts`` counted in the labels on disk -- so a processed twin (points
removed) gets its own counts from its own labels.

Where the spec comes from: the dataset's ``manifest.json`` (``generate``), or the spec file the caller
names (datasets made with ``urbangen lidar``, which writes no manifest).
"""

from __future__ import annotations

import logging
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from generator.detection import SweepClock, instance_counts, subjects, sweep_boxes
from generator.errors import UserError
from generator.formats import semantickitti as sk
from generator.imaging import meta_fields as md

log = logging.getLogger(__name__)

META_NAME = "lidar_meta.json"


def dataset_spec(root: Path, spec_path: str | None = None):
    """The spec a dataset was made from: ``spec_path`` if given, else the one in ``root/manifest.json``.

    Raises
    ------
    UserError
        Neither is there (one line saying to name the spec).
    """
    from generator.spec import load_spec
    from generator.spec.load import parse_spec

    if spec_path is not None:
        return load_spec(spec_path)
    path = Path(root) / "manifest.json"
    if not os.path.lexists(path):
        raise UserError(f"{path}: missing; name the spec the dataset was made from with --spec "
                        "(datasets made with 'urbangen lidar' have no manifest)")
    doc = md.load_metadata(path).get("spec")
    if not isinstance(doc, dict):
        raise UserError(f"{path}: spec: missing or not an object")
    return parse_spec(doc, str(path))


@dataclass
class SequenceBoxes:
    """One sequence's world and its box records.

    Attributes
    ----------
    spec : generator.spec.SceneSpec
        The sequence's own spec (a re-drawn town's).
    rig : generator.world.rig.Rig
        Riding the sequence's ego: ``rig.T_world_lidar(t)`` is the pose the records were made with.
    times : (n,) float64
        Sweep starts (``times.txt``), seconds.
    records : dict of int to list of BoxRecord
        Per sweep asked for.
    subjects : list of generator.detection.Subject
    """

    spec: object
    rig: object
    times: np.ndarray
    records: dict = field(default_factory=dict)
    subjects: list = field(default_factory=list)


def sequence_boxes(root: Path, sequence: str, spec, sweeps=None, min_points: int = 1) -> SequenceBoxes:
    """Box records of ``root/lidar/sequences/NN`` (every sweep, or those of ``sweeps``).

    Parameters
    ----------
    root : Path
        Dataset folder (``lidar/sequences/NN`` inside).
    sequence : str
        ``NN``.
    spec : generator.spec.SceneSpec
        The dataset's spec (:func:`dataset_spec`); must have the hash the sequence recorded.
    sweeps : iterable of int, optional
    min_points : int
        Keep boxes with at least this many points in their sweep (default 1, seed 002).
    """
    from generator.jobs.boxes import sequence_world
    from generator.layout import build_scene
    from generator.lidar.sensors import sensor_for_spec
    from generator.spec.towns import spec_for_record
    from generator.world.rig import Rig

    seq = sk.Sequence(Path(root) / "lidar", sequence)
    meta_path = seq.dir / META_NAME
    meta = md.load_metadata(meta_path)
    src = str(meta_path)
    if md.field(meta, "scene.spec_hash", src, default=None) != spec.spec_hash:
        raise UserError(f"{meta_path}: cast from another spec (spec_hash differs from {spec.source})")
    spec = spec_for_record(spec, md.field(meta, "scene", src, default=None), src)
    if seq.times is None:
        raise UserError(f"{seq.dir / 'times.txt'}: missing")
    if not seq.has_labels:
        raise UserError(f"{seq.labels_dir}: missing (box records count points in the labels)")
    log.info("rebuilding %s (sequence %s) for its boxes", spec.name, sequence)
    scene = build_scene(spec)
    stream = md.field(meta, "sweep_period_s", src, default=None) is not None
    world = sequence_world(spec, scene, meta, seq.times, src) if stream else None
    route = md.integer(meta, "scene.route", src, 0, max(len(scene.paths) - 1, 0), default=0)
    rig = Rig.from_world(spec, world) if world is not None else Rig.from_spec(spec, scene, route)
    things = subjects(scene, world)
    skew = md.field(meta, "motion_skew", src, default=False) is True
    clock = SweepClock.of(sensor_for_spec(spec)) if skew else None
    out = SequenceBoxes(spec, rig, np.asarray(seq.times, np.float64), {}, things)
    for j in seq.frames if sweeps is None else sweeps:
        _, inst = sk.read_labels(seq.label_path(j))
        out.records[j] = sweep_boxes(things, j, float(seq.times[j]), lambda t: rig.T_world_lidar(t)[0],
                                     instance_counts(inst), clock, min_points)
    return out
