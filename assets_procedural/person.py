"""Pedestrians: an articulated, shaped figure (~1 800-2 100 triangles) facing +x.

Proportions follow standard anthropometric ratios of body height (shoulders at 0.8 h, hips at
0.545 h, knees at 0.3 h) and breadths (:data:`TORSO`). The body is parts joined at joints, each a
skin of shaped cross-sections rather than a cylinder (:mod:`assets_procedural.person_shape`,
:mod:`assets_procedural.person_head`): a torso from the crotch over hips, waist, chest and shoulders
into the neck (women's hips wider and waist narrower, men's shoulders broader); legs whose thighs
taper to the knee and whose calves bulge behind the shin; arms with a deltoid over the shoulder and a
flat wrist; hands with a palm and curled fingers; shoes with a heel, an instep and a toe; a head with
a skull, a jaw narrowing to the chin, a nose, a brow and ears, under hair that is a volume. A walking
figure's limbs follow the gait cycle of :mod:`assets_procedural.person_gait`.
Every face is class ``person``. Each garment has its own material, so each can take its own
colour per object (:mod:`generator.layout.placement.appearance`): ``clothing`` (the top: torso,
sleeves, a jacket, a coat, a beanie), ``clothing_bottom`` (trousers, shorts, a skirt), ``shoes`` (shoes,
a cap, a carried bag or a backpack), ``skin`` (face, neck, hands, bare arms and legs) and ``hair``.
Garments have their own silhouettes: trousers looser than the leg with a hem over the shoe, shorts
ending above the knee with a hem, a skirt flaring from the waist, a hip-length jacket whose hem stands
proud of the trousers, a coat to mid-thigh, short sleeves with a hem over the biceps.

Drawn per prototype from its generator: the build (girth 0.88-1.12, shoulder breadth 0.94-1.05), the
garments (trousers, shorts, skirt, long coat; short sleeves), what the arms do (hang, hold a phone to
the ear, hands in the pockets, carry a bag), a walker's hip swing (20-25 degrees) and leading leg,
then (drawn last, after everything the figure drew before) the hair style (:data:`HAIR`), headwear
(:data:`HEADWEAR`), a backpack and (last of all) a jacket over trousers or shorts (:data:`JACKET_P`).

Given by the caller: the height, the ``age`` and the ``sex``. A child's head is a larger part of
its height (head height about 1/5.5 of stature at 4 years, 1/6.5 at 10, 1/7.5 for adults:
:data:`HEAD_SCALE`), its build slimmer; men's shoulders are broader than women's.

Walking: the mesh returned is the figure at gait phase 0 (both feet down, the leading one ahead);
it also carries the whole cycle as anchors: ``"gait/NN"`` (n, 3) the vertices at phase
``NN / GAIT_PHASES`` (same faces), and ``"gait/stride"`` two points one stride apart (metres walked
per cycle). :mod:`generator.traffic.build` turns these into the phase meshes a walking actor shows.
"""

from __future__ import annotations

import functools

import numpy as np

from assets_procedural import person_gait as gait
from assets_procedural import person_head as head
from assets_procedural import person_shape as shape
from generator.geometry import Mesh, box, merge

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
#: a hip-length jacket over trousers or shorts, how often (drawn after everything else)
JACKET_P = 0.35
#: the standing model's hips lie this much higher than the constants of the torso and head below
DZ_STANDING = gait.HIP_Z - 0.53


#: torso sections (z, half width, half depth, forward offset of the centre), unit body height, hips at
#: 0.53: crotch, hips over the buttocks, iliac crest, waist, lower ribs, chest, upper chest, shoulders,
#: shoulder tops, trapezius, neck, the neck's top inside the head (adult breadths: hips 0.35 m, waist
#: 0.29 m, chest 0.32 m, biacromial 0.39 m at 1.75 m stature)
TORSO = np.array([(0.468, 0.058, 0.044, -0.004), (0.5, 0.094, 0.062, -0.008), (0.545, 0.092, 0.06, -0.005),
                  (0.6, 0.082, 0.056, 0.0), (0.65, 0.086, 0.059, 0.004), (0.705, 0.093, 0.065, 0.008),
                  (0.76, 0.099, 0.062, 0.004), (0.8, 0.106, 0.053, -0.004), (0.826, 0.094, 0.046, -0.006),
                  (0.842, 0.046, 0.038, -0.004), (0.862, 0.032, 0.033, 0.008), (0.888, 0.029, 0.031, 0.02)])
#: half the distance between the hip joints (the thighs touch at the crotch, not below it)
HIP_Y = 0.053
#: the trousers' (shorts', skirt's) waistband: torso bands below this height are ``clothing_bottom``
WAIST_Z = 0.6
#: sex -> width factor of the hips, the waist and the shoulders; extra chest depth
SEX_SHAPE = {"female": (1.07, 0.93, 0.96, 0.007), "male": (0.97, 1.03, 1.03, 0.0), None: (1.0, 1.0, 1.0, 0.003)}
TORSO_SIDES = 12
_TA = np.linspace(0.0, 2.0 * np.pi, TORSO_SIDES, endpoint=False)
_TX, _TY = np.sign(np.cos(_TA)) * np.abs(np.cos(_TA)) ** 0.8, np.sign(np.sin(_TA)) * np.abs(np.sin(_TA)) ** 0.8


