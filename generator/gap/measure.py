"""Measuring one dataset: every scan through the ring fit into a :class:`~generator.gap.profile.Profile`."""

from __future__ import annotations

import dataclasses
import logging
import os
from collections import deque
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from generator.errors import UserError
from generator.gap.objects import instance_objects
from generator.gap.profile import Profile
from generator.gap.rings import RingModel
from generator.gap.window import Window
from generator.progress import progress

log = logging.getLogger(__name__)


def objects_mode(choice: str, sources) -> str | None:
    """Where points per object come from for every dataset: ``boxes``, ``instances`` or None (off).

    Raises
    ------
    UserError
        ``--objects boxes`` (or ``instances``) asked of a dataset without boxes (labels).
    """
    boxes = all(s.has_boxes for s in sources)
    labels = all(s.has_instances for s in sources)
    if choice == "auto":
        return "boxes" if boxes else "instances" if labels else None
    if choice == "boxes" and not boxes:
        bad = next(s for s in sources if not s.has_boxes)
        raise UserError(f"--objects: {bad.role} ({bad.root}) has no boxes (openlabel/NN.json beside it)")
    if choice == "instances" and not labels:
        bad = next(s for s in sources if not s.has_instances)
        raise UserError(f"--objects: {bad.role} ({bad.root}) has no labels with instance ids")
    return None if choice == "off" else choice


def measure(name: str, source, sensor, objects: str | None, threads: int | None = None,
            window: Window | None = None) -> tuple[Profile, dict]:
    """(profile, JSON record) of one dataset (scans measured on ``threads`` threads, default: the cores),
    within ``window`` when given (:mod:`generator.gap.window`)."""
    prof = Profile(name, RingModel(sensor), window)

    def one(scan):
        if scan.ring is not None and scan.ring.size and int(scan.ring.max()) >= prof.rings:
            raise UserError(f"--sensor: {sensor.name} has {prof.rings} rings, {source.root} records ring "
                            f"{int(scan.ring.max())} (leave --sensor out to use the data's own)")
        keep, fit = prof.crop(scan.xyz, scan.ring)
        if keep is not None:
            per_point = ("xyz", "remission", "learning", "instance", "ring")
            scan = dataclasses.replace(scan, **{k: None if getattr(scan, k) is None else getattr(scan, k)[keep]
                                                for k in per_point})
        obj = None
        if objects == "boxes":
            obj = source.boxes(scan.sequence)(scan.index, scan.xyz)
        elif objects == "instances":
            obj = instance_objects(scan.xyz, scan.learning, scan.instance)
        return prof.measure(scan.xyz, scan.remission, scan.learning, obj, scan.ring, fit)

    # numpy releases the GIL in the large array operations: scans measured in threads, merged in order,
    # a few at a time so a long sequence is never all in memory
    workers = threads or os.cpu_count() or 1
    with ThreadPoolExecutor(workers) as pool:
        for part in progress(_bounded_map(pool, one, source.scans(), 2 * workers), total=source.n_scans,
                             desc=f"gap {name}", unit="scan"):
            prof.merge(part)
    recorded = source.sensor_name()
    if recorded is not None and recorded != sensor.name:
        log.warning("%s was cast with sensor %s, the ring fit uses %s", source.root, recorded, sensor.name)
    v = prof.vertical
    centre = (np.linspace(-0.25, 0.25, len(v) + 1)[:-1] + 0.25 / len(v))
    record = {
        "name": name, "path": str(source.root), "layout": source.layout, "scans": prof.scans,
        "points_per_scan": prof.points / max(prof.scans, 1), "rays_per_scan": int(prof.rays_per_ring.sum()),
        "labels": source.has_labels, "boxes": source.has_boxes, "sensor_recorded": recorded,
        "ring_fit": {"within_1cm_of_cone": float(v[np.abs(centre) < 0.01].sum() / max(v.sum(), 1)),
                     "cell_collisions_per_scan": prof.collisions / max(prof.scans, 1)},
    }
    return prof, record


def _bounded_map(pool, fn, items, ahead: int):
    """``pool.map(fn, items)`` in order, with at most ``ahead`` items submitted and not yet returned."""
    pending = deque()
    for item in items:
        pending.append(pool.submit(fn, item))
        if len(pending) >= ahead:
            yield pending.popleft().result()
    while pending:
        yield pending.popleft().result()
