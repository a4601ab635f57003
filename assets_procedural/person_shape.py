"""Shaped body parts of a person (unit body height): limbs lofted through their joints, hands, shoes.

A limb is one skin of elliptical cross-sections swept along its two bones (hip-knee-ankle,
shoulder-elbow-wrist). Each section has its own half-widths across (lateral) and along the body's
forward direction (sagittal) and an offset of its centre forward or back, so a thigh tapers to the
knee, the calf bulges behind the shin, the deltoid caps the shoulder and the wrist is flat. The
section at a joint turns with the bisector of the two bones, so a bent knee or elbow keeps its volume
without a ball at the joint. The skin is one closed mesh of fixed topology: the phases of a walker's
gait share its faces.

Sections are tables of rows ``(s, half_lateral, half_sagittal, sagittal_offset)`` (unit body height):
``s`` in [0, 1] runs down the first bone, [1, 2] down the second; values outside extrapolate
along the end bones (into the torso, into the shoe).
"""

from __future__ import annotations

import functools

import numpy as np

from assets_procedural import person_gait as gait
from generator.geometry import Mesh, resolve_ids, unit
from generator.geometry.transforms import cross

#: sides of a limb section
SIDES = 8
_ANG = np.linspace(0.0, 2.0 * np.pi, SIDES, endpoint=False)
#: cosines and sines of the section angles (a walker makes ~300 limbs: computed once, the same values)
_COS, _SIN = np.cos(_ANG), np.sin(_ANG)

#: leg sections, bare skin: upper thigh, mid thigh, above the knee, knee, calf bulge (behind), ankle
LEG = np.array([(-0.12, 0.038, 0.044, 0.0), (0.0, 0.048, 0.058, -0.004), (0.3, 0.045, 0.052, 0.003),
                (0.65, 0.038, 0.044, 0.005), (0.9, 0.032, 0.035, 0.004), (1.0, 0.030, 0.034, 0.005),
                (1.12, 0.030, 0.032, -0.002), (1.32, 0.034, 0.04, -0.01), (1.56, 0.027, 0.030, -0.006),
                (1.8, 0.019, 0.021, -0.002), (1.97, 0.017, 0.019, 0.0), (2.06, 0.012, 0.012, 0.0)])
#: arm sections, bare skin: deltoid, biceps, elbow, forearm, flat wrist (wide front to back)
ARM = np.array([(-0.1, 0.018, 0.024, 0.0), (0.02, 0.034, 0.04, 0.0), (0.22, 0.033, 0.035, 0.002),
                (0.5, 0.028, 0.03, 0.002), (0.85, 0.023, 0.025, 0.0), (1.0, 0.021, 0.023, -0.003),
                (1.18, 0.023, 0.026, 0.0), (1.55, 0.018, 0.021, 0.0), (1.95, 0.011, 0.017, 0.0),
                (2.02, 0.009, 0.014, 0.0)])


@functools.lru_cache(maxsize=64)
def skin_faces(n_rings: int, k: int, start: bool, end: bool) -> np.ndarray:
    """Faces of :func:`skin` (read-only): quads between rings, fans to the end points."""
    i = np.arange(k)
    j = (i + 1) % k
    faces = []
    for r in range(n_rings - 1):
        a, b = r * k + i, (r + 1) * k + i
        faces += [np.stack([a, a - i + j, b - i + j], 1), np.stack([a, b - i + j, b], 1)]
    n = n_rings * k
    if start:
        faces.append(np.stack([np.full(k, n), j, i], 1))
    if end:
        last = (n_rings - 1) * k
        faces.append(np.stack([np.full(k, n + int(start)), last + i, last + j], 1))
    out = np.concatenate(faces)
    out.setflags(write=False)
    return out


def skin(rings: np.ndarray, cls: str, materials, start=None, end=None) -> Mesh:
    """A closed skin over ``rings`` (as :func:`generator.geometry.loft` builds it, with fixed topology).

    Parameters
    ----------
    rings : (s, k, 3) float
        Sections in order along the axis ``t``; each ring's points run counter-clockwise seen from
        the end ``t`` points to (``u`` to ``v`` with ``u x v = t``), so the faces point outward.
    cls : str
        Class of every face.
    materials : str or sequence of str
        One material, or one per band between rings (``s - 1``), the end caps taking their bands'.
    start, end : (3,) float, optional
        Apex of the fan that closes the first / last ring (None: left open).

    Returns
    -------
    Mesh
    """
    rings = np.asarray(rings, float)
    s, k, _ = rings.shape
    names = (materials,) * (s - 1) if isinstance(materials, str) else tuple(materials)
    apex = [np.asarray(p, float)[None] for p in (start, end) if p is not None]
    verts = np.concatenate([rings.reshape(-1, 3), *apex])
    return Mesh(verts, skin_faces(s, k, start is not None, end is not None), resolve_ids(cls, "skin")[0],
                _skin_materials(cls, names, k, start is not None, end is not None))


