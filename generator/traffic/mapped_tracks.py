"""Carry tracks simulated on a skewed town's grid into its world (:mod:`generator.layout.mapping.town_map`).

The traffic of a town whose streets cross at an angle runs on the grid lanes
(:func:`generator.traffic.build.build_world`); every actor is rigid, so its track is mapped by its
centre: the centre goes through the map, the heading turns to the mapped direction, and the
origin is put back behind the centre at the actor's own (unmapped) offset. The map stretches every
length along a street by :attr:`~generator.layout.mapping.town_map.TownMap.stretch`, so the track is also
slowed by that factor (its times stretched): along the streets every actor moves in the world at
the speed, and waits as long as, it was simulated with (speed limits, the ego's ``speed_mps``,
walking speeds hold in the world).
"""

from __future__ import annotations

import numpy as np

from generator.world.actors import Track


def map_track(track: Track, tmap, offset_xy=(0.0, 0.0)) -> Track:
    """``track`` (grid frame) in the world.

    Parameters
    ----------
    track : Track
        Origin positions (T, 3) and unwrapped headings (T,), grid frame.
    tmap : generator.layout.mapping.town_map.TownMap
    offset_xy : (2,) float
        The actor's footprint centre in its local frame, metres (the origin is not the centre).

    Returns
    -------
    Track
        Positions in the world (z unchanged), headings still unwrapped; start time and sample
        spacing multiplied by ``tmap.stretch`` (a pose simulated at grid time t is the world's at
        ``t * stretch``).
    """
    ox, oy = float(offset_xy[0]), float(offset_xy[1])
    yaw = np.asarray(track.yaw, np.float64)
    c, s = np.cos(yaw), np.sin(yaw)
    centre = track.xyz[:, :2] + np.stack([ox * c - oy * s, ox * s + oy * c], -1)
    centre_w = centre @ tmap.A.T
    yaw_w = tmap.yaw(yaw)
    cw, sw = np.cos(yaw_w), np.sin(yaw_w)
    origin = centre_w - np.stack([ox * cw - oy * sw, ox * sw + oy * cw], -1)
    k = tmap.stretch
    return Track(track.t0 * k, track.dt * k, np.c_[origin, track.xyz[:, 2]], yaw_w)
