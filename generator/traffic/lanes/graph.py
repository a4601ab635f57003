"""The lane graph vehicles drive: lane edges between intersections and connectors through them.

Every street segment carries ``lanes`` lanes per direction (right-hand traffic, lane ``k``
centred ``(k + 0.5) * lane_w`` right of the centre line). A *lane edge* runs from the exit
point of one intersection to the entry point of the next; a *connector* runs through an
intersection from an incoming lane to the same lane number of another arm: straight across,
or a quarter circle. Entry and exit points sit :attr:`LaneGraph.entry_m` from the node
centre; the turning arcs are those of the ego's route (:mod:`generator.layout.network.routes`: a
right turn of the outer lane has radius ``r``, its left turn ``r + 2 off``, concentric), so
route 0 is a walk on this graph.

Vehicles stop with their front at the stop line (:attr:`LaneGraph.stop_m` from the node
centre) until they may enter. Two connectors *conflict* when a standard car on one (from the
stop line to past the far crosswalk) can touch a standard car on the other
(:mod:`generator.traffic.lanes.conflicts`); one table serves every node, as every node has the
same cross-section. At a roundabout node (:mod:`generator.layout.network.roundabouts`) the
connectors run round the island instead, and the roundabouts share a second table
(:mod:`generator.traffic.lanes.roundabouts`); one-way streets rewrite the graph
(:mod:`generator.traffic.lanes.one_way`).
"""

from __future__ import annotations

import numpy as np

from generator.layout.network.design_vehicle import STANDARD_CAR_M
from generator.layout.network.grid import Grid
from generator.layout.network.measures import ARM_DIRS, STOP_U
from generator.layout.network.rings import entry_distance, ring_path
from generator.traffic.lanes.conflicts import conflicts
from generator.traffic.lanes.edges import Edge
from generator.traffic.lanes.one_way import apply_one_way
from generator.traffic.lanes.paths import connector_path, line
from generator.traffic.lanes.roundabouts import ring_conflicts
from generator.world.scene import Path


class LaneGraph:
    """Lane edges and connectors of a :class:`~generator.layout.network.grid.Grid`.

    Attributes
    ----------
    edges : list of Edge
    lane_edge : dict
        ``(segment index, direction, lane) -> edge index`` (direction +1 towards +u).
    connector : dict
        ``(node, arm_in, arm_out, lane) -> edge index``.
    entry_m, stop_m : float
        Distance from a node centre to the connectors' ends and to the stop line, metres.
    conflict : dict
        ``(arm_in, arm_out, lane) -> set of (arm_in, arm_out, lane)`` it conflicts with.
    memo : dict
        Answers about the graph's fixed geometry that the traffic simulation asks every step (turn
        radii, approach arms, lanes blocked by a scene for a width), computed once each.
    """

    def __init__(self, grid: Grid):
        self.grid = grid
        self.memo: dict = {}
        self.entry_m = entry_distance(grid.lanes, grid.lane_w, grid.road_half)
        self.stop_m = grid.road_half + STOP_U[1]
        self.edges: list[Edge] = []
        self.lane_edge: dict = {}
        self.connector: dict = {}
        for seg in grid.segments:
            a, b = grid.node_xy(seg.a), grid.node_xy(seg.b)
            u = (b - a) / np.linalg.norm(b - a)
            for d in (1, -1):
                start, end, e = (a, b, u) if d > 0 else (b, a, -u)
                right = np.array([e[1], -e[0]])
                for k in range(grid.lanes):
                    o = (k + 0.5) * grid.lane_w
                    p = line(start + self.entry_m * e + o * right, end - self.entry_m * e + o * right,
                             f"lane_{seg.index}_{d}_{k}")
                    arm_out = int(np.argmax(ARM_DIRS @ e))
                    node = seg.b if d > 0 else seg.a
                    self.lane_edge[(seg.index, d, k)] = self._add(p, "lane", node, k, (arm_out, -1))
        for node in grid.nodes:
            arms = grid.arms(node)
            for x in arms:
                for y in arms:
                    if y != x:
                        for k in range(grid.lanes):
                            path = self._connector_path(node, x, y, k)
                            self.connector[(node, x, y, k)] = self._add(path, "connector", node, k, (x, y))
        self._link()
        if not apply_one_way(self):     # one-way streets turn lanes round (and build the conflict table)
            self.conflict = conflicts(self, STANDARD_CAR_M)
        self.ring_conflict: dict = {}
        if grid.roundabouts:
            self.ring_conflict = ring_conflicts(self, STANDARD_CAR_M)

    def _add(self, path: Path, kind: str, node, lane: int, arms) -> int:
        self.edges.append(Edge(len(self.edges), path, kind, node, lane, arms))
        return len(self.edges) - 1

    def _connector_path(self, node, x: int, y: int, k: int) -> Path:
        if self.grid.is_roundabout(node):
            return ring_path(self.grid.ring, self.grid.node_xy(node), x, y, k, f"ring_{node[0]}_{node[1]}_{x}{y}_{k}")
        return connector_path(self.grid.node_xy(node), self.entry_m, self.grid.lane_w, x, y, k,
                              f"conn_{node[0]}_{node[1]}_{x}{y}_{k}")

    def _link(self) -> None:
        for (node, x, y, k), ci in self.connector.items():
            # the lane arriving at ``node`` from arm x, and the lane leaving by arm y
            self.lane_in(node, x, k).succ.append(ci)
            self.edges[ci].succ.append(self.lane_out(node, y, k).index)

    def _segment_of(self, node, arm: int):
        nb = (node[0] + int(ARM_DIRS[arm][0]), node[1] + int(ARM_DIRS[arm][1]))
        return self.grid.segment_between(node, nb)

    def lane_in(self, node, arm: int, k: int) -> Edge:
        """The lane of number ``k`` arriving at ``node`` from arm ``arm``."""
        seg, d = self._segment_of(node, arm)
        return self.edges[self.lane_edge[(seg.index, -d, k)]]

    def lane_out(self, node, arm: int, k: int) -> Edge:
        """The lane of number ``k`` leaving ``node`` by arm ``arm``."""
        seg, d = self._segment_of(node, arm)
        return self.edges[self.lane_edge[(seg.index, d, k)]]

    def lanes(self) -> list[Edge]:
        return [e for e in self.edges if e.kind == "lane"]

    def conflicts_at(self, node) -> dict:
        """The conflict table of ``node``: :attr:`conflict`, or the roundabouts' own."""
        return self.ring_conflict if self.grid.is_roundabout(node) else self.conflict

    def turn_radius(self, edge: Edge) -> float | None:
        """Tightest radius of a connector's arcs, metres (None: a straight connector or a lane)."""
        key = ("turn_radius", edge.index)
        if key not in self.memo:
            self.memo[key] = self._turn_radius(edge)
        return self.memo[key]

    def _turn_radius(self, edge: Edge) -> float | None:
        if edge.kind != "connector":
            return None
        if self.grid.is_roundabout(edge.node):
            return min(self.grid.ring.fillet_r, self.grid.ring.ring_r[edge.lane])
        if edge.arms[0] == (edge.arms[1] + 2) % 4:
            return None
        return edge.length / (np.pi / 2)

    @property
    def stop_s_from_end(self) -> float:
        """Distance from a lane edge's end back to its stop line, metres."""
        return self.stop_m - self.entry_m
