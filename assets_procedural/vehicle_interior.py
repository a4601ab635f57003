"""The cabin behind a car's glass: seats, dashboard, steering wheel, door cards, floor and headliner.

Silhouettes, not upholstery: a few boxes and quads (about 180 triangles) placed from the body's own
landmarks (:func:`assets_procedural.car_body.body_shell`), so they sit inside the shell of every body
type. The camera sees them through the transparent glass and the LiDAR returns from them (the
``interiors`` classes of ``generator/materials.yaml``, :mod:`generator.lidar.returns`); their class is
the car's (Cityscapes and SemanticKITTI label a car's interior as car).

The shell's underside rises over each axle (the wheel arches span its whole width), so the floor
runs between the arches, the rear bench sits ahead of the rear arch and every part keeps above the
underside. The car is left-hand drive (the driver on the +y side), as in continental Europe.

Local frame as :mod:`assets_procedural.vehicle`: +x forward, z up, ground at z = 0.
"""

from __future__ import annotations

import numpy as np

from generator.geometry import Mesh, box, merge, polygon, pose, quads, tube

GAP = 0.03          #: metres kept between a cabin part and the shell
SEAT_W = 0.5        #: width of a front seat, metres
BACK_LEAN = np.radians(18.0)  #: backrests lean back by this much


def _bottom(info: dict, x0: float, x1: float) -> float:
    """Highest point of the shell's underside over [x0, x1] (the loft is linear between stations)."""
    xs, zb = info["xs"], info["bottom"]
    grid = np.concatenate([[x0, x1], xs[(xs > x0) & (xs < x1)]])
    return float(np.interp(grid, xs, zb).max())


def _top(info: dict, x0: float, x1: float) -> float:
    """Lowest point of the shell's top line over [x0, x1]."""
    xs, u = info["xs"], info["top"]
    grid = np.concatenate([[x0, x1], xs[(xs > x0) & (xs < x1)]])
    return float(np.interp(grid, xs, u).min())


def _seat(x_back: float, y: float, width: float, z_floor: float, z_cushion: float, headroom: float,
          cls: str) -> list[Mesh]:
    """A seat whose backrest stands at ``x_back``: cushion ahead of it, a leaning backrest, a headrest.

    ``headroom`` caps the top of the headrest (metres above ground)."""
    depth = 0.46
    cushion = box((depth, width, z_cushion - z_floor), cls, "car_interior",
                  (x_back + depth / 2, y, (z_cushion + z_floor) / 2))
    back_h = min(0.58, headroom - z_cushion - 0.22)
    back = box((0.12, width, back_h), cls, "car_interior", (0.0, 0.0, back_h / 2))
    back = back.transformed(pose(x_back, y, z_cushion - 0.04, pitch=-BACK_LEAN))
    top = z_cushion - 0.04 + back_h * np.cos(BACK_LEAN)
    x_top = x_back - back_h * np.sin(BACK_LEAN)
    rests = []
    for yy in ([y] if width < 0.8 else [y - width / 4, y + width / 4]):
        rests.append(box((0.1, 0.26, 0.18), cls, "car_interior", (x_top - 0.01, yy, top + 0.12)))
    return [cushion, back, *rests]


def _steering_wheel(centre: np.ndarray, radius: float, tilt: float, cls: str, sections: int = 12) -> Mesh:
    """A rim (a flat annulus of ``sections`` quads) facing the driver, tilted back by ``tilt``, with a hub."""
    n = np.array([-np.cos(tilt), 0.0, np.sin(tilt)])          # towards the driver and up
    u = np.array([0.0, 1.0, 0.0])
    v = np.cross(n, u)
    a = 2 * np.pi * np.arange(sections + 1) / sections
    ring = np.cos(a)[:, None] * u + np.sin(a)[:, None] * v
    outer, inner = centre + radius * ring, centre + 0.82 * radius * ring
    corners = np.stack([outer[:-1], outer[1:], inner[1:], inner[:-1]], 1)
    rim = quads(corners, cls, "car_trim", np.repeat(n[None], sections, 0))
    hub = polygon(centre + 0.07 * ring[:-1:2] + 0.005 * n, cls, "car_trim", n)
    spoke = box((0.02, 1.64 * radius, 0.035), cls, "car_trim").transformed(pose(*centre, pitch=tilt))
    column = tube(centre - 0.02 * n, centre - 0.3 * n, 0.03, cls, "car_trim", sections=6, caps=False)
    return merge([rim, hub, spoke, column])


