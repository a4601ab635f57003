"""A person's head, hair and headwear (unit body height, facing +x).

The head is a closed skin of latitude rings (chin to crown) over a shaped ellipsoid: a rounded skull
with the occiput behind, a jaw that narrows to the chin, the lower face ahead of the skull, a flat
face with a brow, a nose and ears. Adult head length 0.195 m, breadth 0.152 m and height (chin to
crown) 0.23 m at 1.75 m stature set the radii; ``k`` grows the head about its chin (a child's).

Hair is a volume on the head, not a cap: a second skin over the same shape, grown where the hair is
(thicker on the crown) and sunk under the skin where it is not (the face, the neck), so its visible
edge is the hairline where the two surfaces cross; the faces wholly under the skin are dropped. Long
hair falls behind the neck to the shoulders; a ponytail or a bun adds its own piece. A cap or a
beanie is a third such shell (a cap with a brim).
"""

from __future__ import annotations

import numpy as np

from assets_procedural.person_shape import skin
from generator.geometry import Mesh, box, icosphere, tube

#: head half-length, half-breadth, half-height (chin to crown) before shaping, unit body height
RADII = np.array([0.052, 0.043, 0.066])
#: latitude rings (degrees, chin -90 to crown +90) and longitudes of the head's skin
LATS = np.radians([-72, -52, -34, -17, -4, 10, 26, 44, 62, 78])
LONS = 12
#: where a shell leaves the head bare it lies this far in (share of the head's radius), under the skin
SUNK = 0.7
#: hair thickness (share of the head radius) and how far down the back it falls (share of the head height)
HAIR_STYLES = {"short": (0.09, 0.0), "buzz": (0.03, 0.0), "long": (0.12, 0.9), "ponytail": (0.06, 0.0),
               "bun": (0.06, 0.0)}


