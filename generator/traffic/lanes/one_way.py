"""One-way streets in the lane graph: every lane of a one-way segment runs its one direction.

:class:`~generator.traffic.lanes.graph.LaneGraph` builds ``lanes`` lanes per direction on every
segment; :func:`apply_one_way` then rewrites it for the segments whose cross-section is one-way
(:attr:`generator.layout.network.cross_sections.CrossSection.one_way`):

* the lanes of the contra side turn round. Lane numbers are *signed slots*: slot ``k`` is
  centred ``(k + 0.5) * lane_w`` right of the centre line seen in the driving direction, so a
  two-way street has slots ``0 .. lanes - 1`` per direction and a one-way street
  ``-lanes .. lanes - 1`` in its direction (the negative ones left of the centre line) and none
  against it;
* connectors are rebuilt at every plain node: from each lane arriving at a node to every other arm
  that has lanes *leaving* the node (so no connector enters a one-way street against it),
  into the same slot when the exit has it (the quarter circles of
  :func:`~generator.traffic.lanes.paths.connector_path`) or else into the nearest slot it has (a lane
  of a one-way street left of the centre line merging into a two-way street: a cubic curve
  with the same end tangents);
* the conflict table gains the keys ``(arm_in, arm_out, slot_in, slot_out)`` of the merging
  connectors and the negative slots, measured as :func:`~generator.traffic.lanes.conflicts`
  does (one table still serves every node); ``graph.conflict_keys`` maps a connector's edge
  index to its key.

Roundabout nodes keep their ring connectors as :class:`~generator.traffic.lanes.graph.LaneGraph` built
them (same paths, keys ``(node, arm_in, arm_out, lane)``, linked to the rebuilt lane edges) and keep
the roundabouts' own conflict table: the layout never makes a segment ending at a roundabout one-way
(:mod:`generator.layout.network.one_way`), so every ring arm keeps its slots ``0 .. lanes - 1`` both ways.
Segments are looked up by :attr:`~generator.layout.network.grid.Segment.index` (with closed streets
``grid.segments`` is not in index order of the full numbering).

Every lane keeps a successor as long as every node has an arm leaving it, which the layout
guarantees (:mod:`generator.layout.network.one_way` keeps the open network strongly connected).
"""

from __future__ import annotations

import numpy as np

from generator.layout.network.design_vehicle import STANDARD_CAR_M
from generator.layout.network.measures import ARM_DIRS
from generator.traffic.lanes.conflicts import conflict_table
from generator.traffic.lanes.edges import Edge
from generator.traffic.lanes.paths import connector_path, merge_path, reversed_path


def one_way_of(grid) -> dict[int, int]:
    """``segment index -> +1 | -1`` for the open one-way segments of ``grid`` (empty if none)."""
    if not grid.sections:
        return {}
    return {s.index: grid.sections[s.index].one_way for s in grid.segments if grid.sections[s.index].one_way}


