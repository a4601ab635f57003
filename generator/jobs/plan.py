"""A dataset plan: frames x weather x time of day, balanced like seed 003 Table II.

Every frame is rendered in every planned combination (masks and depth are shared by a
frame's variants), so each (time of day, weather) pair gets exactly one image per frame:
equal counts by construction. Every frame also gets one LiDAR scan in sequence ``NN``.

A plan is compact: its frames are ranges (:class:`generator.jobs.frameset.FrameSet`), so a
million-image plan is a few numbers in memory and in ``manifest.json``.

Before any work, a plan is checked against what the formats allow (:func:`check_plan`: frame
numbers fit the six digits of file names, ``NNNNNN_<time>_<weather>``, KITTI's and Cityscapes'
frame ids; there is no cap on the number of images, which only the disk bounds) and the disk it
will write is estimated (:func:`image_bytes`, :func:`scan_bytes`) and compared with the free space
at the output (:func:`check_free_space`), so an absurd ``--frames`` ends in one line at once
instead of running until killed or until the disk is full.
"""

from __future__ import annotations

import os
import shutil
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

from generator.errors import UserError
from generator.imaging.paths import image_name
from generator.jobs.frameset import FrameSet
from generator.safeload import printable
from generator.weather import combinations

#: Largest frame number: file names hold six digits (``NNNNNN_day_clear.exr``, KITTI's ``NNNNNN.png``,
#: Cityscapes' ``city_SSSSSS_NNNNNN``).
MAX_FRAME_INDEX = 999_999
#: Frames one run may plan (``--frames``): every six-digit frame number.
MAX_FRAMES = MAX_FRAME_INDEX + 1
#: Parallel render workers (``--workers``); the local executor also stops at the machine's cores.
MAX_WORKERS = 256


@dataclass(frozen=True)
class Plan:
    """What a dataset holds.

    Attributes
    ----------
    frames : FrameSet
        Frame indices along route 0 (``NNNNNN`` of file names), as ranges.
    combos : tuple of (str, str)
        (time_of_day, weather_kind) rendered for every frame.
    sequence : str
        SemanticKITTI sequence id of the LiDAR scans (of the first town).
    """

    frames: FrameSet
    combos: tuple[tuple[str, str], ...]
    sequence: str = "00"

    def __post_init__(self):
        if not isinstance(self.frames, FrameSet):
            object.__setattr__(self, "frames", FrameSet.of(self.frames))

    @property
    def n_images(self) -> int:
        return len(self.frames) * len(self.combos)

    def images(self) -> list[str]:
        """Every image name of the plan, frame-major (a list as long as the plan: for small plans)."""
        return [image_name(k, t, w) for k in self.frames for t, w in self.combos]

    def images_of(self, frame: int) -> list[str]:
        return [image_name(frame, t, w) for t, w in self.combos]

    def counts(self) -> Counter:
        """Images per (time_of_day, weather)."""
        return Counter({c: len(self.frames) for c in self.combos})

    def is_balanced(self) -> bool:
        return len(set(self.counts().values())) <= 1

    def to_dict(self) -> dict:
        """The manifest's ``plan``: ``frame_ranges`` (half-open ``[start, stop)``), counts, combos, sequence."""
        return {"frame_ranges": self.frames.to_json(), "frame_count": len(self.frames),
                "combos": [list(c) for c in self.combos], "sequence": self.sequence, "images": self.n_images}

    @classmethod
    def from_dict(cls, d: dict) -> Plan:
        """From :meth:`to_dict`'s form, or the frame list of manifests before version 2 (``frames``)."""
        frames = FrameSet.from_json(d["frame_ranges"]) if "frame_ranges" in d else FrameSet.of(d["frames"])
        return cls(frames, tuple(tuple(c) for c in d["combos"]), d["sequence"])


def make_plan(frames: int, first: int = 0, combos=None, sequence: str = "00") -> Plan:
    """Frames ``first .. first + frames - 1`` in ``combos`` (default: all 12 of Table II)."""
    return Plan(FrameSet.span(first, frames), tuple(combos or combinations()), sequence)


def check_plan(plan: Plan, flag: str = "--frames") -> None:
    """Refuse a plan whose frame numbers leave ``0..MAX_FRAME_INDEX`` (one line). The number of images
    is not capped: the disk estimate (:func:`check_free_space`) bounds it."""
    if not plan.frames:
        raise UserError(f"{flag}: the plan has no frames")
    if plan.frames.min() < 0 or plan.frames.max() > MAX_FRAME_INDEX:
        raise UserError(f"{flag}: frame {plan.frames.max()} planned; frame numbers must stay in 0..{MAX_FRAME_INDEX} "
                        f"(six digits in file names)")


