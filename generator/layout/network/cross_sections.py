"""Street cross-section types: what fills the strips between the driving lanes and the curbs.

Every street keeps the grid's kerb-to-kerb width (:class:`generator.layout.network.grid.Grid`), so
intersections, lanes and routes are the same for all of them; what differs is the *strip* on
each side between the outer lane edge (``|v| = lane_half``) and the curb (``|v| = road_half``),
over the middle of the segment (``PARKING_START_U <= u <= length - PARKING_START_U``, where
parking bays run; the segment ends stay asphalt for the turning arcs), and whether a median
island splits the directions there:

============  ====================================  =========================================
type          strips (side -1, side +1)             extra
============  ====================================  =========================================
plain         parking, parking                      (every street of a town without ``streets``)
residential   parking or verge, each at even odds   bushes and small trees on the verges
              (one of each: see below)
boulevard     verge, verge                          a tree row on each verge
arterial      shoulder, shoulder (asphalt)          a raised median island (other-ground), where
                                                    the lanes are wide enough that the ego on its
                                                    lane centre keeps ``MEDIAN_CLEAR_M`` off it
one_way       parking, parking                      every lane runs one way (``one_way`` = +1
                                                    towards +u, -1 towards -u; see
                                                    :mod:`generator.layout.network.one_way`); no centre
                                                    line, dashed dividers between its lanes
shared        furnished, furnished                  paved kerb to kerb (class road), no lane
                                                    markings, bollards in the strips, 20 km/h
                                                    (:data:`SHARED_SPEED_MPS`)
============  ====================================  =========================================

With ``streets.residential_strips = "parking_and_verge"`` a residential street has one parking
strip and one verge, so every residential street has parked cars and greenery and a drive's
class mix does not hang on how many of its streets happened to draw verges on both sides
(``kitti_like``). On a street route 0 (the user's drive) passes, the verge lines the drive's own
kerb and the parked cars stand across the street, on its left; elsewhere the side is drawn at
even odds (from the same two draws as per side). A car parked beside the ego's lane fills about
three times the points of one across the street, so a coin per street made the car share of a
one-minute drive swing threefold from town to town.

With ``streets.drive_types`` the streets route 0 drives take the listed types in turn, in driving
order from its start (the other streets keep their draws, and every street still takes its draw
from the stream, so the draws after it stay), so one minute of the drive passes the same mix of
streets in every town.

A *verge* is grass (terrain) raised to curb height behind a curb along the lane edge; a
*shoulder* is asphalt (road) with the edge line, no bays; a *furnished* strip is paving at road
level (road) holding bollards. Each parking strip draws the share of
its bays that hold a vehicle from ``streets.parking_occupancy``, so some streets are empty and
some full, and the ego is not always beside parked cars. Draws: stream
``("layout", "street_types")``, one type per segment in segment order, then the strips. A
segment drawn ``one_way`` that cannot be (the routes drive it both ways, or its direction would
cut the network apart) takes a two-way type drawn again from the other weights (stream
``("layout", "street_types", "two_way")``, one draw per such segment in segment order; plain if
no other type has weight); its strips are then drawn as that type's.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from generator.layout.network.cycles import route_node_cycles
from generator.layout.network.design_vehicle import EGO_HALF_WIDTH_M
from generator.layout.network.one_way import one_way_directions
from generator.rng import stream

TYPES = ("plain", "residential", "boulevard", "arterial", "one_way", "shared")   #: new types go last (same draws)
STRIPS = ("parking", "verge", "shoulder", "furnished")
MEDIAN_W_M = 0.6      #: width of an arterial's median island
MEDIAN_CLEAR_M = 0.1  #: the ego (half width EGO_HALF_WIDTH_M) on its lane centre keeps this off the island
SHARED_SPEED_MPS = 20.0 / 3.6   #: vehicles' speed limit on a shared street (20 km/h)


@dataclass(frozen=True)
class CrossSection:
    """The cross-section of one street segment.

    Attributes
    ----------
    kind : str
        One of :data:`TYPES`.
    strips : (str, str)
        What fills the strip at side -1 (``v < 0``) and side +1: one of :data:`STRIPS`.
    occupancy : (float, float)
        Share of the bays holding a vehicle, per side (meaningful where the strip is parking;
        ``nan`` where the town has no ``streets`` and ``density.parked_cars_per_100m`` decides).
    """

    kind: str
    strips: tuple[str, str]
    occupancy: tuple[float, float]
    median: bool = False     #: a median island separates the directions
    one_way: int = 0         #: 0 two-way; +1 every lane runs towards +u; -1 towards -u

    def strip(self, side: int) -> str:
        return self.strips[0 if side < 0 else 1]

    def share(self, side: int) -> float:
        return self.occupancy[0 if side < 0 else 1]


PLAIN = CrossSection("plain", ("parking", "parking"), (float("nan"), float("nan")))


def draw_sections(spec, segments, closed=(), roundabouts=frozenset()) -> tuple[CrossSection, ...]:
    """One :class:`CrossSection` per segment drawn from ``spec.streets`` (empty without it).

    Parameters
    ----------
    spec : SceneSpec
    segments : sequence of Segment
        Every segment of the grid, closed ones included, in index order (one-way directions
        depend on the routes).
    closed : sequence of Segment
        The closed segments (:mod:`generator.layout.network.closures`): never one-way, and the one-way
        network's connectivity is that of the open streets.
    roundabouts : frozenset of (int, int)
        Roundabout nodes: a segment ending at one is never one-way (its ring keeps every arm two-way).

    Returns
    -------
    tuple of CrossSection
        ``()`` when ``spec.streets`` is None (every segment is :data:`PLAIN`) or the town has no
        parking strips (then every strip is lane asphalt and there is nothing to vary).
    """
    n_segments = len(segments)
    streets = spec.streets
    if streets is None or spec.town.parking_strip_width_m <= 0:
        return ()
    island = spec.town.lane_width_m / 2 - EGO_HALF_WIDTH_M - MEDIAN_W_M / 2 >= MEDIAN_CLEAR_M
    g = stream(spec.seed, "layout", "street_types")
    w = np.array([float(streets.types.get(t, 0.0)) for t in TYPES])
    kinds = [TYPES[int(k)] for k in g.choice(len(TYPES), size=n_segments, p=w / w.sum())]
    drive = drive_directions(segments, spec.town.blocks_x, spec.town.blocks_y)
    if streets.drive_types:       # route 0's streets in driving order take the listed types in turn
        for k, i in enumerate(drive):
            kinds[i] = streets.drive_types[k % len(streets.drive_types)]
    cand = [i for i, k in enumerate(kinds) if k == "one_way"]
    direction = one_way_directions(spec.seed, segments, cand, spec.town.blocks_x, spec.town.blocks_y,
                                   closed, roundabouts)
    refused = [i for i in cand if i not in direction]
    if refused:
        two = np.array([0.0 if t == "one_way" else x for t, x in zip(TYPES, w, strict=True)])
        redraw = stream(spec.seed, "layout", "street_types", "two_way")
        for i in refused:
            kinds[i] = TYPES[int(redraw.choice(len(TYPES), p=two / two.sum()))] if two.sum() > 0 else "plain"
    lo, hi = streets.parking_occupancy
    out = []
    for i, kind in enumerate(kinds):
        if kind in ("plain", "one_way"):
            strips = ("parking", "parking")
        elif kind == "residential":
            r = g.random(2)       # two draws either way: the occupancies and later segments stay put
            if streets.residential_strips == "parking_and_verge":
                # driven towards +u (d = +1) the ego keeps to side -1: parking across, on side +1
                parking_side = drive[i] if i in drive else (-1 if r[0] < 0.5 else 1)
                strips = ("parking", "verge") if parking_side < 0 else ("verge", "parking")
            else:
                strips = tuple("parking" if x < 0.5 else "verge" for x in r)
        elif kind == "shared":
            strips = ("furnished", "furnished")
        elif kind == "boulevard":
            strips = ("verge", "verge")
        else:
            strips = ("shoulder", "shoulder")
        occ = tuple(float(x) for x in g.uniform(lo, hi, 2))
        out.append(CrossSection(kind, strips, occ, kind == "arterial" and island, direction.get(i, 0)))
    return tuple(out)


def drive_directions(segments, nx: int, ny: int) -> dict[int, int]:
    """``segment index -> +1 | -1``: the direction route 0 (the ego's drive) passes each segment it
    drives (+1 towards +u), in driving order from the route's start; segments it does not drive are
    absent."""
    index = {(s.a, s.b): s.index for s in segments}
    cyc = route_node_cycles(nx, ny)[0]
    out = {}
    for k, a in enumerate(cyc):
        b = cyc[(k + 1) % len(cyc)]
        if (a, b) in index:
            out.setdefault(index[(a, b)], 1)
        elif (b, a) in index:
            out.setdefault(index[(b, a)], -1)
    return out


def sections_record(grid) -> list[dict]:
    """The drawn cross-section of every segment of ``grid`` as JSON rows (``[]`` when all are plain
    by default): segment index, its nodes, type, strips, occupancy, median and one-way direction
    (+1: from node ``a`` to node ``b``), for the open segments (closed ones are parks)."""
    return [{"segment": s.index, "a": list(s.a), "b": list(s.b), "kind": sec.kind, "strips": list(sec.strips),
             "occupancy": [round(x, 4) for x in sec.occupancy], "median": sec.median, "one_way": sec.one_way}
            for s, sec in ((s, grid.section(s)) for s in grid.segments) if grid.sections]


def shared_segments(grid) -> list:
    """The segments of ``grid`` whose cross-section is ``shared``."""
    return [s for s in grid.segments if grid.section(s).kind == "shared"]