def _smooth(x: np.ndarray, a: float, b: float) -> np.ndarray:
    t = np.clip((x - a) / (b - a), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def _sphere(lats: np.ndarray = LATS, lons: int = LONS) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit-sphere ring points (len(lats), lons, 3), chin and crown poles; longitude 0 faces +x."""
    b = np.linspace(0.0, 2.0 * np.pi, lons, endpoint=False)
    ring = np.stack([np.cos(lats)[:, None] * np.cos(b), np.cos(lats)[:, None] * np.sin(b),
                     np.broadcast_to(np.sin(lats)[:, None], (len(lats), lons))], -1)
    return ring, np.array([0.0, 0.0, -1.0]), np.array([0.0, 0.0, 1.0])


def shape(p: np.ndarray) -> np.ndarray:
    """Unit-sphere points ``p`` (..., 3) moved onto the shaped head (still in units of :data:`RADII`)."""
    x, y, z = p[..., 0].copy(), p[..., 1].copy(), p[..., 2].copy()
    jaw = _smooth(-z, 0.2, 1.0)                                      # 0 above the cheekbones, 1 at the chin
    y *= 1.0 - 0.25 * jaw
    z = np.where(z < 0, z * (1.0 - 0.22 * np.clip(-x, 0, 1)), z)     # the jaw's underside rises toward the nape
    x = x + 0.28 * jaw + 0.06 * _smooth(z, 0.05, 0.45) * (x > 0)    # chin and forehead ahead, the nape under the skull
    x = np.where(x > 0.66, 0.66 + 0.55 * (x - 0.66), x)             # a flat face
    x = x - 0.1 * np.exp(-((z - 0.2) / 0.45) ** 2) * (p[..., 0] < -0.2)   # the occiput
    if_front = (p[..., 0] > 0.5).astype(float)
    x = x + if_front * (0.32 * np.exp(-(y / 0.2) ** 2 - ((z + 0.12) / 0.2) ** 2)           # nose
                        + 0.07 * np.exp(-(y / 0.55) ** 2 - ((z - 0.2) / 0.1) ** 2))         # brow
    y = y + np.sign(y) * 0.14 * np.exp(-((p[..., 0] + 0.05) / 0.2) ** 2 - ((z + 0.02) / 0.22) ** 2)  # ears
    return np.stack([x, y, z], -1)


def _solid(ring: np.ndarray, bottom: np.ndarray, top: np.ndarray, cls: str, material: str) -> Mesh:
    return skin(ring, cls, material, bottom, top)


def head(centre: np.ndarray, k: float, cls: str, material: str = "skin") -> Mesh:
    """The head skin around ``centre`` (the middle of the chin-crown span), grown ``k`` times."""
    ring, bottom, top = _sphere()
    r = RADII * k
    return _solid(shape(ring) * r + centre, shape(bottom) * r + centre, shape(top) * r + centre, cls, material)


def _hairline(p: np.ndarray, long: bool) -> np.ndarray:
    """Coverage in [0, 1] of the unit-sphere point ``p``: 1 under the hair, 0 on the face and neck."""
    x, z = p[..., 0], p[..., 2]
    line = np.interp(x, [-1.0, -0.4, 0.2, 0.7, 1.0], [-1.2, -1.2, -0.8, 0.5, 0.58] if long
                     else [-0.62, -0.5, -0.1, 0.5, 0.58])
    return _smooth(z - line, -0.08, 0.12)


def shell(centre: np.ndarray, k: float, cls: str, material: str, thick: float, fall: float = 0.0,
          long: bool = False, line: float | None = None) -> Mesh:
    """A closed shell over the head: ``thick`` (share of the radius) proud of it where covered, sunk
    under it elsewhere; ``fall`` stretches the covered back down toward the shoulders; ``line`` a level
    (unit sphere z) below which nothing is covered (a hat's edge) instead of the hairline."""
    ring, bottom, top = _sphere()
    pts = np.concatenate([ring.reshape(-1, 3), bottom[None], top[None]])
    cover = _hairline(pts, long) if line is None else _smooth(pts[:, 2] - line, -0.05, 0.05)
    grow = SUNK + (1.0 + thick * (0.6 + 0.6 * np.clip(pts[:, 2], 0, 1)) - SUNK) * cover
    q = shape(pts) * grow[:, None]
    if fall:
        back = cover * _smooth(-pts[:, 0], -0.1, 0.45) * _smooth(-pts[:, 2], -0.3, 0.6)
        q[:, 2] -= fall * back
        q[:, 0] -= 0.3 * back
        q[:, 1] *= 1.0 + 0.15 * back
    v = q * RADII * k + centre
    n = ring.shape[0] * ring.shape[1]
    m = _solid(v[:n].reshape(ring.shape), v[n], v[n + 1], cls, material)
    # faces wholly sunk under the skin are never seen: drop them (the shell's rim stays inside the head)
    keep = cover[m.faces].max(1) > 0.02
    used, faces = np.unique(m.faces[keep], return_inverse=True)
    return Mesh(m.vertices[used], faces.reshape(-1, 3), m.face_class[keep], m.face_material[keep])


def hair(style: str, centre: np.ndarray, k: float, cls: str) -> list[Mesh]:
    """Hair of ``style`` (:data:`HAIR_STYLES`) on the head at ``centre``."""
    thick, fall = HAIR_STYLES[style]
    out = [shell(centre, k, cls, "hair", thick, fall, long=style == "long")]
    r = RADII * k
    if style == "ponytail":
        root = centre + r * np.array([-1.05, 0.0, 0.15])
        out.append(tube(root, root + r * np.array([-0.5, 0.0, -1.5]), 0.3 * r[1], cls, "hair", 0.12 * r[1],
                        sections=6))
    elif style == "bun":
        out.append(icosphere(0.48 * r[1], cls, "hair", 1, center=centre + r * np.array([-1.0, 0.0, 0.55])))
    return out


def headwear(kind: str, centre: np.ndarray, k: float, cls: str) -> list[Mesh]:
    """A cap (crown and brim, ``shoes`` material) or a beanie (``clothing``) over the head, or nothing."""
    if kind == "none":
        return []
    if kind == "beanie":
        return [shell(centre, k, cls, "clothing", 0.16, line=0.05)]
    r = RADII * k
    brim = centre + r * np.array([1.2, 0.0, 0.3])
    return [shell(centre, k, cls, "shoes", 0.13, line=0.3),
            box((0.9 * r[0], 1.5 * r[1], 0.08 * r[2]), cls, "shoes", tuple(brim))]
