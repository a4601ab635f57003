"""Shared parts for the asset families of issue 13: swept tubes, tori, open wheels, solid helpers.

Everything returns a :class:`generator.geometry.Mesh` (metres, z up, faces counter-clockwise
seen from outside) labelled with the class and material it is given, like the primitives in
:mod:`generator.geometry.primitives`. Kept here rather than in ``generator.geometry`` so the
new families add code without touching the shared geometry layer.
"""

from __future__ import annotations

import numpy as np

from generator.geometry import Mesh, cylinder, disc, merge, pose, resolve_ids, tube, unit


def sweep(path: np.ndarray, radius: float | tuple[float, float], cls: str | int, material: str | int,
          sides: int = 6, closed: bool = False, caps: bool = True, binormal=None) -> Mesh:
    """A tube swept along a polyline (handlebars, hoops, tyres, fenders).

    Parameters
    ----------
    path : (n, 3) float
        Centre line, metres; consecutive points must differ.
    radius : float or (a, b)
        Circular section, or an elliptical one with half-axes ``a`` (in the path's plane,
        across the tube) and ``b`` (along ``binormal``).
    sides : int
        Vertices per section.
    closed : bool
        Join the last section to the first (a ring); no caps then.
    caps : bool
        Close both ends of an open tube with a fan.
    binormal : (3,) float, optional
        A fixed direction perpendicular to a planar path (the plane normal). Without it the
        section frame is parallel-transported along the path.
    """
    p = np.asarray(path, float)
    n = len(p)
    a, b = (radius, radius) if np.isscalar(radius) else radius
    if closed:
        t = unit(np.roll(p, -1, 0) - np.roll(p, 1, 0))
    else:
        d = np.diff(p, axis=0)
        t = np.empty_like(p)
        t[0], t[-1] = d[0], d[-1]
        t[1:-1] = unit(d[:-1]) + unit(d[1:])
        t = unit(t)
    if binormal is not None:
        v = np.tile(unit(binormal), (n, 1))
        u = unit(np.cross(v, t))
    else:
        u = np.empty_like(p)
        helper = np.array([0.0, 0.0, 1.0]) if abs(t[0, 2]) < 0.9 else np.array([1.0, 0.0, 0.0])
        u[0] = unit(np.cross(helper, t[0]))
        for i in range(1, n):
            w = u[i - 1] - np.dot(u[i - 1], t[i]) * t[i]
            u[i] = unit(w)
        v = np.cross(t, u)
    ang = np.linspace(0, 2 * np.pi, sides, endpoint=False)
    ca, sa = np.cos(ang), np.sin(ang)
    verts = (p[:, None, :] + a * ca[None, :, None] * u[:, None, :] + b * sa[None, :, None] * v[:, None, :]).reshape(
        -1, 3
    )
    k = np.arange(sides)
    k1 = (k + 1) % sides
    faces = []
    rows = n if closed else n - 1
    for i in range(rows):
        j = (i + 1) % n
        faces += [np.stack([i * sides + k, i * sides + k1, j * sides + k1], 1),
                  np.stack([i * sides + k, j * sides + k1, j * sides + k], 1)]
    faces = np.concatenate(faces)
    if caps and not closed:
        c0, c1 = len(verts), len(verts) + 1
        verts = np.concatenate([verts, p[[0, -1]]])
        last = (n - 1) * sides
        faces = np.concatenate([faces, np.stack([np.full(sides, c0), k1, k], 1),
                                np.stack([np.full(sides, c1), last + k, last + k1], 1)])
    c, m = resolve_ids(cls, material)
    return Mesh(verts, faces, c, m)


def arc(center, u, v, radius: float, a0: float, a1: float, n: int) -> np.ndarray:
    """(n, 3) points of a circular arc ``center + r (cos a u + sin a v)`` from angle ``a0`` to ``a1``."""
    a = np.linspace(a0, a1, n)
    return np.asarray(center, float) + radius * (
        np.cos(a)[:, None] * np.asarray(u, float) + np.sin(a)[:, None] * np.asarray(v, float)
    )


