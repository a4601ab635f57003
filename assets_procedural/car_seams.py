"""Where a car's panels meet: door, bonnet, boot and bumper seams and the door handles, as anchors.

A real car body is a dozen pressed panels with 3-5 mm gaps between them: the doors (front door from
behind the front wheel arch to the B-pillar, rear door from there to the C-pillar or the rear arch), the
bonnet (its front edge above the grille, its sides along the wings), the boot lid or tailgate, and
bumpers whose top edge runs under the lamps round the corners to the wheel arches. Close up, these
lines are what tells a car from a soap bar. The shell (:mod:`assets_procedural.car_body`) stays one
loft: the gaps are drawn by its paint (``car_body`` in :mod:`generator.blender.recipes_actors`) from the
anchors below, so the LiDAR and the labels see exactly the triangles they saw before.

Anchors (car frame: +x forward, z up, the right side at +y; points on the right side, the paint mirrors
them to the left):

* ``seam/doors`` (3, 3): a point on each vertical door seam (front door's leading edge, between the
  doors, rear door's trailing edge), at mid-door height;
* ``seam/band`` (2, 3): the doors' bottom (top of the sill) and the belt line, at x = 0;
* ``seam/handles`` (2, 3): the centres of the two door handles;
* ``seam/bumpers`` (2, 3): where the front and the rear bumper's top edge meets the wheel arch, at
  the edge's height;
* ``seam/lids`` (2, 3): the bonnet's front edge (x) and side seams (y), then the boot lid's or
  tailgate's front edge and side seams, at their height.

:func:`generator.blender.car_seam_shader.seam_properties` packs them into the properties the paint reads.
"""

from __future__ import annotations

import numpy as np

HANDLE_AHEAD_M = 0.135  #: a door handle's centre ahead of its door's rear edge, metres (its grip is 0.17 m long)
#: names of the anchors :func:`seam_anchors` returns
SEAM_ANCHORS = ("seam/doors", "seam/band", "seam/handles", "seam/bumpers", "seam/lids")


def seam_anchors(p: dict, info: dict) -> dict[str, np.ndarray]:
    """The seam anchors of one car body.

    Parameters
    ----------
    p : dict
        Dimensions (:func:`assets_procedural.car_body.draw_dimensions`), metres.
    info : dict
        Landmarks of :func:`assets_procedural.car_body.body_shell` (``xf``, ``xr``, ``xa``, ``xd``,
        ``glass_front``, ``glass_back``, ``pillars``, ``top``), metres.

    Returns
    -------
    dict of str to (k, 3) float64
        The anchors named in the module docstring, in the body's frame before it is set on the ground.
    """
    L, W, r, belt = p["L"], p["W"], p["r"], p["belt_z"]
    arch = r + 0.06                                   # wheel-arch radius of the shell
    half = W / 2
    pillars = sorted(info["pillars"])
    x_front = min(info["glass_front"] - 0.02, info["xf"] - arch - 0.05)
    x_b = pillars[-1]                                 # the B-pillar: the front-most pillar
    x_rear = pillars[0] if len(pillars) > 1 else info["glass_back"] + 0.04
    x_rear = max(x_rear, info["xr"] + 0.25 * arch)    # a rear door ends over the rear arch, ahead of the axle
    sill = p["clear"] + 0.1
    z_mid = 0.5 * (sill + belt)
    z_handle = belt - 0.075
    nose, tail_top = float(info["top"][-1]), float(info["top"][0])
    z_front, z_rear = nose - 0.13, tail_top - 0.2     # bumper tops: under the head- and taillamps
    deck = float(np.interp(info["xd"] - 0.03, info["xs"], info["top"]))
    return {
        "seam/doors": np.array([[x, half, z_mid] for x in (x_front, x_b, x_rear)]),
        "seam/band": np.array([[0.0, half, sill], [0.0, half, belt]]),
        "seam/handles": np.array([[x + HANDLE_AHEAD_M, half, z_handle] for x in (x_b, x_rear)]),
        "seam/bumpers": np.array([[info["xf"] + arch - 0.02, half, z_front], [info["xr"] - arch + 0.02, half, z_rear]]),
        "seam/lids": np.array([[L / 2 - 0.12, 0.75 * half, nose + 0.1], [info["xd"] - 0.03, 0.72 * half, deck]]),
    }
