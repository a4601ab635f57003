"""Pedestrians: an articulated low-poly figure (~600-750 triangles) facing +x.

Proportions follow standard anthropometric ratios of body height (shoulders at 0.8 h, hips at
0.545 h, knees at 0.3 h). The body is parts joined at joints: head (with hair or a hat), neck,
torso, upper arms, elbows, forearms, hands (palm and fingers), thighs, knees, shins and shoes (heel
and toe); a walking figure's limbs follow the gait cycle of :mod:`assets_procedural.person_gait`.
Every face is class ``person``. Each garment has its own material, so each can take its own
colour per object (:mod:`generator.layout.placement.appearance`): ``clothing`` (the top: torso,
sleeves, a coat, a beanie), ``clothing_bottom`` (trousers, shorts, a skirt), ``shoes`` (shoes, a cap,
a carried bag or a backpack), ``skin`` (face, hands, bare arms and legs) and ``hair``.

Drawn per prototype from its generator: the build (girth 0.88-1.12, shoulder breadth 0.94-1.05), the
garments (trousers, shorts, skirt, long coat; short sleeves), what the arms do (hang, hold a phone to
the ear, hands in the pockets, carry a bag), a walker's hip swing (20-25 degrees) and leading leg,
then (drawn last, after everything the figure drew before) the hair style (:data:`HAIR`), headwear
(:data:`HEADWEAR`) and a backpack.

Given by the caller: the height, the ``age`` and the ``sex``. A child's head is a larger part of
its height (head height about 1/5.5 of stature at 4 years, 1/6.5 at 10, 1/7.5 for adults:
:data:`HEAD_SCALE`), its build slimmer; men's shoulders are broader than women's.

Walking: the mesh returned is the figure at gait phase 0 (both feet down, the leading one ahead);
it also carries the whole cycle as anchors: ``"gait/NN"`` (n, 3) the vertices at phase
``NN / GAIT_PHASES`` (same faces), and ``"gait/stride"`` two points one stride apart (metres walked
per cycle). :mod:`generator.traffic.build` turns these into the phase meshes a walking actor shows.
"""

from __future__ import annotations

import numpy as np

from assets_procedural import person_gait as gait
from generator.geometry import Mesh, box, cylinder, icosphere, loft, merge, resolve_ids, tube

CLS = "person"
POSES = ("standing", "walking")
#: gait phases a walker's cycle is cut into (meshes of the same faces)
GAIT_PHASES = 16
#: age (years) -> head size relative to an adult's of the same height (head height / stature: about
#: 0.18 at 4 years, 0.155 at 10, 0.13 for adults; anthropometric growth charts)
HEAD_AGE = (4.0, 6.0, 10.0, 14.0, 17.0)
HEAD_SCALE = (1.38, 1.3, 1.19, 1.07, 1.0)
SEXES = ("female", "male", None)
#: what the arms do, and how often
ARMS: dict[str, float] = {"hanging": 0.55, "phone": 0.15, "pockets": 0.15, "bag": 0.15}
#: lower-body garments, and how often
GARMENTS: dict[str, float] = {"trousers": 0.58, "shorts": 0.1, "skirt": 0.12, "coat": 0.2}
#: hair styles given long hair (first) or short hair (second), and how often
HAIR: tuple[dict[str, float], dict[str, float]] = ({"long": 0.5, "ponytail": 0.25, "bun": 0.25},
                                                   {"short": 0.7, "buzz": 0.3})
HEADWEAR: dict[str, float] = {"none": 0.8, "cap": 0.1, "beanie": 0.1}
BACKPACK_P = 0.15
#: the standing model's hips lie this much higher than the constants of the torso and head below
DZ_STANDING = gait.HIP_Z - 0.53


def _ring(z: float, half_w: float, half_d: float, x: float = 0.0, k: int = 8) -> np.ndarray:
    a = np.linspace(0, 2 * np.pi, k, endpoint=False)
    return np.stack([x + half_d * np.cos(a), half_w * np.sin(a), np.full(k, z)], 1)


