"""The drive a ``generate`` run is taken from: its world in time, image times and sweep count.

Image frame ``k`` is exposed where the ego has driven ``k * paths.spacing_m`` metres, at the
start of the 10 Hz sweep nearest to that instant (:meth:`generator.world.rig.Rig.frame`);
the LiDAR sequence holds every sweep from t = 0 to the last image's, so the scans are the
whole drive and image ``k`` pairs with sweep ``j`` (``lidar_meta.json`` ``image_frames``).
Every process that needs the drive builds it with :func:`plan_drive` from the same frames:
the simulation is causal and seeded by name, so they all get the same world.
"""

from __future__ import annotations

from dataclasses import dataclass

from generator.world.rig import SWEEP_PERIOD_S, Rig

#: The world is simulated a little past the last image (the last sweep and central differences).
MARGIN_M = 5.0


@dataclass
class Drive:
    """What :func:`plan_drive` found.

    Attributes
    ----------
    world : generator.world.actors.World
    rig : Rig
        Riding the world's ego.
    image_frames : list of (int, int)
        ``(image frame k, sweep j)``, sorted by k.
    sweeps : int
        Sweeps of the LiDAR sequence (0 .. sweeps-1).
    """

    world: object
    rig: Rig
    image_frames: list
    sweeps: int


def plan_drive(spec, scene, frames, first: int = 0) -> Drive:
    """The drive covering image frames ``frames`` (frame numbers) of ``spec``'s route 0.

    ``first``: the frame number at the drive's start (a re-drawn town's first frame,
    :mod:`generator.jobs.towns`); frame ``k`` is driven ``(k - first) * spacing_m`` metres.
    """
    from generator.jobs.towns import local_frame
    from generator.traffic.build import build_world

    last = max(frames) - first if len(frames) else 0
    world = build_world(spec, scene, 0.0, last * spec.paths.spacing_m + MARGIN_M)
    rig = Rig.from_world(spec, world)
    pairs = [(int(k), Rig.sweep_of(local_frame(rig, int(k), first))) for k in sorted(frames)]
    sweeps = max(j for _, j in pairs) + 1 if pairs else 1
    if world.duration_s < sweeps * SWEEP_PERIOD_S + 0.2:  # a stop near the end: simulate on
        world = build_world(spec, scene, sweeps * SWEEP_PERIOD_S + 0.2, last * spec.paths.spacing_m + MARGIN_M)
        rig = Rig.from_world(spec, world)
    return Drive(world, rig, pairs, sweeps)
