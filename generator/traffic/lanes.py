"""The lane graph vehicles drive: lane edges between intersections and connectors through them.

Every street segment carries ``lanes`` lanes per direction (right-hand traffic, lane ``k``
centred ``(k + 0.5) * lane_w`` right of the centre line). A *lane edge* runs from the exit
point of one intersection to the entry point of the next; a *connector* runs through an
intersection from an incoming lane to the same lane number of another arm: straight across,
or a quarter circle. Entry and exit points sit :attr:`LaneGraph.entry_m` from the node
centre; the turning arcs are those of the ego's route (:mod:`generator.layout.routes`: a
right turn of the outer lane has radius ``r``, its left turn ``r + 2 off``, concentric), so
route 0 is a walk on this graph.

Vehicles stop with their front at the stop line (:attr:`LaneGraph.stop_m` from the node
centre) until they may enter. Two connectors *conflict* when a standard car on one (from the
stop line to past the far crosswalk) can touch a standard car on the other
(:func:`conflicts`); one table serves every node, as every node has the same cross-section.
At a roundabout node (:mod:`generator.layout.roundabouts`) the connectors run round the island
instead, and the roundabouts share a second table (:mod:`generator.traffic.roundabout_lanes`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from generator.layout.network.rings import ring_path
from generator.layout.network.design_vehicle import MIN_RADIUS_M, RIGHT_RADIUS_M
from generator.layout.network.measures import STOP_U
from generator.layout.network.grid import Grid
from generator.world.scene import Path

ARM_DIRS = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])  #: east, north, west, south
STEP_M = 0.25
CAR_BOX_M = (4.8, 2.1)    #: the standard vehicle of the conflict table (length, width)
CONFLICT_PAD_M = 0.3


@dataclass
class Edge:
    """A directed lane edge or connector.

    Attributes
    ----------
    index : int
    path : Path
        Centre line (open polyline, world frame).
    kind : {"lane", "connector"}
    node : tuple of int or None
        The intersection a connector crosses; for a lane, the node it arrives at.
    lane : int
        Lane number (0 next to the centre line).
    arms : (int, int)
        Connector: (arm it comes from, arm it leaves by); lane: (arm it leaves its start node by, -1).
    succ : list of int
        Edges that may follow.
    """

    index: int
    path: Path
    kind: str
    node: tuple[int, int] | None
    lane: int
    arms: tuple[int, int]
    succ: list[int] = field(default_factory=list)

    @property
    def length(self) -> float:
        return float(self.path.s[-1])


def _line(p0: np.ndarray, p1: np.ndarray, name: str) -> Path:
    n = max(1, int(np.ceil(np.linalg.norm(p1 - p0) / STEP_M)))
    pts = p0 + (p1 - p0) * (np.arange(n + 1)[:, None] / n)
    hd = np.full(n + 1, np.arctan2(*(p1 - p0)[::-1]))
    s = np.linspace(0.0, float(np.linalg.norm(p1 - p0)), n + 1)
    return Path(name, np.c_[pts, np.zeros(n + 1)], hd, s)


def _arc(centre: np.ndarray, r: float, h0: float, sign: float, name: str) -> Path:
    n = max(2, int(np.ceil(r * np.pi / 2 / STEP_M)))
    ang = h0 + sign * np.pi / 2 * np.arange(n + 1) / n
    radial = ang - sign * np.pi / 2
    pts = centre + r * np.stack([np.cos(radial), np.sin(radial)], 1)
    return Path(name, np.c_[pts, np.zeros(n + 1)], ang, np.linspace(0.0, r * np.pi / 2, n + 1))


class LaneGraph:
    """Lane edges and connectors of a :class:`~generator.layout.streets.Grid`.

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
    """

    def __init__(self, grid: Grid):
        self.grid = grid
        off = (grid.lanes - 0.5) * grid.lane_w
        r_right = max(MIN_RADIUS_M, min(RIGHT_RADIUS_M, (grid.road_half - 0.3 - off) / (1 - np.sqrt(0.5))))
        self.entry_m = r_right + off
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
                    p = _line(start + self.entry_m * e + o * right, end - self.entry_m * e + o * right, f"lane_{seg.index}_{d}_{k}")
                    arm_out = int(np.argmax(ARM_DIRS @ e))
                    node = seg.b if d > 0 else seg.a
                    self.lane_edge[(seg.index, d, k)] = self._add(p, "lane", node, k, (arm_out, -1))
        for node in grid.nodes:
            arms = grid.arms(node)
            for x in arms:
                for y in arms:
                    if y != x:
                        for k in range(grid.lanes):
                            self.connector[(node, x, y, k)] = self._add(self._connector_path(node, x, y, k), "connector",
                                                                        node, k, (x, y))
        self._link()
        from generator.traffic.one_way import apply_one_way   # hook: one-way streets turn lanes round
        if not apply_one_way(self):
            self.conflict = conflicts(self, CAR_BOX_M)
        self.ring_conflict: dict = {}
        if grid.roundabouts:
            from generator.traffic.roundabout_lanes import ring_conflicts   # it reuses this module's boxes

            self.ring_conflict = ring_conflicts(self, CAR_BOX_M)

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


def connector_path(c0: np.ndarray, entry_m: float, lane_w: float, x: int, y: int, k: int, name: str = "") -> Path:
    """The connector of lane ``k`` from arm ``x`` to arm ``y`` of a node centred at ``c0`` ((2,) world xy):
    a straight line across, or the route's quarter circle (radius ``entry - o`` right, ``entry + o`` left)."""
    a, b = -ARM_DIRS[x], ARM_DIRS[y]
    right_a, right_b = np.array([a[1], -a[0]]), np.array([b[1], -b[0]])
    o = (k + 0.5) * lane_w
    t_in, t_out = c0 - entry_m * a + o * right_a, c0 + entry_m * b + o * right_b
    sign = float(np.sign(a[0] * b[1] - a[1] * b[0]))
    if sign == 0:
        return _line(t_in, t_out, name)
    r = entry_m - o if sign < 0 else entry_m + o
    centre = t_in + r * sign * np.array([-a[1], a[0]])
    return _arc(centre, r, float(np.arctan2(a[1], a[0])), sign, name)


def conflicts(graph: LaneGraph, size) -> dict:
    """Which connector kinds ``(arm_in, arm_out, lane)`` conflict, measured at a four-arm node.

    The table is the same for every node: every node has the same cross-section and entry
    distance, and a node with fewer arms simply lacks some connectors. It is
    :func:`generator.traffic.one_way.conflict_table` on the keys of a two-way node (one
    implementation for both; cached per cross-section).
    """
    from generator.traffic.one_way import conflict_table    # it builds on this module's paths and boxes

    lanes = graph.grid.lanes
    keys = frozenset((x, y, k) for x in range(4) for y in range(4) if x != y for k in range(lanes))
    table = conflict_table(graph.entry_m, graph.stop_m, graph.grid.lane_w, keys, tuple(size))
    return {k: set(v) for k, v in table.items()}
