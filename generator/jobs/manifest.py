"""``manifest.json``: what a dataset folder holds and how it was made -- its summary.

The manifest records the spec (and its hash), the render config, the software versions, the plan
(frame ranges, not a list of frames) and a summary of what is finished (counts and the ranges of
complete frames). The item-by-item record is the journal (:mod:`generator.jobs.journal`): the
manifest is written when a run starts, every :data:`generator.jobs.schedule.CHECKPOINT_S` seconds
and when it ends, never per item. A rerun of the same command resumes from the journal; a folder
made from another spec or config is refused rather than mixed.

Version 2 (this one) replaced version 1's ``plan.frames`` (every frame number) by
``plan.frame_ranges`` (``[[start, stop], ...]``, half-open) and ``finished.images`` (every image
name) by counts and ``finished.frame_ranges``; version 1 manifests are still read (and resumed).
"""

from __future__ import annotations

import json
import time
from pathlib import Path

from generator.atomic import write_json
from generator.errors import UserError
from generator.imaging.metadata import software_versions
from generator.jobs.frameset import FrameSet
from generator.jobs.journal import DIR as JOURNAL_DIR
from generator.jobs.journal import combo_mask
from generator.jobs.plan import Plan

NAME = "manifest.json"
VERSION = 2


def new_manifest(spec, cfg, plan: Plan, executor: str) -> dict:
    return {
        "manifest_version": VERSION,
        "scene": spec.name,
        "seed": spec.seed,
        "spec_hash": spec.spec_hash,
        "spec": spec.to_dict(),
        "render_config": {**cfg.to_dict(), "config_hash": cfg.config_hash},
        "software": software_versions(),
        "plan": plan.to_dict(),
        "executor": executor,
        "created": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        "finished": {"images": 0, "frames": 0, "frame_ranges": [], "stereo": 0, "lidar": False, "openlabel": False,
                     "stats": False, "journal": f"{JOURNAL_DIR}/"},
        "runs": [],
    }


def load(out: Path) -> dict | None:
    """The manifest of ``out`` or None; a corrupt manifest is a one-line user error."""
    p = Path(out) / NAME
    if not p.exists():
        return None
    try:
        return json.loads(p.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as e:
        raise UserError(f"{p}: not a valid manifest ({e}); use another --out or delete the folder") from None


def check_compatible(old: dict, new: dict, out: Path) -> None:
    """Refuse to resume into a folder made from another spec, config or sequence."""
    for key, what in (("spec_hash", "spec"), ("render_config", "render config")):
        a = old.get(key) if key == "spec_hash" else old.get(key, {}).get("config_hash")
        b = new.get(key) if key == "spec_hash" else new.get(key, {}).get("config_hash")
        if a != b:
            raise UserError(f"--out: {out} holds a dataset made from another {what} ({str(a)[:12]} != {str(b)[:12]}); "
                            "use a new folder")
    if old["plan"]["sequence"] != new["plan"]["sequence"]:
        raise UserError(f"--out: {out} holds sequence {old['plan']['sequence']}, not {new['plan']['sequence']}")


def merge_plan(old: dict, plan: Plan) -> dict:
    """A resumed run may extend the plan (more frames or variants); keep the union (a version 2 manifest)."""
    before = Plan.from_dict(old["plan"])
    combos = list(before.combos) + [c for c in plan.combos if c not in before.combos]
    merged = Plan(before.frames.union(plan.frames), tuple(combos), plan.sequence)
    return {**old, "manifest_version": VERSION, "plan": merged.to_dict()}


def finished_summary(plan: Plan, ledger, towns: int, products: dict, stats: bool) -> dict:
    """The manifest's ``finished``: counts of what the journal holds (``ledger``) for ``plan``.

    Parameters
    ----------
    towns : int
        Towns of the plan.
    products : dict of str -> int
        Towns whose per-town product is made, by product (``lidar``, ``openlabel`` ...).
    stats : bool
        The dataset statistics are made for this plan.
    """
    complete = ledger.frames_done(plan.frames, combo_mask(plan.combos))
    out = {"images": ledger.n_images(plan.frames, plan.combos), "frames": len(complete),
           "frame_ranges": complete.to_json(), "stereo": sum(len(v) for v in ledger.stereo.values()),
           "towns": {"count": towns, **products}}
    out.update({p: n == towns for p, n in products.items()})
    out.update(stats=stats, journal=f"{JOURNAL_DIR}/")
    return out


def complete_frames(doc: dict) -> FrameSet:
    """The frames a manifest says are complete (version 2 ``finished.frame_ranges``; version 1: from the names
    in ``finished.images`` whose frame has every planned variant)."""
    finished = doc.get("finished", {})
    if "frame_ranges" in finished:
        return FrameSet.from_json(finished["frame_ranges"])
    plan = Plan.from_dict(doc["plan"])
    names = set(finished.get("images", []))
    return FrameSet.of(k for k in plan.frames if all(n in names for n in plan.images_of(k)))


def save(out: Path, manifest: dict) -> None:
    manifest["updated"] = time.strftime("%Y-%m-%dT%H:%M:%S%z")
    write_json(Path(out) / NAME, manifest)
