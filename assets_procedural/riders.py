"""Riders: a cyclist or motorcyclist seated on the two-wheeler they ride.

Riders are built for a particular vehicle: ``bicyclist(rng, ...)`` first draws exactly the
bicycle :func:`assets_procedural.two_wheelers.bicycle` would draw from the same generator
state, then seats a rider on it (pelvis on the saddle, hands on the grips, feet on the pedals;
a cyclist's body height follows the saddle height, as on a fitted bike). The figure uses the
pedestrian's proportions, materials and head (:mod:`assets_procedural.person`); the torso
leans just far enough for the arms to reach the bars; a motorcyclist wears a helmet.

Labels: rider faces are ``bicyclist`` / ``motorcyclist`` (Cityscapes rider), the vehicle's
faces keep ``bicycle`` / ``motorcycle`` (Cityscapes: "bicycle with or without rider").
``ridden(kind, rng, ...)`` returns rider and vehicle as two meshes in one local frame (the
vehicle's: origin at its footprint centre, tyres on z = 0), so a layout can place them as two
objects - two instances, as both datasets count them - under one transform;
``bicyclist(..., with_vehicle=False)`` is the rider alone in that frame.
"""

from __future__ import annotations

import numpy as np

from assets_procedural.motorcycles import _motorcycle_parts
from assets_procedural.parts import centring, two_link
from assets_procedural.person import HIP_Y, _arms_table, _head, _legs_table, torso_sections
from assets_procedural.person_shape import hand, limb, shoe, skin
from assets_procedural.two_wheelers import _bicycle_parts, contact_anchors
from generator.geometry import Mesh, icosphere, merge, pose, resolve_ids


def _rot_y(alpha: float) -> np.ndarray:
    """3x3 rotation about +y: a torso leaning forward (toward +x) by ``alpha`` radians."""
    c, s = np.cos(alpha), np.sin(alpha)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def _lean_for_reach(hip: np.ndarray, shoulder_local: np.ndarray, grip: np.ndarray, reach: float) -> float:
    """Torso lean (radians, -5..75 degrees) that puts the shoulder ``reach`` metres from the grip."""
    def gap(alpha):
        return float(np.linalg.norm(grip - (hip + _rot_y(alpha) @ shoulder_local))) - reach

    lo, hi = np.radians(-5), np.radians(75)
    if gap(lo) <= 0:
        return lo
    if gap(hi) >= 0:
        return hi
    for _ in range(40):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if gap(mid) > 0 else (lo, mid)
    return (lo + hi) / 2


