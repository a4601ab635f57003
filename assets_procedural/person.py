"""Pedestrians: a low-poly articulated figure (~450-520 triangles) facing +x.

Proportions follow standard anthropometric ratios of body height (shoulders at 0.8 h,
hips at 0.53 h, knees at 0.285 h). Every face is class ``person``. Each garment has its own
material, so each can take its own colour per object (:mod:`generator.layout.placement.appearance`):
``clothing`` (the top: torso, sleeves, a coat), ``clothing_bottom`` (trousers, shorts, a
skirt), ``shoes`` (shoes and a carried bag), ``skin`` (face, hands, bare arms and legs) and
``hair``.

Drawn per prototype from its generator: the build (girth 0.88-1.12, shoulder breadth 0.94-1.05), the
garments (trousers, shorts, skirt, long coat; short sleeves), the hair, and what the arms do
(hang, hold a phone to the ear, hands in the pockets, carry a bag).

Given by the caller: the height, the ``age`` and the ``sex``. A child's head is a larger part of
its height (head height about 1/5.5 of stature at 4 years, 1/6.5 at 10, 1/7.5 for adults:
:data:`HEAD_SCALE`), its build slimmer; men's shoulders are broader than women's.
"""

from __future__ import annotations

import numpy as np

from assets_procedural.parts import two_link
from generator.geometry import Mesh, box, icosphere, loft, merge, on_ground, resolve_ids, tube

CLS = "person"
POSES = ("standing", "walking")
#: what the arms do, and how often
#: age (years) -> head size relative to an adult's of the same height (head height / stature: about
#: 0.18 at 4 years, 0.155 at 10, 0.13 for adults; anthropometric growth charts)
HEAD_AGE = (4.0, 6.0, 10.0, 14.0, 17.0)
HEAD_SCALE = (1.38, 1.3, 1.19, 1.07, 1.0)
SEXES = ("female", "male", None)
ARMS: dict[str, float] = {"hanging": 0.55, "phone": 0.15, "pockets": 0.15, "bag": 0.15}
#: lower-body garments, and how often
GARMENTS: dict[str, float] = {"trousers": 0.58, "shorts": 0.1, "skirt": 0.12, "coat": 0.2}


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


def _head(h: float, rng: np.random.Generator, k: float = 1.0) -> list[Mesh]:
    """Head, hair and neck; ``k`` scales the head about its chin (the neck stays)."""
    centre = np.array([0.01 * h, 0.0, (0.859 + 0.066 * k) * h])
    radii = np.array([0.056, 0.05, 0.066]) * h * k
    head = icosphere(1.0, CLS, "skin", 1)
    head.vertices = head.vertices * radii + centre
    hair = icosphere(1.0, CLS, "hair", 1)
    rel = hair.vertices[hair.faces].mean(1)
    long_hair = rng.random() < 0.4
    keep = (rel[:, 2] > (-0.6 if long_hair else -0.15)) & ~((rel[:, 0] > 0.35) & (rel[:, 2] < 0.5))
    if long_hair:
        keep &= ~((rel[:, 0] > 0.1) & (rel[:, 2] < 0.1))
    hair = Mesh(hair.vertices * radii * 1.08 + centre, hair.faces[keep], hair.face_class[keep],
                hair.face_material[keep])
    neck = tube((0, 0, 0.82 * h), (0.005 * h, 0, 0.88 * h), 0.028 * h, CLS, "skin", sections=6, caps=False)
    return [head, hair, neck]


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


def _arm(side: float, shoulder: np.ndarray, action: str, swing: float, rng: np.random.Generator,
         girth: float, short_sleeves: bool) -> list[Mesh]:
    """Upper arm, forearm, hand (and a bag) of one arm, unit height."""
    l1, l2 = 0.175, 0.15
    if action == "phone":
        elbow, wrist = two_link(
            shoulder, np.array([0.03, side * 0.075, 0.9]), l1, l2, np.array([0.35, side * 0.3, -1.0])
        )
    elif action == "pockets":
        elbow, wrist = two_link(
            shoulder, np.array([0.03, side * 0.095, 0.5]), l1, l2, np.array([-1.0, side * 0.45, 0.0])
        )
    else:                                                            # hanging (swinging when walking) or a bag
        elbow, wrist = _limb(shoulder, swing if action == "hanging" else 0.03, np.radians(rng.uniform(8, 25)), l1, l2)
        elbow[1] += side * 0.02
        wrist[1] += side * 0.025
    parts = [tube(shoulder, elbow, 0.032 * girth, CLS, "clothing", 0.026, sections=6),
             tube(elbow, wrist, 0.025, CLS, "skin" if short_sleeves else "clothing", 0.019, sections=6, caps=False)]
    hand = icosphere(1.0, CLS, "skin", 0)
    d = (wrist - elbow) / np.linalg.norm(wrist - elbow)
    hand.vertices = hand.vertices * np.array([0.022, 0.014, 0.045]) + wrist + d * 0.035
    parts.append(hand)
    if action == "bag":
        grip = wrist + d * 0.06
        parts.append(box((0.17, 0.05, 0.19), CLS, "shoes", (grip[0], grip[1], grip[2] - 0.105)))
    return parts


