"""One directed edge of the lane graph: a lane between two nodes, or a connector through one."""

from __future__ import annotations

from dataclasses import dataclass, field

from generator.world.scene import Path


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