def check_workers(workers: int, executor: str, flag: str = "--workers") -> None:
    """Local render workers are processes on this machine: at most one per core (at least 2 allowed)."""
    if not 1 <= workers <= MAX_WORKERS:
        raise UserError(f"{flag}: must be an integer in 1..{MAX_WORKERS}, got {workers}")
    cores = os.cpu_count() or 1
    if executor == "local" and workers > max(cores, 2):
        raise UserError(f"{flag}: {workers} local workers but this machine has {cores} cores; use at most "
                        f"{max(cores, 2)} (or --executor ray on a cluster)")


# -- disk the run will write ---------------------------------------------------------------------------------------

#: Bytes per pixel of one image's files, measured on the shipped presets: the multilayer EXR
#: (half RGB, one half mask per class, float depth, uint instance) compressed ~7.5 B/px with
#: zip; uncompressed it is 6 + 2 per class + 8. The preview PNG (three panels) ~1.3 B/px.
EXR_BYTES_PER_PIXEL = 8.0
PREVIEW_BYTES_PER_PIXEL = 1.5
#: Per image: metadata JSON and file-system slack.
IMAGE_OVERHEAD_BYTES = 16 * 1024
#: Per LiDAR ray that returns: .bin (16) + .label (4) + point_times (4) + native_labels (1) + scene_flow (16).
SCAN_BYTES_PER_POINT = 41
#: Per scan: bird's-eye PNG and file-system slack.
SCAN_OVERHEAD_BYTES = 96 * 1024


def image_bytes(width: int, height: int, codec: str = "zip", classes: int = 35, preview: bool = True) -> int:
    """Estimated bytes one rendered image variant writes (EXR, metadata, preview)."""
    px = int(width) * int(height)
    per_px = (6 + 2 * classes + 8) if codec == "none" else EXR_BYTES_PER_PIXEL
    return int(px * (per_px + (PREVIEW_BYTES_PER_PIXEL if preview else 0.0))) + IMAGE_OVERHEAD_BYTES


#: Per pixel of a frame's or a stereo camera's motion files: the float flow EXR (two directions, ZIP: ~5 bytes
#: measured at 640x360) and the KITTI PNGs (~1), with room to spare.
MOTION_BYTES_PER_PIXEL = 12


def motion_bytes(width: int, height: int) -> int:
    """Estimated bytes of one image's motion files (:mod:`generator.jobs.motion`): flows or disparity."""
    return int(width) * int(height) * MOTION_BYTES_PER_PIXEL


def scan_bytes(rays: int, range_image: bool = False, ply: bool = False, bev: bool = True) -> int:
    """Estimated bytes one LiDAR scan writes (every ray counted as a return: an upper bound)."""
    per_point = SCAN_BYTES_PER_POINT + (4 if range_image else 0) + (27 if ply else 0)
    return int(rays) * per_point + (SCAN_OVERHEAD_BYTES if bev else 4096)


def human(n: float) -> str:
    """``1.5 GiB``-style size."""
    for unit in ("bytes", "KiB", "MiB", "GiB", "TiB"):
        if abs(n) < 1024 or unit == "TiB":
            return f"{n:.0f} {unit}" if unit == "bytes" else f"{n:.1f} {unit}"
        n /= 1024
    return f"{n:.1f} PiB"  # pragma: no cover


def free_bytes(path: str | os.PathLike) -> tuple[Path, int] | None:
    """(nearest existing folder of ``path``, bytes free there for this user), or None if unknown."""
    p = Path(path).absolute()
    while not p.exists() and p != p.parent:
        p = p.parent
    if not p.is_dir():
        p = p.parent
    try:
        return p, shutil.disk_usage(p).free
    except OSError:
        return None


def check_free_space(path: str | os.PathLike, need: int, what: str, flag: str = "--out") -> None:
    """Refuse a run that would write more than the free space at ``path`` (one line; nothing written).

    Parameters
    ----------
    need : int
        Estimated bytes the run writes.
    what : str
        What they hold, for the message (``24 images at 1920x1080 + 2 scans``).
    """
    free = free_bytes(path)
    if free is None or need <= free[1]:
        return
    raise UserError(f"{flag}: this run writes about {human(need)} ({what}) but {printable(free[0], 200)} has "
                    f"{human(free[1])} free")