def _figure(rng: np.random.Generator, height: float, seat: np.ndarray, hip_dx: float, grips: list[np.ndarray],
            feet: list[np.ndarray], foot_pitch: float, cls: str, helmet: bool) -> Mesh:
    """A seated person on the seat whose top centre is ``seat``: the pelvis rests on it (hip
    joints ``hip_dx`` ahead of it), hands on ``grips`` (right, left), the balls of the feet on
    ``feet`` (pedal or peg tops, right, left). The torso leans forward just enough for the arms
    to reach the grips; body, limbs, hands and shoes are the pedestrian's shaped parts.
    """
    h = height
    g = float(rng.uniform(0.92, 1.12))
    short_sleeves = rng.random() < 0.3
    arm_reach = 0.9 * (0.175 + 0.15) * h + 0.035 * h
    sh_local = [np.array([0.0, s * 0.1 * h * g, 0.26 * h]) for s in (-1.0, 1.0)]
    rings, mats = torso_sections(g, 1.0, None, "trousers")
    rings = (rings - [0.0, 0.0, 0.53]) * h                       # hip-relative, metres
    hip = np.asarray(seat, float) + np.array([hip_dx, 0.0, 0.06 * h])
    for _ in range(3):
        # lean for the reach, then sit the lowest point of pelvis and thighs 3 mm above the seat
        alpha = _lean_for_reach(hip, sh_local[1], grips[1], arm_reach)
        pelvis = np.concatenate([rings[:2].reshape(-1, 3), rings[:1].mean(1) - [0.0, 0.0, 0.01 * h]]) @ _rot_y(alpha).T
        low = min(float(pelvis[:, 2].min()), -0.053 * h * g)           # the thighs' undersides near the hips
        hip[2] = seat[2] + 0.003 - low
    R = _rot_y(alpha)
    neck_base = hip + R @ np.array([0.0, 0.0, 0.29 * h])
    t = pose(*neck_base, pitch=0.3 * alpha) @ pose(z=-0.82 * h)      # the head's frame: tilted less than the torso
    neck = rings[:, 0, 2] >= 0.31 * h
    rings[~neck] = rings[~neck] @ R.T + hip
    rings[neck] = (rings[neck] + [0.0, 0.0, 0.53 * h]) @ t[:3, :3].T + t[:3, 3]
    parts = [skin(rings, cls, mats, rings[0].mean(0) - R @ [0.0, 0.0, 0.01 * h],
                  rings[-1].mean(0) + [0.0, 0.0, 0.01 * h])]
    cid, _ = resolve_ids(cls, "skin")
    head_parts = [Mesh(m.transformed(t).vertices, m.faces, cid, m.face_material) for m in _head(h, rng)]
    if helmet:
        centre = neck_base + _rot_y(0.3 * alpha) @ np.array([0.01 * h, 0.0, 0.105 * h])
        shell = icosphere(1.0, cls, "car_paint", 1)
        rel = shell.vertices[shell.faces].mean(1)
        keep = rel[:, 2] > -0.45
        visor = keep & (rel[:, 0] > 0.55) & (rel[:, 2] < 0.45) & (rel[:, 2] > -0.2)
        _, glass = resolve_ids(cls, "car_glass")
        mats_h = shell.face_material.copy()
        mats_h[visor] = glass
        shell = Mesh(shell.vertices * np.array([0.075, 0.066, 0.082]) * h, shell.faces[keep], shell.face_class[keep],
                     mats_h[keep])
        shell = shell.transformed(pose(*centre, pitch=0.3 * alpha))
        _, hair_id = resolve_ids(cls, "hair")
        head_parts = [m for m in head_parts if not (m.face_material == hair_id).all()] + [shell]
    parts += head_parts
    leg_t, leg_m = _legs_table("trousers")
    arm_t, arm_m = _arms_table(short_sleeves, False)
    leg_t, arm_t = leg_t * [1.0, g * h, g * h, g * h], arm_t * [1.0, g * h, g * h, g * h]
    leg_t[:, 2] *= np.interp(leg_t[:, 0], [0.3, 0.7], [0.8, 1.0])   # a seated thigh flattens on the saddle
    y = np.array([0.0, 1.0, 0.0])
    for k, s in enumerate((-1.0, 1.0)):
        hip_s = hip + np.array([0.0, s * HIP_Y * h * g, 0.0])
        # foot: the ball of the foot on the support, toes forward, heel behind and above it
        fdir = np.array([np.cos(foot_pitch), 0.0, -np.sin(foot_pitch)])
        up = np.array([np.sin(foot_pitch), 0.0, np.cos(foot_pitch)])
        ankle = feet[k] - 0.03 * h * fdir + 0.055 * h * up + np.array([0.0, 0.0, 0.01])
        knee, ankle = two_link(hip_s, ankle, 0.245 * h, 0.25 * h, np.array([1.0, s * 0.25, 0.6]))
        parts += [limb(np.stack([hip_s, knee, ankle]), leg_t, y, cls, leg_m),
                  shoe(ankle, foot_pitch, cls, "shoes", h)]
        shoulder = hip + R @ sh_local[k]
        grip = grips[k]
        wrist_t = grip - 0.035 * h * (grip - shoulder) / np.linalg.norm(grip - shoulder)
        elbow, wrist = two_link(shoulder, wrist_t, 0.175 * h, 0.15 * h, np.array([-0.3, s * 0.8, -1.0]))
        parts += [limb(np.stack([shoulder, elbow, wrist]), arm_t, y, cls, arm_m),
                  hand(wrist, elbow, s, cls, "skin" if not helmet else "rubber", 0.5, h)]   # gloves with a helmet
    return merge(parts)


