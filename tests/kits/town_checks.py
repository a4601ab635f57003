"""Invariants of a built town, shared by the layout, street-variety and traffic tests.

Each ``check_*`` / ``no_*`` / ``rests_*`` function asserts a property of a scene or a lane graph
(world frame, metres); the others are small geometric helpers those checks and the tests use.
"""

from __future__ import annotations

import numpy as np
import pytest

from generator.geometry import apply
from generator.geometry.boxes import boxes_overlap
from generator.layout.network.draw import make_grid
from generator.layout.network.grid import segment_frame_points
from generator.layout.network.one_way import strongly_connected

#: kinds of the ground pieces (never "placed things")
GROUND_KINDS = ("street", "sidewalk", "intersection", "corner", "lot_ground", "terrain", "horizon")
#: classes that sit on a two-wheeler rather than stand on the ground
RIDERS = ("bicyclist", "motorcyclist")
#: what may stand on a driving lane
ON_LANES = ("car", "truck", "bus", "on_rails", "other_vehicle", "ridden_bicycle", "ridden_motorcycle",
            "bicyclist", "motorcyclist", "road")


def no_collisions(scene) -> None:
    """Below 1 m no two placed objects overlap (a rider and the two-wheeler under it excepted),
    as test_assemble's check for the default town."""
    boxes, names, riding = [], [], []
    for o in scene.objects:
        if o.kind in GROUND_KINDS or o.kind == "tram_rails":     # a tram stands on its rails
            continue
        m = scene.prototypes[o.prototype]
        tri = m.vertices[m.faces]
        low = tri[tri[:, :, 2].min(1) < 1.0].reshape(-1, 3)
        if not len(low):
            continue
        lo, hi = low.min(0), low.max(0)
        c = apply(o.transform, ((lo + hi) / 2)[None])[0]
        boxes.append([c[0], c[1], (hi[0] - lo[0]) / 2, (hi[1] - lo[1]) / 2, o.box.yaw, 0.0, 1.0])
        names.append(o.name)
        riding.append(scene.objects[o.index - 1].name if o.cls in RIDERS else "")
    b = np.array(boxes)
    hit = boxes_overlap(b, b)
    np.fill_diagonal(hit, False)
    pairs = [(names[i], names[j]) for i, j in zip(*np.nonzero(np.triu(hit)), strict=False)
             if riding[i] != names[j] and riding[j] != names[i]]
    assert not pairs


def rests_on_ground(spec, grid, scene) -> None:
    """Every thing but a rider (who sits on its two-wheeler) has its lowest vertex on the ground
    under its origin: the road (0) or curb height (sidewalks, verges, islands, lots)."""
    things = [o for o in scene.objects if o.instance_id > 0 and o.cls not in RIDERS]
    ground = grid.ground_height(np.array([o.transform[:2, 3] for o in things]))
    low = np.array([apply(o.transform, scene.prototypes[o.prototype].vertices)[:, 2].min() for o in things])
    bad = [(o.name, float(z), float(g)) for o, z, g in zip(things, low, ground, strict=False) if abs(z - g) > 0.01]
    assert not bad


def check_vehicles(spec, scene) -> list:
    """Every car and truck of ``scene`` stands within a lane or a parking strip; returns them."""
    grid = make_grid(spec)
    rects = np.array([r for *_, r in grid.lane_rects()] + [r for *_, r in grid.parking_rects()])
    vehicles = [o for o in scene.objects if o.kind in ("car", "truck")]
    for o in vehicles:
        corners = o.box.corners_xy()
        inside = ((corners[:, None, 0] >= rects[None, :, 0] - 0.01) & (corners[:, None, 0] <= rects[None, :, 2] + 0.01)
                  & (corners[:, None, 1] >= rects[None, :, 1] - 0.01) & (corners[:, None, 1] <= rects[None, :, 3]
                                                                         + 0.01))
        assert inside.any(1).all(), f"{o.name} ({o.attrs.get('placement')}) leaves the parking strips and lanes"
    return vehicles


