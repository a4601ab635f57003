"""The regulatory signs of one-way streets: "one way" at the entry and along it, "no entry" at its exit.

For a one-way segment (:attr:`generator.layout.network.cross_sections.CrossSection.one_way`) whose traffic
runs from its *entry* node to its *exit* node:

* **entry**: a "one way" sign (:mod:`assets_procedural.regulatory_signs`) on each sidewalk just past
  the crosswalk of the entry node, facing the traffic that turns in (the driver's right first);
* **along**: a "one way" repeater every :data:`REPEAT_M` metres after that, on alternating sides,
  facing the traffic, while more than :data:`REPEAT_M` / 2 is left before the exit end;
* **exit**: a "no entry" sign on each sidewalk just past the crosswalk of the exit node, facing
  the drivers at that node who could otherwise turn in against the flow (their right first).

Every sign stands on the kerb line of the sidewalk (as the other signs, :class:`Street.kerb_line`)
at curb height and goes through the placer (route keep-out, occupancy). A spot taken by something
placed earlier moves the sign on by :data:`STEP_M` up to :data:`TRIES` times. The step runs right
after the signal heads, so the regulatory signs win their spots over lamps, trees and furniture.
No draws: the two sign prototypes come from the asset streams
``("assets", "traffic_sign", "one_way" | "no_entry", 0)``, so a town without one-way streets is
byte-identical. Each sign's ``attrs``: ``sign`` (its shape), ``placement``
(``one_way_entry`` / ``one_way_repeat`` / ``one_way_exit``) and ``segment`` (the segment index).
"""

from __future__ import annotations

import numpy as np

from generator.layout.placement.placer import Placer

REPEAT_M = 25.0   #: spacing of the "one way" repeaters along a long one-way street, metres
SETBACK_M = 1.0   #: the entry and exit signs stand this far past the sidewalk's corner square, metres
STEP_M = 1.0      #: a sign whose spot is taken moves on along the street by this much, metres
TRIES = 6         #: spots tried per sign


def one_way_ends(grid) -> list[tuple]:
    """``(segment, direction, entry node, exit node)`` of every open one-way segment of ``grid``.

    ``direction`` is +1 when the traffic runs towards +u (from ``segment.a`` to ``segment.b``).
    """
    out = []
    for seg in grid.segments:
        d = grid.section(seg).one_way
        if d:
            out.append((seg, d, seg.a if d > 0 else seg.b, seg.b if d > 0 else seg.a))
    return out


def place_one_way_signs(placer: Placer, spec, st) -> int:
    """Place the signs of every one-way street (see the module docstring); returns how many stood."""
    grid = st.grid
    ends = one_way_ends(grid)
    if not ends:
        return 0
    one_way = placer.lib.variant("traffic_sign", 0, lambda g: {"shape": "one_way"}, tag="one_way")
    no_entry = placer.lib.variant("traffic_sign", 0, lambda g: {"shape": "no_entry"}, tag="no_entry")
    near = st.walk_u0 + SETBACK_M           # from the segment end: past the corner square and crosswalk
    placed = 0
    for seg, d, _, _ in ends:
        L = seg.length
        flow = seg.yaw if d > 0 else seg.yaw + np.pi       # heading of the traffic
        right = -d                                           # the traffic's right-hand side (v sign)

        def at(dist_from_entry: float, d=d, L=L) -> float:  # u of a point this far from the entry end
            return dist_from_entry if d > 0 else L - dist_from_entry

        def put(proto, dist0: float, step: float, side: int, yaw: float, what: str, seg=seg, L=L, at=at) -> bool:
            for k in range(TRIES):
                dist = dist0 + step * k
                if not near - 1e-9 <= dist <= L - near + 1e-9:
                    break
                x, y = seg.to_world(at(dist), side * st.kerb_line)[0]
                attrs = {"sign": proto.params["shape"], "placement": what, "segment": seg.index}
                if placer.try_place(proto, x, y, st.h, yaw, attrs, pad=0.1):
                    return True
            return False

        for side in (right, -right):         # entry: facing the traffic turning in
            placed += put(one_way, near, STEP_M, side, flow + np.pi, "one_way_entry")
        for side in (-right, right):          # exit: facing the wrong-way driver (his right is -right)
            placed += put(no_entry, L - near, -STEP_M, side, flow, "one_way_exit")
        side, dist = right, near + REPEAT_M
        while dist <= L - near - REPEAT_M / 2:
            side = -side
            placed += put(one_way, dist, STEP_M, side, flow + np.pi, "one_way_repeat")
            dist += REPEAT_M
    return placed