@functools.lru_cache(maxsize=256)
def _skin_materials(cls: str, names: tuple, k: int, start: bool, end: bool) -> np.ndarray:
    """Material id per face of :func:`skin` (read-only): the bands', the end fans taking their bands'."""
    band = np.array([resolve_ids(cls, m)[1] for m in names])
    mats = [np.repeat(band, 2 * k)]
    if start:
        mats.append(np.full(k, band[0]))
    if end:
        mats.append(np.full(k, band[-1]))
    out = np.concatenate(mats)
    out.setflags(write=False)
    return out


def chain_rings(joints: np.ndarray, table: np.ndarray, lateral: np.ndarray) -> np.ndarray:
    """Sections of ``table`` along the two bones ``joints`` (3, 3): (rows, SIDES, 3) ring points.

    ``lateral`` (3,) is the direction across the limb (the body's side for a leg or an arm); the
    sagittal axis is ``t x lateral`` for the local bone direction ``t`` (forward for a limb hanging
    down). Sections within 0.15 of the joint turn with the bisector of the bones.
    """
    p0, p1, p2 = (np.asarray(p, float) for p in joints)
    d1, d2 = unit(p1 - p0), unit(p2 - p1)
    s = table[:, 0]
    centre = np.where((s <= 1.0)[:, None], p0 + s[:, None] * (p1 - p0), p1 + (s[:, None] - 1.0) * (p2 - p1))
    w = np.minimum(np.maximum((s - 0.85) / 0.3, 0.0), 1.0)[:, None]      # np.clip's values, without its wrapper
    t = unit((1.0 - w) * d1 + w * d2)
    lat = np.asarray(lateral, float)
    u = lat - (t @ lat)[:, None] * t
    weak = np.sqrt(np.add.reduce(u * u, axis=1)) < 0.3          # np.linalg.norm(u, axis=1)
    if weak.any():                       # a bone along the lateral axis: fall back to the forward one
        fwd = np.array([1.0, 0.0, 0.0])
        u[weak] = fwd - (t[weak] @ fwd)[:, None] * t[weak]
    u = unit(u)
    v = cross(t, u)
    c = centre + table[:, 3:4] * v
    return (c[:, None] + table[:, 1, None, None] * _COS[None, :, None] * u[:, None]
            + table[:, 2, None, None] * _SIN[None, :, None] * v[:, None])


def _mean0(a: np.ndarray) -> np.ndarray:
    """``a.mean(0)``: the same sum and division, without ndarray.mean's bookkeeping."""
    return np.add.reduce(a, 0) / a.shape[0]


def limb(joints: np.ndarray, table: np.ndarray, lateral, cls: str, materials) -> Mesh:
    """A closed limb skin (see :func:`chain_rings`), its ends rounded by the fans' apexes."""
    rings = chain_rings(joints, table, lateral)
    c0, c1 = _mean0(rings[0]), _mean0(rings[-1])
    d0, d1 = c0 - _mean0(rings[1]), c1 - _mean0(rings[-2])
    r0, r1 = _mean0(table[0, 1:3]), _mean0(table[-1, 1:3])
    return skin(rings, cls, materials, c0 + 0.6 * r0 * unit(d0), c1 + 0.6 * r1 * unit(d1))


def eased(table: np.ndarray, ease: float, bulge: float = 0.5) -> np.ndarray:
    """A garment's sections over the body's: ``ease`` wider all round, the muscle offsets ``bulge`` as deep."""
    out = table.copy()
    out[:, 1:3] += ease
    out[:, 3] *= bulge
    return out