def torus(center, axis, major: float, minor: float | tuple[float, float], cls: str | int, material: str | int,
          segments: int = 24, sides: int = 6) -> Mesh:
    """A ring (tyre, rim, hoop) around ``axis`` through ``center``; ``minor`` may be (radial, axial)."""
    axis = unit(axis)
    helper = np.array([0.0, 0.0, 1.0]) if abs(axis[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    e1 = unit(np.cross(helper, axis))
    e2 = np.cross(axis, e1)
    path = arc(center, e1, e2, major, 0.0, 2 * np.pi, segments + 1)[:-1]
    return sweep(path, minor, cls, material, sides, closed=True, binormal=axis)


def spoked_wheel(center, radius: float, tyre: float, cls: str, n_spokes: int = 16, rim: str = "chrome",
                 spoke_radius: float = 0.0025, hub_width: float = 0.09, segments: int = 16,
                 tyre_sides: int = 6) -> Mesh:
    """A bicycle wheel in the x-z plane: tyre torus, rim ring, hub and thin spokes, open between them.

    Parameters
    ----------
    center : (3,) float
        Axle centre; the tyre's outer radius is ``radius`` (so the wheel touches z = center_z - radius).
    tyre : float
        Tyre cross-section radius, metres (road 0.013, city 0.02, mountain 0.028).
    n_spokes : int
        Spokes, laced alternately to the two hub flanges (so they cross the wheel plane).
    """
    c = np.asarray(center, float)
    y = np.array([0.0, 1.0, 0.0])
    rim_r = 0.008
    parts = [torus(c, y, radius - tyre, tyre, cls, "rubber", segments, tyre_sides),
             torus(c, y, radius - 2 * tyre - rim_r * 0.5, (rim_r, 0.009), cls, rim, segments, 3)]
    parts.append(tube(c - [0, hub_width / 2, 0], c + [0, hub_width / 2, 0], 0.018, cls, rim, sections=6))
    spoke_end = radius - 2 * tyre - rim_r * 1.2
    for k in range(n_spokes):
        a = 2 * np.pi * k / n_spokes
        flange = c + [0, (hub_width / 2 - 0.01) * (1 if k % 2 else -1), 0]
        end = c + spoke_end * np.array([np.cos(a), 0.0, np.sin(a)])
        start = flange + 0.025 * np.array([np.cos(a + 0.6), 0.0, np.sin(a + 0.6)])
        parts.append(tube(start, end, spoke_radius, cls, rim, sections=3, caps=False))
    return merge(parts)


def disc_wheel(center, radius: float, tyre: float, cls: str, spokes: int = 5, rim: str = "pole_metal",
               width: float | None = None, brake_disc: bool = True, segments: int = 20) -> Mesh:
    """A cast motorcycle / scooter wheel in the x-z plane: fat tyre, rim, a few thick spokes, brake disc.

    The space between the spokes is open (rays pass between them), as on a real cast wheel.
    """
    c = np.asarray(center, float)
    y = np.array([0.0, 1.0, 0.0])
    width = 2 * tyre if width is None else width
    rim_r = radius - 2 * tyre
    parts = [torus(c, y, radius - tyre, (tyre, width / 2), cls, "rubber", segments, 6),
             torus(c, y, rim_r - 0.01, (0.015, width / 2 * 0.8), cls, rim, segments, 4),
             tube(c - [0, width / 2, 0], c + [0, width / 2, 0], 0.045, cls, rim, sections=8)]
    for k in range(spokes):
        a = 2 * np.pi * (k + 0.25) / spokes
        d = np.array([np.cos(a), 0.0, np.sin(a)])
        parts.append(tube(c + 0.04 * d, c + (rim_r - 0.02) * d, 0.014, cls, rim, radius1=0.01, sections=4, caps=False))
    if brake_disc:
        parts.append(ring_plate(c + [0, -width / 2 * 0.6, 0], y, 0.06, min(0.16, rim_r - 0.03), cls, "chrome", 14))
    return merge(parts)


def ring_plate(center, normal, r_in: float, r_out: float, cls: str | int, material: str | int,
               segments: int = 20, thickness: float = 0.005) -> Mesh:
    """A flat annulus (brake disc, chainring) of ``thickness``, both faces and both edges closed."""
    n = unit(normal)
    helper = np.array([0.0, 0.0, 1.0]) if abs(n[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    e1 = unit(np.cross(helper, n))
    e2 = np.cross(n, e1)
    a = np.linspace(0, 2 * np.pi, segments, endpoint=False)
    ring = np.cos(a)[:, None] * e1 + np.sin(a)[:, None] * e2
    c = np.asarray(center, float)
    h = thickness / 2
    v = np.concatenate(
        [c + r_out * ring + h * n, c + r_in * ring + h * n, c + r_out * ring - h * n, c + r_in * ring - h * n]
    )
    k = np.arange(segments)
    k1 = (k + 1) % segments
    O1, I1, O0, I0 = 0, segments, 2 * segments, 3 * segments
    faces = np.concatenate([
        np.stack([O1 + k, O1 + k1, I1 + k1], 1), np.stack([O1 + k, I1 + k1, I1 + k], 1),      # top (+n)
        np.stack([O0 + k, I0 + k1, O0 + k1], 1), np.stack([O0 + k, I0 + k, I0 + k1], 1),      # bottom (-n)
        np.stack([O0 + k, O0 + k1, O1 + k1], 1), np.stack([O0 + k, O1 + k1, O1 + k], 1),      # outer edge
        np.stack([I0 + k, I1 + k1, I0 + k1], 1), np.stack([I0 + k, I1 + k, I1 + k1], 1),      # inner edge
    ])
    cl, m = resolve_ids(cls, material)
    return Mesh(v, faces, cl, m)


def oriented_box(center, size: tuple[float, float, float], cls: str | int, material: str | int,
                 yaw: float = 0.0, pitch: float = 0.0, roll: float = 0.0, bottom: bool = True) -> Mesh:
    """A box of ``size`` (x, y, z) rotated by roll, pitch, yaw about its centre, then moved to ``center``."""
    from generator.geometry import box

    b = box(tuple(float(s) for s in size), cls, material, (0.0, 0.0, 0.0), bottom=bottom)
    return b.transformed(pose(*np.asarray(center, float), yaw=yaw, pitch=pitch, roll=roll))


def rounded_section(half_w: float, z0: float, z1: float, r_top: float, r_bottom: float = 0.0,
                    k_corner: int = 3) -> np.ndarray:
    """(k, 2) (y, z) outline of a vehicle cross-section: a rectangle with rounded corners.

    Runs from -y to +y along the bottom, then back along the top: counter-clockwise seen from +x.
    """
    pts = []

    def corner(cy, cz, r, a0, a1):
        if r <= 1e-9:
            pts.append((cy, cz))
            return
        for a in np.linspace(a0, a1, k_corner):
            pts.append((cy + r * np.cos(a), cz + r * np.sin(a)))

    corner(-half_w + r_bottom, z0 + r_bottom, r_bottom, np.pi, 1.5 * np.pi)
    corner(half_w - r_bottom, z0 + r_bottom, r_bottom, 1.5 * np.pi, 2 * np.pi)
    corner(half_w - r_top, z1 - r_top, r_top, 0.0, 0.5 * np.pi)
    corner(-half_w + r_top, z1 - r_top, r_top, 0.5 * np.pi, np.pi)
    return np.array(pts)


def extrude_x(section: np.ndarray, x0: float, x1: float, cls: str | int, material: str | int,
              cap_material: str | int | None = None) -> Mesh:
    """Extrude a (y, z) outline (any winding, star-shaped around its centroid) along x from ``x0`` to ``x1``."""
    from generator.geometry import loft

    sec = np.asarray(section, float)
    rings = np.array([np.c_[np.full(len(sec), x), sec] for x in (x0, x1)])
    m = loft(rings, cls, material, caps=True)
    if cap_material is not None:
        _, cm = resolve_ids(cls, cap_material)
        m.face_material[-2 * len(sec):] = cm
    return m


def centred(mesh: Mesh, reference: Mesh | None = None) -> Mesh:
    """``mesh`` moved so that the footprint centre (x-y bounding box) of ``reference`` (default
    ``mesh``) is at x = y = 0 and its lowest point at z = 0; anchors move with it."""
    return mesh.transformed(centring(mesh if reference is None else reference))


def centring(reference: Mesh) -> np.ndarray:
    """The 4x4 translation :func:`centred` applies for ``reference``."""
    lo, hi = reference.bounds()
    return pose(x=-(lo[0] + hi[0]) / 2, y=-(lo[1] + hi[1]) / 2, z=-lo[2])


def wheel_cylinder(x: float, y_centre: float, radius: float, width: float, cls: str, sections: int = 16,
                   hub: str = "chrome", z: float | None = None) -> Mesh:
    """A solid tyre (``rubber`` cylinder across y) with a hub disc on its outer face (y sign of ``y_centre``)."""
    side = 1.0 if y_centre >= 0 else -1.0
    zc = radius if z is None else z
    tyre = cylinder(radius, width, cls, "rubber", sections).transformed(
        pose(x, y_centre - side * width / 2, zc, roll=-side * np.pi / 2))
    hubd = disc((x, y_centre + side * (width / 2 + 0.01), zc), (0, side, 0), 0.6 * radius, cls, hub, 10)
    return merge([tyre, hubd])


def two_link(
    root: np.ndarray, target: np.ndarray, l1: float, l2: float, hint: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """(middle joint, end) of a two-segment limb from ``root`` reaching toward ``target``.

    The joint bends toward ``hint``; a target out of reach is approached along the line.
    """
    d = target - root
    dist = float(np.linalg.norm(d))
    u = d / dist
    reach = min(dist, 0.995 * (l1 + l2))
    reach = max(reach, abs(l1 - l2) + 1e-3)
    end = root + reach * u
    a = (l1 ** 2 - l2 ** 2 + reach ** 2) / (2 * reach)
    h = np.sqrt(max(l1 ** 2 - a ** 2, 0.0))
    w = hint - np.dot(hint, u) * u
    w = w / np.linalg.norm(w)
    return root + a * u + h * w, end
