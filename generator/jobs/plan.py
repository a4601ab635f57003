"""A dataset plan: frames x weather x time of day, balanced like seed 003 Table II.

Every frame is rendered in every planned combination (masks and depth are shared by a
frame's variants), so each (time of day, weather) pair gets exactly one image per frame:
equal counts by construction. Every frame also gets one LiDAR scan in sequence ``NN``.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import asdict, dataclass

from generator.jobs.images import image_name
from generator.weather import combinations


@dataclass(frozen=True)
class Plan:
    """What a dataset holds.

    Attributes
    ----------
    frames : tuple of int
        Frame indices along route 0 (``NNNNNN`` of file names).
    combos : tuple of (str, str)
        (time_of_day, weather_kind) rendered for every frame.
    sequence : str
        Two-digit SemanticKITTI sequence id of the LiDAR scans.
    """

    frames: tuple[int, ...]
    combos: tuple[tuple[str, str], ...]
    sequence: str = "00"

    def images(self) -> list[str]:
        """Every image name of the plan, frame-major."""
        return [image_name(k, t, w) for k in self.frames for t, w in self.combos]

    def images_of(self, frame: int) -> list[str]:
        return [image_name(frame, t, w) for t, w in self.combos]

    def counts(self) -> Counter:
        """Images per (time_of_day, weather)."""
        return Counter((t, w) for _ in self.frames for t, w in self.combos)

    def is_balanced(self) -> bool:
        return len(set(self.counts().values())) <= 1

    def to_dict(self) -> dict:
        d = asdict(self)
        d["frames"] = list(self.frames)
        d["combos"] = [list(c) for c in self.combos]
        d["images"] = len(self.frames) * len(self.combos)
        return d

    @classmethod
    def from_dict(cls, d: dict) -> "Plan":
        return cls(tuple(d["frames"]), tuple(tuple(c) for c in d["combos"]), d["sequence"])


def make_plan(frames: int, first: int = 0, combos=None, sequence: str = "00") -> Plan:
    """Frames ``first .. first + frames - 1`` in ``combos`` (default: all 12 of Table II)."""
    return Plan(tuple(range(first, first + frames)), tuple(combos or combinations()), sequence)