def radii(headings: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Radius of curvature between consecutive samples (inf on straights)."""
    dh = np.abs(np.angle(np.exp(1j * np.diff(headings))))
    return np.where(dh > 1e-9, np.diff(s) / np.maximum(dh, 1e-12), np.inf)


def forward(seg, direction: int) -> np.ndarray:
    """(2,) unit vector of travel on ``seg`` in ``direction`` (+1 along its yaw, -1 against)."""
    return direction * np.array([np.cos(seg.yaw), np.sin(seg.yaw)])


def on_carriageways(grid, xy: np.ndarray) -> tuple[list, np.ndarray]:
    """The one-way carriageways holding world points ``xy`` ((n, 2)): ``(segments, uv)``, the
    first one-way segment (in ``grid.segments`` order) whose carriageway holds each point (None
    where none does) and the (n, 2) ``(u, v)`` of the point in that segment's frame."""
    xy = np.asarray(xy, np.float64).reshape(-1, 2)
    segs, uv = [None] * len(xy), np.zeros((len(xy), 2))
    free = np.ones(len(xy), bool)
    for seg in grid.segments:
        if not grid.section(seg).one_way:
            continue
        p = segment_frame_points(seg, xy)
        hit = free & (p[:, 0] > 0.0) & (p[:, 0] < seg.length) & (np.abs(p[:, 1]) < grid.road_half)
        for k in np.flatnonzero(hit):
            segs[k] = seg
        uv[hit], free = p[hit], free & ~hit
    return segs, uv


def check_lane_graph(grid, graph) -> None:
    """The lane graph of ``grid`` obeys its one-way streets (also with closures and roundabouts, see
    test_street_mix): every lane runs its direction on its slot and ends at the node it names,
    one-way segments carry ``2 x lanes`` lanes their way and none against it, no dead end, edges
    join end to start with the same heading, every lane is fed by a connector, and every street
    reaches every other without a U-turn."""
    lanes = grid.lanes
    ow = {s.index: grid.section(s).one_way for s in grid.segments if grid.section(s).one_way}
    segs = {s.index: s for s in grid.segments}
    assert set(k[0] for k in graph.lane_edge) == set(segs), "lanes on a closed street, or an open one without"
    for (si, d, k), ei in graph.lane_edge.items():
        e, seg = graph.edges[ei], segs[si]
        h = np.stack([np.cos(e.path.headings), np.sin(e.path.headings)], 1)
        assert np.allclose(h @ np.array([np.cos(seg.yaw), np.sin(seg.yaw)]), d)     # it runs direction d
        assert e.node == (seg.b if d > 0 else seg.a)                                  # it arrives where it says
        ahead = d * np.array([np.cos(seg.yaw), np.sin(seg.yaw)])
        assert np.dot(grid.node_xy(e.node) - e.path.points[-1, :2], ahead) == pytest.approx(graph.entry_m)
        uv = segment_frame_points(seg, e.path.points[:, :2])
        assert np.allclose(uv[:, 1], -d * (k + 0.5) * grid.lane_w)                    # on slot k's centre
        if si in ow:
            assert d == ow[si] and -lanes <= k < lanes
        else:
            assert 0 <= k < lanes
    for si in ow:
        assert sum(1 for key in graph.lane_edge if key[0] == si) == 2 * lanes
    for e in graph.edges:
        assert e.succ, f"{e.path.name} is a dead end"
        for n in e.succ:
            nxt = graph.edges[n]
            assert np.linalg.norm(nxt.path.points[0, :2] - e.path.points[-1, :2]) < 1e-6
            assert abs(np.angle(np.exp(1j * (nxt.path.headings[0] - e.path.headings[-1])))) < 1e-3
    fed = {n for e in graph.edges if e.kind == "connector" for n in e.succ}
    assert fed == {e.index for e in graph.lanes()}, "a lane no connector leads into (its traffic dies out)"
    assert strongly_connected(grid.segments, ow)
