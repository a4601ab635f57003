"""The 3D box records of a dataset's LiDAR sequence, for the exports (nuScenes) and ``urbangen process``.

Read from the sequence's box file (``boxes/NN.npz``, :mod:`generator.formats.box_file`, which
``generate`` and ``urbangen openlabel`` write) when it is there: no spec, no rebuild. Without it (a
dataset made with ``urbangen lidar``, or before box files existed) they are rebuilt from the spec as
the box file's writer does (:func:`generator.jobs.boxes.open_sequence`: the sequence's town, its
traffic checked against the recorded digest, ``num_lidar_pts`` counted in the labels on disk).

Where the spec comes from: the dataset's ``manifest.json`` (``generate``), or the spec file the caller
names (``urbangen lidar`` writes no manifest).
"""

from __future__ import annotations

import logging
import os
from dataclasses import dataclass, field
from pathlib import Path

from generator.errors import UserError
from generator.imaging import meta_fields as md

log = logging.getLogger(__name__)

#: The stereo camera whose image boxes give a nuScenes annotation its visibility (the left one, CAM_FRONT).
VISIBILITY_IMAGE = "image_2"


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
    """One sequence's box records.

    Attributes
    ----------
    records : dict of int to list of BoxRecord
        Per sweep asked for (``num_lidar_pts`` >= the threshold they were made with).
    visibility : dict of int to dict of int to str
        Per sweep: track id -> nuScenes visibility token of the box in that sweep's ``image_2`` (only
        sweeps with such an image, only boxes whose footprint touches it).
    source : str
        ``"box file"`` or ``"rebuilt from the spec"``.
    """

    records: dict = field(default_factory=dict)
    visibility: dict = field(default_factory=dict)
    source: str = ""


def box_file_of(root: Path, name: str) -> Path | None:
    """``root/boxes/NN.npz`` when it exists."""
    p = Path(root) / "boxes" / f"{name}.npz"
    return p if os.path.lexists(p) else None


def sequence_boxes(root: Path, name: str, spec=None, sweeps=None, min_points: int = 1) -> SequenceBoxes:
    """Box records of ``root/lidar/sequences/NN`` (every sweep, or those of ``sweeps``).

    Parameters
    ----------
    spec : generator.spec.SceneSpec, optional
        Needed only without a box file (:func:`dataset_spec`).
    min_points : int
        Threshold of rebuilt records (a box file keeps its own).
    """
    from generator.formats import semantickitti as sk

    root = Path(root)
    path = box_file_of(root, name)
    if path is not None:
        from generator.formats.box_file import read_box_file

        bf = read_box_file(path)
        js = sorted(bf.sweeps) if sweeps is None else list(sweeps)
        out = SequenceBoxes({j: bf.records(j) for j in js}, {}, "box file")
        for j in js:
            entry = bf.image(f"{VISIBILITY_IMAGE}/{j:06d}")
            if entry is not None:
                out.visibility[j] = {r.track_id: b.nuscenes_visibility for r, b in entry.boxes}
        return out
    if spec is None:
        raise UserError(f"{root / 'boxes' / f'{name}.npz'}: missing, so the boxes are rebuilt from the spec: "
                        "name it with --spec (or write the box file with 'urbangen openlabel SPEC DIR')")
    from generator.detection import SweepClock, instance_counts, subjects, sweep_boxes
    from generator.jobs.boxes import open_sequence

    sw = open_sequence(spec, root, name)
    log.info("no box file for %s: rebuilding %s (sequence %s) for its boxes", name, sw.spec.name, name)
    things = subjects(sw.scene, sw.world)
    clock = None
    if md.field(sw.meta, "motion_skew", sw.src, default=False) is True:
        from generator.lidar.sensors import sensor_for_spec

        clock = SweepClock.of(sensor_for_spec(sw.spec))
    out = SequenceBoxes({}, {}, "rebuilt from the spec")
    for j in sw.seq.frames if sweeps is None else sweeps:
        _, inst = sk.read_labels(sw.seq.label_path(j))
        out.records[j] = sweep_boxes(things, j, float(sw.seq.times[j]), sw.lidar_pose, instance_counts(inst), clock,
                                     min_points)
    return out
