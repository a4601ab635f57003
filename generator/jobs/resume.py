"""Resuming a dataset folder: its manifest read and checked, and what is done (the journal, or the files).

A folder is resumed from its journal (:mod:`generator.jobs.journal`). A folder from before the
journal (manifest version 1), or one whose journal was removed, is looked at file by file once
(:func:`ledger_from_files`); the run then writes its journal.
"""

from __future__ import annotations

import logging
import os
from pathlib import Path

from generator.errors import SpecError, UserError
from generator.imaging.paths import find_image
from generator.jobs import manifest as mf
from generator.jobs.frameset import FrameSet
from generator.jobs.journal import Journal, Ledger
from generator.jobs.plan import MAX_FRAME_INDEX, Plan
from generator.jobs.stereo import pair_done, stereo_frames
from generator.jobs.towns import TownPlan
from generator.safeload import MAX_METADATA_BYTES, load_json
from generator.weather import TIMES, combinations

log = logging.getLogger(__name__)


def read_manifest(out: Path) -> dict | None:
    """The manifest of a folder being resumed, or None; a damaged one is a one-line error naming the field."""
    path = out / mf.NAME
    if not os.path.lexists(path):
        return None
    src = str(path)
    doc = load_json(path, source=src, max_bytes=MAX_METADATA_BYTES, max_nodes=20 * (MAX_FRAME_INDEX + 1) + 100_000)

    def need(obj, key, kind, where=""):
        if not isinstance(obj, dict) or not isinstance(obj.get(key), kind):
            what = {str: "text", dict: "a mapping", list: "a list"}[kind]
            raise SpecError(src, where + key, f"must be {what} (not a manifest urbangen wrote; use another --out "
                                              "or delete the folder)")
        return obj[key]

    need(doc, "spec_hash", str)
    need(need(doc, "render_config", dict), "config_hash", str, "render_config.")
    plan = need(doc, "plan", dict)
    if "frame_ranges" in plan:
        try:
            FrameSet.from_json(plan["frame_ranges"], 0, MAX_FRAME_INDEX + 1)
        except ValueError as e:
            raise SpecError(src, "plan.frame_ranges", str(e)) from None
    else:  # version 1: every frame number
        frames = need(plan, "frames", list, "plan.")
        if not all(type(k) is int and 0 <= k <= MAX_FRAME_INDEX for k in frames):
            raise SpecError(src, "plan.frames", f"must be frame numbers in 0..{MAX_FRAME_INDEX}")
    combos = need(plan, "combos", list, "plan.")
    need(plan, "sequence", str, "plan.")
    valid = {tuple(c) for c in combinations(TIMES)}
    if not all(isinstance(c, list) and tuple(c) in valid for c in combos):
        raise SpecError(src, "plan.combos", "must be [time_of_day, weather] pairs like [day, fog]")
    need(doc, "finished", dict)
    if not isinstance(doc.get("runs", []), list):
        raise SpecError(src, "runs", "must be a list")
    return doc


def ledger_from_files(out: Path, plan: Plan, towns: TownPlan) -> Ledger:
    """What is done, looked up file by file: a dataset from before the journal (manifest version 1) or one
    whose journal was removed. Once per such folder: the run then writes the journal."""
    from generator.jobs.journal import combo_mask, frames_text

    ledger = Ledger()
    mask = combo_mask(plan.combos)
    for k in plan.frames:
        if all(find_image(out, n, ".json").exists() for n in plan.images_of(k)):
            ledger.add_frame(k, mask)
    for index in towns.indices:
        run = towns.run(index)
        seq_dir = out / "lidar" / "sequences" / run.plan.sequence
        sweeps = _lidar_sweeps(out, run.plan, run.spec)
        if sweeps is not None:
            ledger.add_town(run.plan.sequence, "lidar", frames_text(run.plan.frames), {"sweeps": str(sweeps)})
            for j in stereo_frames(run.spec, range(sweeps)):
                if pair_done(seq_dir, j):
                    ledger.add_stereo(run.plan.sequence, j)
    return ledger


def _lidar_sweeps(out: Path, plan: Plan, spec) -> int | None:
    """Sweeps of ``lidar/sequences/NN`` if it is complete for this spec and plan (its metadata, read safely,
    says so), else None."""
    meta = out / "lidar" / "sequences" / plan.sequence / "lidar_meta.json"
    if not os.path.lexists(meta):
        return None
    n = 20 * len(plan.frames)  # the metadata grows with the scans (~2 KB and ~200 values each), ~15 sweeps a frame
    try:
        m = load_json(meta, max_bytes=MAX_METADATA_BYTES + n * 16 * 1024, max_nodes=100_000 + n * 2_000)
    except UserError:  # damaged: it is cast again
        return None
    if not isinstance(m, dict) or not isinstance(m.get("image_frames"), list) or type(m.get("frames")) is not int:
        return None
    scene = m.get("scene")
    pairs = sorted(tuple(p) for p in m["image_frames"] if isinstance(p, list) and len(p) == 2)
    ok = (isinstance(scene, dict) and scene.get("spec_hash") == spec.spec_hash and scene.get("seed") == spec.seed
          and [k for k, _ in pairs] == list(plan.frames))
    return m["frames"] if ok else None


def read_journal(out: Path, old: dict | None, plan: Plan, towns: TownPlan) -> Journal:
    journal = Journal(out)
    if old is None:
        return journal  # a new folder (a journal left without its manifest is dropped when the run starts)
    if journal.exists():
        journal.load()
    else:
        if old.get("manifest_version", 1) >= 2:
            log.warning("%s: no journal beside the manifest: finished items are looked up file by file", out)
        journal.ledger = ledger_from_files(out, plan, towns)
    return journal