def hem(table: np.ndarray, s: float, flare: float) -> tuple[np.ndarray, int]:
    """``table`` with a garment edge at ``s``: a ring ``flare`` wider and one at the body's width just
    below it (the band between them is the hem's underside). Returns the table and the hem ring's index."""
    rows = [tuple(r) for r in table]
    body = [np.interp(s, table[:, 0], table[:, c]) for c in (1, 2, 3)]
    at = int(np.searchsorted(table[:, 0], s))
    rows[at:at] = [(s, body[0] + flare, body[1] + flare, body[2]), (s + 0.005, *body)]
    return np.array(rows), at


#: hand sections (palm to finger tips), unit body height
_HAND = np.array([(-0.05, 0.010, 0.016, 0.0), (0.35, 0.013, 0.025, 0.0), (0.95, 0.011, 0.026, 0.0),
                  (1.5, 0.009, 0.021, 0.0), (2.0, 0.006, 0.015, 0.0)])
_HAND.setflags(write=False)


def hand(wrist: np.ndarray, elbow: np.ndarray, side: float, cls: str, material: str, curl: float = 0.35,
         scale: float = 1.0) -> Mesh:
    """A hand continuing the forearm: a flat palm (wide front to back, thin across) tapering into
    fingers that curl ``curl`` radians toward the palm (the body's side ``-side``); ``scale`` the body height."""
    d = unit(np.asarray(wrist, float) - np.asarray(elbow, float))
    lateral = np.array([0.0, side, 0.0])         # out of the body (the curl's sign); the frame uses +y
    knuckle = wrist + 0.058 * scale * d
    tip = knuckle + 0.05 * scale * unit(d * np.cos(curl) - lateral * np.sin(curl))    # toward the palm (the body)
    table = _HAND * [1.0, scale, scale, scale]
    return limb(np.stack([wrist, knuckle, tip]), table, np.array([0.0, 1.0, 0.0]), cls, material)


#: shoe sections along the foot, heel to toe, relative to the ankle: (x, half width, top z); soles at -ANKLE_Z
SHOE = np.array([(gait.HEEL_X, 0.021, -0.008), (-0.03, 0.026, 0.006), (0.015, 0.029, -0.004),
                 (0.06, 0.032, -0.022), (0.095, 0.028, -0.03), (gait.TOE_X, 0.016, -0.036)])


def shoe(ankle: np.ndarray, pitch: float, cls: str, material: str, scale: float = 1.0) -> Mesh:
    """A shoe under ``ankle``: heel counter, collar, instep, a wide ball and a rounded toe, the sole flat
    on z = -ANKLE_Z from HEEL_X to TOE_X (what :mod:`assets_procedural.person_gait` keeps on the ground);
    pitched by ``pitch`` (+ = toe down) about the ankle; ``scale`` the body height."""
    verts, faces, cls_id, mats = _shoe_at_ankle(cls, material)
    c, s = np.cos(pitch), np.sin(pitch)
    rot = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    return Mesh((verts @ rot.T) * scale + ankle, faces, cls_id, mats)


@functools.lru_cache(maxsize=16)
def _shoe_at_ankle(cls: str, material: str) -> tuple[np.ndarray, np.ndarray, int, np.ndarray]:
    """The unposed shoe of :func:`shoe` (vertices relative to the ankle, faces, class id, materials;
    read-only): every shoe is this one rotated, scaled and moved, so it is lofted once."""
    sole = -gait.ANKLE_Z
    a = np.linspace(0.0, 2.0 * np.pi, SIDES, endpoint=False)
    cy, sz = np.cos(a), np.sin(a)
    ey = np.sign(cy) * np.abs(cy) ** 0.7          # a rounded box: flat sole, upright sides
    ez = np.sign(sz) * np.abs(sz) ** 0.7 * np.where(sz < 0, 1.3, 1.0)      # three sole points on the sole
    rings = []
    for x, hw, top in SHOE:
        mid, half = (top + sole) / 2, (top - sole) / 2
        rings.append(np.stack([np.full(SIDES, x), hw * ey, np.maximum(mid + half * ez, sole)], 1))
    rings = np.array(rings)                       # along +x: u = y, v = z
    heel, toe = rings[0].mean(0) - [0.006, 0.0, 0.0], rings[-1].mean(0) + [0.006, 0.0, 0.0]
    m = skin(rings, cls, material, heel, toe)
    for x in (m.vertices, m.face_material):
        x.setflags(write=False)
    return m.vertices, m.faces, int(m.face_class[0]), m.face_material
