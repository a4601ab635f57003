"""A walking person actor (a library person variant with its gait cycle) on a given track."""

from __future__ import annotations

import numpy as np

from generator.world.actors import Actor, Gait, Track


def walker(prototypes: dict, track: Track, uid: int = 0, instance_id: int = 1000, seed: int = 0, variant: int = 0,
           height: float = 1.75) -> Actor:
    """A walking actor of person variant ``variant`` of ``Library(seed)``; its rest and phase meshes are
    added to ``prototypes`` (keys ``walker_v<i>`` and ``walker_v<i>@gNN``), as the traffic does."""
    from generator.layout.placement.prototypes import Library
    from generator.traffic.pedestrians.gait import gait_cycle

    proto = Library(seed).variant("person", variant, lambda g: {"height": height, "pose": "walking"})
    key = f"walker_v{variant}"
    prototypes[key] = proto.mesh
    keys, stride, lo, hi = gait_cycle(key, proto.mesh, prototypes)
    gait = Gait(keys, stride, Gait.walked(track), lo, hi)
    blo, bhi = lo.min(0), hi.max(0)
    return Actor(uid, f"actor_person_{uid:04d}", "person", "person", instance_id, key, tuple(bhi - blo),
                 tuple((blo + bhi) / 2), track, None, {"role": "walking"}, gait)


def straight(p0, velocity, seconds: float = 4.0, dt: float = 0.05) -> Track:
    """A track from ``p0`` at constant ``velocity`` (2,) m/s, heading along it (x forward if it is 0)."""
    t = np.arange(round(seconds / dt) + 1) * dt
    v = np.array([*velocity, 0.0])
    yaw = float(np.arctan2(v[1], v[0])) if np.any(v) else 0.0
    return Track(0.0, dt, np.asarray(p0, float) + t[:, None] * v, np.full(len(t), yaw))