def _limb(top: np.ndarray, angle: float, bend: float, l0: float, l1: float) -> tuple[np.ndarray, np.ndarray]:
    """Joint positions (middle, end) of a limb hanging from ``top``; angles in radians, + = forward (+x)."""
    mid = top + l0 * np.array([np.sin(angle), 0.0, -np.cos(angle)])
    end = mid + l1 * np.array([np.sin(angle + bend), 0.0, -np.cos(angle + bend)])
    return mid, end


def _pick(rng: np.random.Generator, table: dict[str, float]) -> str:
    names = list(table)
    return names[int(rng.choice(len(names), p=np.array(list(table.values()))))]


def _hair_shell(style: str, centre: np.ndarray, radii: np.ndarray) -> list[Mesh]:
    """Hair of ``style`` over a head of ``radii`` at ``centre`` (the face, +x, left bare)."""
    hair = icosphere(1.0, CLS, "hair", 1)
    rel = hair.vertices[hair.faces].mean(1)
    low = {"long": -0.6, "buzz": 0.1}.get(style, -0.15)
    keep = (rel[:, 2] > low) & ~((rel[:, 0] > 0.35) & (rel[:, 2] < 0.5))
    if style == "long":
        keep &= ~((rel[:, 0] > 0.1) & (rel[:, 2] < 0.1))
    grow = 1.03 if style == "buzz" else 1.08
    out = [Mesh(hair.vertices * radii * grow + centre, hair.faces[keep], hair.face_class[keep],
                hair.face_material[keep])]
    if style == "ponytail":
        top = centre + radii * np.array([-0.95, 0.0, 0.2])
        out.append(tube(top, top + radii * np.array([-0.45, 0.0, -1.5]), 0.28 * radii[1], CLS, "hair", 0.14 * radii[1],
                        sections=5))
    elif style == "bun":
        out.append(icosphere(0.45 * radii[1], CLS, "hair", 0, center=centre + radii * np.array([-0.95, 0.0, 0.5])))
    return out


def _headwear(kind: str, centre: np.ndarray, radii: np.ndarray) -> list[Mesh]:
    """A cap (crown and brim, ``shoes`` material) or a beanie (``clothing``) over the head."""
    if kind == "none":
        return []
    shell = icosphere(1.0, CLS, "shoes" if kind == "cap" else "clothing", 1)
    rel = shell.vertices[shell.faces].mean(1)
    keep = rel[:, 2] > (0.15 if kind == "cap" else 0.0)
    out = [Mesh(shell.vertices * radii * 1.12 + centre, shell.faces[keep], shell.face_class[keep],
                shell.face_material[keep])]
    if kind == "cap":
        brim = centre + radii * np.array([1.2, 0.0, 0.3])
        out.append(box((0.9 * radii[0], 1.5 * radii[1], 0.08 * radii[2]), CLS, "shoes", tuple(brim)))
    return out


def _head_parts(h: float, k: float = 1.0, style: str = "short", headwear: str = "none") -> list[Mesh]:
    """Head, hair, headwear and neck (hips at 0.53 h); ``k`` scales the head about its chin."""
    centre = np.array([0.01 * h, 0.0, (0.859 + 0.066 * k) * h])
    radii = np.array([0.056, 0.05, 0.066]) * h * k
    head = icosphere(1.0, CLS, "skin", 1)
    head.vertices = head.vertices * radii + centre
    neck = tube((0, 0, 0.82 * h), (0.005 * h, 0, 0.88 * h), 0.028 * h, CLS, "skin", sections=6, caps=False)
    return [head, *_hair_shell(style, centre, radii), *_headwear(headwear, centre, radii), neck]


def _head(h: float, rng: np.random.Generator, k: float = 1.0) -> list[Mesh]:
    """Head, hair and neck with long or short hair drawn from ``rng`` (one draw; riders use it)."""
    return _head_parts(h, k, "long" if rng.random() < 0.4 else "short")


