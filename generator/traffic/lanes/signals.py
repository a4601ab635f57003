"""Signal phases at intersections: when pedestrians may cross and vehicles may enter.

Every intersection runs one fixed cycle of :data:`CYCLE_S` seconds with its own offset
(stream ``("traffic", "signal", i, j)``). During the *walk* phase (the first
:data:`WALK_S` seconds of the cycle) every crosswalk of the node is open and no vehicle
enters the node; a vehicle may only enter while the next walk phase is at least
:data:`CLEAR_S` seconds away, so it has left the crosswalks before pedestrians step out.
A pedestrian steps onto a crosswalk only while the walk phase has time left for the whole
crossing. Both rules are pure functions of (node, time), so vehicles and pedestrians never
need to see each other to stay apart on a crosswalk.

The phases belong to the node, not to its approaches: there is no green per arm, so a one-way
street that only leaves a node (no approach, no signal head there:
:func:`generator.layout.network.one_way.arriving_arms`) has no phase to remove either; vehicles only ever
wait at the stop lines of the arms the lane graph enters the node from.
"""

from __future__ import annotations

import numpy as np

from generator.rng import stream

CYCLE_S = 40.0   #: one signal cycle, seconds
WALK_S = 14.0    #: walk phase at the start of each cycle, seconds
CLEAR_S = 8.0    #: vehicles stop entering this long before a walk phase starts, seconds


class Signals:
    """The signal phases of every node of a grid.

    Parameters
    ----------
    seed : int
        The spec's seed.
    nodes : list of (int, int)
        Intersections ``(i, j)``.
    unsignalled : set of (int, int)
        Nodes without signal heads (roundabouts): vehicles may always enter, giving way to people on
        the crosswalks (:mod:`generator.traffic.lanes.roundabouts`); people still cross in the walk
        phase of the node's cycle, as at a pedestrian-called crossing.
    """

    def __init__(self, seed: int, nodes: list[tuple[int, int]], unsignalled=frozenset()):
        self.offset = {n: float(stream(seed, "traffic", "signal", n[0], n[1]).uniform(0.0, CYCLE_S)) for n in nodes}
        self.unsignalled = frozenset(unsignalled)

    def phase(self, node: tuple[int, int], t: float) -> float:
        """Seconds since the node's current cycle started, in ``[0, CYCLE_S)``."""
        return float(np.mod(t + self.offset[node], CYCLE_S))

    def walk_left(self, node: tuple[int, int], t: float) -> float:
        """Seconds of walk phase left at ``t`` (0 outside the walk phase)."""
        return max(0.0, WALK_S - self.phase(node, t))

    def vehicles_may_enter(self, node: tuple[int, int], t: float) -> bool:
        """True when a vehicle may enter the node at ``t``: no walk phase now or within ``CLEAR_S``
        (always at an unsignalled node: a roundabout, where vehicles give way instead)."""
        if node in self.unsignalled:
            return True
        p = self.phase(node, t)
        return WALK_S <= p < CYCLE_S - CLEAR_S

    def may_cross(self, node: tuple[int, int], t: float, duration_s: float) -> bool:
        """True when a pedestrian starting at ``t`` finishes a ``duration_s`` crossing inside the walk phase."""
        return self.walk_left(node, t) >= duration_s