def _limb(top: np.ndarray, angle: float, bend: float, l0: float, l1: float) -> tuple[np.ndarray, np.ndarray]:
    """Joint positions (middle, end) of a limb hanging from ``top``; angles in radians, + = forward (+x)."""
    mid = top + l0 * np.array([np.sin(angle), 0.0, -np.cos(angle)])
    end = mid + l1 * np.array([np.sin(angle + bend), 0.0, -np.cos(angle + bend)])
    return mid, end


def _pick(rng: np.random.Generator, table: dict[str, float]) -> str:
    names = list(table)
    return names[int(rng.choice(len(names), p=np.array(list(table.values()))))]


def _head_parts(h: float, k: float = 1.0, style: str = "short", headwear: str = "none", cls: str = CLS) -> list[Mesh]:
    """Head, hair and headwear (hips at 0.53 h); ``k`` scales the head about its chin."""
    centre = np.array([0.012, 0.0, 0.859 + 0.066 * k]) * h
    return [head.head(centre, k * h, cls), *head.hair(style, centre, k * h, cls),
            *head.headwear(headwear, centre, k * h, cls)]


def _head(h: float, rng: np.random.Generator, k: float = 1.0, cls: str = CLS) -> list[Mesh]:
    """Head and hair with long or short hair drawn from ``rng`` (one draw; riders use it)."""
    return _head_parts(h, k, "long" if rng.random() < 0.4 else "short", cls=cls)


def torso_sections(girth: float, breadth: float, sex: str | None, garment: str,
                   jacket: bool = False) -> tuple[np.ndarray, list[str]]:
    """Torso rings (s, 12, 3) bottom to top (hips at 0.53, unit height) and each band's material:
    the waistband down in ``clothing_bottom`` (a coat or a jacket covering it in ``clothing``), a skirt
    flaring to above the knees, a coat's hem at mid-thigh, the neck in ``skin``."""
    hips, waist, shoulders, bust = SEX_SHAPE[sex]
    t = TORSO.copy()
    t[:, 1] *= np.interp(t[:, 0], [0.5, 0.545, 0.6, 0.65, 0.76, 0.826], [hips, hips, waist, 1.0, 1.0, shoulders])
    t[:, 1] *= np.interp(t[:, 0], [0.65, 0.705, 0.826, 0.842], [1.0, breadth, breadth, 1.0])
    t[:, 1:3] *= np.interp(t[:, 0], [0.826, 0.862], [girth, 1.0])[:, None]
    t[5, 2:4] += bust
    rows = [tuple(r) for r in t]
    top_from = WAIST_Z
    if garment == "coat":                        # hem at mid-thigh, hanging straight from the hips
        rows = [(0.36, 0.108 * girth, 0.08 * girth, -0.006), (0.43, 0.104 * girth, 0.074 * girth, -0.006)] + rows[1:]
        top_from = 0.0
    elif garment == "skirt":
        rows = [(0.35, 0.118 * girth, 0.095 * girth, 0.0), (0.43, 0.104 * girth, 0.077 * girth, -0.004)] + rows[1:]
    elif jacket:                                 # a hip-length jacket: its hem a lip over the trousers
        z, w, d, x = rows[0]
        rows[1:1] = [(0.487, 0.085 * girth, 0.058 * girth, x), (0.49, 0.1 * girth, 0.068 * girth, -0.007)]
        top_from = 0.486
    rows = np.array(rows)
    if garment == "coat" or jacket:              # the top garment's ease over the chest and waist
        rows[(rows[:, 0] >= top_from) & (rows[:, 0] < 0.82), 1:3] += 0.005
    rings = np.stack([rows[:, 3:4] + rows[:, 2:3] * _TX, rows[:, 1:2] * _TY,
                      np.broadcast_to(rows[:, :1], (len(rows), TORSO_SIDES))], -1)
    mats = ["skin" if lo >= 0.842 else "clothing" if lo >= top_from else "clothing_bottom" for lo in rows[:-1, 0]]
    return rings, mats


@functools.lru_cache(maxsize=16)
def _legs_table(garment: str) -> tuple[np.ndarray, tuple[str, ...]]:
    """:func:`_legs_table_of`, made once per garment (read-only; a walker asks once per gait phase)."""
    t, m = _legs_table_of(garment)
    t = t.copy()
    t.setflags(write=False)
    return t, tuple(m)


@functools.lru_cache(maxsize=16)
def _arms_table(short_sleeves: bool, coat: bool) -> tuple[np.ndarray, tuple[str, ...]]:
    """:func:`_arms_table_of`, made once per sleeve (read-only)."""
    t, m = _arms_table_of(short_sleeves, coat)
    t = t.copy()
    t.setflags(write=False)
    return t, tuple(m)


