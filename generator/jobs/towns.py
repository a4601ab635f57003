"""The towns of a ``generate`` run: which frames each shows, its spec and its LiDAR sequence.

With ``town.redraw_every_frames`` null a run is one town (the spec as read, sequence
``--sequence``): :func:`town_runs` returns that one entry and nothing changes. With ``N`` set,
the plan's frames are split by ``k // N`` (:mod:`generator.spec.towns`): town ``i`` is drawn
from its own seed, drives from its own t = 0 (frame ``k`` is local frame ``k - i*N`` of its
route) and is LiDAR sequence ``base + i``, so a sequence never spans two towns.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from generator.errors import UserError
from generator.jobs.plan import Plan
from generator.spec.towns import first_frame, frames_by_town, redraw_every, town_spec

#: SemanticKITTI sequence folders are two digits.
MAX_SEQUENCE = 99


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
        The town's frames (global frame numbers, sorted) and its sequence ``NN``.
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


def town_runs(spec, plan: Plan, flag: str = "--frames") -> list[TownRun]:
    """The towns of ``plan`` in order; a plan whose towns need sequences beyond 99 is one-line refused."""
    if redraw_every(spec) is None:
        return [TownRun(None, spec, plan, 0)]
    groups = frames_by_town(spec, plan.frames)
    base = int(plan.sequence)
    last = base + max(groups)
    if last > MAX_SEQUENCE:
        raise UserError(f"{flag}: frames up to {max(plan.frames)} with town.redraw_every_frames = "
                        f"{redraw_every(spec)} make towns up to {max(groups)}, LiDAR sequences {plan.sequence}.."
                        f"{last}; sequence folders stop at {MAX_SEQUENCE} (fewer frames, a larger "
                        f"redraw_every_frames or a lower --sequence)")
    return [TownRun(i, town_spec(spec, i), dataclasses.replace(plan, frames=tuple(ks), sequence=f"{base + i:02d}"),
                    first_frame(spec, i)) for i, ks in groups.items()]


def local_frame(rig, k: int, first: int = 0):
    """The rig's frame of image frame ``k`` of a town whose drive starts at frame ``first``: driven
    ``(k - first) * spacing`` metres, numbered ``k`` (file names stay unique across towns)."""
    f = rig.frame(int(k) - int(first))
    if first == 0:
        return f
    jit = rig.camera_jitter(int(k))  # drawn by frame number, as the OpenLABEL boxes read it back
    return dataclasses.replace(f, index=int(k), camera_jitter=jit, T_ego_camera=rig.T_ego_camera(jit))
