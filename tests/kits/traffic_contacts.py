"""Contact checks shared by the traffic tests: the ego's box, actor-actor / actor-ego /
actor-static overlaps and vehicle-person overlaps at one instant (world frame, metres)."""

from __future__ import annotations

import numpy as np

from generator.geometry.boxes import quads_overlap
from generator.world.scene import OrientedBox

EGO_SIZE_M = (4.6, 1.9, 1.5)


def ego_box(world, t: float) -> OrientedBox:
    """The ego vehicle's box at time ``t`` (s)."""
    E = world.ego.T_world_ego(t)[0]
    return OrientedBox((E[0, 3], E[1, 3], 0.7), EGO_SIZE_M, float(np.arctan2(E[1, 0], E[0, 0])))


def static_quads(scene) -> np.ndarray:
    """(n, 4, 2) footprints of the placed things (instance id > 0) of ``scene``."""
    return np.stack([o.box.corners_xy() for o in scene.objects if o.instance_id > 0])


def assert_no_contact(world, t: float, parked: np.ndarray | None = None, ego: bool = True) -> np.ndarray:
    """No two actors overlap at ``t``, none touches the ego (unless ``ego`` is False), and none a
    ``parked`` footprint. Returns the (n, 4, 2) actor footprints at ``t``."""
    q = np.stack([b.corners_xy() for b in world.boxes(t)])
    ov = quads_overlap(q, q)
    np.fill_diagonal(ov, False)
    assert not ov.any(), f"actors {np.argwhere(ov)[0]} overlap at t={t:.1f}"
    if ego:
        assert not quads_overlap(ego_box(world, t).corners_xy()[None], q).any(), f"an actor touches the ego at t={t:.1f}"
    if parked is not None:
        assert not quads_overlap(q, parked).any(), f"an actor touches a static object at t={t:.1f}"
    return q


def assert_vehicles_miss_people(world, t: float, vehicles: list, people: list) -> None:
    """No vehicle (nor the ego) touches a person at ``t``."""
    p = np.stack([a.box(t).corners_xy() for a in people])
    hit = quads_overlap(np.stack([a.box(t).corners_xy() for a in vehicles] + [ego_box(world, t).corners_xy()]), p)
    assert not hit.any(), (t, np.argwhere(hit)[:3])
