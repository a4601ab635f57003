"""The towns of a ``generate`` run: which frames each shows, its spec and its LiDAR sequence.

With ``town.redraw_every_frames`` null a run is one town (the spec as read, sequence
``--sequence``): :func:`town_runs` returns that one entry and nothing changes. With ``N`` set,
the plan's frames are split by ``k // N`` (:mod:`generator.spec.towns`): town ``i`` is drawn
from its own seed, drives from its own t = 0 (frame ``k`` is local frame ``k - i*N`` of its
route) and is LiDAR sequence ``base + i``, so a sequence never spans two towns.

Sequence numbers go past 99 when there are more towns: folder ``100``, ``101`` ... as
semantic-kitti-api names them (:data:`generator.formats.semantickitti.MAX_SEQUENCE`).

:class:`TownPlan` gives the towns lazily (a million-frame plan of one-frame towns is a million
towns: none is held before it is needed); :func:`town_runs` lists them for small plans.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from dataclasses import dataclass

from generator.errors import UserError
from generator.formats.semantickitti import MAX_SEQUENCE
from generator.jobs.frameset import FrameSet
from generator.jobs.plan import Plan
from generator.spec.towns import first_frame, redraw_every, town_spec


@dataclass(frozen=True)
class TownRun:
    """One town of a run.

    Attributes
    ----------
    index : int or None
        Town number (None: the spec's one town, option off).
    spec : generator.spec.SceneSpec
        The town's spec (:func:`generator.spec.towns.town_spec`).
    plan : Plan
        The town's frames (global frame numbers) and its sequence ``NN``.
    first : int
        Frame number of the start of the town's drive (local frame = ``k - first``).
    """

    index: int | None
    spec: object
    plan: Plan
    first: int

    @property
    def local_frames(self) -> list[int]:
        return [k - self.first for k in self.plan.frames]


class TownPlan:
    """The towns of ``plan`` (lazily), checked against the sequence numbers the format allows.

    Parameters
    ----------
    spec : generator.spec.SceneSpec
        The spec as read.
    plan : Plan

    Raises
    ------
    UserError
        One line when the last town's sequence would pass :data:`MAX_SEQUENCE`.
    """

    def __init__(self, spec, plan: Plan, flag: str = "--frames"):
        self.spec, self.plan = spec, plan
        self.every = redraw_every(spec)
        self.base = int(plan.sequence)
        if self.every is None:
            self.indices: list[int | None] = [None]
        else:
            self.indices = sorted({i for a, b in plan.frames.ranges for i in range(a // self.every,
                                                                                     (b - 1) // self.every + 1)})
        last = self.base + (self.indices[-1] or 0)
        if last > MAX_SEQUENCE:
            raise UserError(f"{flag}: frames up to {plan.frames.max()} with town.redraw_every_frames = "
                            f"{self.every} make towns up to {self.indices[-1]}, LiDAR sequences {plan.sequence}.."
                            f"{last}; sequence numbers stop at {MAX_SEQUENCE} (fewer frames, a larger "
                            f"redraw_every_frames or a lower --sequence)")

    def __len__(self) -> int:
        return len(self.indices)

    def sequence(self, index: int | None) -> str:
        return f"{self.base + (index or 0):02d}"

    def frames(self, index: int | None) -> FrameSet:
        if index is None:
            return self.plan.frames
        return self.plan.frames.intersection(index * self.every, (index + 1) * self.every)

    def run(self, index: int | None) -> TownRun:
        """Town ``index`` with its spec (made now) and plan."""
        plan = dataclasses.replace(self.plan, frames=self.frames(index), sequence=self.sequence(index))
        return TownRun(index, town_spec(self.spec, index), plan, first_frame(self.spec, index))

    def __iter__(self) -> Iterator[TownRun]:
        return (self.run(i) for i in self.indices)


def town_runs(spec, plan: Plan, flag: str = "--frames") -> list[TownRun]:
    """Every town of ``plan`` in order (a list: for plans of a few towns; see :class:`TownPlan`)."""
    return list(TownPlan(spec, plan, flag))


def local_frame(rig, k: int, first: int = 0):
    """The rig's frame of image frame ``k`` of a town whose drive starts at frame ``first``: driven
    ``(k - first) * spacing`` metres, numbered ``k`` (file names stay unique across towns)."""
    f = rig.frame(int(k) - int(first))
    if first == 0:
        return f
    jit = rig.camera_jitter(int(k))  # drawn by frame number, as the OpenLABEL boxes read it back
    return dataclasses.replace(f, index=int(k), camera_jitter=jit, T_ego_camera=rig.T_ego_camera(jit))