def _torso(girth: float, breadth: float, garment: str) -> Mesh:
    """Hips to neck base (unit height), the waistband down in ``clothing_bottom`` (the top in a coat)."""
    g = girth
    rings = [_ring(0.48, 0.088 * g, 0.06 * g), _ring(0.555, 0.082 * g, 0.058 * g), _ring(0.62, 0.078 * g, 0.058 * g),
             _ring(0.72, 0.095 * g * breadth, 0.066 * g), _ring(0.795, 0.11 * g * breadth, 0.058 * g),
             _ring(0.835, 0.045, 0.04)]
    hem = {"coat": _ring(0.36, 0.1 * g, 0.075 * g), "skirt": _ring(0.35, 0.118 * g, 0.092 * g)}.get(garment)
    if hem is not None:
        rings.insert(0, hem)
    torso = loft(np.array(rings), CLS, "clothing")
    n_bottom = {"coat": 0, "skirt": 2}.get(garment, 1)            # ring gaps below the waistband
    _, bottom = resolve_ids(CLS, "clothing_bottom")
    torso.face_material[: 2 * 8 * n_bottom] = bottom
    if n_bottom:
        torso.face_material[-16:-8] = bottom                        # the cap under the hips
    return torso


_SIDES = 6
_RING = np.stack([np.cos(np.linspace(0, 2 * np.pi, _SIDES, endpoint=False)),
                  np.sin(np.linspace(0, 2 * np.pi, _SIDES, endpoint=False))], 1)
#: faces of a 6-sided tube with and without end caps (the vertex order of :func:`generator.geometry.cylinder`)
_TUBE_FACES = {caps: cylinder(1.0, 1.0, CLS, "skin", _SIDES, caps=caps).faces for caps in (True, False)}


def _limb_tube(p0: np.ndarray, p1: np.ndarray, r0: float, r1: float, material: str, caps: bool = True) -> Mesh:
    """A 6-sided tapered tube from ``p0`` to ``p1`` (as :func:`generator.geometry.tube` builds it, in a
    fraction of its time: a walker builds ~20 per gait phase)."""
    axis = np.asarray(p1, float) - np.asarray(p0, float)
    length = float(np.sqrt(axis @ axis))
    w = axis / length
    h = (0.0, 0.0, 1.0) if abs(w[2]) < 0.9 else (1.0, 0.0, 0.0)
    u = np.array([h[1] * w[2] - h[2] * w[1], h[2] * w[0] - h[0] * w[2], h[0] * w[1] - h[1] * w[0]])
    u /= np.sqrt(u @ u)
    v = np.array([w[1] * u[2] - w[2] * u[1], w[2] * u[0] - w[0] * u[2], w[0] * u[1] - w[1] * u[0]])
    ring = _RING[:, :1] * u + _RING[:, 1:] * v
    verts = [p0 + r0 * ring, p1 + r1 * ring] + ([np.stack([p0, p1])] if caps else [])
    c, m = resolve_ids(CLS, material)
    return Mesh(np.concatenate(verts), _TUBE_FACES[caps], c, m)


def _oriented(center: np.ndarray, axes: np.ndarray, size: tuple[float, float, float], material: str,
              cls: str = CLS) -> Mesh:
    """A box of ``size`` along the columns of ``axes`` (3x3, orthonormal) centred on ``center``."""
    b = box(size, cls, material)
    return Mesh(b.vertices @ axes.T + center, b.faces, b.face_class, b.face_material)


def _hand(wrist: np.ndarray, elbow: np.ndarray, material: str = "skin", k: float = 1.0, cls: str = CLS) -> list[Mesh]:
    """Palm and fingers continuing the forearm, flat across it (palm toward the body's side); ``k`` is the
    body height (the sizes are fractions of it), ``cls`` the class of the faces (a rider's)."""
    d = (wrist - elbow) / np.linalg.norm(wrist - elbow)
    w = np.cross(d, [0.0, 1.0, 0.0])
    if np.linalg.norm(w) < 0.3:
        w = np.cross(d, [1.0, 0.0, 0.0])
    w /= np.linalg.norm(w)
    axes = np.stack([d, w, np.cross(d, w)], 1)
    palm = _oriented(wrist + 0.03 * k * d, axes, (0.058 * k, 0.046 * k, 0.022 * k), material, cls)
    fingers = _oriented(wrist + 0.08 * k * d, axes, (0.045 * k, 0.04 * k, 0.015 * k), material, cls)
    return [palm, fingers]


