"""Which actor the surface seen by a pixel belongs to.

The depth pass is the distance to the real geometry along the ray through the pixel CENTRE; the
instance pass is the label pass's, which with ``label_supersample`` > 1 is a majority vote over
``k x k`` samples of the pixel. On an actor's silhouette the two can disagree: the vote says
"car" while the centre ray passes the car and sees the wall behind (or the reverse). Moving
the wall point with the car would give it the car's flow. So a pixel's owner is decided on
the surface point itself: a pixel labelled with an actor, or next to one, belongs to that actor
when its point lies in the actor's box (grown by :data:`BOX_MARGIN_M`); a pixel the label pass
gives to something else must also be above the box's bottom (:data:`GROUND_M`), so the road
under a car stays road. Actors are rigid and their boxes hold their whole mesh, so on a pixel
whose label and centre agree (every pixel with ``label_supersample: 1``) this is the label.
"""

from __future__ import annotations

import numpy as np

#: Boxes are grown by this much before the test (float32 depth of a point 100 m away is ~1e-5 m off).
BOX_MARGIN_M = 0.02
#: A pixel not labelled with the actor joins it only this far above the box's bottom face, metres (the road
#: under a car lies on it, within float32 depth error, ~1 mm at 100 m).
GROUND_M = 0.01


def _dilate(mask: np.ndarray) -> np.ndarray:
    """(H, W) bool: ``mask`` grown by one pixel (8-neighbourhood)."""
    h, w = mask.shape
    p = np.pad(mask, 1)
    out = np.zeros_like(mask)
    for dy in (0, 1, 2):
        for dx in (0, 1, 2):
            out |= p[dy:dy + h, dx:dx + w]
    return out


def pixel_owners(points_world: np.ndarray, known: np.ndarray, instance: np.ndarray, movers: list) -> np.ndarray:
    """Index into ``movers`` of the actor each pixel's surface point belongs to, -1 for the static town.

    Parameters
    ----------
    points_world : (H, W, 3) float64
        The surface point of each pixel at the image time, world frame, metres (any value where
        not ``known``).
    known : (H, W) bool
        Pixels with a surface (finite depth).
    instance : (H, W) integer
        Instance pass.
    movers : list of generator.world.kinematics.Mover
        The actors, posed at the image time (``T0``).

    Returns
    -------
    (H, W) int32
    """
    out = np.full(instance.shape, -1, np.int32)
    if not movers:
        return out
    ids = np.array([m.instance_id for m in movers], np.int64)
    inst = np.asarray(instance).astype(np.int64, copy=False)
    counts = np.bincount(inst.ravel(), minlength=int(ids.max()) + 1)
    present = np.flatnonzero(counts[ids] > 0)
    for i in present:
        m = movers[i]
        lab = inst == m.instance_id
        rows, cols = np.nonzero(lab)
        r0, r1 = max(rows.min() - 1, 0), rows.max() + 2
        c0, c1 = max(cols.min() - 1, 0), cols.max() + 2
        sub = (slice(r0, r1), slice(c0, c1))
        region = _dilate(lab[sub]) & known[sub]
        rr, cc = np.nonzero(region)
        rr, cc = rr + r0, cc + c0
        loc = m.local(points_world[rr, cc])
        inside = np.all(np.abs(loc) <= m.box_size / 2 + BOX_MARGIN_M, axis=1)
        above = loc[:, 2] + m.box_size[2] / 2 > GROUND_M
        take = inside & (lab[rr, cc] | above)
        out[rr[take], cc[take]] = i
    return out