def apply_one_way(graph) -> bool:
    """Rewrite ``graph`` (a LaneGraph, in place) for the one-way segments of its grid, conflict table
    included; False (and nothing done) when the grid has none."""
    grid = graph.grid
    ow = one_way_of(grid)
    if not ow:
        return False
    old_edges, segs = graph.edges, {s.index: s for s in grid.segments}
    edges: list[Edge] = []
    lane_edge: dict = {}
    slots: dict = {}      # (segment, direction) -> sorted signed slots
    for (si, d, k), ei in sorted(graph.lane_edge.items(), key=lambda kv: kv[1]):
        e = old_edges[ei]
        D = ow.get(si, 0)
        if D == 0 or d == D:
            key, path, node, arms = (si, d, k), e.path, e.node, e.arms
        else:   # the contra lane k turns round: slot -1 - k of direction D
            seg = segs[si]
            key, path = (si, D, -1 - k), reversed_path(e.path, f"lane_{si}_{D}_{-1 - k}")
            node = seg.b if D > 0 else seg.a
            arms = (int(np.argmax(ARM_DIRS @ np.array([np.cos(path.headings[0]), np.sin(path.headings[0])]))), -1)
        lane_edge[key] = len(edges)
        slots.setdefault(key[:2], []).append(key[2])
        edges.append(Edge(len(edges), path, "lane", node, key[2], arms))
    slots = {k: sorted(v) for k, v in slots.items()}
    connector, ckeys = {}, {}
    rings: dict = {}      # roundabout node -> its ring connectors, kept as built
    for key, ei in graph.connector.items():
        if grid.is_roundabout(key[0]):
            rings.setdefault(key[0], []).append((key, ei))
    for node in grid.nodes:
        if grid.is_roundabout(node):
            _keep_ring(graph, node, rings.get(node, []), edges, lane_edge, connector)
            continue
        c0 = grid.node_xy(node)
        arms = grid.arms(node)
        for x in arms:
            seg_in, d_in = graph._segment_of(node, x)
            s_in = slots.get((seg_in.index, -d_in), [])
            for y in arms:
                if y == x:
                    continue
                seg_out, d_out = graph._segment_of(node, y)
                s_out = slots.get((seg_out.index, d_out), [])
                if not s_out:
                    continue      # the arm is one-way towards this node: nothing may enter it
                left = x != (y + 2) % 4 and (y - x) % 4 == 3      # arm y is left of the arriving traffic
                for k in s_in:
                    for n, ko in enumerate(exit_slots(k, s_in, s_out, left)):
                        name = f"conn_{node[0]}_{node[1]}_{x}{y}_{k}" + (f"_{ko}" if n else "")
                        path = connector_path(c0, graph.entry_m, grid.lane_w, x, y, k, name) if ko == k else \
                            merge_path(c0, graph.entry_m, grid.lane_w, x, y, k, ko, name)
                        ci = len(edges)
                        edges.append(Edge(ci, path, "connector", node, ko, (x, y)))
                        connector[(node, x, y, k) if n == 0 else (node, x, y, k, ko)] = ci
                        ckeys[ci] = (x, y, k) if ko == k else (x, y, k, ko)
                        edges[lane_edge[(seg_in.index, -d_in, k)]].succ.append(ci)
                        edges[ci].succ.append(lane_edge[(seg_out.index, d_out, ko)])
    graph.edges, graph.lane_edge, graph.connector, graph.conflict_keys = edges, lane_edge, connector, ckeys
    graph.conflict = conflict_table(graph.entry_m, graph.stop_m, grid.lane_w, frozenset(ckeys.values()), STANDARD_CAR_M)
    return True


def _keep_ring(graph, node, ring: list, edges: list, lane_edge: dict, connector: dict) -> None:
    """Copy the ring connectors ``ring`` (``[(key, old edge index)]``) of roundabout ``node`` into the
    rebuilt ``edges`` and link them to the rebuilt lane edges (in place).

    Raises
    ------
    ValueError
        An arm of ``node`` is one-way (the layout never draws one: see :mod:`generator.layout.network.one_way`).
    """
    for (_, x, y, k), old in ring:
        seg_in, d_in = graph._segment_of(node, x)
        seg_out, d_out = graph._segment_of(node, y)
        k_in, k_out = (seg_in.index, -d_in, k), (seg_out.index, d_out, k)
        if k_in not in lane_edge or k_out not in lane_edge:
            raise ValueError(f"roundabout {node}: arm {x if k_in not in lane_edge else y} is one-way")
        ci = len(edges)
        edges.append(Edge(ci, graph.edges[old].path, "connector", node, k, (x, y)))
        connector[(node, x, y, k)] = ci
        edges[lane_edge[k_in]].succ.append(ci)
        edges[ci].succ.append(lane_edge[k_out])


def exit_slots(k: int, s_in: list[int], s_out: list[int], left: bool) -> list[int]:
    """The slots of the exit lanes that slot ``k`` arriving at a node continues into (first: the one
    the routes use, the same slot where the exit has it).

    * same slot where the exit has it; a two-way street's lane entering a one-way street also
      continues into the mirrored slot ``-1 - k`` left of the centre line, so the one-way street's
      left lanes carry traffic too;
    * a one-way street's left lane (``k < 0``) entering a two-way street: the mirrored slot
      ``-1 - k`` on a left turn (the turn stays inside the one of the lanes to its right), else the
      nearest slot the exit has (it merges).
    """
    if k in s_out:
        return [k, -1 - k] if s_in[0] >= 0 and s_out[0] < 0 else [k]
    if left and -1 - k in s_out:
        return [-1 - k]
    return [int(min(max(k, s_out[0]), s_out[-1]))]