def _shoe(ankle: np.ndarray, pitch: float) -> Mesh:
    """A shoe under ``ankle``: heel to toe, the toe box lower than the instep, pitched (+ = toe down)."""
    b = box((gait.TOE_X - gait.HEEL_X, 0.056, gait.ANKLE_Z - 0.004), CLS, "shoes",
            ((gait.TOE_X + gait.HEEL_X) / 2, 0.0, -(gait.ANKLE_Z + 0.004) / 2))
    v = b.vertices.copy()
    toe_top = (v[:, 0] > 0) & (v[:, 2] > -0.02)
    v[toe_top, 2] = -0.028
    c, s = np.cos(pitch), np.sin(pitch)
    v = v @ np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]).T
    return Mesh(v + ankle, b.faces, b.face_class, b.face_material)


def _draw(rng: np.random.Generator, pose: str, sex: str | None) -> dict:
    """Every random choice of a figure, in the order the figure always drew them (new ones last)."""
    girth = rng.uniform(0.88, 1.12)
    breadth = rng.uniform(0.94, 1.05) + {"female": -0.03, "male": 0.03}.get(sex, 0.0)
    garment = _pick(rng, GARMENTS)
    if sex == "male" and garment == "skirt":
        garment = "trousers"
    short_sleeves = garment != "coat" and rng.random() < 0.3
    arms = [_pick(rng, ARMS), "hanging"]
    if rng.random() < 0.5:
        arms.reverse()
    amplitude, lead = 0.0, 0.0
    if pose == "walking":
        amplitude = np.radians(rng.uniform(20, 25))
        lead = 0.0 if rng.random() < 0.5 else 0.5
    long_hair = rng.random() < 0.4
    bends = [np.radians(rng.uniform(8, 25)) if a in ("hanging", "bag") else 0.0 for a in arms]
    style = _pick(rng, HAIR[0 if long_hair else 1])
    headwear = _pick(rng, HEADWEAR)
    backpack = "bag" not in arms and rng.random() < BACKPACK_P
    return dict(girth=girth, breadth=breadth, garment=garment, short_sleeves=short_sleeves, arms=arms,
                amplitude=amplitude, lead=lead, style=style, headwear=headwear, backpack=backpack, bends=bends)


def _body(d: dict, head_k: float) -> Mesh:
    """The parts that do not articulate (torso, head, neck, a backpack), hips at 0.53, unit height."""
    g = d["girth"]
    parts = [_torso(g, d["breadth"], d["garment"]), *_head_parts(1.0, head_k, d["style"], d["headwear"])]
    if d["backpack"]:
        parts.append(box((0.11, 0.22 * g, 0.27), CLS, "shoes", (-0.066 * g - 0.052, 0.0, 0.66)))
    return merge(parts)