def _rider_height_for(info: dict) -> float:
    """Body height whose legs just reach the bicycle's pedals at the bottom of the stroke (about
    a 25-degree knee bend there), from the saddle height: a fitted bike."""
    bb, saddle = info["bb"], info["saddle"]
    h = 1.75
    for _ in range(4):
        hip = saddle + np.array([-0.02, 0.0, 0.057 * h])
        worst = 0.0
        for a in np.linspace(0, 2 * np.pi, 24, endpoint=False):
            pedal = bb + 0.17 * np.array([np.cos(a), 0.0, np.sin(a)])
            fdir = np.array([np.cos(0.3), 0.0, -np.sin(0.3)])
            up = np.array([np.sin(0.3), 0.0, np.cos(0.3)])
            ankle = pedal + 0.02 * h * fdir + 0.025 * h * up - 0.05 * h * fdir + 0.03 * h * up
            worst = max(worst, float(np.linalg.norm(ankle - hip)))
        h = worst / (0.93 * 0.495)
    return float(np.clip(h, 1.45, 2.05))


def ridden(kind: str, rng: np.random.Generator, style: str | None = None,
           height: float | None = None) -> tuple[Mesh, Mesh]:
    """A rider and the two-wheeler they ride, as two meshes in one local frame.

    Parameters
    ----------
    kind : {"bicyclist", "motorcyclist"}
    rng : numpy.random.Generator
        The vehicle is drawn first, exactly as :func:`bicycle` / :func:`motorcycle` would draw
        it from the same state; then the rider.
    style : str, optional
        Vehicle style (see :func:`bicycle`, :func:`motorcycle`).
    height : float, optional
        Rider height, metres. A cyclist's height otherwise follows the saddle height (a fitted
        bike); a motorcyclist's is drawn (1.6-1.9 m).

    Returns
    -------
    (rider, vehicle) : Mesh, Mesh
        Rider faces class ``bicyclist`` / ``motorcyclist``; vehicle faces ``bicycle`` /
        ``motorcycle``. The frame is the vehicle's own (origin at its footprint centre, tyres on
        z = 0), so ``vehicle`` equals the parked vehicle drawn from the same generator state.
    """
    if kind == "bicyclist":
        parts, info = _bicycle_parts(rng, style)
        h = _rider_height_for(info) if height is None else float(height)
        rider = _figure(rng, h, info["saddle"], -0.02, info["grips"], info["pedals"], 0.3, "bicyclist",
                        helmet=rng.random() < 0.5)
        vehicle = merge(parts)
        vehicle.anchors = contact_anchors(info)
    elif kind == "motorcyclist":
        parts, info = _motorcycle_parts(rng, style)
        h = float(rng.uniform(1.6, 1.9)) if height is None else float(height)
        pitch = 0.05 if info["style"] == "scooter" else 0.15
        rider = _figure(rng, h, info["saddle"], 0.0, info["grips"], info["feet"], pitch, "motorcyclist", helmet=True)
        vehicle = merge(parts)
        vehicle.anchors = {"headlight": info["headlight"][None], "taillight": info["taillight"][None],
                           **contact_anchors(info)}
    else:
        raise ValueError(f"ridden kind must be 'bicyclist' or 'motorcyclist', got {kind!r}")
    t = centring(vehicle)
    return rider.transformed(t), vehicle.transformed(t)


def bicyclist(rng: np.random.Generator, style: str | None = None, height: float | None = None,
              with_vehicle: bool = True) -> Mesh:
    """A cyclist riding a bicycle (faces ``bicyclist`` and ``bicycle``), or the rider alone.

    See :func:`ridden`; ``with_vehicle=False`` returns only the rider, in the frame of the
    bicycle ``bicycle(rng, style)`` draws from the same generator state.
    """
    rider, vehicle = ridden("bicyclist", rng, style, height)
    return merge([rider, vehicle]) if with_vehicle else rider


def motorcyclist(rng: np.random.Generator, style: str | None = None, height: float | None = None,
                 with_vehicle: bool = True) -> Mesh:
    """A motorcyclist (helmet) on a motorcycle or scooter (faces ``motorcyclist`` and
    ``motorcycle``), or the rider alone; see :func:`ridden`."""
    rider, vehicle = ridden("motorcyclist", rng, style, height)
    if not with_vehicle:
        return rider
    out = merge([rider, vehicle])
    out.anchors = dict(vehicle.anchors)
    return out
