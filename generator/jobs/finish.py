"""Dataset-level outputs written after the towns: label config, statistics; OpenLABEL and boxes per sequence.

:func:`run_dataset` is the last task of a ``generate`` run (on the executor like the others): the
label config sums every sequence's class content, the statistics read every image's metadata.
"""

from __future__ import annotations

import logging
import os
import time
from dataclasses import dataclass
from pathlib import Path

from generator.errors import UserError

log = logging.getLogger(__name__)

#: The dataset products of ``generate``, in order.
DATASET_PRODUCTS = ("label_config", "stats")


@dataclass(frozen=True)
class DatasetJob:
    """The dataset task (picklable).

    Attributes
    ----------
    out : str
    products : tuple of str
        Names in :data:`DATASET_PRODUCTS` to make.
    split : str or None
        ``--split`` of the run's sequences (None: keep each sequence's split, new ones ``valid``).
    sequences : tuple of str
        The run's sequences (the ones ``split`` applies to).
    """

    out: str
    products: tuple[str, ...]
    split: str | None = None
    sequences: tuple[str, ...] = ()


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


def run_dataset(job: DatasetJob, report) -> None:
    """Make the dataset products of ``job`` and report each (``("item", ("dataset", name), payload)``)."""
    from generator.jobs.lidar_sequence import write_dataset_label_config

    out = Path(job.out)
    report.put(("ready", {"pid": os.getpid()}))
    try:
        for name in job.products:
            t = time.perf_counter()
            if name == "label_config":
                if (out / "lidar" / "sequences").is_dir():
                    write_dataset_label_config(out / "lidar", job.split, list(job.sequences) if job.split else None)
            elif name == "stats":
                write_stats(out)
            else:
                raise ValueError(f"unknown dataset product {name!r}")
            report.put(("item", ("dataset", name), {"seconds": time.perf_counter() - t}))
    except UserError as e:
        report.put(("user_error", str(e)))
        return
    report.put(("done", {"pid": os.getpid()}))