def person(rng: np.random.Generator, height: float, pose: str = "standing", age: float = 30.0,
           sex: str | None = None) -> Mesh:
    """A pedestrian ``height`` metres tall, facing +x.

    Parameters
    ----------
    rng : numpy.random.Generator
        Build, garments, hair, stride and what the arms do are drawn from it.
    height : float
        Top of the head, metres (0.9-2.2).
    pose : {"standing", "walking"}
        Walking: legs and free arms swing in opposite phase (stride 15-25 degrees).
    age : float
        Years; below 17 the head grows relative to the height (:data:`HEAD_SCALE`) and the build
        slims (girth x0.92 under 14).
    sex : {"female", "male"} or None
        Shoulder breadth -0.03 / +0.03; men wear no skirt (trousers instead). None: neither.

    Returns
    -------
    Mesh
        Class ``person``; the top of the hair exactly ``height`` above the ground, the soles at z = 0.
    """
    if pose not in POSES:
        raise ValueError(f"person pose must be one of {POSES}, got {pose!r}")
    if not 0.9 <= height <= 2.2:
        raise ValueError(f"person height must be in [0.9, 2.2] m, got {height}")
    if sex not in SEXES:
        raise ValueError(f"person sex must be one of {SEXES}, got {sex!r}")
    girth = rng.uniform(0.88, 1.12) * (0.92 if age < 14 else 1.0)
    breadth = rng.uniform(0.94, 1.05) + {"female": -0.03, "male": 0.03}.get(sex, 0.0)
    garment = _pick(rng, GARMENTS)
    if sex == "male" and garment == "skirt":
        garment = "trousers"
    short_sleeves = garment != "coat" and rng.random() < 0.3
    arms = [_pick(rng, ARMS), "hanging"]
    if rng.random() < 0.5:
        arms.reverse()
    swing = np.radians(rng.uniform(15, 25)) * (1 if rng.random() < 0.5 else -1) if pose == "walking" else 0.0
    parts = [_torso(girth, breadth, garment)] + _head(1.0, rng, float(np.interp(age, HEAD_AGE, HEAD_SCALE)))
    thigh = "skin" if garment == "skirt" else "clothing_bottom"
    shin = "skin" if garment in ("skirt", "shorts") else "clothing_bottom"
    for (side, phase), action in zip(((1.0, 1.0), (-1.0, -1.0)), arms, strict=False):
        # legs: the side with phase +1 steps forward, the other pushes off with a bent knee
        hip = np.array([0.0, side * 0.052 * girth, 0.53])
        leg = phase * swing
        knee, ankle = _limb(hip, leg, -np.radians(22) if leg < 0 else -np.radians(4), 0.245, 0.25)
        parts.append(tube(hip, knee, 0.05 * girth, CLS, thigh, 0.037, sections=6))
        parts.append(tube(knee, ankle + [0, 0, -0.01], 0.035, CLS, shin, 0.024, sections=6, caps=False))
        parts.append(box((0.15, 0.055, 0.045), CLS, "shoes", (ankle[0] + 0.035, ankle[1], ankle[2] - 0.0275)))
        # arms swing against the leg on the same side
        shoulder = np.array([0.0, side * 0.1 * girth * breadth, 0.79])
        parts += _arm(side, shoulder, action, -0.8 * leg, rng, girth, short_sleeves)
    out = on_ground(merge(parts))
    s = height / float(out.vertices[:, 2].max())
    return out.transformed(np.diag([s, s, s, 1.0]))
