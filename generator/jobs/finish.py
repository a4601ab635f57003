"""Dataset-level outputs written after the frames: OpenLABEL and the box file per sequence, statistics."""

from __future__ import annotations

import logging
from pathlib import Path

log = logging.getLogger(__name__)


def write_stats(out: Path) -> list[Path]:
    """Write ``out/stats/`` (seed 003 Tables I and II, charts) from the dataset's metadata."""
    from generator.stats import section_modules
    from generator.stats.report import write_report

    sections = [mod.section(data) for mod in section_modules() if (data := mod.load(out)) is not None]
    return write_report(Path(out) / "stats", out, sections) if sections else []


def write_openlabel(spec, out: Path, plan, scene=None, world=None, supersample: int = 1) -> Path:
    """Write ``out/openlabel/NN.json`` (cuboids of every boxed thing) and ``out/boxes/NN.npz`` (box
    records per sweep, visibility per image) for the plan's sequence.

    ``world``: the world the sequence was cast in, when the caller has it (else rebuilt);
    ``supersample``: the render config's ``label_supersample``.
    """
    from generator.jobs.box_labels import write_sequence_boxes
    from generator.jobs.boxes import write_sequence_openlabel

    path, _ = write_sequence_openlabel(spec, out, plan.sequence, scene=scene, world=world)
    write_sequence_boxes(spec, out, plan.sequence, scene=scene, world=world, supersample=supersample)
    return path