def car_interior(p: dict, info: dict, cls: str = "car") -> Mesh:
    """The cabin of one car.

    Parameters
    ----------
    p : dict
        Dimensions (:func:`assets_procedural.car_body.draw_dimensions`): ``W``, ``H``, ``r``,
        ``clear``, ``belt_z``.
    info : dict
        Landmarks and per-station lines of :func:`assets_procedural.car_body.body_shell`.

    Returns
    -------
    Mesh
        Class ``cls``; materials ``car_interior`` (seats, dashboard, door cards, floor),
        ``car_headliner`` (the ceiling) and ``car_trim`` (the steering wheel); every vertex inside
        the shell, about 180 triangles.
    """
    W, H, r, belt = p["W"], p["H"], p["r"], p["belt_z"]
    xa, xb, xc = info["xa"], info["xb"], info["xc"]
    xf, xr = info["xf"], info["xr"]
    ar = r + 0.06                                              # the arch radius of body_shell
    front_arch, rear_arch = xf - ar - 0.02, xr + ar + 0.02
    z_floor = p["clear"] + 0.1
    z_cushion = z_floor + 0.3 + 0.5 * max(H - 1.45, 0.0)   # taller bodies seat higher (SUV, MPV, pickup)
    parts: list[Mesh] = []

    # front seats: backrest ~0.45 m behind the top of the windscreen, never ahead of the front arch's end
    x_front = min(xb - 0.45, front_arch - 0.75)
    y_seat = 0.23 * W
    head = _top(info, x_front - 0.4, x_front) - GAP
    for side in (1.0, -1.0):
        parts += _seat(x_front, side * y_seat, SEAT_W, z_floor, z_cushion, head, cls)
    # rear bench ahead of the rear arch; its backrest leans back over the arch
    x_rear = max(rear_arch, info["glass_back"] + 0.2)
    if x_front - x_rear > 0.55:
        zc = max(z_cushion, _bottom(info, x_rear, x_rear + 0.46) + 0.12)
        head = _top(info, x_rear - 0.4, x_rear) - GAP
        parts += _seat(x_rear, 0.0, 2 * y_seat + SEAT_W, max(z_floor, zc - 0.3), zc, head, cls)
    # floor between the arches
    fx0, fx1 = rear_arch, front_arch
    half_floor = 0.88 * W / 2
    parts.append(box((fx1 - fx0, 2 * half_floor, 0.02), cls, "car_interior", ((fx0 + fx1) / 2, 0.0, z_floor - 0.01)))
    # dashboard under the windscreen's base, above the front arch
    dx0, dx1 = xa - 0.5, xa - 0.03
    dz1 = belt - 0.01
    dz0 = max(belt - 0.3, _bottom(info, dx0, dx1) + GAP)
    parts.append(box((dx1 - dx0, 0.86 * W, dz1 - dz0), cls, "car_interior", ((dx0 + dx1) / 2, 0.0, (dz0 + dz1) / 2),
                     bottom=False))
    # the steering wheel in front of the driver (+y)
    wheel_x = min(dx0 - 0.12, x_front + 0.75)
    parts.append(_steering_wheel(np.array([wheel_x, y_seat, belt - 0.02]), 0.185, np.radians(25.0), cls))
    # door cards below the side windows
    gx0, gx1 = max(info["glass_back"], rear_arch), min(info["glass_front"], front_arch)
    for side in (1.0, -1.0):
        y = side * 0.9 * W / 2
        q = np.array([[gx0, y, z_floor], [gx1, y, z_floor], [gx1, y, belt - 0.04], [gx0, y, belt - 0.04]])
        parts.append(polygon(q, cls, "car_interior", (0.0, -side, 0.0)))
    # headliner under the roof, where the roof is flat
    xs, u = info["xs"], info["top"]
    flat = xs[(u >= H - 0.02) & (xs > xc - 0.3) & (xs < xb + 0.3)]
    if len(flat) >= 2 and flat[-1] - flat[0] > 0.3:
        z = H - 0.07
        hw = 0.55 * W / 2
        q = np.array([[flat[0], -hw, z], [flat[-1], -hw, z], [flat[-1], hw, z], [flat[0], hw, z]])
        parts.append(polygon(q, cls, "car_headliner", (0.0, 0.0, -1.0)))
    return merge(parts)