def _limbs(d: dict, phi: float | None) -> tuple[Mesh, float]:
    """Legs and arms at gait phase ``phi`` (None: standing), and the pelvis lift ``dz`` they need."""
    g = d["girth"]
    garment = d["garment"]
    thigh = "skin" if garment == "skirt" else "clothing_bottom"
    shin = "skin" if garment in ("skirt", "shorts") else "clothing_bottom"
    sleeve = "skin" if d["short_sleeves"] else "clothing"
    phase = None if phi is None else (phi + d["lead"]) % 1.0
    legs, hip_z = gait.legs(phase, d["amplitude"], 0.052 * g)
    dz = hip_z - 0.53
    parts = []
    for leg in legs:
        parts += [_limb_tube(leg.hip, leg.knee, 0.05 * g, 0.037, thigh),
                  icosphere(0.036, CLS, shin, 0, center=tuple(leg.knee)),
                  _limb_tube(leg.knee, leg.ankle, 0.035, 0.024, shin, caps=False),
                  _shoe(leg.ankle, leg.pitch)]
    for side, action, bend in zip((1.0, -1.0), d["arms"], d["bends"], strict=True):
        shoulder = np.array([0.0, side * 0.1 * g * d["breadth"], 0.79 + dz])
        l1, l2 = 0.175, 0.15
        if action == "phone":
            elbow, wrist = gait.two_link(shoulder, np.array([0.03, side * 0.075, 0.9 + dz]), l1, l2,
                                         np.array([0.35, side * 0.3, -1.0]))
        elif action == "pockets":
            elbow, wrist = gait.two_link(shoulder, np.array([0.03, side * 0.095, 0.5 + dz]), l1, l2,
                                         np.array([-1.0, side * 0.45, 0.0]))
        else:                                                        # hanging (swinging when walking) or a bag
            swing = gait.arm_angle(phase, d["amplitude"], side) if action == "hanging" else 0.03
            elbow, wrist = _limb(shoulder, swing, bend + 0.6 * max(swing, 0.0), l1, l2)
            elbow[1] += side * 0.02
            wrist[1] += side * 0.025
        parts += [_limb_tube(shoulder, elbow, 0.032 * g, 0.026, "clothing"),
                  icosphere(0.026, CLS, sleeve, 0, center=tuple(elbow)),
                  _limb_tube(elbow, wrist, 0.025, 0.019, sleeve, caps=False), *_hand(wrist, elbow)]
        if action == "bag":
            grip = wrist + 0.06 * (wrist - elbow) / np.linalg.norm(wrist - elbow)
            parts.append(box((0.17, 0.05, 0.19), CLS, "shoes", (grip[0], grip[1], grip[2] - 0.105)))
    return merge(parts), dz


def _posed(body: Mesh, d: dict, phi: float | None) -> Mesh:
    limbs, dz = _limbs(d, phi)
    return merge([Mesh(body.vertices + [0.0, 0.0, dz], body.faces, body.face_class, body.face_material), limbs])


def person(rng: np.random.Generator, height: float, pose: str = "standing", age: float = 30.0,
           sex: str | None = None) -> Mesh:
    """A pedestrian ``height`` metres tall, facing +x.

    Parameters
    ----------
    rng : numpy.random.Generator
        Build, garments, hair, headwear, gait and what the arms do are drawn from it.
    height : float
        Standing stature, metres (0.9-2.2): the top of the head (or hat) of the standing figure.
    pose : {"standing", "walking"}
        Walking: the figure at gait phase 0 carrying its whole cycle (module docstring), hips
        swinging 20-25 degrees, arms opposite the legs.
    age : float
        Years; below 17 the head grows relative to the height (:data:`HEAD_SCALE`) and the build
        slims (girth x0.92 under 14).
    sex : {"female", "male"} or None
        Shoulder breadth -0.03 / +0.03; men wear no skirt (trousers instead). None: neither.

    Returns
    -------
    Mesh
        Class ``person``; soles at z = 0. Standing: the top exactly ``height`` above the ground;
        walking: up to 2 % lower (the knees are never quite straight).
    """
    if pose not in POSES:
        raise ValueError(f"person pose must be one of {POSES}, got {pose!r}")
    if not 0.9 <= height <= 2.2:
        raise ValueError(f"person height must be in [0.9, 2.2] m, got {height}")
    if sex not in SEXES:
        raise ValueError(f"person sex must be one of {SEXES}, got {sex!r}")
    d = _draw(rng, pose, sex)
    if age < 14:
        d["girth"] *= 0.92
    body = _body(d, float(np.interp(age, HEAD_AGE, HEAD_SCALE)))
    s = height / (float(body.vertices[:, 2].max()) + DZ_STANDING)
    scale = np.diag([s, s, s, 1.0])
    if pose == "standing":
        return _posed(body, d, None).transformed(scale)
    frames = [_posed(body, d, k / GAIT_PHASES).transformed(scale) for k in range(GAIT_PHASES)]
    for f in frames:                                 # a planted sole lies on z = 0 (not 1e-17 below it)
        np.maximum(f.vertices[:, 2], 0.0, out=f.vertices[:, 2])
    out = frames[0]
    out.anchors = {f"gait/{k:02d}": f.vertices for k, f in enumerate(frames)}
    out.anchors["gait/stride"] = np.array([[0.0, 0.0, 0.0], [s * gait.stride(d["amplitude"]), 0.0, 0.0]])
    return out
