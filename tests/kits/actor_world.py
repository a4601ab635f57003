"""The test town with a few hand-built car actors on straight tracks in front of the ego (no Blender
needed to build it; the actor render tests draw it)."""

from __future__ import annotations

import numpy as np

from generator.world.actors import Actor, Track, World
from generator.world.rig import Rig

FRAME = 2
RES = (96, 54)
DT = 0.05
#: (metres ahead of the ego at the image time, metres to its left, direction ("fwd" | "left"), speed m/s)
CARS = [(14.0, 1.8, "fwd", 8.0), (7.0, -3.0, "left", 10.0)]
#: A second image time: the crossing car has moved 2 m to the left, the ego 1.6 m on.
LATER = 0.2


def car_world(spec, scene, rig: Rig, t: float, cars=CARS) -> World:
    """``scene`` plus car actors on straight tracks, placed relative to the ego at time ``t``."""
    from generator.geometry.proxy import label_proxy
    from generator.layout.placement.prototypes import Library

    T = rig.T_world_ego(t)[0]
    axes = {"fwd": T[:3, 0], "left": T[:3, 1]}
    lib = Library(spec.seed)
    first = 1 + max(o.instance_id for o in scene.objects)
    actors, protos, proxies = [], {}, {}
    ts = np.arange(0.0, 20.0, DT)
    for i, (ahead, side, direction, speed) in enumerate(cars):
        p = lib.variant("car", i)
        protos[p.key] = p.mesh
        hull = label_proxy(p.mesh)
        if hull is not None:
            proxies[p.key] = hull
        d = axes[direction]
        xyz = (T[:3, 3] + ahead * T[:3, 0] + side * T[:3, 1])[None] + (ts - t)[:, None] * speed * d[None]
        xyz[:, 2] = 0.0
        track = Track(0.0, DT, xyz, np.full(len(ts), np.arctan2(d[1], d[0])))
        actors.append(Actor(i, f"actor_car_{i:04d}", "car", "car", first + i, p.key, tuple(p.hi - p.lo),
                            tuple((p.hi + p.lo) / 2), track, p.key if p.key in proxies else None,
                            {"color": (0.7, 0.1, 0.1)}))
    return World(scene, actors, protos, proxies, rig.trajectory, float(ts[-1]))
