"""Pedestrians: a low-poly articulated figure (~420 triangles) facing +x.

Proportions follow standard anthropometric ratios of body height (shoulders at 0.8 h,
hips at 0.53 h, knees at 0.285 h). Every face is class ``person``; materials ``skin``
(face, hands, optionally forearms and shins), ``hair``, ``clothing`` and ``rubber`` (shoes).
"""

from __future__ import annotations

import numpy as np

from generator.geometry import Mesh, box, icosphere, loft, merge, on_ground, tube

CLS = "person"
POSES = ("standing", "walking")


def _ring(z: float, half_w: float, half_d: float, x: float = 0.0, k: int = 8) -> np.ndarray:
    a = np.linspace(0, 2 * np.pi, k, endpoint=False)
    return np.stack([x + half_d * np.cos(a), half_w * np.sin(a), np.full(k, z)], 1)


def _limb(top: np.ndarray, angle: float, bend: float, l0: float, l1: float) -> tuple[np.ndarray, np.ndarray]:
    """Joint positions (middle, end) of a limb hanging from ``top``; angles in radians, + = forward (+x)."""
    mid = top + l0 * np.array([np.sin(angle), 0.0, -np.cos(angle)])
    end = mid + l1 * np.array([np.sin(angle + bend), 0.0, -np.cos(angle + bend)])
    return mid, end


def _head(h: float, rng: np.random.Generator) -> list[Mesh]:
    centre = np.array([0.01 * h, 0.0, 0.925 * h])
    radii = np.array([0.056, 0.05, 0.066]) * h
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


def person(rng: np.random.Generator, height: float, pose: str = "standing") -> Mesh:
    """A pedestrian ``height`` metres tall, facing +x.

    Parameters
    ----------
    rng : numpy.random.Generator
        Build (slim/broad), clothing and stride are drawn from it.
    height : float
        Top of the head, metres (0.9-2.2).
    pose : {"standing", "walking"}
        Walking: legs and arms swing in opposite phase (stride 15-25 degrees).

    Returns
    -------
    Mesh
        Class ``person``; the top of the hair exactly ``height`` above the ground.
    """
    name = pose
    if name not in POSES:
        raise ValueError(f"person pose must be one of {POSES}, got {name!r}")
    if not 0.9 <= height <= 2.2:
        raise ValueError(f"person height must be in [0.9, 2.2] m, got {height}")
    h = 1.0  # build at unit height, scale at the end
    girth = rng.uniform(0.9, 1.15)
    short_sleeves = rng.random() < 0.3
    shorts = rng.random() < 0.2
    swing = np.radians(rng.uniform(15, 25)) * (1 if rng.random() < 0.5 else -1) if name == "walking" else 0.0
    rings = [_ring(0.48 * h, 0.088 * h * girth, 0.06 * h * girth), _ring(0.62 * h, 0.078 * h * girth, 0.058 * h * girth), _ring(0.72 * h, 0.095 * h * girth, 0.066 * h * girth),
             _ring(0.795 * h, 0.11 * h * girth, 0.058 * h * girth), _ring(0.835 * h, 0.045 * h, 0.04 * h)]
    parts = [loft(np.array(rings), CLS, "clothing")] + _head(h, rng)
    for side, phase in ((1.0, 1.0), (-1.0, -1.0)):
        # legs: the side with phase +1 steps forward, the other pushes off with a bent knee
        hip = np.array([0.0, side * 0.052 * h * girth, 0.53 * h])
        leg = phase * swing
        knee, ankle = _limb(hip, leg, -np.radians(22) if leg < 0 else -np.radians(4), 0.245 * h, 0.25 * h)
        parts.append(tube(hip, knee, 0.05 * h * girth, CLS, "clothing", 0.037 * h, sections=6))
        parts.append(tube(knee, ankle + [0, 0, -0.01 * h], 0.035 * h, CLS, "skin" if shorts else "clothing",
                          0.024 * h, sections=6, caps=False))
        parts.append(box((0.15 * h, 0.055 * h, 0.045 * h), CLS, "rubber",
                         (ankle[0] + 0.035 * h, ankle[1], ankle[2] - 0.0225 * h - 0.005 * h)))
        # arms swing against the leg on the same side
        shoulder = np.array([0.0, side * 0.1 * h * girth, 0.79 * h])
        arm = -0.8 * leg
        elbow, wrist = _limb(shoulder, arm, np.radians(rng.uniform(8, 25)), 0.175 * h, 0.15 * h)
        elbow[1] += side * 0.02 * h
        wrist[1] += side * 0.025 * h
        parts.append(tube(shoulder, elbow, 0.032 * h * girth, CLS, "clothing", 0.026 * h, sections=6))
        parts.append(tube(elbow, wrist, 0.025 * h, CLS, "skin" if short_sleeves else "clothing", 0.019 * h,
                          sections=6, caps=False))
        hand = icosphere(1.0, CLS, "skin", 0)
        d = (wrist - elbow) / np.linalg.norm(wrist - elbow)
        hand.vertices = hand.vertices * np.array([0.022, 0.014, 0.045]) * h + wrist + d * 0.035 * h
        parts.append(hand)
    out = on_ground(merge(parts))
    top = float(out.vertices[:, 2].max())
    s = height / top
    return out.transformed(np.diag([s, s, s, 1.0]))
