"""Shared streets' furniture and people: bollards where others park, people on the carriageway.

A segment of cross-section type ``shared`` (:mod:`generator.layout.network.cross_sections`) keeps the
grid's kerb-to-kerb width and two-way lanes (so intersections, the lane graph and the routes
are unchanged), but:

* its whole carriageway is paved (:func:`generator.layout.ground.roads.shared_road_mesh`, material
  ``block_paving``: small red-brown and grey concrete blocks in stretcher bond, ~0.28 LiDAR
  reflectivity; not the sidewalks' square grey slabs, so a camera tells the carriageway from the
  pavement) instead of asphalt, and it stays class ``road``: vehicles drive on it, which is what
  Cityscapes (7 road, "part of ground on which cars usually drive") and SemanticKITTI (40 road)
  call road; the strips behind the bollards would be *sidewalk* by Cityscapes' rule ("delimited
  from the road by some obstacle, such as curbs or poles"), but people and cars both use them
  here, so they stay road like the rest (see ``generator/labels/classes.yaml``);
* no lane markings (no centre line, dividers, edge lines or bays); the stop lines and
  crosswalks at the intersections stay, as the signals still govern the nodes;
* both side strips (``furnished``) hold bollards every :data:`BOLLARD_SPACING_M` instead of
  parking (:func:`place_shared_bollards`);
* moving vehicles keep to
  :data:`~generator.layout.network.cross_sections.SHARED_SPEED_MPS` on it
  (:mod:`generator.traffic.vehicles.sim.shared`);
* in the frozen town people stand and walk on its carriageway (:func:`place_shared_people`).

Curbs stay raised: a flush curb needs the sidewalk and the carriageway at one height, which the
ground model (road at z = 0, everything else at curb height) and every placement on sidewalks
assume; that is not done.
"""

from __future__ import annotations

import numpy as np

from generator.layout.network.cross_sections import shared_segments
from generator.layout.network.measures import BAY_M, PARKING_START_U
from generator.layout.placement.appearance import outfit
from generator.layout.placement.street_frame import N_VAR, variants
from generator.rng import stream

BOLLARD_SPACING_M = 4.0         #: bollards along each furnished strip
PEOPLE_PER_100M = 6.0           #: frozen town: people on a shared carriageway per 100 m


def place_shared_bollards(placer, spec, st) -> None:
    """Bollards every :data:`BOLLARD_SPACING_M` along both furnished strips of every shared street,
    centred in the strip (stream ``("layout", "shared_bollards")`` picks the variants)."""
    grid = st.grid
    segs = shared_segments(grid)
    if not segs or grid.parking_w <= 0:
        return
    g = stream(spec.seed, "layout", "shared_bollards")
    protos = variants(placer, "bollard")
    for seg in segs:
        u0, u1 = PARKING_START_U, seg.length - PARKING_START_U
        if u1 - u0 < BAY_M:
            continue
        n = int((u1 - u0) // BOLLARD_SPACING_M) + 1
        us = u0 + (u1 - u0 - (n - 1) * BOLLARD_SPACING_M) / 2 + np.arange(n) * BOLLARD_SPACING_M
        for s in (-1, 1):
            to_road, _ = st.side_yaws(seg, s)
            for u in us:
                x, y = seg.to_world(u, s * (grid.lane_half + grid.parking_w / 2))[0]
                placer.try_place(protos[int(g.integers(N_VAR))], x, y, 0.0, to_road,
                                 {"placement": "shared_street"}, pad=0.05)


def place_shared_people(placer, spec, st, protos, look) -> None:
    """Frozen town only: people standing and walking on shared carriageways (stream
    ``("layout", "shared_people")``), tagged ``placement = "shared_street"``."""
    grid = st.grid
    segs = shared_segments(grid)
    if not segs or spec.traffic.enabled or spec.density.people_per_100m <= 0:
        return
    g = stream(spec.seed, "layout", "shared_people")
    for seg in segs:
        u0, u1 = PARKING_START_U, seg.length - PARKING_START_U
        for _ in range(int(g.poisson(PEOPLE_PER_100M * max(0.0, u1 - u0) / 100))):
            i = int(g.integers(len(protos)))
            x, y = seg.to_world(g.uniform(u0, u1), g.uniform(-grid.lane_half + 0.5, grid.lane_half - 0.5))[0]
            placer.try_place(protos[i], x, y, 0.0, float(g.uniform(0, 2 * np.pi)),
                             {**outfit(look), "placement": "shared_street"}, pad=0.15)