def _legs_table_of(garment: str) -> tuple[np.ndarray, list[str]]:
    """Leg sections and band materials: trousers to the ankle, shorts above the knee, bare under a skirt."""
    bare = shape.LEG
    if garment == "skirt":
        return bare, ["skin"] * (len(bare) - 1)
    if garment == "shorts":
        t, at = shape.hem(shape.eased(bare, 0.008, 0.4), 0.62, 0.008)
        t = np.concatenate([t[: at + 2], bare[bare[:, 0] > 0.63]])
        return t, ["clothing_bottom"] * (at + 1) + ["skin"] * (len(t) - at - 2)
    t, at = shape.hem(shape.eased(bare, 0.007, 0.35), 1.9, 0.004)
    t = np.concatenate([t[: at + 2], bare[bare[:, 0] > 1.91]])
    return t, ["clothing_bottom"] * (at + 1) + ["skin"] * (len(t) - at - 2)


def _arms_table_of(short_sleeves: bool, coat: bool) -> tuple[np.ndarray, list[str]]:
    """Arm sections and band materials: a short sleeve's hem above the biceps, a long one's cuff."""
    bare = shape.ARM
    s, ease = (0.45, 0.006) if short_sleeves else (1.86, 0.009 if coat else 0.005)
    t, at = shape.hem(shape.eased(bare, ease, 0.4), s, 0.006)
    t = np.concatenate([t[: at + 2], bare[bare[:, 0] > s + 0.01]])
    return t, ["clothing"] * (at + 1) + ["skin"] * (len(t) - at - 2)


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
    jacket = garment in ("trousers", "shorts") and rng.random() < JACKET_P
    return dict(girth=girth, breadth=breadth, garment=garment, short_sleeves=short_sleeves and not jacket,
                arms=arms, amplitude=amplitude, lead=lead, style=style, headwear=headwear, backpack=backpack,
                bends=bends, jacket=jacket, sex=sex)


def _body(d: dict, head_k: float) -> Mesh:
    """The parts that do not articulate (torso and neck, head, hair, a backpack), hips at 0.53, unit height."""
    g = d["girth"]
    rings, mats = torso_sections(g, d["breadth"], d["sex"], d["garment"], d["jacket"])
    torso = shape.skin(rings, CLS, mats, rings[0].mean(0) - [0.0, 0.0, 0.01], rings[-1].mean(0) + [0.0, 0.0, 0.01])
    parts = [torso, *_head_parts(1.0, head_k, d["style"], d["headwear"])]
    if d["backpack"]:
        parts.append(box((0.11, 0.22 * g, 0.27), CLS, "shoes", (-0.066 * g - 0.052, 0.0, 0.66)))
    return merge(parts)


def _limbs(d: dict, phi: float | None) -> tuple[Mesh, float]:
    """Legs and arms at gait phase ``phi`` (None: standing), and the pelvis lift ``dz`` they need."""
    g, garment = d["girth"], d["garment"]
    phase = None if phi is None else (phi + d["lead"]) % 1.0
    legs, hip_z = gait.legs(phase, d["amplitude"], HIP_Y * g)
    dz = hip_z - 0.53
    leg_t, leg_m = _legs_table(garment)
    leg_t = leg_t * [1.0, g, g, g]
    arm_t, arm_m = _arms_table(d["short_sleeves"], garment == "coat")
    arm_t = arm_t * [1.0, g, g, g]
    y = np.array([0.0, 1.0, 0.0])
    parts = []
    for leg in legs:
        parts += [shape.limb(np.stack([leg.hip, leg.knee, leg.ankle]), leg_t, y, CLS, leg_m),
                  shape.shoe(leg.ankle, leg.pitch, CLS, "shoes")]
    for side, action, bend in zip((1.0, -1.0), d["arms"], d["bends"], strict=True):
        shoulder = np.array([0.0, side * 0.1 * g * d["breadth"], 0.79 + dz])
        l1, l2 = 0.175, 0.15
        if action == "phone":
            elbow, wrist = gait.two_link(shoulder, np.array([0.03, side * 0.085, 0.9 + dz]), l1, l2,
                                         np.array([0.35, side * 0.3, -1.0]))
        elif action == "pockets":
            elbow, wrist = gait.two_link(shoulder, np.array([0.03, side * 0.095, 0.5 + dz]), l1, l2,
                                         np.array([-1.0, side * 0.45, 0.0]))
        else:                                                        # hanging (swinging when walking) or a bag
            swing = gait.arm_angle(phase, d["amplitude"], side) if action == "hanging" else 0.03
            elbow, wrist = _limb(shoulder, swing, bend + 0.6 * max(swing, 0.0), l1, l2)
            elbow[1] += side * 0.02
            wrist[1] += side * 0.025
        pocket = "clothing" if garment == "coat" else "clothing_bottom"    # a hand in a pocket: the pocket's bulge
        parts += [shape.limb(np.stack([shoulder, elbow, wrist]), arm_t, y, CLS, arm_m),
                  shape.hand(wrist, elbow, side, CLS, pocket if action == "pockets" else "skin")]
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
