"""``manifest.json``: what a dataset folder holds and how it was made.

The manifest records the spec (and its hash), the render config, the software
versions, the plan and the finished items. It is rewritten atomically after every
finished frame. A rerun of the same command resumes: finished items are those whose
files are complete on disk (an image's metadata JSON is written last), so a run killed
at any instant loses at most the frames in flight. A folder made from another spec or
config is refused rather than mixed.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

from generator.atomic import write_json
from generator.errors import UserError
from generator.imaging.metadata import software_versions
from generator.jobs.plan import Plan

NAME = "manifest.json"
VERSION = 1


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
        "finished": {"images": [], "lidar": False, "openlabel": False, "stats": False},
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
    """A resumed run may extend the plan (more frames or variants); keep the union."""
    frames = sorted(set(old["plan"]["frames"]) | set(plan.frames))
    combos = [tuple(c) for c in old["plan"]["combos"]]
    combos += [c for c in plan.combos if c not in combos]
    merged = Plan(tuple(frames), tuple(combos), plan.sequence)
    return {**old, "plan": merged.to_dict()}


def save(out: Path, manifest: dict) -> None:
    manifest["updated"] = time.strftime("%Y-%m-%dT%H:%M:%S%z")
    write_json(Path(out) / NAME, manifest)
